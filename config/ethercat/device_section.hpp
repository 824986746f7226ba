#pragma once
// The `ethercat:` section of a device profile (schema in profiles/devices/README.md "EtherCAT").
#include "config/ethercat/plan.hpp"
#include "config/plan.hpp"
#include "config/yaml_reader.hpp"

namespace drivegate::config {

// Reads the `ethercat:` map of the profile `root` into p.sections (EthercatDeviceSpec). Needs
// p.quirks already read.
void read_ethercat_device(const MapReader& root, DeviceProfile& p);
// The objects of its PDOs, RxPDOs first (BusTypeInfo::mapped_objects).
std::vector<cia402::ObjectId> ethercat_mapped_objects(const DeviceProfile& p);

}  // namespace drivegate::config
