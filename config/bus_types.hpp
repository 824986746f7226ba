#pragma once
// The bus types the configuration knows, each registered once with everything that is its own:
// its schema (address and cycle ranges, option keys, the axis and device profile sections it
// owns), the readers and checks of those, its rows of the --check-config printout, the factory
// that builds the bus and the scanner that looks for devices on it. The loader, the plan, the
// printout and the daemon's bus factory know no bus type; they go through these entries.
// A type without an adapter in this build is known (so its configs get a clear "not in this
// build" instead of a typo hint) but not available.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "config/plan.hpp"
#include "config/yaml_reader.hpp"
#include "core/bus.hpp"
#include "core/param_value.hpp"
#include "core/scan.hpp"
#include "profiles/cia402/objects.hpp"

namespace drivegate::config {

// Choice: a string out of `choices` (stored as that string).
enum class OptionKind : std::uint8_t { Integer, Number, Boolean, String, Duration, Choice };

struct OptionSpec {
  std::string name;
  OptionKind kind = OptionKind::Integer;
  double min = 0;  // Integer and Number; Duration: seconds (both 0: any duration > 0 up to 1 h;
                   // a negative min: zero or more)
  double max = 0;
  OptionValue default_value;
  std::string help;
  std::vector<std::string> choices;  // Choice only
};

// "label: value" rows of the --check-config printout.
using DescribeRows = std::vector<std::pair<std::string, std::string>>;

// A bus entry of the file, for checks of the whole bus with its axes.
struct BusEntry {
  const Source& source;
  YAML::Mark mark;
  std::string path;  // "buses[0]"
};

// A parameter of an axis as its bus type resolves it (a client's parameter request).
struct ParameterRef {
  std::optional<cia402::ObjectId> id;  // none: not a parameter of the axis (`error` says why)
  core::ParamType type = core::ParamType::Unknown;  // Unknown: the bus type does not know it
  std::string type_source;  // where `type` comes from ("the EDS", "device profile kollmorgen-akd")
  std::string error;
  // `error` says only that the type's files do not know the name: the bus may still know it from
  // the device itself (core::Bus::find_object).
  bool name_unknown = false;
};

// Looks for devices on a bus of this type (`drivegated --scan TYPE:WHERE`, daemon/scan.hpp): `plan`
// reads WHERE into a bus plan (through the type's own option reader, so a scan and a file agree);
// the caller then holds the bus (`resource`, as a gateway does) and calls `run`, which only reads
// from the devices (but for the write actions of a scanner that `writes`). Both throw
// core::ScanError or core::BusError with one line a person can act on.
class BusTypeRegistry;
struct BusScanner {
  // `types`: the bus types of the caller (the daemon's registry), for the plan and the device profiles.
  std::function<BusPlan(const core::ScanRequest& request, const BusTypeRegistry& types)> plan;
  std::function<core::ScanResult(const BusPlan& bus, const core::ScanRequest& request, const BusTypeRegistry& types)>
      run;
  // Takes ScanRequest::actions (its `plan` checks them, its `run` does them); a scanner that does
  // not is not given any.
  bool writes = false;
  [[nodiscard]] explicit operator bool() const noexcept { return plan && run; }
};

struct BusTypeInfo {
  std::string name;
  std::int64_t min_address = 1;
  std::int64_t max_address = 127;
  std::vector<OptionSpec> options;
  std::string axis_section;  // per-axis section only axes on this bus type may have ("sim")
  std::string address_words = "an integer";  // what an address is, for messages ("a CANopen node-ID")
  core::Duration min_cycle_time = std::chrono::microseconds(100);
  core::Duration max_cycle_time = std::chrono::seconds(1);
  std::string address_name = "address";  // in messages and the printout ("node-ID")
  bool reused_address_names_axes = false;  // an address given twice names both axes
  std::string device_section;  // the device profile section of this type ("canopen"); empty: none
  // Its drives are CiA 402 drives, so a profile with its section needs a CiA 402 cyclic image
  // (controlword, statusword, the cyclic modes' targets); false for PROFIdrive.
  bool cia402_device = true;
  std::vector<std::string> bus_keys;  // keys of the bus entry besides the common ones ("io"), for read_bus
  // The key under which two axes of one bus may not share an address; empty: the address. (An
  // EtherCAT slave with several axes carries them at one position, told apart by their section.)
  std::function<std::string(const AxisPlan& axis)> address_key;

