#pragma once
// The DDS side of the gateway (DESIGN.md §6): one bridge thread that turns DDS commands,
// set-points and parameter requests into Runtime submissions, and Runtime snapshots, replies,
// events and bus status into DDS samples. It is control plane: it allocates and logs freely, and
// never runs on a cycle thread.
//
// Every command and parameter request it takes gets exactly one final reply, also in a burst:
// requests the Runtime cannot queue yet wait in the bridge (and, while they do, the bridge takes
// no more from DDS, so the keep-all topics push back on the clients); one that waited too long is
// answered "busy". Replies for a client wait until that client's reply reader is matched, so the
// first reply to a new client is not lost to volatile durability.
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "daemon/runtime.hpp"
#include "idl/dds_security.hpp"

namespace drivegate::daemon {

struct DdsBridgeOptions {
  std::uint32_t domain = 0;
  std::string ns = "drivegate";  // topic names are "<ns>/<topic>"
  double status_rate_hz = 50;    // axis_state rate; bus_status goes at min(1 Hz, this)
  // An unchanged axis state is written again after this long (0: every period).
  std::chrono::nanoseconds status_keepalive = std::chrono::milliseconds(250);
  std::string profiles_file;     // Fast DDS XML profiles (idl/dds_node.hpp)
  std::string profile;
  std::vector<std::string> interfaces;  // UDPv4 on these only
  std::optional<msg::SecurityFiles> security;
};

// Another running instance of this gateway (the same name) on the domain.
struct DuplicateGateway {
  bool seen = false;
  bool this_one_stops = false;  // this instance started later: it must stop
  std::string text;             // who and where, for the log
};

class DdsBridge {
 public:
  DdsBridge(Runtime& runtime, DdsBridgeOptions options);
  ~DdsBridge();  // stops the thread
  DdsBridge(const DdsBridge&) = delete;
  DdsBridge& operator=(const DdsBridge&) = delete;

  // Creates the participant, topics and endpoints, publishes gateway_info and starts the bridge
  // thread. Throws std::runtime_error (DDS setup failure) or std::invalid_argument (bad options).
  void start();
  // Joins the bridge thread and releases the DDS entities. Idempotent.
  void stop();

  // Waits up to `window` for another instance of this gateway to show itself on the domain
  // (its gateway_info); returns what was seen. Used before any bus is opened.
  DuplicateGateway wait_for_duplicate(std::chrono::milliseconds window) const;
  // Safe from any thread.
  [[nodiscard]] DuplicateGateway duplicate() const;
  // Before a refusing instance goes: waits (at most `budget`) until the other instance has this
  // one's gateway_info, so both of them report the clash.
  void let_others_see_us(std::chrono::milliseconds budget);

  struct Stats {
    std::uint64_t commands_routed = 0;
    std::uint64_t commands_rejected = 0;
    std::uint64_t commands_busy = 0;     // waited too long for a place in the Runtime's queue
    std::uint64_t commands_ignored = 0;  // addressed to another gateway
    std::uint64_t setpoints_routed = 0;
    std::uint64_t setpoints_dropped = 0;  // unknown axis or full queue
    std::uint64_t params_routed = 0;
    std::uint64_t replies_written = 0;
    std::uint64_t replies_unmatched = 0;  // written after the hold time without a matched reader of the client
    std::uint64_t replies_held = 0;       // write attempts refused by a client's full reply history (retried)
    std::uint64_t states_published = 0;
    std::uint64_t io_writes_routed = 0;
    std::uint64_t io_states_published = 0;
    std::uint64_t wakeups = 0;  // passes of the bridge loop: it runs on work and publication deadlines, not a poll
  };
  // Safe from any thread.
  [[nodiscard]] Stats stats() const;

  class Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace drivegate::daemon
