#include "daemon/systemd_notify.hpp"

#include <systemd/sd-daemon.h>

#include <chrono>
#include <cstdint>
#include <string>

namespace drivegate::daemon {
namespace {

bool send(const char* message) { return sd_notify(0, message) > 0; }

}  // namespace

bool SystemdNotifier::ready() const { return send("READY=1"); }
bool SystemdNotifier::stopping() const { return send("STOPPING=1"); }
bool SystemdNotifier::reloading() const { return send("RELOADING=1"); }
bool SystemdNotifier::watchdog() const { return send("WATCHDOG=1"); }

bool SystemdNotifier::status(std::string_view text) const {
  std::string message = "STATUS=";
  message.reserve(message.size() + text.size());
  for (const char c : text) message += (c == '\n' || c == '\r' || c == '\0') ? ' ' : c;
  return send(message.c_str());
}

std::optional<core::Duration> SystemdNotifier::watchdog_interval() const {
  std::uint64_t usec = 0;
  if (sd_watchdog_enabled(0, &usec) <= 0 || usec == 0) return std::nullopt;
  // systemd sends "infinity" as UINT64_MAX; anything beyond the duration range means "no limit".
  constexpr std::uint64_t kMaxUsec = static_cast<std::uint64_t>(core::Duration::max().count() / 1000);
  if (usec > kMaxUsec) return std::nullopt;
  return std::chrono::microseconds(static_cast<std::int64_t>(usec));
}

}  // namespace drivegate::daemon
