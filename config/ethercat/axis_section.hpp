#pragma once
// The per-axis `ethercat:` section (axes on an ethercat bus) and the checks of the whole bus: the
// device has an ethercat section, the axis index fits the slave, the axes that share a slave
// share its device, I/O slaves and drives do not share a position.
#include <filesystem>
#include <string>

#include "config/bus_types.hpp"
#include "config/ethercat/plan.hpp"
#include "config/plan.hpp"
#include "config/yaml_reader.hpp"

namespace drivegate::config {

void read_ethercat_axis(const MapReader& axis, const BusPlan& bus, const DeviceProfile* device,
                        const std::filesystem::path& base_dir, AxisPlan& a);
// "3" for the first axis of the slave at position 3, "3 axis 2" for its third.
std::string ethercat_address_key(const AxisPlan& a);
void check_ethercat_slaves(const BusPlan& bus, const BusEntry& at);

}  // namespace drivegate::config
