#pragma once
// What every bus type's scanner (`drivegated --scan TYPE:WHERE`, config/bus_types.hpp BusScanner)
// does with the configuration: read WHERE's options, turn them into a bus plan through the type's
// own option reader (a generated file, so a scan and a file agree), and pick the device profiles
// that have the type's section.
#include <filesystem>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "config/device_profile.hpp"
#include "config/loader.hpp"
#include "core/scan.hpp"

namespace drivegate::config {

// WHERE's options, "?key=value&key=value", in order. Throws core::ScanError for an item that is
// not KEY=VALUE.
std::vector<std::pair<std::string, std::string>> scan_where_options(const std::string& where);

// Whether `v` can go into the generated YAML as it is: letters, digits, '.', '_', '-' and '@'.
bool scan_plain_value(const std::string& v) noexcept;

// The one bus of `yaml` (a whole configuration with `axes: []`) as the loader reads it with the
// request's device directories and `types`. Throws core::ScanError with the loader's problems,
// each as "KEY MESSAGE", joined by "; ".
BusPlan scan_bus_plan(const std::string& yaml, const core::ScanRequest& request, const BusTypeRegistry& types);

// The device profiles in `dirs` for which `wanted` is true, in name order; broken ones are left out
// with a note ("device profile not used: ...") in `notes`.
std::vector<DeviceProfile> scan_device_profiles(const std::vector<std::filesystem::path>& dirs,
                                                const BusTypeRegistry& types,
                                                const std::function<bool(const DeviceProfile&)>& wanted,
                                                std::vector<std::string>& notes);

}  // namespace drivegate::config
