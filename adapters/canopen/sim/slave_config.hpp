#pragma once
// What one simulated CANopen drive is made of: its node-ID, persona, drive model settings and the
// power-on parameters of its PDOs. Built from a plan's axis (slave_config_for) or by hand in tests
// (make_slave_config); SlaveNode takes it as it is.
#include <array>
#include <span>

#include "adapters/canopen/sim/persona.hpp"
#include "adapters/canopen/sim/slave_pdo.hpp"
#include "adapters/canopen/wire/cob_id.hpp"
#include "config/canopen/plan.hpp"
#include "profiles/cia402/sim/drive_model.hpp"

namespace drivegate::canopen::sim {

struct SlaveNodeConfig {
  NodeId node = 1;
  Persona persona;
  cia402::sim::DriveModelConfig drive;
  std::array<SlavePdoConfig, 4> rpdos{};  // RPDO 1..4 power-on parameters (1400h../1600h..)
  std::array<SlavePdoConfig, 4> tpdos{};  // TPDO 1..4 (1800h../1A00h..)
};

// The drive a persona makes of these settings: its identity and start-up mode applied to `drive`,
// and its PDO defaults (its factory tables, or the device profile's maps when the persona takes
// them: a drive commissioned with them). Throws std::invalid_argument for a node-ID outside
// 1..127 or a PDO number outside 1..4.
SlaveNodeConfig make_slave_config(NodeId node, const Persona& persona, cia402::sim::DriveModelConfig drive,
                                  std::span<const config::PdoSpec> profile_rpdos = {},
                                  std::span<const config::PdoSpec> profile_tpdos = {});

// The simulated drive of a canopen axis: its device profile's persona and PDO maps, the drive
// model from sim::drive_config_for() (adapters/sim/sim_bus.hpp). Throws std::invalid_argument for
// an unknown persona.
SlaveNodeConfig slave_config_for(const config::AxisPlan& axis);

}  // namespace drivegate::canopen::sim
