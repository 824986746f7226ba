#pragma once
// The slave side of NMT and error control for one simulated node [CiA 301 §7.2.8, §7.3.2]:
// the NMT state machine (power-on -> boot-up 700h+n: 00 -> Pre-operational; Start, Stop, Enter
// Pre-operational, Reset Node, Reset Communication for its node-ID or 0), which services the
// current state allows (SD6 digest §6.7 table), the heartbeat producer (1017h), the node-guard
// responder with its toggle, life guarding (100Ch x 100Dh) and one heartbeat consumer entry
// (1016h:01, as on the AKD: part 1 §11.2, quirk 11).
//
// The owner (a simulated drive) holds the object dictionary: its SDO server writes 1016h, 1017h,
// 100Ch and 100Dh through the setters here, and it reacts to the events (reset its application or
// communication objects, fault on a life-guarding or heartbeat loss: AKD F129 / EMCY 8130h, part 1
// §11; SD6 fault 52 cause 1 / EMCY 7500h, §4.4, §6.9).
//
// Sans-I/O like the master engines: frames and time in, frames into a TxQueue and the next
// deadline out; nothing allocates after construction.
#include <array>
#include <cstddef>
#include <cstdint>

#include "adapters/canopen/master/tx_queue.hpp"
#include "adapters/canopen/wire/can_frame.hpp"
#include "adapters/canopen/wire/cob_id.hpp"
#include "adapters/canopen/wire/nmt_codec.hpp"
#include "core/clock.hpp"

namespace drivegate::canopen::sim {

// Persona options: where the reference drives differ from CiA 301 or from each other.
struct NmtSlaveOptions {
  // SD6 quirk 9: the boot-up is described as sent once at power-on; false models a node that
  // enters Pre-operational silently after Reset Node / Reset Communication.
  bool boot_up_after_reset = true;
  // SD6 §6.8, quirk 8: a life-guarding timeout faults the drive only in Operational. The AKD
  // raises F129 in any state (part 1 §11.1).
  bool life_guarding_only_operational = false;
};

// Power-on values of the communication objects; Reset Node and Reset Communication restore them.
struct NmtSlaveConfig {
  NodeId node = 1;
  std::uint16_t heartbeat_period_ms = 0;   // 1017h, 0 = no heartbeat
  std::uint16_t guard_time_ms = 0;         // 100Ch
  std::uint8_t life_time_factor = 0;       // 100Dh; 0 in either disables life guarding
  std::uint32_t heartbeat_consumer = 0;    // 1016h:01 = producer node << 16 | time in ms; 0 = off
  NmtSlaveOptions options;
};

// Services that depend on the NMT state (SD6 digest §6.7 table; NMT itself and error control run
// in every state after initialisation).
enum class NmtService : std::uint8_t { Sdo, Pdo, Emcy, Sync };

enum class NmtSlaveEventKind : std::uint8_t {
  StateChanged,        // state() changed (Operational: PDOs start; left it: they stop)
  ResetNode,           // reset the application and communication objects (then boot-up)
  ResetCommunication,  // reset the communication objects (PDO/SDO/EMCY COB-IDs, mapping...)
  LifeGuarding,        // no RTR within guard time x life time factor once guarding started
  HeartbeatLost,       // the consumed producer was silent longer than 1016h:01 allows
};

struct NmtSlaveEvent {
  NmtSlaveEventKind kind = NmtSlaveEventKind::StateChanged;
  NmtState state = NmtState::Initialising;  // the state when it happened
};

struct NmtSlaveCounters {
  std::uint64_t nmt_commands = 0;     // commands for this node or all nodes
  std::uint64_t boot_ups_sent = 0;
  std::uint64_t heartbeats_sent = 0;
  std::uint64_t guard_replies = 0;
  std::uint64_t life_guarding = 0;    // timeouts, whether or not they raised an event
  std::uint64_t heartbeat_lost = 0;
  std::uint64_t unexpected = 0;       // data on our own 700h+n, an RTR while heartbeat is on
  std::uint64_t malformed = 0;        // wrong DLC, unknown command specifier or state byte
  std::uint64_t ignored = 0;          // frames received while silent or initialising
  std::uint64_t tx_full = 0;
  std::uint64_t events_dropped = 0;
};

class NmtSlave {
 public:
  static constexpr std::size_t kEventCapacity = 16;
  // RTRs answered per poll at most; more before the next poll are counted and dropped (a real
  // controller would answer each, but a master never has more than one out).
  static constexpr std::uint8_t kMaxPendingReplies = 4;

