#pragma once
// A CANopen bus (core::Bus): one transport, the master's engines (NMT and error control, SDO
// client, SYNC, EMCY, PDOs) and a CiA 402 profile per axis over NodeAccess. Each axis is one node.
//
// Per node the bus runs the life cycle the issue asks for:
//   start:        wait for the boot-up, or probe 1000h by SDO (a drive already running, or one
//                 that does not repeat its boot-up: SD6 quirk 9) and send NMT pre-operational
//   configuring:  NodeBoot (identity, start-up writes, PDOs, error control), then NMT start
//   operational:  PDOs after each SYNC, heartbeat or guarding supervision, EMCY
//   lost / failed: link Lost or Offline with the reason; probed again with back-off, and on its
//                 next boot-up or answer reconfigured from scratch, coming back disabled
//   safe stop:    the profile found the drive not following its controlword: link Degraded, the
//                 RPDOs stop, quick stop (6040h := 0002h) over SDO until 6041h shows it left
//                 operation enabled, disable voltage (0000h), NMT stop, NMT reset communication;
//                 then reconfigured from scratch like a lost node, coming back disabled
// A bus-off of the gateway's controller takes every node to Lost; when the controller is back,
// every node is probed and reconfigured. Nothing needs a daemon restart.
//
// Every EMCY a node sends (fault, warning, error reset / no error 0000h, an AKD error-state
// update) is an `emcy` event of its axis (next_event()): code, error register and the five vendor
// bytes, with the text of the device profile's table. A fault's EMCY also gives the axis' fault
// event its text. Per node at most kEmcyBurst at once and then one per kEmcyRefill are published;
// the rest are counted (emcy_events_dropped()) and summed up in one warning event when the node
// has a token again.
//
// link_detail() says what the node's last transition did, set by that transition and never left
// over from an earlier one; the axis' link_changed event carries it ("link lost -> configuring:
// node 35 answered again; configuring it"). In order of the life cycle:
//   waiting for node N's boot-up                          start (link booting)
//   node N sent no boot-up: asking it (SDO read of 1000h) probe after 500 ms without boot-up
//   node N booted: configuring it                         boot-up received (also after a loss)
//   node N answered[ again]; configuring it               probe answered
//   node N configured                                     NMT start sent (link operational)
//   node N: <boot step, object and SDO abort>             boot failed (link offline, or lost)
//   node N does not answer (SDO read of 1000h: <abort>)   probe failed
//   node N: asking it again after T ms (...)              next probe after the back-off
//   node N stopped answering (heartbeat timeout | node guarding)       operational -> lost
//   node N is heard again: asking it (SDO read of 1000h)  heartbeat/guard reply of a lost node
//   node N left operational (now S): configuring it again another master stopped it
//   <why the profile found the drive not following>       safe stop (link degraded)
//   node N was stopped over SDO ...: configuring it again safe stop done
//   the gateway's CAN controller is bus-off / CAN controller recovered from bus-off: ...
//
// receive() and transmit() are the cyclic path: no allocation, lock, logging or blocking.
//
// Between cycles (serve_until()), while an SDO transfer is in flight or waiting, the bus waits on
// the transport's wait_fd() until shortly before the next cycle and hands SDO responses to the SDO
// client as they arrive, so the next segment request goes out at once instead of one exchange per
// cycle. Every other frame it reads then (PDOs, heartbeats, EMCY, ...) is held, in order, for the
// next receive(), which handles it with the cycle's time exactly as if it had just been read:
// PDO freshness, loss detection and error control see no difference. With no SDO work, or a
// transport without wait_fd() (the in-process bus of `transport: sim`), it returns at once and
// the thread sleeps: it never wakes per frame then.
#include <array>
#include <atomic>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "adapters/canopen/master/emcy_consumer.hpp"
#include "adapters/canopen/master/nmt_master.hpp"
#include "adapters/canopen/master/node_boot.hpp"
#include "adapters/canopen/master/pdo.hpp"
#include "adapters/canopen/master/sdo_client.hpp"
#include "adapters/canopen/master/tx_queue.hpp"
#include "adapters/canopen/node_access.hpp"
#include "adapters/canopen/transport/transport.hpp"
#include "config/canopen/plan.hpp"
#include "core/bus.hpp"
#include "core/event_ring.hpp"
#include "profiles/cia402/cia402_master.hpp"

