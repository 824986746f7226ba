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
#include "config/canopen/plan.hpp"
#include "config/sim/plan.hpp"
#include "core/units.hpp"
#include "profiles/cia402/objects.hpp"

namespace drivegate::config {

// DDS Security files of the gateway (absolute paths; idl/dds_security.hpp says what each is).
struct SecurityPlan {
  std::string identity_ca;
  std::string certificate;
  std::string private_key;
  std::string permissions_ca;
  std::string governance;
  std::string permissions;
};

struct GatewayPlan {
  std::string name;
  int domain = 0;
  std::string ns = "drivegate";  // DDS topic name prefix
  std::string dds_profiles_file;  // Fast DDS XML profiles, absolute; empty: none
  std::string dds_profile;        // participant profile in it; empty: its default profile
  std::vector<std::string> dds_interfaces;  // UDPv4 on these only (names or IPv4 addresses)
  std::optional<SecurityPlan> security;
  // At start-up, how long to listen for another instance of this gateway before any bus opens.
  core::Duration duplicate_check = std::chrono::seconds(2);
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
  CanopenDeviceSpec canopen;
  [[nodiscard]] bool quirk(const std::string& flag) const {
    const auto it = quirks.find(flag);
    return it != quirks.end() && it->second;
  }
};

struct AxisPlan {
  core::AxisSpec spec;
  int address = 0;
  DeviceProfile device;
  core::Mechanics mechanics;
  core::NativeUnits native;
  double encoder_counts_per_rev = 0;
  SimAxisOptions sim;  // meaningful for axes on a sim bus only
  CanopenAxisOptions canopen;  // meaningful for axes on a canopen bus only
};

// The axis' gateway watch: its own option, else its device profile's.
[[nodiscard]] inline GatewayWatch gateway_watch_of(const AxisPlan& a) noexcept {
  return a.canopen.gateway_watch.value_or(a.device.canopen.gateway_watch);
}

// A bus-type option value after validation (see BusTypeRegistry for which keys a type takes).
using OptionValue = std::variant<std::int64_t, double, bool, std::string, core::Duration>;


struct BusPlan {
  std::string name;
  std::string type;
  core::Duration cycle_time = std::chrono::milliseconds(1);
  int priority = 0;  // SCHED_FIFO 1..99; 0 = normal scheduling
  int cpu = -1;      // CPU affinity; -1 = any
  std::map<std::string, OptionValue> options;  // every option of the type, defaults filled in
  SimBusOptions sim;  // the typed view of `options` when type == "sim"
  CanopenBusOptions canopen;  // the typed view of `options` when type == "canopen"
  std::vector<AxisPlan> axes;
};

struct Plan {
  std::string file;
  GatewayPlan gateway;
  std::vector<BusPlan> buses;
  std::vector<std::string> warnings;  // "FILE:LINE:COL: PATH: message"
};

}  // namespace drivegate::config