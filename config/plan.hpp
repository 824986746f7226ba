#pragma once
// The checked, compiled form of a configuration file: everything the daemon needs to build its
// buses and axes, with every value validated and converted (see config/README.md for the file).
// Only what every bus type shares is here; a bus type's own parts (its typed options, an axis' and
// a device profile's section of that type) are Sections, defined in its folder (config/canopen/plan.hpp).
#include <any>
#include <cstdint>
#include <map>
#include <memory>
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

struct BusTypeInfo;  // bus_types.hpp

// The parts of a plan that belong to one bus type, each held by its type: a bus' typed options, an
// axis' section, a device profile's section (CanopenBusOptions, SimAxisOptions, CanopenDeviceSpec).
class Sections {
 public:
  // The part of type T, or nullptr.
  template <typename T>
  [[nodiscard]] const T* find() const noexcept {
    for (const auto& p : parts_)
      if (const T* t = std::any_cast<T>(&p)) return t;
    return nullptr;
  }
  // The part of type T; a default-made T when there is none (a profile without that section).
  template <typename T>
  [[nodiscard]] const T& get() const {
    if (const T* t = find<T>()) return *t;
    static const T kAbsent{};
    return kAbsent;
  }
  // The part of type T to fill in; added, default-made, when there is none. The reference holds
  // until another part is added.
  template <typename T>
  T& edit() {
    for (auto& p : parts_)
      if (T* t = std::any_cast<T>(&p)) return *t;
    return std::any_cast<T&>(parts_.emplace_back(std::in_place_type<T>));
  }

 private:
  std::vector<std::any> parts_;
};

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
  // An axis state that did not change is published again after this long (0: at every
  // status_rate_hz period); a change goes out at the next period.
  core::Duration status_keepalive = std::chrono::milliseconds(250);
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
  Sections sections;  // the sections of bus types (`canopen:`): CanopenDeviceSpec
  template <typename T>
  [[nodiscard]] const T& section() const {
    return sections.get<T>();
  }
  // The profile has the bus type's section (`canopen:`) whose part is T.
  template <typename T>
  [[nodiscard]] bool has_section() const noexcept {
    return sections.find<T>() != nullptr;
  }
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
  Sections sections;  // its bus type's section (`sim:`, `canopen:`): SimAxisOptions, CanopenAxisOptions
  template <typename T>
  [[nodiscard]] const T& section() const {
    return sections.get<T>();
  }
};

// A bus-type option value after validation (see BusTypeRegistry for which keys a type takes).
using OptionValue = std::variant<std::int64_t, double, bool, std::string, core::Duration>;


struct BusPlan {
  std::string name;
  std::string type;
  core::Duration cycle_time = std::chrono::milliseconds(1);
  int priority = 0;  // SCHED_FIFO 1..99; 0 = normal scheduling
  int cpu = -1;      // CPU affinity; -1 = any
  std::map<std::string, OptionValue> options;  // every option of the type, defaults filled in
  Sections sections;  // the typed view of `options`: SimBusOptions, CanopenBusOptions
  std::vector<AxisPlan> axes;
  // The type it was read as: its readers, printout rows, factory (null when the type is unknown).
  std::shared_ptr<const BusTypeInfo> type_info;
  template <typename T>
  [[nodiscard]] const T& section() const {
    return sections.get<T>();
  }
};

struct Plan {
  std::string file;
  GatewayPlan gateway;
  std::vector<BusPlan> buses;
  std::vector<std::string> warnings;  // "FILE:LINE:COL: PATH: message"
};

}  // namespace drivegate::config