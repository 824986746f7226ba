#pragma once
// The `ethercat:` section of a device profile (schema in profiles/devices/README.md "EtherCAT").
#include "config/ethercat/plan.hpp"
#include "config/plan.hpp"
#include "config/yaml_reader.hpp"

namespace drivegate::config {

// Reads the `ethercat:` map of the profile `root` into p.sections (EthercatDeviceSpec). Needs
// p.quirks already read. When the profile does not list cyclic_objects they are derived from the
// PDOs; when it does, the PDOs must carry exactly them.
void read_ethercat_device(const MapReader& root, DeviceProfile& p, bool cyclic_given);

}  // namespace drivegate::config
