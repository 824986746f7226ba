// No work: (b) then measures what CycleThread adds over a bare sleep loop.
#include "bench/workload.hpp"

namespace drivegate::bench {

std::function<void(core::TimePoint, std::uint64_t)> make_workload(int /*argc*/, char** /*argv*/) {
  return [](core::TimePoint, std::uint64_t) {};
}

}  // namespace drivegate::bench
