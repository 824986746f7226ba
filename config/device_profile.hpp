#pragma once
// Device profiles (profiles/devices/<name>.yaml, schema in profiles/devices/README.md): parsing,
// and the catalog that finds them by name in a list of directories.
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "config/bus_types.hpp"
#include "config/config_error.hpp"
#include "config/plan.hpp"

namespace drivegate::config {

// Quirk flags code knows how to honour; any other name in a profile is an error.
const std::vector<std::string>& known_quirks();

// The directories built in at compile time: the source tree's profiles/devices (so binaries in
// the build tree see current profiles) and the installed data directory.
std::vector<std::filesystem::path> default_device_dirs();

// Parses one profile, with the sections of the bus types in `types`; its problems go to `problems`
// and the result is nullopt if there were any.
std::optional<DeviceProfile> parse_device_profile(const std::filesystem::path& file, Problems& problems,
                                                  const BusTypeRegistry& types = BusTypeRegistry::builtin());
// The same, throwing ConfigError.
DeviceProfile load_device_profile(const std::filesystem::path& file,
                                  const BusTypeRegistry& types = BusTypeRegistry::builtin());

class DeviceCatalog {
 public:
  // `types` must outlive the catalog.
  DeviceCatalog(std::vector<std::filesystem::path> dirs, const BusTypeRegistry& types)
      : dirs_(std::move(dirs)), types_(types) {}
  // The first <dir>/<name>.yaml in search order, if any.
  [[nodiscard]] std::optional<std::filesystem::path> locate(const std::string& name) const;
  // Loads (once) and returns the profile; nullptr when it is not found or broken. A broken file's
  // problems are reported to `problems` the first time only.
  const DeviceProfile* get(const std::string& name, Problems& problems);
  // Names of all profiles in the search directories, sorted.
  [[nodiscard]] std::vector<std::string> available() const;
  [[nodiscard]] const std::vector<std::filesystem::path>& dirs() const noexcept { return dirs_; }

 private:
  std::vector<std::filesystem::path> dirs_;
  const BusTypeRegistry& types_;
  std::map<std::string, std::optional<DeviceProfile>> cache_;
};

}  // namespace drivegate::config
