#pragma once
// The work bench_cycle_timing runs inside its CycleThread, chosen at link time: workload_empty.cpp
// (no work: the cost of the cycle thread itself) or a workload that drives real bus engines. It
// receives the benchmark's whole command line and ignores options it does not know.
#include <cstdint>
#include <functional>

#include "core/clock.hpp"

namespace drivegate::bench {

// Called once before timing starts (may allocate and set things up). The returned body runs on
// the cycle thread and must follow the cycle-thread rules: no allocation, lock or blocking I/O.
std::function<void(core::TimePoint, std::uint64_t)> make_workload(int argc, char** argv);

}  // namespace drivegate::bench
