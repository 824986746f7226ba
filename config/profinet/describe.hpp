#pragma once
// The `profinet` rows of the --check-config printout: the timing, the stations with their IP
// suites, each AR's IOCRs (proposed frame IDs, C_SDU lengths, update and watchdog time), the IO
// devices; per axis its station and telegram with the word layout.
#include "config/bus_types.hpp"
#include "config/profinet/wire_rules.hpp"

namespace drivegate::config {

void describe_profinet_bus(const ProfinetWireRules& rules, const BusPlan& bus, DescribeRows& rows);
void describe_profinet_axis(const BusPlan& bus, const AxisPlan& axis, DescribeRows& rows);

}  // namespace drivegate::config
