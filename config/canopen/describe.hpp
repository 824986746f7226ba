#pragma once
// The `canopen` bus type's rows of the --check-config printout (config/describe.hpp).
#include "config/bus_types.hpp"
#include "config/canopen/plan.hpp"

namespace drivegate::config {

// Link and SYNC of a canopen bus.
void describe_canopen_bus(const BusPlan& bus, DescribeRows& rows);
// Error control, gateway watch, SDO channel, PDO maps, start-up writes, EDS of a canopen axis.
void describe_canopen_axis(const BusPlan& bus, const AxisPlan& axis, DescribeRows& rows);

}  // namespace drivegate::config