namespace drivegate::canopen {

// Something the bus steps every cycle besides its own engines: the simulated drives of a
// `transport: sim` bus, which live on the same in-process wire.
class CyclePeer {
 public:
  virtual ~CyclePeer() = default;
  virtual void step(core::TimePoint now) noexcept = 0;
};

// Transport for a plan's options (socketcan or udp-multicast); `sim` buses get theirs from
// make_canopen_bus(). Throws TransportError.
std::unique_ptr<Transport> make_transport(const config::BusPlan& plan);

class CanopenBus final : public core::Bus {
 public:
  enum class Phase : std::uint8_t { Start, WaitBootUp, Probe, Configuring, Operational, Backoff, Lost, SafeStop };

  CanopenBus(const config::BusPlan& plan, std::unique_ptr<Transport> transport,
             std::unique_ptr<CyclePeer> peer = nullptr);
  ~CanopenBus() override;

  std::string_view name() const noexcept override { return name_; }
  std::string_view type() const noexcept override { return "canopen"; }
  void open(core::TimePoint now) override;
  void close() noexcept override;
  std::size_t axis_count() const noexcept override { return nodes_.size(); }
  core::AxisController& controller(std::size_t axis) noexcept override { return *nodes_[axis]->master; }
  core::LinkState link_state(std::size_t axis) const noexcept override;
  std::string_view link_detail(std::size_t axis) const noexcept override;
  void receive(core::TimePoint now) noexcept override;
  void transmit(core::TimePoint now) noexcept override;
  void serve_until(core::TimePoint deadline) noexcept override;
  bool next_event(core::Event& out) noexcept override;
  core::BusCounters counters() const noexcept override;

  // EMCY events per node: this many at once, then one per kEmcyRefill.
  static constexpr std::uint32_t kEmcyBurst = 8;
  static constexpr core::Duration kEmcyRefill = std::chrono::seconds(1);
  // serve_until() ends this long plus two 8-byte frame times before the next cycle, and sends only
  // as many frames as are off the wire by then: a frame handled at the last moment cannot delay
  // the cycle's start, and the SYNC is not queued behind our own frames (CAN does not preempt a
  // frame on the wire; the controller sends our frames in order).
  static constexpr core::Duration kServeGuard = std::chrono::microseconds(100);
  // Frames serve_until() holds for the next receive(); when full, it stops reading.
  static constexpr std::size_t kHeldFrames = 256;

  // What serve_until() did (bus thread only, or while the bus is not cycling).
  struct ServeCounters {
    std::uint64_t waits = 0;         // waits on the transport's fd
    std::uint64_t sdo_frames = 0;    // SDO responses handled between cycles
    std::uint64_t held_frames = 0;   // other frames held for the next receive()
    std::uint64_t held_full = 0;     // returned early because the held frames filled up
    std::uint64_t fd_errors = 0;     // returned early: the fd reported an error or hang-up
  };
  [[nodiscard]] const ServeCounters& serve_counters() const noexcept { return serve_; }

  // Diagnostics (bus thread only, or while the bus is not cycling).
  [[nodiscard]] Phase phase(std::size_t axis) const noexcept { return nodes_[axis]->phase; }
  [[nodiscard]] const SdoClient& sdo() const noexcept { return sdo_; }
  [[nodiscard]] const NmtMaster& nmt() const noexcept { return nmt_; }
  [[nodiscard]] const EmcyConsumer& emcy() const noexcept { return emcy_; }
  [[nodiscard]] const NodePdos& pdos(std::size_t axis) const noexcept { return nodes_[axis]->pdos; }
  [[nodiscard]] std::uint64_t unexpected_frames() const noexcept { return unexpected_; }
  std::uint64_t foreign_master_ = 0;
  core::TimePoint foreign_reported_{};  // last foreign-master warning (at most one per 10 s)
  bool foreign_pending_ = false;         // a warning waits for next_event()
  core::Event foreign_event_{};
  // SYNC and NMT commands on the wire that this gateway did not send: another master.
  [[nodiscard]] std::uint64_t foreign_master_frames() const noexcept { return foreign_master_; }
  [[nodiscard]] std::uint64_t boots(std::size_t axis) const noexcept { return nodes_[axis]->boots; }
  // EMCYs that were not published as events: over a node's rate limit, or lost in the consumer's
  // full report queue.
  [[nodiscard]] std::uint64_t emcy_events_dropped() const noexcept {
    return emcy_rate_dropped_ + emcy_.counters().reports_dropped;
  }
  [[nodiscard]] Transport& transport() noexcept { return *transport_; }

