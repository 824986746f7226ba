#pragma once
// The per-axis `profinet:` section (axes on a profinet bus: PROFIdrive drives) and the checks of
// the whole bus: the device has a profidrive section and offers the telegram, the bus updates
// often enough for it, the telegram can do the homing and modes asked for, and every station is
// used by one axis or IO device.
#include <filesystem>

#include "config/bus_types.hpp"
#include "config/plan.hpp"
#include "config/profinet/plan.hpp"
#include "config/yaml_reader.hpp"

namespace drivegate::config {

void read_profinet_axis(const MapReader& axis, const BusPlan& bus, const DeviceProfile* device,
                        const std::filesystem::path& base_dir, AxisPlan& a);
void check_profinet_stations(const BusPlan& bus, const BusEntry& at);

}  // namespace drivegate::config
