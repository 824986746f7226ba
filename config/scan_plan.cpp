#include "config/scan_plan.hpp"

#include <algorithm>
#include <sstream>

namespace drivegate::config {

std::vector<std::pair<std::string, std::string>> scan_where_options(const std::string& where) {
  std::vector<std::pair<std::string, std::string>> options;
  const auto q = where.find('?');
  if (q == std::string::npos) return options;
  std::istringstream in(where.substr(q + 1));
  for (std::string item; std::getline(in, item, '&');) {
    const auto eq = item.find('=');
    if (eq == std::string::npos || eq == 0) throw core::ScanError("option \"" + item + "\" is not KEY=VALUE");
    options.emplace_back(item.substr(0, eq), item.substr(eq + 1));
  }
  return options;
}

bool scan_plain_value(const std::string& v) noexcept {
  return !v.empty() && std::all_of(v.begin(), v.end(), [](char c) {
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '.' || c == '_' ||
           c == '-' || c == '@';
  });
}

BusPlan scan_bus_plan(const std::string& yaml, const core::ScanRequest& request, const BusTypeRegistry& types) {
  const LoadOptions load{.device_dirs = request.device_dirs, .bus_types = types};
  try {
    auto plan = load_plan_from_string(yaml, "scan", load);
    return std::move(plan.buses.at(0));
  } catch (const ConfigError& e) {
    std::string what;
    for (const auto& d : e.problems()) {
      const auto dot = d.path.rfind('.');
      what += (what.empty() ? "" : "; ") + (dot == std::string::npos ? d.path : d.path.substr(dot + 1)) + " " +
              d.message;
    }
    throw core::ScanError(what);
  }
}

std::vector<DeviceProfile> scan_device_profiles(const std::vector<std::filesystem::path>& dirs,
                                                const BusTypeRegistry& types,
                                                const std::function<bool(const DeviceProfile&)>& wanted,
                                                std::vector<std::string>& notes) {
  DeviceCatalog catalog(dirs, types);
  std::vector<DeviceProfile> out;
  Problems problems;
  for (const auto& name : catalog.available())
    if (const auto* p = catalog.get(name, problems); p != nullptr && wanted(*p)) out.push_back(*p);
  for (const auto& e : problems.errors()) notes.push_back("device profile not used: " + e.to_string());
  return out;
}

}  // namespace drivegate::config
