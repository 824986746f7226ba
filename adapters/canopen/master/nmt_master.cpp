// NMT master and error control: see nmt_master.hpp for the rules. Everything after the
// constructor works on the fixed node table and event ring; nothing allocates.
#include "adapters/canopen/master/nmt_master.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "adapters/canopen/wire/cob_id.hpp"

namespace drivegate::canopen {

NmtMaster::NmtMaster(NmtMasterConfig config, std::span<const NmtNodeConfig> nodes) : config_(config) {
  if (config_.heartbeat_period > core::Duration::zero() && !valid_node_id(config_.own_node)) {
    throw std::invalid_argument("NMT master: own node-ID " + std::to_string(config_.own_node) +
                                " is outside 1..127 but a heartbeat period is set");
  }
  nodes_.reserve(nodes.size());
  for (const auto& cfg : nodes) {
    if (!valid_node_id(cfg.node)) {
      throw std::invalid_argument("NMT master: node-ID " + std::to_string(cfg.node) + " is outside 1..127");
    }
    if (index_[cfg.node] != 0) {
      throw std::invalid_argument("NMT master: node-ID " + std::to_string(cfg.node) + " is registered twice");
    }
    Node n;
    n.config = cfg;
    // A life time factor of 0 would make every node lost at its first RTR; 1 is the least that
    // means anything (CiA 301 uses 0 for "guarding off", which is Watch::None here).
    n.config.life_time_factor = std::max(1, cfg.life_time_factor);
    nodes_.push_back(n);
    index_[cfg.node] = static_cast<std::uint8_t>(nodes_.size());
  }
}

NmtMaster::Node* NmtMaster::find(NodeId node) noexcept {
  if (node > kMaxNodeId || index_[node] == 0) return nullptr;
  return &nodes_[index_[node] - 1U];
}

const NmtMaster::Node* NmtMaster::find(NodeId node) const noexcept {
  if (node > kMaxNodeId || index_[node] == 0) return nullptr;
  return &nodes_[index_[node] - 1U];
}

bool NmtMaster::command(NmtCommand cs, NodeId node, TxQueue& tx) noexcept {
  if (node > kMaxNodeId) return false;
  const auto bytes = encode_nmt(cs, node);
  if (!tx.push(make_frame(cob::kNmt, bytes))) {
    ++counters_.tx_full;
    return false;
  }
  if (cs == NmtCommand::ResetNode || cs == NmtCommand::ResetCommunication) {
    for (auto& n : nodes_) {
      if (node == 0 || n.config.node == node) {
        n.expected_toggle = false;
        n.awaiting_reply = false;  // a resetting node does not answer the RTR that was out
      }
    }
  }
  return true;
}

void NmtMaster::watch(NodeId node, core::TimePoint now) noexcept {
  Node* n = find(node);
  if (n == nullptr || n->config.watch == Watch::None) return;
  n->watching = true;
  n->heartbeat_deadline = now + n->config.heartbeat_timeout;
  n->next_rtr = now;  // the first RTR goes out at once: guarding starts when the owner says so
  n->awaiting_reply = false;
  n->misses = 0;
}

void NmtMaster::watch(NodeId node, Watch how, core::TimePoint now) noexcept {
  if (Node* n = find(node)) n->config.watch = how;
  watch(node, now);
}

void NmtMaster::unwatch(NodeId node) noexcept {
  if (Node* n = find(node)) {
    n->watching = false;
    n->awaiting_reply = false;
    n->misses = 0;
  }
}

NmtState NmtMaster::state(NodeId node) const noexcept {
  const Node* n = find(node);
  return n != nullptr ? n->state : NmtState::Unknown;
}

bool NmtMaster::lost(NodeId node) const noexcept {
  const Node* n = find(node);
  return n != nullptr && n->lost;
}

core::TimePoint NmtMaster::last_heard(NodeId node) const noexcept {
  const Node* n = find(node);
  return n != nullptr ? n->last_heard : core::TimePoint{};
}

bool NmtMaster::next_event(NmtEvent& out) noexcept {
  if (event_count_ == 0) return false;
  out = events_[event_head_];
  event_head_ = (event_head_ + 1) % kEventCapacity;
  --event_count_;
  return true;
}

void NmtMaster::push_event(NmtEventKind kind, const Node& n) noexcept {
  if (event_count_ == kEventCapacity) {
    ++counters_.events_dropped;
    return;
  }
  events_[(event_head_ + event_count_) % kEventCapacity] = NmtEvent{kind, n.config.node, n.state};
  ++event_count_;
}

bool NmtMaster::on_frame(const CanFrame& frame, core::TimePoint now) noexcept {
  if (frame.extended) return false;
  const auto split = split_cob_id(frame.id);
  if (split.function != Function::ErrorControl) return false;
  Node* n = find(split.node);
  if (n == nullptr || frame.remote) {
    // Another node's frame, or an RTR on 700h+n: only a master sends those, and it is not us.
    ++counters_.unexpected;
    return true;
  }
  const auto payload = frame.payload();
  const auto decoded = decode_error_control(payload);
  if (!decoded) {
    ++counters_.malformed;
    return true;
  }
  if (payload[0] == 0x00) {
    on_boot_up(*n, now);
  } else if (decoded->state == NmtState::Initialising) {
    // 80h: a "boot-up" with the toggle set is no frame any node sends.
    ++counters_.malformed;
  } else if (n->watching && n->config.watch == Watch::Guarding) {
    on_guard_reply(*n, *decoded, now);
  } else {
    on_heartbeat(*n, decoded->state, now);
  }
  return true;
}

void NmtMaster::on_boot_up(Node& n, core::TimePoint now) noexcept {
  ++counters_.boot_ups;
  n.state = NmtState::PreOperational;
  n.last_heard = now;
  n.lost = false;
  n.watching = false;
  n.awaiting_reply = false;
  n.expected_toggle = false;  // the responder restarts its toggle at 0 [CiA 301 §7.2.8.3.1]
  n.misses = 0;
  push_event(NmtEventKind::BootUp, n);
}

void NmtMaster::heard(Node& n, NmtState state, core::TimePoint now) noexcept {
  n.last_heard = now;
  const bool changed = state != n.state;
  n.state = state;
  if (n.lost) {
    n.lost = false;
    push_event(NmtEventKind::Recovered, n);
  }
  if (changed) push_event(NmtEventKind::StateChanged, n);
}

void NmtMaster::on_heartbeat(Node& n, NmtState state, core::TimePoint now) noexcept {
  ++counters_.heartbeats;
  n.heartbeat_deadline = now + n.config.heartbeat_timeout;
  heard(n, state, now);
}

void NmtMaster::on_guard_reply(Node& n, ErrorControlFrame reply, core::TimePoint now) noexcept {
  if (!n.awaiting_reply) {
    // No RTR is out: a late duplicate, or a heartbeat from a node that should be guarded.
    ++counters_.unexpected;
    return;
  }
  n.awaiting_reply = false;
  ++counters_.guard_replies;
  if (reply.toggle != n.expected_toggle) {
    ++counters_.toggle_errors;
    n.expected_toggle = !reply.toggle;
    push_event(NmtEventKind::ToggleError, n);
    miss(n);
    return;
  }
  n.expected_toggle = !n.expected_toggle;
  n.misses = 0;
  heard(n, reply.state, now);
}

void NmtMaster::lose(Node& n) noexcept {
  if (n.lost) return;
  n.lost = true;
  ++counters_.losses;
  push_event(NmtEventKind::Lost, n);
}

void NmtMaster::miss(Node& n) noexcept {
  if (++n.misses >= n.config.life_time_factor) lose(n);
}

void NmtMaster::poll_guarding(Node& n, core::TimePoint now, TxQueue& tx) noexcept {
  if (now < n.next_rtr) return;
  if (n.awaiting_reply) miss(n);  // no reply before the next RTR
  CanFrame rtr;
  rtr.id = cob::error_control(n.config.node);
  rtr.remote = true;
  rtr.dlc = 1;  // the length of the reply it asks for (AKD part 1 §14 vector 25)
  // A refused RTR counts like one lost on the bus: the missing reply makes it a miss.
  if (!tx.push(rtr)) ++counters_.tx_full;
  n.awaiting_reply = true;
  // Steady schedule; after a stall the next RTR is one guard time from now, not a burst.
  n.next_rtr += n.config.guard_time;
  if (n.next_rtr <= now) n.next_rtr = now + n.config.guard_time;
}

void NmtMaster::poll(core::TimePoint now, TxQueue& tx) noexcept {
  if (config_.heartbeat_period > core::Duration::zero() && now >= next_own_heartbeat_) {
    // The master reports Operational: consumers (AKD 1016h) only care that it is alive.
    const std::uint8_t state = encode_error_control(NmtState::Operational);
    if (!tx.push(make_frame(cob::error_control(config_.own_node), {state}))) ++counters_.tx_full;
    // Steady schedule; the first one and one after a stall set it to one period from now.
    next_own_heartbeat_ += config_.heartbeat_period;
    if (next_own_heartbeat_ <= now) next_own_heartbeat_ = now + config_.heartbeat_period;
  }
  for (auto& n : nodes_) {
    if (!n.watching) continue;
    if (n.config.watch == Watch::Heartbeat) {
      if (now >= n.heartbeat_deadline) lose(n);
    } else {
      poll_guarding(n, now, tx);
    }
  }
}

core::TimePoint NmtMaster::next_deadline() const noexcept {
  auto next = core::TimePoint::max();
  if (config_.heartbeat_period > core::Duration::zero()) next = next_own_heartbeat_;
  for (const auto& n : nodes_) {
    if (!n.watching) continue;
    if (n.config.watch == Watch::Heartbeat) {
      if (!n.lost) next = std::min(next, n.heartbeat_deadline);
    } else {
      next = std::min(next, n.next_rtr);
    }
  }
  return next;
}

}  // namespace drivegate::canopen
