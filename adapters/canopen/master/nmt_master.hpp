#pragma once
// NMT master and error control (CiA 301 §7.2.8): NMT commands, node states from boot-up,
// heartbeat and node-guard replies, heartbeat consumer timeouts, node guarding with the toggle bit
// (for drives without a consumer heartbeat, e.g. the SD6: stoeber-sd6-canopen.md §6.8, quirk 7),
// and the master's own heartbeat producer (so drives with a consumer heartbeat notice a dead
// gateway: AKD part 1 §16 step 10).
//
// Nodes are registered at construction. Each node is watched either by heartbeat (a timeout after
// the last heartbeat) or by guarding (an RTR on 700h+n every guard time; a missing reply or a
// wrong toggle is a miss; `life_time_factor` consecutive misses make the node lost). Watching
// starts with watch() once the node is configured; before that only boot-ups and states are
// tracked.
//
// A boot-up ends the watch: the node's error-control objects are back at their defaults, so the
// owner reconfigures the node and calls watch() again (otherwise a heartbeat node would be
// declared lost in the middle of its own configuration). The state after a boot-up is
// PreOperational, the state a node enters when it sends 00h [CiA 301 §7.3.2.2]. Heartbeat bytes
// have bit 7 masked (SD6 digest §6.8: the drive's figure shows a toggle there). A guard reply with
// the wrong toggle is a miss and resynchronises the expected toggle to the reply's, so that one
// lost reply costs two misses (its absence and the toggle error after it), not every following one.
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "adapters/canopen/master/tx_queue.hpp"
#include "adapters/canopen/wire/can_frame.hpp"
#include "adapters/canopen/wire/nmt_codec.hpp"
#include "core/clock.hpp"

namespace drivegate::canopen {

enum class Watch : std::uint8_t { None, Heartbeat, Guarding };

struct NmtNodeConfig {
  NodeId node = 0;
  Watch watch = Watch::Heartbeat;
  core::Duration heartbeat_timeout = std::chrono::milliseconds(300);  // Heartbeat: silence allowed
  core::Duration guard_time = std::chrono::milliseconds(100);         // Guarding: RTR period
  int life_time_factor = 3;                                           // Guarding: misses allowed
};

struct NmtMasterConfig {
  NodeId own_node = 127;  // master heartbeat on 700h + own_node
  core::Duration heartbeat_period = std::chrono::milliseconds(100);  // 0 = no own heartbeat
};

enum class NmtEventKind : std::uint8_t {
  BootUp,        // 700h+n: 00 received (node (re)started, its configuration is lost)
  StateChanged,  // a heartbeat/guard reply reported another state
  Lost,          // heartbeat timeout, or guarding misses reached the life time factor
  Recovered,     // a lost node was heard again (without boot-up)
  ToggleError,   // a guard reply with the wrong toggle bit (counted as a miss)
};

struct NmtEvent {
  NmtEventKind kind = NmtEventKind::BootUp;
  NodeId node = 0;
  NmtState state = NmtState::Unknown;
};

struct NmtCounters {
  std::uint64_t boot_ups = 0;
  std::uint64_t heartbeats = 0;
  std::uint64_t guard_replies = 0;
  std::uint64_t toggle_errors = 0;
  std::uint64_t losses = 0;
  std::uint64_t unexpected = 0;  // error-control frames from nodes that are not registered
  std::uint64_t malformed = 0;   // wrong DLC or unknown state byte
  std::uint64_t events_dropped = 0;
  std::uint64_t tx_full = 0;
};

class NmtMaster {
 public:
  static constexpr std::size_t kEventCapacity = 256;

  // Throws std::invalid_argument for a node-ID outside 1..127 or registered twice, or an own
  // node-ID outside 1..127 with a heartbeat period.
  NmtMaster(NmtMasterConfig config, std::span<const NmtNodeConfig> nodes);

  // Queue an NMT command (node 0 = all nodes). Returns false when the TxQueue is full or the
  // node-ID is above 127. Reset Node / Reset Communication restart the expected guard toggle at
  // 0 for the nodes they address (the responder restarts it even when it sends no boot-up, SD6
  // quirk 9).
  bool command(NmtCommand cs, NodeId node, TxQueue& tx) noexcept;

