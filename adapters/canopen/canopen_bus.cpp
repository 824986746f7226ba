#include "adapters/canopen/canopen_bus.hpp"

#include <poll.h>

#include <algorithm>
#include <thread>

#include "adapters/canopen/boot_plan.hpp"
#include "adapters/canopen/flush_queue.hpp"
#include "adapters/canopen/wire/bit_timing.hpp"
#include "core/fd_wait.hpp"
#include "profiles/cia402/master_settings.hpp"
#include "profiles/cia402/op_modes.hpp"
#include "profiles/cia402/sdo_abort.hpp"
#include "profiles/cia402/statusword.hpp"

namespace drivegate::canopen {
namespace {

using Phase = CanopenBus::Phase;

// How long to wait for a drive's boot-up before probing it by SDO.
constexpr core::Duration kBootUpWait = std::chrono::milliseconds(500);
// A drive out of the gateway's control gets this long on its quick-stop ramp before its power
// stage is switched off (disable voltage) whatever it shows.
constexpr core::Duration kSafeStopBudget = std::chrono::seconds(3);

std::vector<SdoChannelConfig> sdo_channels_for(const config::BusPlan& plan) {
  std::vector<SdoChannelConfig> out;
  for (const auto& a : plan.axes) {
    const auto node = static_cast<NodeId>(a.address);
    const int ch = a.section<config::CanopenAxisOptions>().sdo_channel;
    out.push_back({node, ch, cob::sdo_rx(ch, node), cob::sdo_tx(ch, node)});
  }
  return out;
}

std::vector<NmtNodeConfig> nmt_nodes_for(const config::BusPlan& plan) {
  std::vector<NmtNodeConfig> out;
  const auto& o = plan.section<config::CanopenBusOptions>();
  for (const auto& a : plan.axes) {
    NmtNodeConfig c;
    c.node = static_cast<NodeId>(a.address);
    // Required / optional: heartbeat until a boot finds the drive guards instead (advance()).
    c.watch = config::gateway_watch_of(a) == config::GatewayWatch::Guarding ? Watch::Guarding : Watch::Heartbeat;
    c.heartbeat_timeout = o.drive_heartbeat * o.heartbeat_misses;
    c.guard_time = o.guard_time;
    c.life_time_factor = o.life_time_factor;
    out.push_back(c);
  }
  return out;
}

// A drive that needs a valid mode in 6060h in every RPDO (quirk mode_object_always_valid: NORD
// §13 step 6, quirk 18) gets one from the first RPDO on, before the profile has seen a status and
// mirrors the drive's mode: the axis' default mode, else the first mode the device offers.
void seed_mode_object(const config::AxisPlan& a, ProcessImage& image) {
  if (!a.device.quirk("mode_object_always_valid") || !image.contains(cia402::obj::kModesOfOperation.id)) return;
  core::Mode mode = a.spec.default_mode;
  for (std::size_t i = 1; mode == core::Mode::None && i < core::kModeCount; ++i)
    if (a.device.modes.contains(static_cast<core::Mode>(i))) mode = static_cast<core::Mode>(i);
  if (const auto op = cia402::to_op_mode(mode)) image.set(cia402::obj::kModesOfOperation.id, *op);
}

}  // namespace

CanopenBus::CanopenBus(const config::BusPlan& plan, std::unique_ptr<Transport> transport,
                       std::unique_ptr<CyclePeer> peer)
    : name_(plan.name),
      options_(plan.section<config::CanopenBusOptions>()),
      cycle_time_(plan.cycle_time),
      transport_(std::move(transport)),
      peer_(std::move(peer)),
      tables_([&] {
        std::vector<Tables> t;
        for (const auto& a : plan.axes) {
          Tables x;
          for (const auto& [code, text] : a.device.fault_texts) x.faults.push_back({static_cast<std::uint16_t>(code), text});
          for (const auto& f : a.device.section<config::CanopenDeviceSpec>().emcy_fields)
            x.fields.push_back({static_cast<std::uint8_t>(f.byte), f.name});
          t.push_back(std::move(x));
        }
        return t;
      }()),
      nmt_nodes_(nmt_nodes_for(plan)),
      // The engines copy their node configurations; only nmt_nodes_ is looked at again.
      sdo_(sdo_channels_for(plan), SdoTiming{options_.sdo_timeout, options_.sdo_retries}),
      nmt_(NmtMasterConfig{static_cast<NodeId>(options_.gateway_node_id), options_.heartbeat_period}, nmt_nodes_),
      emcy_([&] {
        std::vector<EmcyNodeConfig> e;
        for (std::size_t i = 0; i < plan.axes.size(); ++i)
          e.push_back({static_cast<NodeId>(plan.axes[i].address), tables_[i].faults, tables_[i].fields,
                       plan.axes[i].device.section<config::CanopenDeviceSpec>().emcy_zero_needs_clear_register});
        return e;
      }()),
      sync_(cob::kSync, plan.cycle_time),
      frame_time_(frame_time(8, plan.section<config::CanopenBusOptions>().bitrate)) {
  for (std::size_t i = 0; i < plan.axes.size(); ++i) {
    const auto& a = plan.axes[i];
    auto steps = build_boot_steps(a, plan);
    // What the boot writes belongs to the gateway: a client may read it, not change it.
    std::vector<OwnedObject> owned;
    for (const auto& st : steps)
      if (st.kind == BootStep::Kind::Write)
        owned.push_back({st.def.id, "set by the CANopen bus at every boot (" + st.stage + ")"});
    auto n = std::make_unique<Node>(static_cast<int>(i), std::move(steps));
    n->id = static_cast<NodeId>(a.address);
    n->channel = static_cast<int>(i);
    n->gateway_watch = config::gateway_watch_of(a);
    n->watchdog = n->gateway_watch == config::GatewayWatch::Guarding ? cia402::ObjectId{0x100C, 0}
                                                                     : cia402::ObjectId{0x1016, 1};
    const NodePdoConfig pdo = build_pdo_config(a, plan.section<config::CanopenBusOptions>().rpdo_refresh);
    if (!n->pdos.configure(pdo.rpdos, pdo.tpdos))
      throw core::BusError("bus '" + name_ + "' axis '" + a.spec.name + "': PDO maps exceed the process image");
    seed_mode_object(a, n->pdos.image());
    n->io = std::make_unique<NodeAccess>(n->id, n->channel, n->pdos, sdo_, emcy_, std::move(owned));
    cia402::MasterSettings settings = cia402::settings_from(a.spec);
    settings.pp_bit6_absolute = a.device.quirk("pp_bit6_absolute");
    n->master = std::make_unique<cia402::Cia402Master>(*n->io, settings);
    n->master->set_fault_table(tables_[i].faults);
    by_id_[n->id] = n.get();
    nodes_.push_back(std::move(n));
  }
}

CanopenBus::~CanopenBus() = default;

void CanopenBus::open(core::TimePoint now) {
  try {
    transport_->open();
  } catch (const TransportError& e) {
    throw core::BusError("bus '" + name_ + "': " + e.what());
  }
  open_ = true;
  held_count_ = 0;
  controller_ = transport_->controller_state();
  if (options_.sync) sync_.start(now);
  for (auto& n : nodes_) {
    n->detail.format("waiting for node %u's boot-up", unsigned{n->id});
    enter(*n, Phase::Start, now);
  }
}

void CanopenBus::close() noexcept {
  if (!open_) return;
  // A transfer the profile still has in flight (a 4 KiB upload takes a while) must not hold up the
  // watchdog writes on its channel: it is aborted.
  for (auto& n : nodes_) n->io->cancel_requests();
  release_watchdogs();
  // Leave the drives pre-operational (SD6 gateway step B15: before guarding and SYNC stop, so a
  // life-guarding fault is not raised), then release the transport.
  for (auto& n : nodes_) nmt_.command(NmtCommand::EnterPreOperational, n->id, tx_);
  flush(core::TimePoint{});
  sync_.stop();
  transport_->close();
  open_ = false;
  for (auto& n : nodes_) n->link.store(core::LinkState::Offline, std::memory_order_relaxed);
}

// An orderly stop is not a lost gateway: the drives stop watching it (consumer heartbeat 1016h:01
// or guard time 100Ch := 0) before its heartbeat and guarding RTRs end, so they do not fault
// (AKD F129, SD6 event 52). Not cyclic: the cycle thread has stopped, so this may wait, briefly.
void CanopenBus::release_watchdogs() noexcept {
  std::array<SdoRequestId, 128> requests{};
  std::size_t pending = 0;
  for (std::size_t i = 0; i < nodes_.size(); ++i) {
    Node& n = *nodes_[i];
    if (n.phase != Phase::Operational || n.watchdog.index == 0) continue;
    requests[i] = sdo_.write(n.channel, n.watchdog, 0, n.watchdog.index == 0x1016 ? 4 : 2);
    if (requests[i] != kNoSdoRequest) ++pending;
  }
  // Time goes on from the last cycle's time line (the daemon's is the monotonic clock; a test's
  // is virtual) by the real time that passes here.
  const core::SteadyClock clock;
  const auto start = clock.now();
  const auto budget = options_.sdo_timeout * (options_.sdo_retries + 1);
  while (pending > 0 && clock.now() - start < budget) {
    const auto now = last_now_ + (clock.now() - start);
    if (peer_) peer_->step(now);
    const std::size_t got = transport_->receive(rx_buffer_, now);
    for (std::size_t i = 0; i < got; ++i) sdo_.on_frame(rx_buffer_[i], now);  // ignores other COB-IDs
    sdo_.poll(now, tx_);
    flush(now);
    for (std::size_t i = 0; i < nodes_.size(); ++i) {
      if (requests[i] == kNoSdoRequest) continue;
      const auto status = sdo_.result(requests[i]).status;
      if (status == SdoStatus::Queued || status == SdoStatus::InFlight) continue;
      sdo_.take(requests[i]);
      requests[i] = kNoSdoRequest;
      --pending;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

core::LinkState CanopenBus::link_state(std::size_t axis) const noexcept {
  return nodes_[axis]->link.load(std::memory_order_relaxed);
}

std::string_view CanopenBus::link_detail(std::size_t axis) const noexcept { return nodes_[axis]->detail.view(); }

void CanopenBus::enter(Node& n, Phase p, core::TimePoint now) noexcept {
  n.phase = p;
  n.since = now;
  core::LinkState link = core::LinkState::Offline;
  switch (p) {
    case Phase::Start:
    case Phase::WaitBootUp:
    case Phase::Probe: link = n.had_link ? core::LinkState::Lost : core::LinkState::Booting; break;
    case Phase::Configuring: link = core::LinkState::Configuring; break;
    case Phase::Operational: link = core::LinkState::Operational; break;
    case Phase::Backoff: link = n.had_link ? core::LinkState::Lost : core::LinkState::Offline; break;
    case Phase::Lost: link = core::LinkState::Lost; break;
    case Phase::SafeStop: link = core::LinkState::Degraded; break;
  }
  n.link.store(link, std::memory_order_relaxed);
}

// The node is gone (or must be brought up again): stop its PDOs, forget its transfers and its
// fault, stop supervising it.
void CanopenBus::drop_node(Node& n, Phase next, core::TimePoint now) noexcept {
  n.boot.abandon(sdo_);
  if (n.probe != kNoSdoRequest) sdo_.cancel(n.probe);
  n.probe = kNoSdoRequest;
  sdo_.reset_channel(n.channel);
  n.io->forget_requests();
  n.pdos.enable(false, now);
  nmt_.unwatch(n.id);
  emcy_.reset(n.id);
  enter(n, next, now);
}

void CanopenBus::fail_node(Node& n, core::TimePoint now) noexcept {
  // Back-off doubles from boot_retry up to boot_retry_max.
  n.backoff = n.backoff == core::Duration::zero() ? options_.boot_retry
                                                  : std::min(n.backoff * 2, options_.boot_retry_max);
  drop_node(n, Phase::Backoff, now);
}

void CanopenBus::receive(core::TimePoint now) noexcept {
  if (!open_) return;
  last_now_ = now;
  if (peer_) peer_->step(now);
  // What serve_until() read since the last cycle comes first: it was on the wire before the rest.
  for (std::size_t i = 0; i < held_count_; ++i) dispatch(held_[i], now);
  held_count_ = 0;
  for (;;) {
    const std::size_t got = transport_->receive(rx_buffer_, now);
    for (std::size_t i = 0; i < got; ++i) dispatch(rx_buffer_[i], now);
    if (got < rx_buffer_.size()) break;
  }
  handle_controller_state(now);
  handle_nmt_events(now);
  publish_emcy(now);
  for (auto& n : nodes_) {
    advance(*n, now);
    n->io->begin_cycle(now, n->phase == Phase::Operational);
  }
}

void CanopenBus::dispatch(const CanFrame& f, core::TimePoint now) noexcept {
  received_.fetch_add(1, std::memory_order_relaxed);
  if (f.extended) {
    ++unexpected_;
    return;
  }
  const CobSplit c = split_cob_id(f.id);
  bool used = false;
  switch (c.function) {
    case Function::SdoTx: used = sdo_.on_frame(f, now); break;
    case Function::ErrorControl: used = nmt_.on_frame(f, now); break;  // counts an RTR there as unexpected
    case Function::Emcy: used = emcy_.on_frame(f, now); break;
    case Function::Tpdo:
      if (Node* n = node_by_id(c.node)) used = n->pdos.on_frame(f, now);
      break;
    case Function::Sync:
    case Function::Nmt: note_foreign_master(f, now); break;  // the gateway never hears its own
    default: break;  // RPDOs, SDO requests of another master: not for us
  }
  if (!used) ++unexpected_;
}

// Two masters on one bus fight over the drives (each SYNCs, starts and stops nodes, writes
// their controlwords): say so, as a bus event, at most every 10 s.
void CanopenBus::note_foreign_master(const CanFrame& f, core::TimePoint now) noexcept {
  ++foreign_master_;
  if (foreign_pending_ || (foreign_master_ > 1 && now - foreign_reported_ < std::chrono::seconds(10))) return;
  foreign_reported_ = now;
  foreign_pending_ = true;
  foreign_event_ = core::Event{};
  foreign_event_.kind = core::EventKind::Warning;
  foreign_event_.text.format("another CANopen master is on bus %s: it sends %s frames (COB-ID %03Xh) that this gateway "
                             "did not; two masters fight over the drives (%llu such frames so far)",
                             name_.c_str(), f.id == cob::kNmt ? "NMT" : "SYNC", static_cast<unsigned>(f.id),
                             static_cast<unsigned long long>(foreign_master_));
}

bool CanopenBus::next_event(core::Event& out) noexcept {
  if (foreign_pending_) {
    foreign_pending_ = false;
    out = foreign_event_;
    return true;
  }
  for (auto& n : nodes_) {
    if (!n->unwatched_pending) continue;
    n->unwatched_pending = false;
    out = core::Event{};
    out.axis = static_cast<core::AxisIndex>(n->channel);
    out.kind = core::EventKind::Warning;
    if (const std::uint32_t code = n->boot.refusal(); code != 0)
      out.text.format("node %u refused 1016h:01 (consumer heartbeat, abort 0x%08X) and has no 100Ch/100Dh (node "
                      "guarding): it will not stop by itself if the gateway dies",
                      unsigned{n->id}, code);
    else
      out.text.format("node %u has neither 1016h (consumer heartbeat) nor 100Ch/100Dh (node guarding): it will not "
                      "stop by itself if the gateway dies (gateway_watch: optional)",
                      unsigned{n->id});
    return true;
  }
  return emcy_events_.pop(out);
}

bool CanopenBus::take_emcy_token(Node& n, core::TimePoint now) noexcept {
  if (n.emcy_tokens >= kEmcyBurst) {
    n.emcy_refilled = now;  // a full bucket earns nothing: the refill period starts with its first use
  } else if (const auto earned = (now - n.emcy_refilled) / kEmcyRefill; earned > 0) {
    n.emcy_tokens = static_cast<std::uint32_t>(std::min<std::int64_t>(kEmcyBurst, n.emcy_tokens + earned));
    n.emcy_refilled = n.emcy_tokens >= kEmcyBurst ? now : n.emcy_refilled + earned * kEmcyRefill;
  }
  if (n.emcy_tokens == 0) return false;
  --n.emcy_tokens;
  return true;
}

// Every EMCY of a node is an event of its axis (a warning, an error reset / no error, a fault):
// its code, error register and vendor bytes, with the text the device profile's tables give it.
// A node that floods EMCYs is limited by its token bucket; what is held back is counted and summed
// up in one warning once the node has a token again.
void CanopenBus::publish_emcy(core::TimePoint now) noexcept {
  const auto room = [&] { return !emcy_events_.full(); };
  const auto push = [&](const core::Event& e) { (void)emcy_events_.push(e); };
  for (auto& np : nodes_) {
    Node& n = *np;
    if (n.emcy_held_back == 0 || !room() || !take_emcy_token(n, now)) continue;
    core::Event e{};
    e.axis = static_cast<core::AxisIndex>(n.channel);
    e.kind = core::EventKind::Warning;
    e.text.format("node %u sent %llu EMCYs that were not published (at most %u at once, then one per %lld s); the "
                  "last: %s",
                  unsigned{n.id}, static_cast<unsigned long long>(n.emcy_held_back), unsigned{kEmcyBurst},
                  static_cast<long long>(std::chrono::duration_cast<std::chrono::seconds>(kEmcyRefill).count()),
                  n.emcy_last_held.text.c_str());
    n.emcy_held_back = 0;
    push(e);
  }
  EmcyReport r;
  while (room() && emcy_.next_report(r)) {
    Node* n = node_by_id(r.node);
    if (n == nullptr) continue;  // the consumer reports registered nodes only
    if (!take_emcy_token(*n, now)) {
      ++emcy_rate_dropped_;
      ++n->emcy_held_back;
      n->emcy_last_held = r;
      continue;
    }
    core::Event e{};
    e.axis = static_cast<core::AxisIndex>(n->channel);
    e.kind = core::EventKind::Emcy;
    e.code = r.emcy.code;
    // The register and the vendor bytes always fit: a long text is cut instead, visibly.
    const core::FixedString<core::Text::capacity() - 50> what(r.text.view());
    const auto& v = r.emcy.vendor;
    e.text.format("EMCY %s; register 0x%02X, vendor bytes %02X %02X %02X %02X %02X", what.c_str(),
                  unsigned{r.emcy.error_register}, unsigned{v[0]}, unsigned{v[1]}, unsigned{v[2]}, unsigned{v[3]},
                  unsigned{v[4]});
    push(e);
  }
}

void CanopenBus::handle_controller_state(core::TimePoint now) noexcept {
  const ControllerState s = transport_->controller_state();
  if (s == controller_) return;
  const bool was_off = controller_ == ControllerState::BusOff;
  controller_ = s;
  if (s == ControllerState::BusOff) {
    for (auto& n : nodes_) {
      n->detail.assign("the gateway's CAN controller is bus-off");
      if (n->phase == Phase::Operational) n->had_link = true;
      drop_node(*n, Phase::Lost, now);
    }
    tx_.clear();
  } else if (was_off) {
    // The controller is back: check every node again from scratch.
    for (auto& n : nodes_) {
      n->detail.assign("CAN controller recovered from bus-off: checking the node again");
      n->backoff = core::Duration::zero();
      enter(*n, Phase::Start, now);
    }
  }
}

void CanopenBus::handle_nmt_events(core::TimePoint now) noexcept {
  NmtEvent e;
  while (nmt_.next_event(e)) {
    Node* n = node_by_id(e.node);
    if (!n) continue;
    switch (e.kind) {
      case NmtEventKind::BootUp:
        // The node (re)started: its configuration is gone. Reconfigure it from scratch.
        if (n->phase == Phase::Operational) n->had_link = true;
        n->detail.format("node %u booted: configuring it", unsigned{n->id});
        drop_node(*n, Phase::Configuring, now);
        ++n->boots;
        n->boot.start();
        break;
      case NmtEventKind::Lost:
        if (n->phase == Phase::Operational) {
          n->had_link = true;
          n->detail.format("node %u stopped answering (%s)", unsigned{n->id},
                           nmt_nodes_[static_cast<std::size_t>(n->channel)].watch == Watch::Guarding
                               ? "node guarding"
                               : "heartbeat timeout");
          drop_node(*n, Phase::Lost, now);
        }
        break;
      case NmtEventKind::StateChanged:
        if (n->phase == Phase::Operational && e.state != NmtState::Operational) {
          // Someone else switched the node out of Operational: its PDOs stopped. Bring it up again.
          n->had_link = true;
          n->detail.format("node %u left operational (now %s): configuring it again", unsigned{n->id},
                           to_string(e.state));
          drop_node(*n, Phase::Probe, now);
        }
        break;
      case NmtEventKind::Recovered:
        if (n->phase == Phase::Lost || n->phase == Phase::Backoff) {
          n->detail.format("node %u is heard again: asking it (SDO read of 1000h)", unsigned{n->id});
          enter(*n, Phase::Probe, now);
        }
        break;
      case NmtEventKind::ToggleError: break;  // counted by the NMT master; misses decide
    }
  }
}

void CanopenBus::advance(Node& n, core::TimePoint now) noexcept {
  if (controller_ == ControllerState::BusOff) return;
  switch (n.phase) {
    case Phase::Start:
      enter(n, Phase::WaitBootUp, now);
      break;
    case Phase::WaitBootUp:
      // A drive powering up announces itself; one that was already running (or does not repeat
      // its boot-up: SD6 quirk 9) is probed by SDO, put into pre-operational and configured
      // completely, whatever state an earlier master left it in.
      if (now - n.since >= kBootUpWait) {
        n.detail.format("node %u sent no boot-up: asking it (SDO read of 1000h)", unsigned{n.id});
        enter(n, Phase::Probe, now);
      }
      break;
    case Phase::Probe:
      if (n.probe == kNoSdoRequest) {
        n.probe = sdo_.read(n.channel, {0x1000, 0}, 4);
        break;
      }
      switch (sdo_.result(n.probe).status) {
        case SdoStatus::Queued:
        case SdoStatus::InFlight: break;
        case SdoStatus::Done:
          sdo_.take(n.probe);
          n.probe = kNoSdoRequest;
          nmt_.command(NmtCommand::EnterPreOperational, n.id, tx_);
          n.detail.format(n.had_link ? "node %u answered again; configuring it" : "node %u answered; configuring it",
                          unsigned{n.id});
          enter(n, Phase::Configuring, now);
          ++n.boots;
          n.boot.start();
          break;
        case SdoStatus::Failed: {
          const auto code = sdo_.take(n.probe).abort_code;
          n.probe = kNoSdoRequest;
          n.detail.format("node %u does not answer (SDO read of 1000h: %s)", unsigned{n.id},
                          cia402::sdo_abort_text(code).data());
          fail_node(n, now);
          break;
        }
        case SdoStatus::Unknown: n.probe = kNoSdoRequest; break;
      }
      break;
    case Phase::Configuring:
      switch (n.boot.step(sdo_, n.pdos.image())) {
        case NodeBoot::Status::Done: {
          // How the drive watches the gateway is what its boot found (gateway_watch required /
          // optional) or what the plan demanded.
          const WatchOutcome outcome = watch_outcome(n.gateway_watch, n.boot.found());
          const Watch how = outcome == WatchOutcome::Guarding ? Watch::Guarding : Watch::Heartbeat;
          nmt_nodes_[static_cast<std::size_t>(n.channel)].watch = how;
          n.watchdog = outcome == WatchOutcome::Heartbeat  ? cia402::ObjectId{0x1016, 1}
                       : outcome == WatchOutcome::Guarding ? cia402::ObjectId{0x100C, 0}
                                                           : cia402::ObjectId{};
          if (outcome == WatchOutcome::Unwatched && !n.unwatched_reported) {
            n.unwatched_reported = true;
            n.unwatched_pending = true;
          }
          nmt_.command(NmtCommand::Start, n.id, tx_);
          nmt_.watch(n.id, how, now);
          n.pdos.enable(true, now);
          n.backoff = core::Duration::zero();
          n.detail.format("node %u configured", unsigned{n.id});
          enter(n, Phase::Operational, now);
          break;
        }
        case NodeBoot::Status::Failed:
          n.detail.format("node %u: %.*s", unsigned{n.id}, static_cast<int>(n.boot.failure().view().size()),
                          n.boot.failure().view().data());
          fail_node(n, now);
          break;
        default: break;
      }
      break;
    case Phase::Backoff:
    case Phase::Lost:
      // Probe again after the back-off (Lost: after boot_retry); a boot-up or heartbeat may come first.
      if (const auto wait = n.backoff == core::Duration::zero() ? options_.boot_retry : n.backoff;
          now - n.since >= wait) {
        n.detail.format("node %u: asking it again after %lld ms (SDO read of 1000h)", unsigned{n.id},
                        static_cast<long long>(std::chrono::duration_cast<std::chrono::milliseconds>(wait).count()));
        enter(n, Phase::Probe, now);
      }
      break;
    case Phase::Operational:
      if (core::FixedString<200> why; n.io->take_control_lost(why)) {
        n.detail = why;
        start_safe_stop(n, now);
      }
      break;
    case Phase::SafeStop: run_safe_stop(n, now); break;
  }
}

// The drive no longer follows the controlword in the RPDOs (DESIGN.md §4): what the gateway says
// now goes over SDO, which answers for itself.
void CanopenBus::start_safe_stop(Node& n, core::TimePoint now) noexcept {
  n.had_link = true;
  n.pdos.enable(false, now);
  sdo_.reset_channel(n.channel);  // the profile's transfers give way to the stop
  n.io->forget_requests();
  n.safe_step = 0;
  n.probe = kNoSdoRequest;
  enter(n, Phase::SafeStop, now);
}

void CanopenBus::run_safe_stop(Node& n, core::TimePoint now) noexcept {
  const auto finished = [&]() -> std::optional<SdoResult> {
    const SdoResult r = sdo_.result(n.probe);
    if (r.status == SdoStatus::Queued || r.status == SdoStatus::InFlight) return std::nullopt;
    if (r.status != SdoStatus::Unknown) sdo_.take(n.probe);
    n.probe = kNoSdoRequest;
    return r;
  };
  switch (n.safe_step) {
    case 0:  // quick stop: the drive brakes on its quick-stop ramp
      n.probe = sdo_.write(n.channel, cia402::obj::kControlword.id, 0x0002, 2);
      if (n.probe != kNoSdoRequest) n.safe_step = 1;
      break;
    case 1:
      if (finished()) n.safe_step = 2;
      break;
    case 2:  // until it left operation enabled and the quick-stop ramp, or the budget ran out
      n.probe = sdo_.read(n.channel, cia402::obj::kStatusword.id, 2);
      if (n.probe != kNoSdoRequest) n.safe_step = 3;
      break;
    case 3:
      if (const auto r = finished()) {
        const auto state = cia402::decode_state(static_cast<std::uint16_t>(r->value));
        const bool braking = r->status == SdoStatus::Done &&
                             (state == core::AxisState::OperationEnabled || state == core::AxisState::QuickStopActive);
        n.safe_step = braking && now - n.since < kSafeStopBudget ? 2 : 4;
      }
      break;
    case 4:  // disable voltage: the power stage goes off
      n.probe = sdo_.write(n.channel, cia402::obj::kControlword.id, 0x0000, 2);
      if (n.probe != kNoSdoRequest) n.safe_step = 5;
      break;
    default:
      if (!finished()) break;
      // Out of operational, then its communication objects back to their defaults: the boot-up
      // that follows (or the probe, for drives that do not repeat it) configures it from scratch.
      nmt_.command(NmtCommand::Stop, n.id, tx_);
      nmt_.command(NmtCommand::ResetCommunication, n.id, tx_);
      nmt_.unwatch(n.id);
      emcy_.reset(n.id);
      n.detail.format("node %u was stopped over SDO after it stopped following its controlword: configuring it "
                      "again",
                      unsigned{n.id});
      enter(n, Phase::WaitBootUp, now);
      break;
  }
}

void CanopenBus::transmit(core::TimePoint now) noexcept {
  if (!open_) return;
  if (controller_ == ControllerState::BusOff) {
    tx_.clear();
    return;
  }
  // SYNC first, then the RPDOs of every operational node inside the SYNC window. The cycle
  // thread keeps the period; the producer only guards against sending twice in one cycle.
  const bool synced = options_.sync && sync_.poll(now + cycle_time_ / 2, tx_);
  for (auto& n : nodes_) {
    if (n->phase != Phase::Operational) continue;
    if (synced)
      n->pdos.after_sync(now, tx_);
    else
      n->pdos.poll(now, tx_);
  }
  nmt_.poll(now, tx_);
  sdo_.poll(now, tx_);
  flush(now);
  publish_counters();
}

void CanopenBus::serve_until(core::TimePoint deadline) noexcept {
  const int fd = transport_->wait_fd();
  if (!open_ || fd < 0 || controller_ == ControllerState::BusOff) return;
  // The controller sends our frames in order (a FIFO), so the SYNC queued at the next cycle start
  // waits behind every frame sent here; other nodes' frames lose arbitration to it. What is sent
  // here must be off the wire kServeGuard plus two frame times (one frame that may be on the wire,
  // one spare) before the deadline: each pass sends only the frames that fit after the ones it
  // sent before (estimated back to back, at 8 data bytes each).
  const core::TimePoint stop = deadline - kServeGuard - 2 * frame_time_;
  core::TimePoint wire_free = clock_.now();  // when the frames sent here have left, estimated
  for (;;) {
    const core::TimePoint now = clock_.now();
    if (now >= stop) return;
    const core::TimePoint from = std::max(now, wire_free);
    const auto fit = from < stop ? static_cast<std::size_t>((stop - from) / frame_time_) : 0;
    // The next segment request, a retry or a queued request goes out now, not at the next cycle
    // (after any frame of the last cycle the transport had no room for: it was due already).
    const std::size_t queued = tx_.size();
    sdo_.poll(now, tx_, fit > queued ? fit - queued : 0);
    wire_free = from + static_cast<std::int64_t>(flush(now)) * frame_time_;
    const core::TimePoint due = sdo_.next_deadline();
    // No SDO work in flight: sleep through the rest of the period (no wake-up per frame).
    if (due == core::TimePoint::max()) return;
    if (held_count_ == held_.size()) {
      ++serve_.held_full;
      return;
    }
    const core::TimePoint until = std::min(stop, due);
    // poll() has just handled what was due, or what is due does not fit before the deadline.
    if (until <= now) return;
    ++serve_.waits;
    const short revents = core::wait_readable(fd, until - now);
    // A timeout: the loop polls the SDO client (its timeout) or returns at `stop`. EINTR: again.
    if (revents == 0) continue;
    // Read on any event: a socket's pending error (a CAN interface that went down) is reported,
    // and cleared, by the read.
    take_between_cycles(clock_.now());
    // An error or hang-up would wake every ppoll() again at once until the deadline: the cycle's
    // receive() meets the transport's state instead.
    if ((revents & (POLLERR | POLLHUP | POLLNVAL)) != 0) {
      ++serve_.fd_errors;
      return;
    }
  }
}

// Reads what the transport has into the held frames and hands the SDO responses among them to the
// SDO client now; the rest stays held, in order, for the next receive().
void CanopenBus::take_between_cycles(core::TimePoint now) noexcept {
  const std::size_t first = held_count_;
  const std::size_t end = first + transport_->receive(std::span<CanFrame>(held_).subspan(first), now);
  for (std::size_t i = first; i < end; ++i) {
    const CanFrame& f = held_[i];
    if (!f.extended && split_cob_id(f.id).function == Function::SdoTx && sdo_.on_frame(f, now)) {
      received_.fetch_add(1, std::memory_order_relaxed);
      ++serve_.sdo_frames;
      continue;
    }
    ++serve_.held_frames;
    held_[held_count_++] = f;
  }
}

std::size_t CanopenBus::flush(core::TimePoint now) noexcept {
  const FlushResult f = flush_queue(tx_, *transport_, now);
  sent_.fetch_add(f.sent, std::memory_order_relaxed);
  tx_dropped_ += f.refused;
  return f.sent;
}

void CanopenBus::publish_counters() noexcept {
  std::uint64_t missed = 0;
  std::uint64_t bad = unexpected_ + tx_dropped_ + sdo_.counters().malformed + sdo_.counters().unexpected +
                      nmt_.counters().malformed + nmt_.counters().unexpected + emcy_.counters().malformed +
                      emcy_.counters().unexpected;
  for (const auto& n : nodes_) {
    missed += n->pdos.counters().missed;
    bad += n->pdos.counters().short_frames;
  }
  // What the transport could not decode (a garbage datagram on udp-multicast) is dropped input too.
  const auto t = transport_->counters();
  lost_.store(missed, std::memory_order_relaxed);
  dropped_.store(bad + t.rx_malformed, std::memory_order_relaxed);
  errors_.store(t.error_frames + t.bus_off, std::memory_order_relaxed);
}

core::BusCounters CanopenBus::counters() const noexcept {
  core::BusCounters c;
  c.frames_sent = sent_.load(std::memory_order_relaxed);
  c.frames_received = received_.load(std::memory_order_relaxed);
  c.frames_lost = lost_.load(std::memory_order_relaxed);
  c.frames_dropped = dropped_.load(std::memory_order_relaxed);
  c.errors = errors_.load(std::memory_order_relaxed);
  return c;
}

}  // namespace drivegate::canopen
