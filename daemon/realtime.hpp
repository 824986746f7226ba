#pragma once
// Real-time set-up of the process and of cycle threads (DESIGN.md §3). None of these fail hard:
// a gateway on a machine without RT privileges still runs, only with worse timing, and says why.
// Each call returns an empty string when everything was applied, otherwise a message naming what
// is missing (capability, rlimit, systemd setting) so the operator can fix it.
#include <cstddef>
#include <string>

namespace drivegate::daemon {

// mlockall(MCL_CURRENT | MCL_FUTURE): no page faults on the cycle path after start-up.
[[nodiscard]] std::string lock_memory();

// For the calling thread: CPU affinity when cpu >= 0, SCHED_FIFO at priority (1..99) when
// priority > 0, otherwise the thread keeps the normal scheduler. Both are attempted even when
// the first fails; the message then lists every problem.
[[nodiscard]] std::string apply_thread_scheduling(int priority, int cpu);

// Touches kPrefaultStackBytes of the calling thread's stack so that, with memory locked, the
// cycle path never faults in a new stack page.
inline constexpr std::size_t kPrefaultStackBytes = 256 * 1024;
void prefault_stack() noexcept;

}  // namespace drivegate::daemon
