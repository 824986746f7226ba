#pragma once
// The estimated load of a canopen bus per SYNC cycle, from its plan (what --check-config prints,
// and what makes a plan that cannot fit on the wire an error).
#include <string>

#include "adapters/canopen/wire/bus_load.hpp"
#include "config/plan.hpp"

namespace drivegate::config {

canopen::BusTraffic canopen_traffic(const BusPlan& bus);
canopen::CycleLoad canopen_cycle_load(const BusPlan& bus);
// "52 frames, 6950 bits = 13.9 ms per 20 ms SYNC cycle at 500 kbit/s (69 %)"
std::string describe_canopen_load(const BusPlan& bus, const canopen::CycleLoad& load);

// A load above this share of the cycle leaves too little room for SDO, EMCY and retries: warned.
inline constexpr double kCanopenLoadWarning = 0.7;

}  // namespace drivegate::config
