#include "adapters/canopen/master/sdo_client.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <utility>

namespace drivegate::canopen {
namespace {

// A request id packs where the request lives and which use of that slot it is, so that lookups
// are O(1) and an id that was taken, cancelled or reset never finds the slot's next request:
// bits 0..6 slot, bits 7..16 channel, bits 17..31 generation (1..7FFFh, so an id is never 0).
constexpr unsigned kSlotBits = 7;
constexpr unsigned kChannelBits = 10;
constexpr std::uint32_t kSlotMask = (1U << kSlotBits) - 1;
constexpr std::uint32_t kChannelMask = (1U << kChannelBits) - 1;
constexpr std::uint16_t kMaxGeneration = 0x7FFF;
constexpr std::size_t kMaxChannels = std::size_t{1} << kChannelBits;

SdoRequestId make_id(std::size_t channel, std::size_t slot, std::uint16_t generation) noexcept {
  return static_cast<SdoRequestId>((std::uint32_t{generation} << (kSlotBits + kChannelBits)) |
                                   (static_cast<std::uint32_t>(channel) << kSlotBits) | static_cast<std::uint32_t>(slot));
}

void invalid(const SdoChannelConfig& c, const char* why) {
  throw std::invalid_argument("SDO client channel " + std::to_string(c.channel) + " of node " + std::to_string(c.node) +
                              ": " + why);
}

}  // namespace

SdoClient::SdoClient(std::span<const SdoChannelConfig> channels, SdoTiming timing) : timing_(timing) {
  static_assert(kSlotsPerChannel <= kSlotMask + 1, "slot numbers must fit the request id");
  if (timing.timeout <= core::Duration::zero()) throw std::invalid_argument("SDO client: timeout must be positive");
  if (channels.size() > kMaxChannels) throw std::invalid_argument("SDO client: too many channels");
  by_tx_cob_.fill(-1);
  std::array<bool, kMaxStandardId + 1> rx_used{};
  channels_.resize(channels.size());
  for (std::size_t i = 0; i < channels.size(); ++i) {
    SdoChannelConfig c = channels[i];
    if (!valid_node_id(c.node)) invalid(c, "node-ID outside 1..127");
    if (c.channel < 1 || c.channel > 4) invalid(c, "channel outside 1..4");
    // Channels 2..4 put the channel into the upper bits of the node field, so derived COB-IDs
    // only exist for node-IDs up to 31 (stoeber-sd6-canopen.md §5.3, quirk 1).
    const bool derived = c.rx_cob == 0 || c.tx_cob == 0;
    if (derived && c.channel > 1 && c.node > 31) invalid(c, "channels 2..4 need a node-ID <= 31");
    if (c.rx_cob == 0) c.rx_cob = cob::sdo_rx(c.channel, c.node);
    if (c.tx_cob == 0) c.tx_cob = cob::sdo_tx(c.channel, c.node);
    if (c.rx_cob > kMaxStandardId || c.tx_cob > kMaxStandardId) invalid(c, "COB-ID above 7FFh");
    if (by_tx_cob_[c.tx_cob] >= 0 || rx_used[c.rx_cob]) invalid(c, "COB-ID used by another channel");
    by_tx_cob_[c.tx_cob] = static_cast<std::int16_t>(i);
    rx_used[c.rx_cob] = true;
    channels_[i].config = c;
  }
}

int SdoClient::channel_of(NodeId node, int channel) const noexcept {
  for (std::size_t i = 0; i < channels_.size(); ++i) {
    if (channels_[i].config.node == node && channels_[i].config.channel == channel) return static_cast<int>(i);
  }
  return -1;
}

SdoRequestId SdoClient::read(int channel, ObjectId object, std::uint8_t expected_size) noexcept {
  if (expected_size > 4) return kNoSdoRequest;
  return submit(channel, Kind::Upload, object, expected_size, {});
}

SdoRequestId SdoClient::write(int channel, ObjectId object, std::uint32_t value, std::uint8_t size) noexcept {
  if (size < 1 || size > 4) return kNoSdoRequest;
  std::array<std::uint8_t, 4> bytes{};
  put_le(bytes, 0, size, value);
  return submit(channel, Kind::Download, object, 0, {bytes.data(), size});
}

SdoRequestId SdoClient::read_into(int channel, ObjectId object, std::span<std::uint8_t> into,
                                  std::uint8_t expected_size) noexcept {
  if (expected_size > 4 || into.empty() || into.size() > kMaxBuffer) return kNoSdoRequest;
  return attach(submit(channel, Kind::Upload, object, expected_size, {}), into.data(), nullptr, into.size());
}

SdoRequestId SdoClient::write_from(int channel, ObjectId object, std::span<const std::uint8_t> data) noexcept {
  if (data.empty() || data.size() > kMaxBuffer) return kNoSdoRequest;
  // Four bytes or fewer go out expedited from the slot; no need to hold the caller's buffer.
  if (data.size() <= 4) return submit(channel, Kind::Download, object, 0, data);
  return attach(submit(channel, Kind::Download, object, 0, {}), nullptr, data.data(), data.size());
}

SdoRequestId SdoClient::attach(SdoRequestId id, std::uint8_t* into, const std::uint8_t* from, std::size_t size) noexcept {
  Slot* s = id == kNoSdoRequest ? nullptr : find(id);
  if (s == nullptr) return kNoSdoRequest;
  s->into = into;
  s->from = from;
  s->size = from != nullptr ? static_cast<std::uint16_t>(size) : std::uint16_t{0};
  s->capacity = into != nullptr ? static_cast<std::uint16_t>(size) : std::uint16_t{0};
  return id;
}

SdoRequestId SdoClient::submit(int channel, Kind kind, ObjectId object, std::uint8_t expected_size,
                               std::span<const std::uint8_t> data) noexcept {
  if (channel < 0 || static_cast<std::size_t>(channel) >= channels_.size()) return kNoSdoRequest;
  auto& ch = channels_[static_cast<std::size_t>(channel)];
  const auto free = std::find_if(ch.slots.begin(), ch.slots.end(), [](const Slot& s) { return s.state == SlotState::Free; });
  if (ch.fifo_size == kQueueDepth || free == ch.slots.end()) {
    ++counters_.queue_full;
    return kNoSdoRequest;
  }
  Slot& slot = *free;
  slot.generation = slot.generation == kMaxGeneration ? std::uint16_t{1} : static_cast<std::uint16_t>(slot.generation + 1);
  slot.state = SlotState::Queued;
  slot.kind = kind;
  slot.object = object;
  slot.expected_size = expected_size;
  slot.size = static_cast<std::uint16_t>(data.size());
  slot.abort_code = 0;
  slot.size_indicated = true;
  slot.into = nullptr;
  slot.from = nullptr;
  slot.capacity = 0;
  std::copy(data.begin(), data.end(), slot.data.begin());
  const auto slot_no = static_cast<std::size_t>(free - ch.slots.begin());
  ch.fifo[(ch.fifo_head + ch.fifo_size) % kQueueDepth] = static_cast<std::uint8_t>(slot_no);
  ++ch.fifo_size;
  ++counters_.requests;
  return make_id(static_cast<std::size_t>(channel), slot_no, slot.generation);
}

const SdoClient::Slot* SdoClient::find(SdoRequestId id) const noexcept {
  const std::size_t channel = (id >> kSlotBits) & kChannelMask;
  const std::size_t slot = id & kSlotMask;
  const auto generation = static_cast<std::uint16_t>(id >> (kSlotBits + kChannelBits));
  if (channel >= channels_.size() || slot >= kSlotsPerChannel) return nullptr;
  const Slot& s = channels_[channel].slots[slot];
  if (s.state == SlotState::Free || s.generation != generation) return nullptr;
  return &s;
}

SdoClient::Slot* SdoClient::find(SdoRequestId id) noexcept {
  return const_cast<Slot*>(std::as_const(*this).find(id));
}

SdoResult SdoClient::result(SdoRequestId id) const noexcept {
  const Slot* s = find(id);
  SdoResult r;
  if (s == nullptr) return r;
  switch (s->state) {
    case SlotState::Queued: r.status = SdoStatus::Queued; break;
    case SlotState::InFlight: r.status = SdoStatus::InFlight; break;
    case SlotState::Done:
      r.status = SdoStatus::Done;
      if (s->kind == Kind::Upload) {
        r.size = s->size;
        r.size_indicated = s->size_indicated;
        if (s->size <= 4) r.value = get_le({s->source(), s->size}, 0, s->size);
      }
      break;
    case SlotState::Failed:
      r.status = SdoStatus::Failed;
      r.abort_code = s->abort_code;
      break;
    case SlotState::Free:
    case SlotState::Cancelled: break;  // the caller gave it up: Unknown
  }
  return r;
}

std::span<const std::uint8_t> SdoClient::data(SdoRequestId id) const noexcept {
  const Slot* s = find(id);
  if (s == nullptr || s->state != SlotState::Done || s->kind != Kind::Upload) return {};
  return {s->source(), s->size};
}

SdoResult SdoClient::take(SdoRequestId id) noexcept {
  const SdoResult r = result(id);
  if (r.status == SdoStatus::Done || r.status == SdoStatus::Failed) find(id)->state = SlotState::Free;
  return r;
}

void SdoClient::cancel(SdoRequestId id) noexcept {
  Slot* s = find(id);
  if (s == nullptr) return;
  auto& ch = channels_[(id >> kSlotBits) & kChannelMask];
  switch (s->state) {
    case SlotState::Queued: {
      // Close the gap in the FIFO so the remaining requests keep their order.
      const auto slot_no = static_cast<std::uint8_t>(id & kSlotMask);
      std::size_t kept = 0;
      for (std::size_t i = 0; i < ch.fifo_size; ++i) {
        const auto n = ch.fifo[(ch.fifo_head + i) % kQueueDepth];
        if (n != slot_no) ch.fifo[(ch.fifo_head + kept++) % kQueueDepth] = n;
      }
      ch.fifo_size = kept;
      s->state = SlotState::Free;
      break;
    }
    // The server is in the middle of it: let the transfer end on the wire, forget the result. A
    // transfer through the caller's buffer cannot go on without it: it is aborted.
    case SlotState::InFlight:
      s->state = SlotState::Cancelled;
      if (s->external()) fail_and_abort(ch, *s, cia402::sdo_abort_code::kGeneral);
      break;
    case SlotState::Done:
    case SlotState::Failed: s->state = SlotState::Free; break;
    case SlotState::Free:
    case SlotState::Cancelled: break;
  }
}

void SdoClient::reset_channel(int channel) noexcept {
  if (channel < 0 || static_cast<std::size_t>(channel) >= channels_.size()) return;
  auto& ch = channels_[static_cast<std::size_t>(channel)];
  for (auto& s : ch.slots) s.state = SlotState::Free;
  ch.fifo_head = ch.fifo_size = 0;
  ch.phase = Phase::Idle;
  ch.deadline = core::TimePoint::max();
  ch.frame_due = ch.abort_due = false;
}

std::size_t SdoClient::pending(int channel) const noexcept {
  if (channel < 0 || static_cast<std::size_t>(channel) >= channels_.size()) return 0;
  const auto& ch = channels_[static_cast<std::size_t>(channel)];
  return ch.fifo_size + (ch.phase != Phase::Idle ? 1U : 0U);
}

bool SdoClient::on_frame(const CanFrame& frame, core::TimePoint /*now*/) noexcept {
  if (frame.extended || frame.id > kMaxStandardId || by_tx_cob_[frame.id] < 0) return false;
  auto& ch = channels_[static_cast<std::size_t>(by_tx_cob_[frame.id])];
  // An RTR carries no SDO; a DLC above 8 cannot come off a real bus (payload() would hide it).
  if (frame.remote || !frame.valid()) {
    ++counters_.malformed;
    return true;
  }
  const SdoDecoded d = decode_sdo_response(frame.payload());
  // Block transfer is not offered by the reference drives (AKD part 1 §17 item 7, SD6 quirk 19),
  // so a block specifier is as unknown to this client as specifier 7.
  if (d.error != SdoDecodeError::None || d.message.command == SdoCommand::Block) {
    ++counters_.malformed;
    return true;
  }
  if (ch.phase == Phase::Idle) {
    ++counters_.unexpected;
    return true;
  }
  on_response(ch, d.message);
  return true;
}

void SdoClient::on_response(Channel& ch, const SdoMessage& m) noexcept {
  Slot& slot = ch.slots[ch.active];
  if (m.command == SdoCommand::Abort) {
    if (!(m.object == slot.object)) {
      ++counters_.unexpected;
      return;
    }
    ++counters_.aborts_received;
    finish(ch, slot, SlotState::Failed, m.abort_code);
    return;
  }
  if (slot.kind == Kind::Upload) {
    on_upload(ch, slot, m);
  } else {
    on_download(ch, slot, m);
  }
}

void SdoClient::on_upload(Channel& ch, Slot& slot, const SdoMessage& m) noexcept {
  if (ch.phase == Phase::Initiate) {
    if (m.command != SdoCommand::InitiateUploadResponse || !(m.object == slot.object)) {
      ++counters_.unexpected;
      return;
    }
    if (m.expedited) {
      // 42h (no size) carries the object's own length, which only the caller knows
      // (stoeber-sd6-canopen.md §6.4); without it all four bytes are handed up.
      const std::uint8_t n = m.size_indicated || slot.expected_size == 0 ? m.length : slot.expected_size;
      if (n > slot.room()) {
        fail_and_abort(ch, slot, cia402::sdo_abort_code::kOutOfMemory);
        return;
      }
      std::copy_n(m.data.begin(), n, slot.sink());
      slot.size = n;
      slot.size_indicated = m.size_indicated || slot.expected_size != 0;
      finish(ch, slot, SlotState::Done, 0);
      return;
    }
    if (m.size_indicated && m.size > slot.room()) {
      fail_and_abort(ch, slot, cia402::sdo_abort_code::kOutOfMemory);
      return;
    }
    ch.total = m.size;
    ch.total_indicated = m.size_indicated;
    ch.phase = Phase::Segment;
    ch.toggle = false;
    ch.offset = 0;
    ch.frame = sdo_upload_segment_request(false);
    ch.frame_due = true;
    ch.deadline = core::TimePoint::max();
    return;
  }
  if (m.command != SdoCommand::UploadSegmentResponse) {
    ++counters_.unexpected;
    return;
  }
  if (m.toggle != ch.toggle) {
    fail_and_abort(ch, slot, cia402::sdo_abort_code::kToggle);
    return;
  }
  const std::size_t received = std::size_t{ch.offset} + m.length;
  if (received > slot.room()) {
    fail_and_abort(ch, slot, cia402::sdo_abort_code::kOutOfMemory);
    return;
  }
  if (ch.total_indicated && received > ch.total) {
    fail_and_abort(ch, slot, cia402::sdo_abort_code::kTooLong);
    return;
  }
  std::copy_n(m.data.begin(), m.length, slot.sink() + ch.offset);
  ch.offset = static_cast<std::uint16_t>(received);
  if (m.last) {
    if (ch.total_indicated && received != ch.total) {
      fail_and_abort(ch, slot, cia402::sdo_abort_code::kTooShort);
      return;
    }
    slot.size = ch.offset;
    finish(ch, slot, SlotState::Done, 0);
    return;
  }
  ch.toggle = !ch.toggle;
  ch.frame = sdo_upload_segment_request(ch.toggle);
  ch.frame_due = true;
  ch.deadline = core::TimePoint::max();
}

void SdoClient::on_download(Channel& ch, Slot& slot, const SdoMessage& m) noexcept {
  if (ch.phase == Phase::Initiate) {
    if (m.command != SdoCommand::InitiateDownloadResponse || !(m.object == slot.object)) {
      ++counters_.unexpected;
      return;
    }
    if (slot.size <= 4) {
      finish(ch, slot, SlotState::Done, 0);
      return;
    }
    ch.phase = Phase::Segment;
    ch.toggle = false;
    ch.offset = 0;
    next_download_segment(ch, slot);
    return;
  }
  if (m.command != SdoCommand::DownloadSegmentResponse) {
    ++counters_.unexpected;
    return;
  }
  if (m.toggle != ch.toggle) {
    fail_and_abort(ch, slot, cia402::sdo_abort_code::kToggle);
    return;
  }
  if (ch.last_sent) {
    finish(ch, slot, SlotState::Done, 0);
    return;
  }
  ch.toggle = !ch.toggle;
  next_download_segment(ch, slot);
}

void SdoClient::next_download_segment(Channel& ch, const Slot& slot) noexcept {
  const std::size_t n = std::min<std::size_t>(7, slot.size - ch.offset);
  ch.last_sent = ch.offset + n == slot.size;
  ch.frame = sdo_download_segment(ch.toggle, {slot.source() + ch.offset, n}, ch.last_sent);
  ch.offset = static_cast<std::uint16_t>(ch.offset + n);
  ch.frame_due = true;
  ch.deadline = core::TimePoint::max();
}

void SdoClient::finish(Channel& ch, Slot& slot, SlotState state, std::uint32_t abort_code) noexcept {
  ch.phase = Phase::Idle;
  ch.frame_due = false;
  ch.deadline = core::TimePoint::max();
  if (state == SlotState::Done) {
    ++counters_.completed;
  } else {
    ++counters_.failed;
  }
  if (slot.state == SlotState::Cancelled) {
    slot.state = SlotState::Free;
    return;
  }
  slot.state = state;
  slot.abort_code = abort_code;
}

void SdoClient::fail_and_abort(Channel& ch, Slot& slot, std::uint32_t abort_code) noexcept {
  ch.abort_frame = sdo_abort(slot.object, abort_code);
  ch.abort_due = true;
  finish(ch, slot, SlotState::Failed, abort_code);
}

void SdoClient::send(Channel& ch, const SdoBytes& bytes, TxQueue& tx) noexcept {
  // A refused frame is a lost frame: the timeout of the transfer sends it again.
  if (!tx.push(make_frame(ch.config.rx_cob, bytes))) ++counters_.tx_full;
}

void SdoClient::start(Channel& ch, core::TimePoint now, TxQueue& tx) noexcept {
  const std::uint8_t slot_no = ch.fifo[ch.fifo_head];
  ch.fifo_head = (ch.fifo_head + 1) % kQueueDepth;
  --ch.fifo_size;
  Slot& slot = ch.slots[slot_no];
  slot.state = SlotState::InFlight;
  ch.active = slot_no;
  ch.phase = Phase::Initiate;
  ch.retries_left = timing_.retries;
  ch.toggle = false;
  ch.last_sent = false;
  ch.offset = 0;
  ch.total = 0;
  ch.total_indicated = false;
  send(ch, initiate_frame(slot), tx);
  ch.deadline = now + timing_.timeout;
}

SdoBytes SdoClient::initiate_frame(const Slot& slot) noexcept {
  if (slot.kind == Kind::Upload) return sdo_upload_request(slot.object);
  if (slot.size <= 4)
    return sdo_download_expedited(slot.object, get_le({slot.source(), slot.size}, 0, slot.size),
                                  static_cast<std::uint8_t>(slot.size));
  return sdo_download_initiate(slot.object, slot.size);
}

void SdoClient::poll(core::TimePoint now, TxQueue& tx, std::size_t max_frames) noexcept {
  // Each frame takes one of `max_frames`; once they are used up the rest waits, so that a
  // channel's frames still leave in order (an abort before its next initiate).
  std::size_t room = max_frames;
  const auto take_room = [&room] {
    if (room == 0) return false;
    --room;
    return true;
  };
  for (auto& ch : channels_) {
    // An abort goes out before the next request's initiate, so the server sees them in order.
    if (ch.abort_due) {
      if (!take_room()) return;
      send(ch, ch.abort_frame, tx);
      ch.abort_due = false;
    }
    if (ch.phase != Phase::Idle && (ch.frame_due || now >= ch.deadline)) {
      if (!take_room()) return;
      Slot& slot = ch.slots[ch.active];
      if (ch.frame_due) {
        send(ch, ch.frame, tx);
        ch.frame_due = false;
        ch.deadline = now + timing_.timeout;
      } else if (ch.phase == Phase::Initiate && ch.retries_left > 0) {
        --ch.retries_left;
        ++counters_.retries;
        send(ch, initiate_frame(slot), tx);
        ch.deadline = now + timing_.timeout;
      } else {
        ++counters_.timeouts;
        send(ch, sdo_abort(slot.object, cia402::sdo_abort_code::kTimeout), tx);
        finish(ch, slot, SlotState::Failed, cia402::sdo_abort_code::kTimeout);
      }
    }
    if (ch.phase == Phase::Idle && ch.fifo_size > 0) {
      if (!take_room()) return;
      start(ch, now, tx);
    }
  }
}

core::TimePoint SdoClient::next_deadline() const noexcept {
  core::TimePoint next = core::TimePoint::max();
  for (const auto& ch : channels_) {
    if (ch.abort_due || ch.frame_due || (ch.phase == Phase::Idle && ch.fifo_size > 0)) return core::TimePoint::min();
    if (ch.phase != Phase::Idle) next = std::min(next, ch.deadline);
  }
  return next;
}

}  // namespace drivegate::canopen
