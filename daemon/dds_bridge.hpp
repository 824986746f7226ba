#pragma once
// The DDS side of the gateway (DESIGN.md §6): one bridge thread that turns DDS commands,
// set-points and parameter requests into Runtime submissions, and Runtime snapshots, replies,
// events and bus status into DDS samples. It is control plane: it allocates and logs freely, and
// never runs on a cycle thread.
#include <cstdint>
#include <memory>
#include <string>

#include "daemon/runtime.hpp"

namespace drivegate::daemon {

struct DdsBridgeOptions {
  std::uint32_t domain = 0;
  std::string ns = "drivegate";  // topic names are "<ns>/<topic>"
  double status_rate_hz = 50;    // axis_state rate; bus_status goes at min(1 Hz, this)
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

  struct Stats {
    std::uint64_t commands_routed = 0;
    std::uint64_t commands_rejected = 0;
    std::uint64_t commands_ignored = 0;  // addressed to another gateway
    std::uint64_t setpoints_routed = 0;
    std::uint64_t setpoints_dropped = 0;  // unknown axis or full queue
    std::uint64_t params_routed = 0;
    std::uint64_t states_published = 0;
  };
  // Safe from any thread.
  [[nodiscard]] Stats stats() const;

  class Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace drivegate::daemon
