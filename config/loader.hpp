#pragma once
// Loading a configuration file into a checked Plan (format: config/README.md).
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "config/bus_types.hpp"
#include "config/config_error.hpp"
#include "config/device_profile.hpp"
#include "config/plan.hpp"

namespace drivegate::config {

struct LoadOptions {
  // Searched after the file's own gateway.device_dirs, in order.
  std::vector<std::filesystem::path> device_dirs = default_device_dirs();
  BusTypeRegistry bus_types = BusTypeRegistry::builtin();
};

// Throws ConfigError listing every problem found ("FILE:LINE:COL: PATH: message", one a line).
// Warnings (e.g. a bus without axes) do not fail the load; they are in Plan::warnings.
Plan load_plan(const std::string& path, const LoadOptions& options = {});
// The same for text in memory; `file_label` names it in messages, and relative device_dirs are
// taken from the label's directory.
Plan load_plan_from_string(std::string_view yaml, std::string_view file_label, const LoadOptions& options = {});

}  // namespace drivegate::config
