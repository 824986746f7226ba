#pragma once
// Waits until a file descriptor is readable, for at most a duration (ppoll: nanosecond timeout).
#include <poll.h>
#include <time.h>

#include <chrono>

#include "core/clock.hpp"

namespace drivegate::core {

// The descriptor's poll events (POLLIN, and POLLERR/POLLHUP/POLLNVAL when it has them); 0 when
// `timeout` passed first, a signal interrupted the wait, or `timeout` is not positive.
inline short wait_readable(int fd, Duration timeout) noexcept {
  if (timeout <= Duration::zero()) return 0;
  const auto s = std::chrono::duration_cast<std::chrono::seconds>(timeout);
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(s.count());
  ts.tv_nsec = static_cast<long>(std::chrono::duration_cast<std::chrono::nanoseconds>(timeout - s).count());
  pollfd p{fd, POLLIN, 0};
  return ::ppoll(&p, 1, &ts, nullptr) > 0 ? p.revents : 0;
}

}  // namespace drivegate::core
