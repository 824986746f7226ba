#pragma once
// The checked, compiled form of a configuration file: everything the daemon needs to build its
// buses and axes, with every value validated and converted (see config/README.md for the file).
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "core/axis_spec.hpp"
#include "core/axis_types.hpp"
#include "core/clock.hpp"
#include "core/units.hpp"
#include "profiles/cia402/objects.hpp"

namespace drivegate::config {

struct GatewayPlan {
  std::string name;
  int domain = 0;
  std::string ns = "drivegate";  // DDS topic name prefix
  std::string log_level = "info";
  double status_rate_hz = 50;
  std::vector<std::string> device_dirs;  // from the file, made absolute
};

// How a device profile states its native units (profiles/devices/README.md): what one drive unit
// is measured against.
enum class UnitBase : std::uint8_t {
  Fixed,          // a fixed number of drive units per motor rev (rev/s, rev/s^2, rated torque)
  EncoderCounts,  // position: the axis' encoder_counts_per_rev per motor rev
  Position,       // velocity/acceleration: drive position units per s (per s^2)
  Velocity,       // acceleration: drive velocity units per s
};

struct NativeUnitsSpec {
  UnitBase position_base = UnitBase::EncoderCounts;
  double position_per_rev = 0;  // when Fixed
  UnitBase velocity_base = UnitBase::Position;
  double velocity_per_rps = 0;  // when Fixed
  UnitBase acceleration_base = UnitBase::Position;
  double acceleration_per_rps2 = 0;  // when Fixed
  double torque_per_rated = 1000;  // CiA 402 default: per mille of rated torque
  // The drive units for an axis with this encoder resolution (counts per motor revolution).
  [[nodiscard]] core::NativeUnits resolve(double encoder_counts_per_rev) const noexcept;
};

struct DeviceIdentity {
  std::optional<std::uint32_t> vendor_id;
  std::optional<std::uint32_t> product_code;
};

struct DeviceProfile {
  std::string name;
  std::string vendor;
  std::string description;
  std::string file;  // where it was loaded from
  DeviceIdentity identity;
  core::ModeSet modes;
  NativeUnitsSpec units;
  std::vector<std::int16_t> homing_methods;
  std::map<std::uint32_t, std::string> fault_texts;
  std::map<std::string, bool> quirks;  // only names from known_quirks()
  std::vector<cia402::ObjectId> cyclic_objects;
  [[nodiscard]] bool quirk(const std::string& flag) const {
    const auto it = quirks.find(flag);
    return it != quirks.end() && it->second;
  }
};

// Settings of the built-in simulated drive for one axis (the `sim:` section), already converted
// from user units to the drive's units so the drive model never sees user units.
struct SimAxisOptions {
  double start_position = 0;  // drive position units
  std::optional<double> home_switch_position;            // drive position units; none = no switch
  std::optional<double> negative_limit_switch_position;  // drive position units
  std::optional<double> positive_limit_switch_position;  // drive position units
  double max_velocity = 0;      // drive velocity units: the motor's top speed
  double max_acceleration = 0;  // drive acceleration units
};

struct AxisPlan {
  core::AxisSpec spec;
  int address = 0;
  DeviceProfile device;
  core::Mechanics mechanics;
  core::NativeUnits native;
  double encoder_counts_per_rev = 0;
  SimAxisOptions sim;  // meaningful for axes on a sim bus only
};

// A bus-type option value after validation (see BusTypeRegistry for which keys a type takes).
using OptionValue = std::variant<std::int64_t, double, bool, std::string, core::Duration>;

// Options of the `sim` bus type.
struct SimBusOptions {
  int acyclic_latency_cycles = 1;  // cycles before an acyclic request is answered
};

struct BusPlan {
  std::string name;
  std::string type;
  core::Duration cycle_time = std::chrono::milliseconds(1);
  int priority = 0;  // SCHED_FIFO 1..99; 0 = normal scheduling
  int cpu = -1;      // CPU affinity; -1 = any
  std::map<std::string, OptionValue> options;  // every option of the type, defaults filled in
  SimBusOptions sim;  // the typed view of `options` when type == "sim"
  std::vector<AxisPlan> axes;
};

struct Plan {
  std::string file;
  GatewayPlan gateway;
  std::vector<BusPlan> buses;
  std::vector<std::string> warnings;  // "FILE:LINE:COL: PATH: message"
};

}  // namespace drivegate::config
