#pragma once
// The estimated load of a canopen bus per SYNC cycle, from its plan (what --check-config prints,
// and what makes a plan that cannot fit on the wire an error: bus_type.cpp).
#include <string>

#include "adapters/canopen/wire/bus_load.hpp"
#include "config/canopen/plan.hpp"

namespace drivegate::canopen {

BusTraffic plan_traffic(const config::BusPlan& bus);
CycleLoad plan_cycle_load(const config::BusPlan& bus);
// "52 frames, 6950 bits = 13.9 ms per 20 ms SYNC cycle at 500 kbit/s (69 %)"
std::string describe_cycle_load(const config::BusPlan& bus, const CycleLoad& load);

// A load above this share of the cycle leaves too little room for SDO, EMCY and retries: warned.
inline constexpr double kCycleLoadWarning = 0.7;

}  // namespace drivegate::canopen
