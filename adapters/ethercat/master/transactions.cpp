#include "adapters/ethercat/master/transactions.hpp"

#include <algorithm>

namespace drivegate::ethercat {

std::string_view to_string(DatagramOutcome o) noexcept {
  switch (o) {
    case DatagramOutcome::Answered: return "answered";
    case DatagramOutcome::Lost: return "lost";
  }
  return "?";
}

Transactions::Transactions(const MacAddress& source) noexcept : source_(source) {}

bool Transactions::index_in_use(std::uint8_t index) const noexcept {
  return std::any_of(slots_.begin(), slots_.end(),
                     [&](const FrameSlot& s) { return s.state != SlotState::Free && s.index == index; });
}

Transactions::FrameSlot* Transactions::open_slot() noexcept {
  for (auto& s : slots_) {
    if (s.state != SlotState::Free) continue;
    // A fresh index not used by another frame still building or in flight, so that a late frame
    // of an expired slot is not taken for a new one at once (256 indexes, at most kMaxFrames used).
    std::uint8_t index = next_index_;
    while (index_in_use(index)) index = static_cast<std::uint8_t>(index + 1);
    next_index_ = static_cast<std::uint8_t>(index + 1);
    s.state = SlotState::Building;
    s.index = index;
    s.order = next_order_++;
    s.count = 0;
    // Broadcast destination: slaves forward any destination [ETG.1000.4 §5.3].
    s.builder = FrameBuilder(s.bytes, kBroadcastMac, source_);
    building_ = static_cast<std::size_t>(&s - slots_.data());
    return &s;
  }
  return nullptr;
}

bool Transactions::queue(DatagramOwner* owner, std::uint32_t tag, Command command, std::uint32_t address,
                         std::uint16_t length, std::span<const std::uint8_t> data) noexcept {
  if (length > kMaxDatagramData || data.size() > length) {
    ++counters_.too_long;
    return false;
  }
  // The newest frame still being built takes it if it has room; else a new frame.
  FrameSlot* target = building_ < slots_.size() ? &slots_[building_] : nullptr;
  if (target != nullptr && (target->count == kMaxDatagramsPerFrame || target->builder.remaining_data() < length)) {
    target = nullptr;
  }
  if (target == nullptr) target = open_slot();
  if (target == nullptr) {
    ++counters_.queue_full;
    return false;
  }
  const AddResult r = target->builder.add(command, target->index, address, length, data);
  if (!r.ok()) {  // cannot happen after the room check; refuse rather than guess
    ++counters_.queue_full;
    if (target->count == 0) {
      target->state = SlotState::Free;
      building_ = kNone;
    }
    return false;
  }
  target->entries[target->count++] = Entry{owner, tag, command, address, length};
  ++counters_.datagrams_queued;
  return true;
}

std::span<const std::span<const std::uint8_t>> Transactions::take_frames(core::TimePoint deadline) noexcept {
  // Building frames in the order they were opened.
  std::size_t out = 0;
  for (;;) {
    FrameSlot* next = nullptr;
    for (auto& s : slots_) {
      if (s.state == SlotState::Building && (next == nullptr || s.order < next->order)) next = &s;
    }
    if (next == nullptr) break;
    FrameSlot& s = *next;
    const auto frame = s.builder.finish();
    if (frame.empty()) {
      s.state = SlotState::Free;
      continue;
    }
    s.deadline = deadline;
    s.state = SlotState::InFlight;
    outgoing_[out++] = frame;
    ++counters_.frames_sent;
  }
  building_ = kNone;
  return {outgoing_.data(), out};
}

bool Transactions::matches(const Entry& e, const Datagram& d, std::uint8_t index) noexcept {
  if (d.header.command != e.command || d.header.index != index || d.header.length != e.length) return false;
  // Auto-increment and broadcast commands: every slave increments the ADP on the way, only the
  // ADO comes back as sent [ETG.1000.4 §5.4]. Configured and logical addresses come back unchanged.
  switch (addressing_of(e.command)) {
    case Addressing::AutoIncrement:
    case Addressing::Broadcast:
      return d.header.ado() == static_cast<std::uint16_t>(e.address >> 16);
    case Addressing::None:
      return true;
    case Addressing::Configured:
    case Addressing::Logical:
      return d.header.address == e.address;
  }
  return false;
}

bool Transactions::on_frame(std::span<const std::uint8_t> frame) noexcept {
  // One pass over the frame: the first datagram's index names the frame in flight, each datagram
  // is checked against the one sent in its place and where its data lies is kept. Results are all
  // or nothing: delivered only when the whole frame is well-formed and matches.
  struct Got {
    std::uint16_t data_offset;
    std::uint16_t wkc;
  };
  std::array<Got, kMaxDatagramsPerFrame> got;  // written for each datagram before it is read
  FrameSlot* slot = nullptr;
  bool same = true;
  std::size_t n = 0;
  FrameParser p(frame);
  Datagram d;
  while (p.next(d)) {
    if (n == 0) {
      for (auto& s : slots_) {
        if (s.state == SlotState::InFlight && s.index == d.header.index) slot = &s;
      }
    }
    if (slot != nullptr && n < slot->count && matches(slot->entries[n], d, slot->index)) {
      got[n] = Got{static_cast<std::uint16_t>(d.data_offset), d.wkc};
    } else {
      same = false;
    }
    ++n;
  }
  if (p.error() != FrameError::None || n == 0) {
    ++counters_.malformed;
    frame_errors_.count(p.error() == FrameError::None ? FrameError::EmptyFrame : p.error());
    return false;
  }
  if (slot == nullptr) {
    ++counters_.foreign;
    return false;
  }
  if (!same || n != slot->count) {
    ++counters_.mismatched;
    return false;
  }
  for (std::size_t i = 0; i < n; ++i) {
    const Entry& e = slot->entries[i];
    ++counters_.datagrams_answered;
    if (e.owner != nullptr) {
      // matches() checked the length: the data lies within the parsed frame.
      e.owner->on_result(e.tag, DatagramAnswer{DatagramOutcome::Answered, e.command, e.address,
                                               frame.subspan(got[i].data_offset, e.length), got[i].wkc});
    }
  }
  ++counters_.frames_returned;
  slot->state = SlotState::Free;
  slot->count = 0;
  return true;
}

void Transactions::expire(core::TimePoint now) noexcept {
  for (auto& s : slots_) {
    if (s.state != SlotState::InFlight || s.deadline > now) continue;
    ++counters_.frames_lost;
    // Free the slot before the callbacks (an owner that queues again at once finds room), so
    // report from a copy of its entries.
    const std::array<Entry, kMaxDatagramsPerFrame> entries = s.entries;
    const std::size_t count = s.count;
    s.state = SlotState::Free;
    s.count = 0;
    for (std::size_t i = 0; i < count; ++i) {
      const Entry& e = entries[i];
      ++counters_.datagrams_lost;
      if (e.owner != nullptr) {
        e.owner->on_result(e.tag, DatagramAnswer{DatagramOutcome::Lost, e.command, e.address, {}, 0});
      }
    }
  }
}

void Transactions::forget(const DatagramOwner* owner) noexcept {
  for (auto& s : slots_) {
    for (std::size_t i = 0; i < s.count; ++i) {
      if (s.entries[i].owner == owner) s.entries[i].owner = nullptr;
    }
  }
}

std::size_t Transactions::frames_in_flight() const noexcept {
  return static_cast<std::size_t>(
      std::count_if(slots_.begin(), slots_.end(), [](const FrameSlot& s) { return s.state == SlotState::InFlight; }));
}

}  // namespace drivegate::ethercat
