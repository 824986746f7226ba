#pragma once
// The per-axis `canopen:` section (axes on a canopen bus) and the checks such an axis needs: its
// device has a canopen section, its node-ID is not the gateway's, its SDO channel exists and
// fits its node-ID, the device's PDO maps and start-up writes agree with its EDS, and the bus
// produces the SYNC the device's synchronous PDOs need.
#include <filesystem>

#include "config/canopen/plan.hpp"
#include "config/plan.hpp"
#include "config/yaml_reader.hpp"

namespace drivegate::config {

// `axis` is the axes[] entry; `device` may be null (unknown or broken profile, already reported).
// Relative EDS paths start at `base_dir` (the config file's directory).
void read_canopen_axis(const MapReader& axis, const BusPlan& bus, const DeviceProfile* device,
                       const std::filesystem::path& base_dir, AxisPlan& a);

}  // namespace drivegate::config
