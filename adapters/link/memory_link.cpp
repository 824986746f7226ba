#include "adapters/link/memory_link.hpp"

#include <algorithm>
#include <cstring>

namespace drivegate::link {

MemoryLink::MemoryLink(const FrameRules& rules, std::size_t capacity) : rules_(rules), slots_(std::max<std::size_t>(capacity, 1)) {}

MemoryLink::~MemoryLink() { detach(); }

void MemoryLink::detach() noexcept {
  if (peer_ != nullptr && peer_->peer_ == this) peer_->peer_ = nullptr;
  peer_ = nullptr;
}

void MemoryLink::connect(MemoryLink& a, MemoryLink& b) noexcept {
  a.detach();
  b.detach();
  a.sink_ = nullptr;
  b.sink_ = nullptr;
  a.peer_ = &b;
  b.peer_ = &a;
}

void MemoryLink::set_sink(FrameSink* sink) noexcept {
  detach();
  sink_ = sink;
}

void MemoryLink::open() {
  open_.store(true, std::memory_order_relaxed);
}

void MemoryLink::close() noexcept {
  open_.store(false, std::memory_order_relaxed);
  head_ = 0;
  count_ = 0;
}

void MemoryLink::set_wire_state(LinkState s) noexcept {
  counters_.count_transition(wire_.exchange(s, std::memory_order_relaxed), s);
}

LinkState MemoryLink::state() const noexcept {
  return open_.load(std::memory_order_relaxed) ? wire_.load(std::memory_order_relaxed) : LinkState::Closed;
}

LinkState MemoryLink::poll_state(core::TimePoint /*now*/) noexcept { return state(); }

bool MemoryLink::deliver(FrameView frame) noexcept {
  if (!is_open() || wire_.load(std::memory_order_relaxed) != LinkState::Up) return false;
  if (const FrameCheck c = check_frame(frame, rules_); c != FrameCheck::Ok) {
    counters_.count_drop(c);
    return false;
  }
  if (count_ == slots_.size()) {
    counters_.rx_overflow.add();
    return false;
  }
  FrameBuffer& slot = slots_[(head_ + count_) % slots_.size()];
  std::memcpy(slot.bytes.data(), frame.data(), frame.size());
  slot.size = frame.size();
  ++count_;
  return true;
}

SendResult MemoryLink::send(std::span<const FrameView> frames) noexcept {
  SendResult r;
  const bool up = is_open() && wire_.load(std::memory_order_relaxed) == LinkState::Up;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const FrameView f = frames[i];
    if (!sendable(f, rules_)) {
      ++r.invalid;
      counters_.tx_invalid.add();
      continue;
    }
    if (!up) {
      ++r.unsent;
      r.status = SendStatus::Down;
      counters_.tx_down.add();
      continue;
    }
    ++r.sent;
    counters_.tx_frames.add();
    if (sink_ != nullptr) {
      sink_->on_frame(f);
    } else if (peer_ != nullptr) {
      peer_->deliver(f);
    }
  }
  return r;
}

std::size_t MemoryLink::receive(std::span<FrameBuffer> out) noexcept {
  std::size_t n = 0;
  while (n < out.size() && count_ > 0) {
    const FrameBuffer& slot = slots_[head_];
    std::memcpy(out[n].bytes.data(), slot.bytes.data(), slot.size);
    out[n].size = slot.size;
    head_ = (head_ + 1) % slots_.size();
    --count_;
    ++n;
  }
  counters_.rx_frames.add(n);
  return n;
}

std::string MemoryLink::describe() const {
  return "memory link (" + std::to_string(slots_.size()) + " frames)";
}

}  // namespace drivegate::link
