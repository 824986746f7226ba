#pragma once
// A device profile's `profidrive:` section (profiles/devices/README.md "PROFIdrive"): the drive's
// normalisation, its telegrams and fastest update time, checked against the profile's units and modes.
#include <string>
#include <vector>

#include "config/plan.hpp"
#include "config/profinet/plan.hpp"
#include "config/yaml_reader.hpp"

namespace drivegate::config {

// Quirk flags of the profidrive section; any other name is an error.
const std::vector<std::string>& known_profidrive_quirks();

void read_profidrive_device(const MapReader& root, DeviceProfile& profile);

}  // namespace drivegate::config
