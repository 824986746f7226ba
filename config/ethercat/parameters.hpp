#pragma once
// The parameters of an axis on an ethercat bus by name or object (client parameter requests): names
// are the object names of the axis' ESI (case-insensitive; "OBJECT:SUB" for a sub-item); the type
// comes from the ESI, else from the device profile's PDO maps and start-up writes.
#include <string_view>

#include "config/bus_types.hpp"

namespace drivegate::config {

ParameterRef find_ethercat_parameter(const AxisPlan& axis, std::string_view name, cia402::ObjectId id);

}  // namespace drivegate::config
