#pragma once
// Wakes one waiting thread (the DDS bridge) from any other: cycle threads when they queued replies
// or events, DDS listener threads when data arrived. notify() takes no lock and allocates nothing:
// an atomic exchange, and an eventfd write only for the first notify() since the waiter last woke,
// so a cycle thread pays one system call at most per wake-up of the bridge.
#include <sys/eventfd.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>

#include "core/fd_wait.hpp"

namespace drivegate::daemon {

class WakeSignal {
 public:
  WakeSignal() : fd_(::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC)) {
    if (fd_ < 0) throw std::runtime_error(std::string("cannot create an eventfd: ") + std::strerror(errno));
  }
  ~WakeSignal() { ::close(fd_); }
  WakeSignal(const WakeSignal&) = delete;
  WakeSignal& operator=(const WakeSignal&) = delete;

  // Any thread.
  void notify() noexcept {
    if (pending_.exchange(true, std::memory_order_acq_rel)) return;  // the waiter has not woken since
    const std::uint64_t one = 1;
    while (::write(fd_, &one, sizeof one) < 0 && errno == EINTR) {
    }
  }

  // The waiting thread: returns at notify() (also one that came before this call and was not yet
  // consumed) or at `deadline`, whichever is first. Whatever was published before a notify() that
  // this call consumed is visible to the caller afterwards.
  template <typename Clock, typename Duration>
  void wait_until(std::chrono::time_point<Clock, Duration> deadline) noexcept {
    if (!pending_.load(std::memory_order_acquire))
      (void)core::wait_readable(fd_, std::chrono::duration_cast<core::Duration>(deadline - Clock::now()));
    std::uint64_t count = 0;
    if (::read(fd_, &count, sizeof count) < 0) {
      // EAGAIN: woken by the deadline, or the notify() is still between its exchange and its write
    }
    // Cleared before the caller looks at its inputs: a notify() from here on writes again.
    pending_.exchange(false, std::memory_order_acq_rel);
  }

 private:
  int fd_;
  std::atomic<bool> pending_{false};
};

}  // namespace drivegate::daemon
