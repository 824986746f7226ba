#pragma once
// The parameters of an axis on a canopen bus by name or object (client parameter requests): names
// are the EDS' ParameterNames first, then the device's parameter naming (SD6 "A83"), so an EDS can
// also name vendor parameters; the type comes from the EDS, else from the device profile's PDO maps
// and start-up writes.
#include <string_view>

#include "config/bus_types.hpp"

namespace drivegate::config {

ParameterRef find_canopen_parameter(const AxisPlan& axis, std::string_view name, cia402::ObjectId id);

}  // namespace drivegate::config