  // Each of these may be empty. After the generic reading filled bus.options: checks across
  // options, and the typed options into bus.sections. `bus_map` is the buses[] entry, `options` its
  // options map (possibly absent).
  std::function<void(const MapReader& bus_map, const MapReader& options, BusPlan& bus)> read_bus;
  // The axes[] entry's `axis_section` into a.sections, checked against its bus and device (null
  // when unknown or broken, already reported). Relative paths start at `base_dir`.
  std::function<void(const MapReader& axis, const BusPlan& bus, const DeviceProfile* device,
                     const std::filesystem::path& base_dir, AxisPlan& a)>
      read_axis;
  // The `device_section` of the profile `root` (called when present) into profile.sections.
  std::function<void(const MapReader& root, DeviceProfile& profile)> read_device;
  // The objects the section maps cyclically (its PDOs, outputs first); empty: it maps none. A
  // profile without cyclic_objects gets them from the first section that maps any, and every such
  // section must map exactly the profile's cyclic objects (config/device_profile.cpp).
  std::function<std::vector<cia402::ObjectId>(const DeviceProfile& profile)> mapped_objects;
  // Checks of a bus with all its axes, reported at its entry, in order.
  std::vector<std::function<void(const BusPlan& bus, const BusEntry& at)>> check_bus;
  // The printout: a bus' rows after its options, in order; an axis' rows after the common ones.
  std::vector<std::function<void(const BusPlan& bus, DescribeRows& rows)>> describe_bus;
  std::function<void(const BusPlan& bus, const AxisPlan& axis, DescribeRows& rows)> describe_axis;
  // A parameter of an axis on this bus type, by `name` when not empty, else by `id`.
  std::function<ParameterRef(const AxisPlan& axis, std::string_view name, cia402::ObjectId id)> find_parameter;
  // What a bus holds on this machine, so a second gateway on it is refused ("canopen socketcan
  // can0"); empty: nothing.
  std::function<std::string(const BusPlan& bus)> resource;
  // The adapter: builds the bus. Throws core::BusError.
  std::function<std::unique_ptr<core::Bus>(const BusPlan& bus)> make_bus;
  BusScanner scan;  // empty: the type cannot scan
  // An adapter for it is linked in: it can make its buses.
  [[nodiscard]] bool available() const noexcept { return static_cast<bool>(make_bus); }
};

class BusTypeRegistry {
 public:
  // The bus types of this build, with their adapters. Defined where the adapters are assembled,
  // daemon/bus_types.cpp (library drivegate_bus_types): config/ knows no adapter.
  static BusTypeRegistry builtin();
  void add(BusTypeInfo info);  // replaces an entry with the same name
  // The entry, shared with the plans of buses of this type; null when unknown.
  [[nodiscard]] std::shared_ptr<const BusTypeInfo> find(std::string_view name) const noexcept;
  [[nodiscard]] const std::vector<std::shared_ptr<const BusTypeInfo>>& types() const noexcept { return types_; }
  [[nodiscard]] std::vector<std::string> names() const;
  [[nodiscard]] std::vector<std::string> available_names() const;
  // Per-axis sections of all types ("sim"), so an axis key can be told apart from a typo.
  [[nodiscard]] std::vector<std::string> axis_sections() const;
  // Device profile sections of all types ("canopen"), likewise for profile keys.
  [[nodiscard]] std::vector<std::string> device_sections() const;

 private:
  std::vector<std::shared_ptr<const BusTypeInfo>> types_;
};

}  // namespace drivegate::config