 private:
  struct Node {
    NodeId id = 0;
    int channel = 0;  // SdoClient channel index, which is the axis index
    NodeBoot boot;
    NodePdos pdos;
    std::unique_ptr<NodeAccess> io;
    std::unique_ptr<cia402::Cia402Master> master;
    Phase phase = Phase::Start;
    core::TimePoint since{};
    core::Duration backoff{};
    SdoRequestId probe = kNoSdoRequest;
    int safe_step = 0;  // SafeStop: which of its SDO steps runs
    bool had_link = false;  // was operational before: a loss shows as Lost, not Offline
    cia402::ObjectId watchdog{};  // how the drive watches the gateway (1016h:01 or 100Ch); index 0: not
    config::GatewayWatch gateway_watch = config::GatewayWatch::Heartbeat;  // the axis' choice
    bool unwatched_pending = false;   // the "drive does not watch the gateway" warning waits for next_event()
    bool unwatched_reported = false;  // ... and is given once
    std::uint64_t boots = 0;
    core::FixedString<200> detail;
    // EMCY events: a token bucket (kEmcyBurst, one more per kEmcyRefill) and what it held back.
    std::uint32_t emcy_tokens = kEmcyBurst;
    core::TimePoint emcy_refilled{};
    std::uint64_t emcy_held_back = 0;  // since the last summary
    EmcyReport emcy_last_held{};
    std::atomic<core::LinkState> link{core::LinkState::Offline};
    Node(int sdo_channel, std::vector<BootStep> steps) : boot(sdo_channel, std::move(steps)) {}
  };

  void dispatch(const CanFrame& f, core::TimePoint now) noexcept;
  void handle_nmt_events(core::TimePoint now) noexcept;
  void handle_controller_state(core::TimePoint now) noexcept;
  void advance(Node& n, core::TimePoint now) noexcept;
  void enter(Node& n, Phase p, core::TimePoint now) noexcept;
  void drop_node(Node& n, Phase next, core::TimePoint now) noexcept;
  void fail_node(Node& n, core::TimePoint now) noexcept;
  void start_safe_stop(Node& n, core::TimePoint now) noexcept;
  void run_safe_stop(Node& n, core::TimePoint now) noexcept;
  Node* node_by_id(NodeId id) noexcept { return id <= kMaxNodeId ? by_id_[id] : nullptr; }
  // Sends what tx_ holds, as far as the transport takes it; returns the frames sent.
  std::size_t flush(core::TimePoint now) noexcept;
  void take_between_cycles(core::TimePoint now) noexcept;
  void release_watchdogs() noexcept;
  void publish_counters() noexcept;
  void note_foreign_master(const CanFrame& f, core::TimePoint now) noexcept;
  void publish_emcy(core::TimePoint now) noexcept;
  bool take_emcy_token(Node& n, core::TimePoint now) noexcept;

  std::string name_;
  config::CanopenBusOptions options_;
  core::Duration cycle_time_;
  std::unique_ptr<Transport> transport_;
  std::unique_ptr<CyclePeer> peer_;
  // Per axis: the device profile's fault texts and EMCY fields (views into the plan, which the
  // daemon keeps alive as long as the bus), referenced by the EMCY consumer and the masters.
  struct Tables {
    std::vector<cia402::FaultText> faults;
    std::vector<EmcyField> fields;
  };
  std::vector<Tables> tables_;
  std::vector<NmtNodeConfig> nmt_nodes_;  // per axis; also tells how a lost node was watched
  SdoClient sdo_;
  NmtMaster nmt_;
  EmcyConsumer emcy_;
  SyncProducer sync_;
  std::vector<std::unique_ptr<Node>> nodes_;
  std::array<Node*, 128> by_id_{};
  TxQueue tx_;
  std::array<CanFrame, 64> rx_buffer_{};
  std::array<CanFrame, kHeldFrames> held_{};  // read between cycles, for the next receive()
  std::size_t held_count_ = 0;
  ServeCounters serve_;
  const core::SteadyClock clock_;  // serve_until()'s time line: the cycle thread's monotonic clock
  const core::Duration frame_time_;  // an 8-byte frame at the bus' bit rate
  bool open_ = false;
  core::TimePoint last_now_{};  // the last cycle's time
  ControllerState controller_ = ControllerState::Active;
  std::uint64_t unexpected_ = 0;
  std::uint64_t tx_dropped_ = 0;
  // EMCY events waiting for next_event(); reports stay in the consumer while this is full.
  core::EventRing<16> emcy_events_;
  std::uint64_t emcy_rate_dropped_ = 0;

  // counters() may be called from any thread.
  std::atomic<std::uint64_t> sent_{0};
  std::atomic<std::uint64_t> received_{0};
  std::atomic<std::uint64_t> lost_{0};
  std::atomic<std::uint64_t> dropped_{0};
  std::atomic<std::uint64_t> errors_{0};
};

// A bus for the plan, with its transport (and, for `transport: sim`, its simulated drives).
std::unique_ptr<CanopenBus> make_canopen_bus(const config::BusPlan& plan);

}  // namespace drivegate::canopen
