#pragma once
// An in-memory Ethernet segment for the DCP engines, on virtual time: every frame an endpoint's
// poll() gives is delivered as bytes to every other endpoint it is addressed to (multicast: all of
// them), at once. run_until() polls everybody until nothing is due, then moves the time to the
// earliest deadline. Optional: a log of every frame (for tshark) and a filter that drops frames.
#include <array>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "adapters/profinet/controller/dcp_client.hpp"
#include "adapters/profinet/controller/station_finder.hpp"
#include "adapters/profinet/sim/dcp_responder.hpp"
#include "core/clock.hpp"

namespace drivegate::profinet::test {

using Bytes = std::vector<std::uint8_t>;
using namespace std::chrono_literals;

inline constexpr MacAddress kControllerMac{0x02, 0x00, 0x00, 0x00, 0x00, 0x01};

// A device MAC whose last two octets are `low` (the response delay is derived from them).
inline MacAddress device_mac(std::uint16_t low) {
  return {0x00, 0x1B, 0x1B, 0x00, static_cast<std::uint8_t>(low >> 8), static_cast<std::uint8_t>(low & 0xFF)};
}

inline IpSuite suite(std::uint8_t host) {
  IpSuite s;
  s.address = {192, 168, 0, host};
  s.netmask = {255, 255, 255, 0};
  s.gateway = {192, 168, 0, 1};
  return s;
}

inline DcpResponderConfig device(std::uint16_t low, std::string name, IpSuite ip = {}) {
  DcpResponderConfig c;
  c.mac = device_mac(low);
  c.type_of_station = "AKD";
  c.vendor_id = 0x0118;
  c.device_id = 0x0501;
  c.name_of_station = std::move(name);
  c.ip = ip;
  return c;
}

class Hub {
 public:
  struct Endpoint {
    MacAddress mac{};
    std::function<std::size_t(core::TimePoint, std::span<std::uint8_t>)> poll;
    std::function<bool(std::span<const std::uint8_t>, core::TimePoint)> on_frame;
    std::function<core::TimePoint()> deadline;
  };

  template <typename Engine>
  void add(Engine& e, const MacAddress& mac) {
    endpoints_.push_back({mac, [&e](core::TimePoint t, std::span<std::uint8_t> out) { return e.poll(t, out); },
                          [&e](std::span<const std::uint8_t> f, core::TimePoint t) { return e.on_frame(f, t); },
                          [&e] { return e.next_deadline(); }});
  }
  void add(DcpClient& c) { add(c, c.mac()); }
  void add(DcpResponder& r) { add(r, r.mac()); }

  // A frame from outside (another station): delivered like the others.
  void inject(std::span<const std::uint8_t> frame) { deliver(frame, nullptr); }

  // Polls and delivers until `done` or the virtual time passes `limit` from now; true when done.
  bool run_until(const std::function<bool()>& done, core::Duration limit = 120s) {
    const core::TimePoint end = now + limit;
    for (;;) {
      pump();
      if (done()) return true;
      core::TimePoint next = core::TimePoint::max();
      for (const Endpoint& e : endpoints_) next = std::min(next, e.deadline());
      if (next == core::TimePoint::max() || next > end) return false;
      if (next > now) now = next;
    }
  }

  core::TimePoint now{};
  bool keep_log = true;
  std::vector<Bytes> log;                       // every frame sent through the hub
  std::vector<core::TimePoint> log_time;        // when
  std::function<bool(std::span<const std::uint8_t>)> drop;  // true: the frame is lost

 private:
  void pump() {
    bool any = true;
    while (any) {
      any = false;
      for (Endpoint& e : endpoints_) {
        while (const std::size_t n = e.poll(now, buf_)) {
          any = true;
          deliver(std::span<const std::uint8_t>(buf_).first(n), &e);
        }
      }
    }
  }

  void deliver(std::span<const std::uint8_t> frame, const Endpoint* from) {
    if (keep_log) {
      log.emplace_back(frame.begin(), frame.end());
      log_time.push_back(now);
    }
    if (drop && drop(frame)) return;
    MacAddress dst{};
    std::copy_n(frame.begin(), dst.size(), dst.begin());
    const bool multicast = (dst[0] & 1) != 0;
    // Delivery reuses buf_ only after the receivers are done with it (they copy what they keep).
    for (Endpoint& e : endpoints_) {
      if (&e == from || (!multicast && e.mac != dst)) continue;
      e.on_frame(frame, now);
    }
  }

  std::vector<Endpoint> endpoints_;
  std::array<std::uint8_t, kMaxFrameSize> buf_{};
};

}  // namespace drivegate::profinet::test