  explicit NmtSlave(NmtSlaveConfig config) noexcept;

  // Power on (again): state Initialising until the next poll() sends the boot-up and enters
  // Pre-operational. Communication objects go back to the config's values.
  void power_on(core::TimePoint now) noexcept;

  // Takes NMT (000h), RTRs on its own 700h+n, and heartbeats of the producer it consumes; returns
  // false for every other frame.
  bool on_frame(const CanFrame& frame, core::TimePoint now) noexcept;
  // Boot-up, heartbeats, guard replies, and the life-guarding / heartbeat-consumer timeouts.
  void poll(core::TimePoint now, TxQueue& tx) noexcept;
  [[nodiscard]] core::TimePoint next_deadline() const noexcept;

  [[nodiscard]] NodeId node() const noexcept { return config_.node; }
  [[nodiscard]] NmtState state() const noexcept { return state_; }
  [[nodiscard]] bool serves(NmtService s) const noexcept;

  // Object writes from the owner's SDO server; the timers restart from `now`.
  void set_heartbeat_period(std::uint16_t ms, core::TimePoint now) noexcept;               // 1017h
  void set_guarding(std::uint16_t guard_time_ms, std::uint8_t factor, core::TimePoint now) noexcept;  // 100Ch, 100Dh
  void set_heartbeat_consumer(std::uint32_t entry) noexcept;  // 1016h:01, armed by the first heartbeat
  [[nodiscard]] std::uint16_t heartbeat_period() const noexcept { return heartbeat_ms_; }
  [[nodiscard]] std::uint16_t guard_time() const noexcept { return guard_ms_; }
  [[nodiscard]] std::uint8_t life_time_factor() const noexcept { return life_factor_; }
  [[nodiscard]] std::uint32_t heartbeat_consumer() const noexcept { return consumer_entry_; }

  // Fault injection: a silent node is cut off the bus. It sends nothing and ignores what it
  // receives; its own timers keep running, so a master that goes on guarding it is what its life
  // guarding misses, as with a pulled cable.
  void set_silent(bool silent) noexcept { silent_ = silent; }
  [[nodiscard]] bool silent() const noexcept { return silent_; }

  bool next_event(NmtSlaveEvent& out) noexcept;
  [[nodiscard]] const NmtSlaveCounters& counters() const noexcept { return counters_; }

 private:
  void restore_communication(core::TimePoint now) noexcept;
  void enter(NmtState s) noexcept;
  void push_event(NmtSlaveEventKind kind) noexcept;
  void on_nmt(const CanFrame& frame, core::TimePoint now) noexcept;
  void on_rtr(const CanFrame& frame, core::TimePoint now) noexcept;
  void on_consumed_heartbeat(const CanFrame& frame, core::TimePoint now) noexcept;
  [[nodiscard]] bool life_guarding_armed() const noexcept;
  [[nodiscard]] bool consumer_armed() const noexcept;
  [[nodiscard]] NodeId consumed_node() const noexcept;

  NmtSlaveConfig config_;
  NmtState state_ = NmtState::Initialising;
  bool powered_ = false;
  bool boot_up_pending_ = false;  // enter Pre-operational at the next poll...
  bool send_boot_up_ = false;     // ...announcing it with 00h
  bool silent_ = false;
  core::TimePoint boot_at_{};

  std::uint16_t heartbeat_ms_ = 0;
  core::TimePoint next_heartbeat_{};

  std::uint16_t guard_ms_ = 0;
  std::uint8_t life_factor_ = 0;
  bool guarding_started_ = false;  // the first RTR starts life guarding (AKD part 1 §11.1)
  bool life_expired_ = false;      // one event per loss; the next RTR re-arms it
  core::TimePoint last_rtr_{};
  bool toggle_ = false;
  std::uint8_t pending_replies_ = 0;
  core::TimePoint reply_at_{};

  std::uint32_t consumer_entry_ = 0;
  bool consumer_started_ = false;  // monitoring starts with the first heartbeat (AKD part 1 §11.2)
  bool consumer_expired_ = false;
  core::TimePoint consumer_last_{};

  std::array<NmtSlaveEvent, kEventCapacity> events_{};
  std::size_t event_head_ = 0;
  std::size_t event_count_ = 0;
  NmtSlaveCounters counters_;
};

}  // namespace drivegate::canopen::sim