  // Start / stop supervising a node (heartbeat timeout or guarding RTRs). watch() restarts the
  // timers from `now`; a lost node stays lost until it is heard again.
  void watch(NodeId node, core::TimePoint now) noexcept;
  // The same, changing how the node is watched first (a boot that found the drive has no 1016h
  // but 100Ch/100Dh guards it instead of consuming its heartbeat).
  void watch(NodeId node, Watch how, core::TimePoint now) noexcept;
  void unwatch(NodeId node) noexcept;

  [[nodiscard]] NmtState state(NodeId node) const noexcept;  // last reported state
  [[nodiscard]] bool lost(NodeId node) const noexcept;
  [[nodiscard]] core::TimePoint last_heard(NodeId node) const noexcept;

  // Events in order of occurrence; returns false when there is none.
  bool next_event(NmtEvent& out) noexcept;

  // Engine interface. on_frame takes 700h+n frames (returns false for other COB-IDs).
  bool on_frame(const CanFrame& frame, core::TimePoint now) noexcept;
  void poll(core::TimePoint now, TxQueue& tx) noexcept;  // heartbeat, RTRs, timeouts
  [[nodiscard]] core::TimePoint next_deadline() const noexcept;

  [[nodiscard]] const NmtCounters& counters() const noexcept { return counters_; }

 private:
  struct Node {
    NmtNodeConfig config;
    NmtState state = NmtState::Unknown;
    core::TimePoint last_heard{};
    bool watching = false;
    bool lost = false;
    core::TimePoint heartbeat_deadline{};  // Heartbeat: lost when nothing is heard by then
    core::TimePoint next_rtr{};            // Guarding: next request
    bool awaiting_reply = false;           // Guarding: an RTR is out and unanswered
    bool expected_toggle = false;
    int misses = 0;                        // Guarding: consecutive
  };

  Node* find(NodeId node) noexcept;
  [[nodiscard]] const Node* find(NodeId node) const noexcept;
  void push_event(NmtEventKind kind, const Node& n) noexcept;
  void on_boot_up(Node& n, core::TimePoint now) noexcept;
  void on_heartbeat(Node& n, NmtState state, core::TimePoint now) noexcept;
  void on_guard_reply(Node& n, ErrorControlFrame reply, core::TimePoint now) noexcept;
  void heard(Node& n, NmtState state, core::TimePoint now) noexcept;
  void miss(Node& n) noexcept;
  void lose(Node& n) noexcept;
  void poll_guarding(Node& n, core::TimePoint now, TxQueue& tx) noexcept;

  NmtMasterConfig config_;
  NmtCounters counters_;
  std::vector<Node> nodes_;                           // sized in the constructor
  std::array<std::uint8_t, kMaxNodeId + 1> index_{};  // node-ID -> position in nodes_ + 1 (0: none)
  std::array<NmtEvent, kEventCapacity> events_{};
  std::size_t event_head_ = 0;
  std::size_t event_count_ = 0;
  core::TimePoint next_own_heartbeat_ = core::TimePoint::min();  // min: due at the first poll
};

// SYNC producer (CiA 301 §7.2.5): COB-ID 080h, DLC 0 (the reference drives use no SYNC counter:
// SD6 digest §6.1). Deadlines are start + k * period, so the period never drifts; a poll that
// comes more than one period late sends one SYNC and counts the skipped ones.
class SyncProducer {
 public:
  SyncProducer(std::uint32_t cob_id, core::Duration period) noexcept : cob_id_(cob_id), period_(period) {}
  void start(core::TimePoint now) noexcept;
  void stop() noexcept;
  // Sends the SYNC if one is due; returns true when it did (RPDOs follow it).
  bool poll(core::TimePoint now, TxQueue& tx) noexcept;
  [[nodiscard]] core::TimePoint next_deadline() const noexcept;
  [[nodiscard]] std::uint64_t sent() const noexcept { return sent_; }
  [[nodiscard]] std::uint64_t skipped() const noexcept { return skipped_; }

 private:
  std::uint32_t cob_id_;
  core::Duration period_;
  bool running_ = false;
  core::TimePoint next_{};
  std::uint64_t sent_ = 0;
  std::uint64_t skipped_ = 0;
};

}  // namespace drivegate::canopen
