#pragma once
// sd_notify(3) for Type=notify services (systemd/drivegated.service): readiness, status text,
// stopping and watchdog keep-alives. Every call is a no-op returning false when NOTIFY_SOCKET is
// unset (not started by systemd, or NotifyAccess= denies us), so the daemon calls them
// unconditionally. Not for the cycle threads: sd_notify allocates and does socket I/O.
#include <optional>
#include <string_view>

#include "core/clock.hpp"

namespace drivegate::daemon {

class SystemdNotifier {
 public:
  // Each returns true when the message was sent to the service manager.
  bool ready() const;    // READY=1: start-up finished, all buses configured
  bool stopping() const;  // STOPPING=1: shutdown began (axes are being stopped)
  bool reloading() const;  // RELOADING=1: SIGHUP is being handled (followed by ready() when done)
  bool watchdog() const;  // WATCHDOG=1: keep-alive, send at least every watchdog_interval() / 2
  // STATUS=text, shown by `systemctl status`. Line breaks would start new assignments in the
  // notify protocol, so they are sent as spaces.
  bool status(std::string_view text) const;

  // Set when the unit has WatchdogSec= (WATCHDOG_USEC, and WATCHDOG_PID is this process).
  [[nodiscard]] std::optional<core::Duration> watchdog_interval() const;
};

}  // namespace drivegate::daemon
