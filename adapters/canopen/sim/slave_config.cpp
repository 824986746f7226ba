// Building a simulated drive's configuration (slave_config.hpp).
#include "adapters/canopen/sim/slave_config.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "adapters/canopen/wire/pdo_mapping.hpp"
#include "adapters/sim/sim_bus.hpp"

namespace drivegate::canopen::sim {
namespace {

void from_table(std::span<const PdoDefault> table, bool receive, NodeId node, const Persona& persona,
                std::array<SlavePdoConfig, 4>& out) {
  for (std::size_t n = 0; n < out.size(); ++n) {
    const int pdo = static_cast<int>(n);
    auto& c = out[n];
    c.cob_id = receive ? cob::rpdo(pdo, node) : cob::tpdo(pdo, node);
    if (n >= table.size()) {
      c.cob_id |= cob::kInvalid;
      c.transmission_type = persona.pdo.transmission_types.unused();
      continue;
    }
    const auto& d = table[n];
    if (!d.valid) c.cob_id |= cob::kInvalid;
    c.transmission_type = d.transmission_type;
    c.mapping = d.mapping;
    c.count = static_cast<std::uint8_t>(std::count_if(d.mapping.begin(), d.mapping.end(), [](auto e) { return e != 0; }));
  }
}

void from_profile(std::span<const config::PdoSpec> specs, bool receive, NodeId node, const Persona& persona,
                  std::array<SlavePdoConfig, 4>& out) {
  for (std::size_t n = 0; n < out.size(); ++n) {
    const int pdo = static_cast<int>(n);
    out[n].cob_id = (receive ? cob::rpdo(pdo, node) : cob::tpdo(pdo, node)) | cob::kInvalid;
    out[n].transmission_type = persona.pdo.transmission_types.unused();
  }
  for (const auto& spec : specs) {
    if (spec.number < 1 || spec.number > 4 || spec.entries.size() > 8 || spec.transmission_type < 0 ||
        spec.transmission_type > 255) {
      throw std::invalid_argument("PDO " + std::to_string(spec.number) + " cannot exist on a CANopen slave");
    }
    auto& c = out[static_cast<std::size_t>(spec.number - 1)];
    c.cob_id &= ~cob::kInvalid;
    c.transmission_type = static_cast<std::uint8_t>(spec.transmission_type);
    c.inhibit_time = static_cast<std::uint16_t>(std::clamp(spec.inhibit_time_100us, 0, 65535));
    c.event_timer = static_cast<std::uint16_t>(std::clamp(spec.event_timer_ms, 0, 65535));
    c.count = static_cast<std::uint8_t>(spec.entries.size());
    for (std::size_t e = 0; e < spec.entries.size(); ++e) {
      c.mapping[e] = encode_mapping({spec.entries[e].object, spec.entries[e].bits});
    }
  }
}

}  // namespace

SlaveNodeConfig make_slave_config(NodeId node, const Persona& persona, cia402::sim::DriveModelConfig drive,
                                  std::span<const config::PdoSpec> profile_rpdos,
                                  std::span<const config::PdoSpec> profile_tpdos) {
  if (!valid_node_id(node)) throw std::invalid_argument("node-ID " + std::to_string(node) + " is not 1..127");
  SlaveNodeConfig c;
  c.node = node;
  c.persona = persona;
  if (persona.device_type) drive.device_type = *persona.device_type;
  if (persona.vendor_id) drive.identity.vendor_id = *persona.vendor_id;
  if (persona.product_code) drive.identity.product_code = *persona.product_code;
  if (persona.revision) drive.identity.revision = *persona.revision;
  // The model refuses a start-up mode it does not support; a drive without that mode keeps its own.
  if (persona.initial_mode &&
      std::find(drive.supported_modes.begin(), drive.supported_modes.end(), *persona.initial_mode) !=
          drive.supported_modes.end()) {
    drive.initial_mode = *persona.initial_mode;
  }
  c.drive = std::move(drive);
  if (persona.pdo_defaults_from_profile) {
    from_profile(profile_rpdos, true, node, persona, c.rpdos);
    from_profile(profile_tpdos, false, node, persona, c.tpdos);
  } else {
    from_table(persona.rpdo_defaults, true, node, persona, c.rpdos);
    from_table(persona.tpdo_defaults, false, node, persona, c.tpdos);
  }
  return c;
}

SlaveNodeConfig slave_config_for(const config::AxisPlan& axis) {
  const auto& dev = axis.device.section<config::CanopenDeviceSpec>();
  auto drive = drivegate::sim::drive_config_for(axis);
  // The profile's expected device type is what a drive of that kind reports, unless the persona
  // is a drive with a type of its own.
  if (dev.device_type) drive.device_type = *dev.device_type;
  if (axis.address < kMinNodeId || axis.address > kMaxNodeId) {
    throw std::invalid_argument("axis \"" + axis.spec.name + "\": node-ID " + std::to_string(axis.address) +
                                " is not 1..127");
  }
  return make_slave_config(static_cast<NodeId>(axis.address), persona_for(dev.persona), std::move(drive), dev.rpdos,
                           dev.tpdos);
}

}  // namespace drivegate::canopen::sim
