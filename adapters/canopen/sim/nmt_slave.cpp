// NMT slave: see nmt_slave.hpp.
#include "adapters/canopen/sim/nmt_slave.hpp"

#include <algorithm>
#include <chrono>
#include <optional>

namespace drivegate::canopen::sim {
namespace {

core::Duration ms(unsigned v) noexcept { return std::chrono::milliseconds(v); }

}  // namespace

NmtSlave::NmtSlave(NmtSlaveConfig config) noexcept : config_(config) {}

void NmtSlave::restore_communication(core::TimePoint now) noexcept {
  heartbeat_ms_ = config_.heartbeat_period_ms;
  next_heartbeat_ = now + ms(heartbeat_ms_);
  guard_ms_ = config_.guard_time_ms;
  life_factor_ = config_.life_time_factor;
  guarding_started_ = false;
  life_expired_ = false;
  toggle_ = false;  // the first guard reply after a reset has toggle 0 [CiA 301 §7.2.8.3.1]
  pending_replies_ = 0;
  consumer_entry_ = config_.heartbeat_consumer;
  consumer_started_ = false;
  consumer_expired_ = false;
}

void NmtSlave::power_on(core::TimePoint now) noexcept {
  powered_ = true;
  restore_communication(now);
  enter(NmtState::Initialising);
  boot_up_pending_ = true;
  // Power-on always announces itself, also on the SD6 (§6.7: "one boot-up message" at start-up).
  send_boot_up_ = true;
  boot_at_ = now;
}

void NmtSlave::enter(NmtState s) noexcept {
  if (s == state_) return;
  state_ = s;
  push_event(NmtSlaveEventKind::StateChanged);
}

void NmtSlave::push_event(NmtSlaveEventKind kind) noexcept {
  if (event_count_ == kEventCapacity) {
    ++counters_.events_dropped;
    return;
  }
  events_[(event_head_ + event_count_) % kEventCapacity] = NmtSlaveEvent{kind, state_};
  ++event_count_;
}

bool NmtSlave::next_event(NmtSlaveEvent& out) noexcept {
  if (event_count_ == 0) return false;
  out = events_[event_head_];
  event_head_ = (event_head_ + 1) % kEventCapacity;
  --event_count_;
  return true;
}

bool NmtSlave::serves(NmtService s) const noexcept {
  // SD6 digest §6.7, service availability per NMT state.
  switch (state_) {
    case NmtState::Operational: return true;
    case NmtState::PreOperational: return s != NmtService::Pdo;
    default: return false;  // Stopped: only NMT and error control; Initialising: nothing
  }
}

NodeId NmtSlave::consumed_node() const noexcept { return static_cast<NodeId>((consumer_entry_ >> 16) & 0xFFU); }

bool NmtSlave::consumer_armed() const noexcept {
  return consumer_started_ && !consumer_expired_ && (consumer_entry_ & 0xFFFFU) != 0;
}

bool NmtSlave::life_guarding_armed() const noexcept {
  // 0 in either object disables life guarding (AKD part 1 §11.1, SD6 §6.8).
  return guarding_started_ && !life_expired_ && guard_ms_ != 0 && life_factor_ != 0;
}

void NmtSlave::set_heartbeat_period(std::uint16_t period_ms, core::TimePoint now) noexcept {
  heartbeat_ms_ = period_ms;
  next_heartbeat_ = now + ms(period_ms);
}

void NmtSlave::set_guarding(std::uint16_t guard_time_ms, std::uint8_t factor, core::TimePoint now) noexcept {
  guard_ms_ = guard_time_ms;
  life_factor_ = factor;
  life_expired_ = false;
  last_rtr_ = now;  // a new life time counts from the write, if guarding already runs
}

void NmtSlave::set_heartbeat_consumer(std::uint32_t entry) noexcept {
  consumer_entry_ = entry;
  // Monitoring starts with the first heartbeat of the new producer (AKD part 1 §11.2).
  consumer_started_ = false;
  consumer_expired_ = false;
}

bool NmtSlave::on_frame(const CanFrame& frame, core::TimePoint now) noexcept {
  if (frame.extended) return false;
  const bool nmt = frame.id == cob::kNmt;
  const bool own = frame.id == cob::error_control(config_.node);
  const NodeId producer = consumed_node();
  const bool consumed = !frame.remote && valid_node_id(producer) && producer != config_.node &&
                        (consumer_entry_ & 0xFFFFU) != 0 && frame.id == cob::error_control(producer);
  if (!nmt && !own && !consumed) return false;
  if (!powered_ || silent_ || state_ == NmtState::Initialising) {
    ++counters_.ignored;
    return true;
  }
  if (nmt) {
    on_nmt(frame, now);
  } else if (own) {
    on_rtr(frame, now);
  } else {
    on_consumed_heartbeat(frame, now);
  }
  return true;
}

void NmtSlave::on_nmt(const CanFrame& frame, core::TimePoint now) noexcept {
  const auto cmd = frame.remote ? std::nullopt : decode_nmt(frame.payload());
  if (!cmd) {
    ++counters_.malformed;
    return;
  }
  if (cmd->node != 0 && cmd->node != config_.node) return;  // for another node
  ++counters_.nmt_commands;
  switch (cmd->command) {
    case NmtCommand::Start: enter(NmtState::Operational); break;
    case NmtCommand::Stop: enter(NmtState::Stopped); break;
    case NmtCommand::EnterPreOperational: enter(NmtState::PreOperational); break;
    case NmtCommand::ResetNode:
    case NmtCommand::ResetCommunication:
      push_event(cmd->command == NmtCommand::ResetNode ? NmtSlaveEventKind::ResetNode
                                                       : NmtSlaveEventKind::ResetCommunication);
      restore_communication(now);
      enter(NmtState::Initialising);
      boot_up_pending_ = true;
      send_boot_up_ = config_.options.boot_up_after_reset;  // SD6 quirk 9
      boot_at_ = now;
      break;
  }
}

void NmtSlave::on_rtr(const CanFrame& frame, core::TimePoint now) noexcept {
  if (!frame.remote) {
    // Data on our own error-control COB-ID: another node with our node-ID.
    ++counters_.unexpected;
    return;
  }
  if (frame.dlc > 1) {
    // A guard request asks for the 1-byte reply; DLC 0 is accepted because some masters send it.
    ++counters_.malformed;
    return;
  }
  if (heartbeat_ms_ != 0) {
    // Heartbeat and guarding exclude each other (SD6 §6.8; CiA 301 gives heartbeat priority).
    ++counters_.unexpected;
    return;
  }
  guarding_started_ = true;  // the first request starts life guarding (AKD part 1 §11.1)
  life_expired_ = false;
  last_rtr_ = now;
  if (pending_replies_ == kMaxPendingReplies) {
    ++counters_.unexpected;
    return;
  }
  if (pending_replies_ == 0) reply_at_ = now;
  ++pending_replies_;
}

void NmtSlave::on_consumed_heartbeat(const CanFrame& frame, core::TimePoint now) noexcept {
  if (!decode_error_control(frame.payload())) {
    ++counters_.malformed;
    return;
  }
  consumer_started_ = true;
  consumer_expired_ = false;
  consumer_last_ = now;
}

void NmtSlave::poll(core::TimePoint now, TxQueue& tx) noexcept {
  if (!powered_) return;
  const auto send = [&](const CanFrame& f, std::uint64_t& sent) {
    if (silent_) return;
    if (tx.push(f)) {
      ++sent;
    } else {
      ++counters_.tx_full;
    }
  };
  const auto error_control = [&](std::uint8_t byte) { return make_frame(cob::error_control(config_.node), {byte}); };

  if (boot_up_pending_ && now >= boot_at_) {
    boot_up_pending_ = false;
    if (send_boot_up_) send(error_control(encode_error_control(NmtState::Initialising)), counters_.boot_ups_sent);
    enter(NmtState::PreOperational);
    next_heartbeat_ = now + ms(heartbeat_ms_);  // the first heartbeat one period after boot-up
  }
  if (state_ == NmtState::Initialising) return;

  for (; pending_replies_ > 0; --pending_replies_) {
    send(error_control(encode_error_control(state_, toggle_)), counters_.guard_replies);
    toggle_ = !toggle_;
  }
  if (heartbeat_ms_ != 0 && now >= next_heartbeat_) {
    send(error_control(encode_error_control(state_)), counters_.heartbeats_sent);
    next_heartbeat_ += ms(heartbeat_ms_);
    if (next_heartbeat_ <= now) next_heartbeat_ = now + ms(heartbeat_ms_);
  }
  if (life_guarding_armed() && now >= last_rtr_ + ms(guard_ms_) * life_factor_) {
    life_expired_ = true;
    ++counters_.life_guarding;
    if (!config_.options.life_guarding_only_operational || state_ == NmtState::Operational) {
      push_event(NmtSlaveEventKind::LifeGuarding);
    }
  }
  if (consumer_armed() && now >= consumer_last_ + ms(consumer_entry_ & 0xFFFFU)) {
    consumer_expired_ = true;
    ++counters_.heartbeat_lost;
    push_event(NmtSlaveEventKind::HeartbeatLost);
  }
}

core::TimePoint NmtSlave::next_deadline() const noexcept {
  if (!powered_) return core::TimePoint::max();
  if (boot_up_pending_) return boot_at_;
  auto next = core::TimePoint::max();
  if (pending_replies_ > 0) next = reply_at_;
  if (heartbeat_ms_ != 0) next = std::min(next, next_heartbeat_);
  if (life_guarding_armed()) next = std::min(next, last_rtr_ + ms(guard_ms_) * life_factor_);
  if (consumer_armed()) next = std::min(next, consumer_last_ + ms(consumer_entry_ & 0xFFFFU));
  return next;
}

}  // namespace drivegate::canopen::sim
