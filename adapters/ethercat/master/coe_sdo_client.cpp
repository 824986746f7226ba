#include "adapters/ethercat/master/coe_sdo_client.hpp"

#include <algorithm>

#include "adapters/ethercat/wire/registers.hpp"
#include "core/bytes.hpp"
#include "profiles/cia402/sdo_abort.hpp"

namespace drivegate::ethercat {

using core::put_u32;

namespace {

// Bytes in front of the data: mailbox header 6 + CoE header 2 + SDO command, index, subindex, size
// (8) for a normal initiate; + command byte (1) for a segment [ETG.1000.6 §5.6.2.2-§5.6.2.5].
constexpr std::size_t kInitiateOverhead = kMailboxHeaderSize + kCoeHeaderSize + kSdoHeaderSize;
constexpr std::size_t kSegmentOverhead = kMailboxHeaderSize + kCoeHeaderSize + 1;
// SDO Information header: opcode with the incomplete bit, reserved, fragments left u16
// [ETG.1000.6 §5.6.3.2].
constexpr std::size_t kInfoHeader = 4;
constexpr std::uint8_t kInfoIncomplete = 0x80;

}  // namespace

std::string_view to_string(CoeSdoStatus s) noexcept {
  switch (s) {
    case CoeSdoStatus::Unknown: return "unknown";
    case CoeSdoStatus::Queued: return "queued";
    case CoeSdoStatus::InFlight: return "in flight";
    case CoeSdoStatus::Done: return "done";
    case CoeSdoStatus::Failed: return "failed";
  }
  return "?";
}

CoeSdoClient::CoeSdoClient(std::uint16_t station, const SiiMailbox& mailbox, CoeSdoTiming timing,
                           EmergencySink* emergencies) noexcept
    : station_(station), mailbox_(mailbox), timing_(timing), emergencies_(emergencies) {
  valid_ = mailbox.rx_size >= kInitiateOverhead && mailbox.tx_size >= kInitiateOverhead &&
           mailbox.rx_size <= kMaxMailbox && mailbox.tx_size <= kMaxMailbox;
}

CoeSdoId CoeSdoClient::submit(bool upload, std::uint16_t index, std::uint8_t subindex, std::uint8_t* into,
                              const std::uint8_t* from, std::size_t size) noexcept {
  if (!valid_) {
    ++counters_.queue_full;
    return 0;
  }
  for (std::size_t i = 0; i < slots_.size(); ++i) {
    Slot& s = slots_[i];
    if (s.state != SlotState::Free) continue;
    const std::uint16_t gen = static_cast<std::uint16_t>(s.generation + 1 == 0 ? 1 : s.generation + 1);
    s = Slot{};
    s.generation = gen;
    s.state = SlotState::Queued;
    ++queued_;
    s.upload = upload;
    s.order = next_order_++;
    s.index = index;
    s.subindex = subindex;
    s.into = into != nullptr ? into : (upload ? s.inline_bytes.data() : nullptr);
    s.from = from;
    s.capacity = size;
    s.result.status = CoeSdoStatus::Queued;
    ++counters_.requests;
    return (static_cast<CoeSdoId>(gen) << 8) | static_cast<CoeSdoId>(i + 1);
  }
  ++counters_.queue_full;
  return 0;
}

CoeSdoId CoeSdoClient::upload(std::uint16_t index, std::uint8_t subindex, std::span<std::uint8_t> into) noexcept {
  if (into.empty()) return 0;
  return submit(true, index, subindex, into.data(), nullptr, into.size());
}

CoeSdoId CoeSdoClient::upload_value(std::uint16_t index, std::uint8_t subindex) noexcept {
  return submit(true, index, subindex, nullptr, nullptr, kInline);
}

CoeSdoId CoeSdoClient::download(std::uint16_t index, std::uint8_t subindex, std::span<const std::uint8_t> data) noexcept {
  if (data.empty() || data.size() > 0xFFFFFFFFU) return 0;
  return submit(false, index, subindex, nullptr, data.data(), data.size());
}

CoeSdoId CoeSdoClient::download_value(std::uint16_t index, std::uint8_t subindex, std::uint32_t value,
                                      std::size_t size) noexcept {
  if (size == 0 || size > 4) return 0;
  const CoeSdoId id = submit(false, index, subindex, nullptr, nullptr, size);
  if (id == 0) return 0;
  Slot& s = slots_[(id & 0xFF) - 1];
  put_u32(s.inline_bytes, 0, value);
  s.from = s.inline_bytes.data();
  return id;
}

CoeSdoId CoeSdoClient::submit_info(Kind kind, std::uint16_t index, std::uint8_t subindex, std::size_t capacity) noexcept {
  const CoeSdoId id = submit(false, index, subindex, nullptr, nullptr, capacity);
  if (id != 0) slots_[(id & 0xFF) - 1].kind = kind;
  return id;
}

CoeSdoId CoeSdoClient::od_list(OdListType type, std::span<std::uint16_t> into) noexcept {
  // List type 0 answers five counts, not indexes: not a list to join.
  if (into.empty() || type == OdListType::Lengths || static_cast<std::uint16_t>(type) > 5) return 0;
  const CoeSdoId id = submit_info(Kind::OdList, 0, 0, into.size());
  if (id == 0) return 0;
  Slot& s = slots_[(id & 0xFF) - 1];
  s.indexes = into.data();
  s.list_type = static_cast<std::uint16_t>(type);
  return id;
}

CoeSdoId CoeSdoClient::object_description(std::uint16_t index, std::span<char> name) noexcept {
  const CoeSdoId id = submit_info(Kind::Object, index, 0, name.size());
  if (id != 0) slots_[(id & 0xFF) - 1].name = name.data();
  return id;
}

CoeSdoId CoeSdoClient::entry_description(std::uint16_t index, std::uint8_t subindex, std::span<char> name,
                                         std::uint8_t value_info) noexcept {
  const CoeSdoId id = submit_info(Kind::Entry, index, subindex, name.size());
  if (id == 0) return 0;
  Slot& s = slots_[(id & 0xFF) - 1];
  s.name = name.data();
  s.value_info = value_info;
  return id;
}

const CoeSdoClient::Slot* CoeSdoClient::find(CoeSdoId id) const noexcept {
  const std::size_t i = id & 0xFF;
  if (i == 0 || i > slots_.size()) return nullptr;
  const Slot& s = slots_[i - 1];
  if (s.state == SlotState::Free || s.generation != static_cast<std::uint16_t>(id >> 8)) return nullptr;
  return &s;
}

CoeSdoResult CoeSdoClient::result(CoeSdoId id) const noexcept {
  const Slot* s = find(id);
  return s != nullptr ? s->result : CoeSdoResult{};
}

std::span<const std::uint8_t> CoeSdoClient::data(CoeSdoId id) const noexcept {
  const Slot* s = find(id);
  if (s == nullptr || !s->upload || s->state != SlotState::Done) return {};
  return {s->into, s->done};
}

std::size_t CoeSdoClient::pending() const noexcept {
  return static_cast<std::size_t>(std::count_if(slots_.begin(), slots_.end(), [](const Slot& s) {
    return s.state == SlotState::Queued || s.state == SlotState::InFlight;
  }));
}

CoeSdoResult CoeSdoClient::take(CoeSdoId id) noexcept {
  const Slot* s = find(id);
  if (s == nullptr || (s->state != SlotState::Done && s->state != SlotState::Failed)) return result(id);
  const CoeSdoResult r = s->result;
  slots_[(id & 0xFF) - 1].state = SlotState::Free;
  return r;
}

void CoeSdoClient::finish(Slot& s, SlotState state, std::uint32_t abort_code) noexcept {
  s.state = state;
  s.result.status = state == SlotState::Done ? CoeSdoStatus::Done : CoeSdoStatus::Failed;
  s.result.abort_code = abort_code;
  if (s.kind != Kind::Sdo) {
    s.result.size = s.done;
  } else if (s.upload) {
    s.result.size = s.done;
    std::uint32_t v = 0;
    for (std::size_t i = 0; i < std::min<std::size_t>(s.done, 4); ++i) v |= static_cast<std::uint32_t>(s.into[i]) << (8 * i);
    s.result.value = v;
  }
  if (state == SlotState::Done) {
    ++counters_.completed;
  } else {
    ++counters_.failed;
  }
  active_ = nullptr;
  phase_ = Phase::Idle;
  write_due_ = false;
}

void CoeSdoClient::reset() noexcept {
  for (auto& s : slots_) {
    if (s.state != SlotState::Queued && s.state != SlotState::InFlight) continue;
    s.state = SlotState::Failed;
    s.result.status = CoeSdoStatus::Failed;
    s.result.abort_code = cia402::sdo_abort_code::kDeviceState;
    ++counters_.failed;
  }
  queued_ = 0;
  active_ = nullptr;
  phase_ = Phase::Idle;
  expect_ = Expect::Initiate;
  toggle_ = false;
  waiting_ = false;  // the answer of a datagram in flight no longer matches (seq_ moves on)
  write_due_ = false;
  out_size_ = 0;
  // A re-initialised slave numbers its replies afresh: forget the last one seen [ETG.1000.6 §5.6,
  // mailbox counter]. Our own counter runs on: a new value is accepted whether or not the slave
  // forgot the last one it saw.
  last_reply_counter_ = 0;
  repeat_activate_ = 0;
  drain_due_ = false;
  next_status_poll_ = core::TimePoint{};
}

void CoeSdoClient::on_status(const DatagramAnswer& a) noexcept {
  // SM1 status 080Dh bit 3: mailbox full [ETG.1000.4 Table 59, SM status].
  const bool full = a.outcome != DatagramOutcome::Lost && a.wkc == 1 && !a.data.empty() &&
                    (a.data[0] & sm_status::kMailboxFull) != 0;
  if (full) {
    phase_ = Phase::DrainRead;
    return;
  }
  if (a.outcome == DatagramOutcome::Lost || a.wkc != 1) {
    // No answer: an active request asks again (its timeout bounds this); idle, give up the drain.
    if (active_ == nullptr) {
      drain_due_ = false;
      phase_ = Phase::Idle;
    }
    return;
  }
  // SM1 empty: the request can go.
  drain_due_ = false;
  phase_ = active_ != nullptr ? Phase::Write : Phase::Idle;
}

template <class Encode>
void CoeSdoClient::prepare(Expect expect, Encode&& encode) noexcept {
  // The whole SM0 mailbox is written (its last byte hands it to the slave): zero what follows the
  // request, stamp the next mailbox counter.
  counter_ = next_mailbox_counter(counter_);
  const std::span<std::uint8_t> out(out_.data(), mailbox_.rx_size);
  std::fill(out.begin(), out.end(), std::uint8_t{0});
  out_size_ = encode(out) == 0 ? 0 : out.size();
  expect_ = expect;
  phase_ = Phase::Write;
  write_due_ = true;
}

void CoeSdoClient::prepare_initiate(Slot& s) noexcept {
  toggle_ = false;
  s.first_fragment = true;
  s.odd = false;
  prepare(Expect::Initiate, [&](std::span<std::uint8_t> out) -> std::size_t {
    switch (s.kind) {
      case Kind::Sdo: break;
      case Kind::OdList: return encode_get_od_list_request(out, counter_, static_cast<OdListType>(s.list_type));
      case Kind::Object: return encode_get_object_description_request(out, counter_, s.index);
      case Kind::Entry: return encode_get_entry_description_request(out, counter_, s.index, s.subindex, s.value_info);
    }
    if (s.upload) return encode_sdo_upload_request(out, counter_, s.index, s.subindex);
    if (s.capacity <= 4) {  // expedited [ETG.1000.6 §5.6.2.1]
      s.done = s.capacity;
      return encode_sdo_download_expedited(out, counter_, s.index, s.subindex, {s.from, s.capacity});
    }
    // Normal: as much as the mailbox carries, segments for the rest.
    const std::size_t first = std::min(s.capacity, out.size() - kInitiateOverhead);
    s.done = first;
    return encode_sdo_download_normal(out, counter_, s.index, s.subindex, static_cast<std::uint32_t>(s.capacity),
                                      {s.from, first});
  });
}

void CoeSdoClient::prepare_download_segment(Slot& s) noexcept {
  prepare(Expect::Segment, [&](std::span<std::uint8_t> out) {
    const std::size_t chunk = std::min(s.capacity - s.done, out.size() - kSegmentOverhead);
    const bool last = s.done + chunk >= s.capacity;
    const std::size_t n = encode_sdo_download_segment(out, counter_, toggle_, last, {s.from + s.done, chunk});
    s.done += chunk;
    return n;
  });
}

void CoeSdoClient::prepare_upload_segment() noexcept {
  prepare(Expect::Segment,
          [&](std::span<std::uint8_t> out) { return encode_sdo_upload_segment_request(out, counter_, toggle_); });
}

void CoeSdoClient::start_next(core::TimePoint now) noexcept {
  if (queued_ == 0) return;
  Slot* next = nullptr;
  for (auto& s : slots_) {
    if (s.state == SlotState::Queued && (next == nullptr || s.order < next->order)) next = &s;
  }
  if (next == nullptr) return;
  active_ = next;
  --queued_;
  next->state = SlotState::InFlight;
  next->result.status = CoeSdoStatus::InFlight;
  deadline_ = now + timing_.timeout;
  prepare_initiate(*next);
  phase_ = Phase::Drain;  // empty SM1 before the request goes out
}

bool CoeSdoClient::queue(Transactions& tx, Command c, std::uint16_t ado, std::uint16_t length,
                         std::span<const std::uint8_t> data) noexcept {
  ++seq_;
  if (!tx.queue(this, seq_, c, physical_address(station_, ado), length, data)) return false;
  waiting_ = true;
  return true;
}

core::TimePoint CoeSdoClient::next_idle_poll(core::TimePoint now) const noexcept {
  const auto interval = timing_.idle_poll_interval.count();
  if (interval <= timing_.poll_interval.count()) return now + timing_.poll_interval;
  // The next point of this station's grid: interval apart, offset by the station address in
  // steps of poll_interval.
  const auto step = std::max<core::Duration::rep>(timing_.poll_interval.count(), 1);
  const auto offset = (static_cast<core::Duration::rep>(station_) * step) % interval;
  const auto t = now.time_since_epoch().count();
  auto next = t - ((t - offset) % interval + interval) % interval + interval;
  if (next - t < step) next += interval;  // never twice within poll_interval
  return core::TimePoint(core::Duration(next));
}

void CoeSdoClient::poll(core::TimePoint now, Transactions& tx) noexcept {
  now_ = now;
  if (waiting_) return;
  if (active_ != nullptr && now >= deadline_) {
    ++counters_.timeouts;
    finish(*active_, SlotState::Failed, cia402::sdo_abort_code::kTimeout);
    drain_due_ = true;  // its reply may still come: emptied before anything else is taken
  }
  if (active_ == nullptr) start_next(now);
  switch (phase_) {
    case Phase::Idle:
      // Nothing of ours in flight: still look for emergencies now and then (and empty SM1 after a
      // timeout); what SM1 holds now is no answer to anything.
      if ((emergencies_ != nullptr || drain_due_) && now >= next_status_poll_) {
        if (queue(tx, Command::FPRD, reg::sm_status(1), 1)) next_status_poll_ = next_idle_poll(now);
      }
      return;
    case Phase::Drain:
      (void)queue(tx, Command::FPRD, reg::sm_status(1), 1);
      return;
    case Phase::DrainRead:
      (void)queue(tx, Command::FPRD, mailbox_.tx_offset, mailbox_.tx_size);
      return;
    case Phase::Write:
      if (write_due_ && out_size_ != 0) {
        ++counters_.mailbox_writes;
        (void)queue(tx, Command::FPWR, mailbox_.rx_offset, static_cast<std::uint16_t>(out_size_),
                    std::span<const std::uint8_t>(out_.data(), out_size_));
      } else if (out_size_ == 0 && active_ != nullptr) {
        finish(*active_, SlotState::Failed, cia402::sdo_abort_code::kGeneral);  // could not encode (cannot happen when valid())
      }
      return;
    case Phase::Wait:
      if (now >= next_status_poll_ && queue(tx, Command::FPRD, reg::sm_status(1), 1)) {
        next_status_poll_ = now + timing_.poll_interval;
      }
      return;
    case Phase::Read:
      (void)queue(tx, Command::FPRD, mailbox_.tx_offset, mailbox_.tx_size);
      return;
    case Phase::RepeatRead:
      // SM1 activate (080Eh) and PDI control (080Fh) [ETG.1000.4 Table 59].
      (void)queue(tx, Command::FPRD, reg::sm_activation(1), 2);
      return;
    case Phase::RepeatWrite: {
      // The activate byte as read, repeat request inverted [ETG.1000.4 §6 SyncManager: repeat].
      const std::array<std::uint8_t, 1> act{repeat_activate_};
      (void)queue(tx, Command::FPWR, reg::sm_activation(1), 1, act);
      return;
    }
    case Phase::RepeatWait:
      if (now >= next_status_poll_ && queue(tx, Command::FPRD, reg::sm_pdi_control(1), 1)) {
        next_status_poll_ = now + timing_.poll_interval;
      }
      return;
  }
}

void CoeSdoClient::on_result(std::uint32_t tag, const DatagramAnswer& a) noexcept {
  if (!waiting_ || tag != seq_) return;
  waiting_ = false;
  const bool lost = a.outcome == DatagramOutcome::Lost;
  switch (phase_) {
    case Phase::Idle:
    case Phase::Drain:
      on_status(a);
      return;
    case Phase::DrainRead:
      // Whatever came (or was lost with the frame), look at the status again: the slave may have
      // put the next mailbox in.
      phase_ = Phase::Drain;
      if (!lost && a.wkc == 1) on_mailbox(a.data, true);
      return;
    case Phase::Write:
      if (lost || a.wkc != 1) {  // not taken (mailbox still full) or lost: write again, same counter
        if (!lost) ++counters_.mailbox_busy;
        return;
      }
      write_due_ = false;
      phase_ = Phase::Wait;
      next_status_poll_ = now_;
      return;
    case Phase::Wait:
      if (!lost && a.wkc == 1 && !a.data.empty() && (a.data[0] & sm_status::kMailboxFull) != 0) phase_ = Phase::Read;
      return;
    case Phase::Read:
      if (lost) {  // the slave may have freed SM1 already: ask it to repeat
        ++counters_.repeats;
        phase_ = Phase::RepeatRead;
        return;
      }
      if (a.wkc != 1) {  // empty after all
        phase_ = active_ != nullptr ? Phase::Wait : Phase::Idle;
        return;
      }
      phase_ = active_ != nullptr ? Phase::Wait : Phase::Idle;
      on_mailbox(a.data, false);
      return;
    case Phase::RepeatRead:
      if (!lost && a.wkc == 1 && a.data.size() >= 1) {
        repeat_activate_ = static_cast<std::uint8_t>(a.data[0] ^ sm_activate::kRepeat);
        phase_ = Phase::RepeatWrite;
      }
      return;
    case Phase::RepeatWrite:
      if (!lost && a.wkc == 1) {
        phase_ = Phase::RepeatWait;
        next_status_poll_ = now_;
      }
      return;
    case Phase::RepeatWait:
      if (!lost && a.wkc == 1 && !a.data.empty() &&
          ((a.data[0] & sm_pdi_control::kRepeatAck) != 0) == ((repeat_activate_ & sm_activate::kRepeat) != 0)) {
        phase_ = Phase::Read;
      }
      return;
  }
}

void CoeSdoClient::on_mailbox(std::span<const std::uint8_t> mb, bool stale) noexcept {
  const MailboxView m = decode_mailbox(mb);
  if (m.error != MailboxError::None) {
    ++counters_.malformed;
    return;
  }
  if (stale) {
    // Emptied before a request: an emergency is still one, anything else is dropped.
    last_reply_counter_ = m.header.counter;
    const EmergencyView e = decode_emergency(mb);
    if (m.header.type == static_cast<std::uint8_t>(MailboxType::CoE) && e.error == MailboxError::None) {
      ++counters_.emergencies;
      if (emergencies_ != nullptr) emergencies_->on_emergency(station_, e.emergency);
    } else {
      ++counters_.stale_replies;
    }
    return;
  }
  // A repeated reply (same counter as the last one taken) is a duplicate [ETG.1000.6 mailbox
  // header counter].
  if (m.header.counter != 0 && m.header.counter == last_reply_counter_) {
    ++counters_.unexpected;
    return;
  }
  last_reply_counter_ = m.header.counter;
  if (m.header.type == static_cast<std::uint8_t>(MailboxType::Error)) {
    const MailboxErrorReply e = decode_mailbox_error(mb);
    if (active_ != nullptr) {
      active_->result.mailbox_error = e.detail;
      finish(*active_, SlotState::Failed, cia402::sdo_abort_code::kGeneral);
    } else {
      ++counters_.unexpected;
    }
    return;
  }
  const CoeView coe = decode_coe(mb);
  if (coe.error != MailboxError::None) {
    if (m.header.type != static_cast<std::uint8_t>(MailboxType::CoE)) {
      ++counters_.unexpected;  // another protocol's mailbox: not ours
    } else {
      ++counters_.malformed;
    }
    return;
  }
  if (coe.service == static_cast<std::uint8_t>(CoeService::Emergency)) {
    const EmergencyView e = decode_emergency(mb);
    if (e.error != MailboxError::None) {
      ++counters_.malformed;
      return;
    }
    ++counters_.emergencies;
    if (emergencies_ != nullptr) emergencies_->on_emergency(station_, e.emergency);
    return;
  }
  if (coe.service == static_cast<std::uint8_t>(CoeService::SdoInformation)) {
    if (active_ == nullptr || active_->kind == Kind::Sdo) {
      ++counters_.unexpected;
      return;
    }
    on_info(*active_, mb, coe.body);
    return;
  }
  const SdoView sdo = decode_sdo_response(mb);
  if (sdo.error != MailboxError::None) {
    ++counters_.malformed;
    return;
  }
  if (active_ == nullptr) {
    ++counters_.unexpected;
    return;
  }
  on_sdo(*active_, sdo.sdo);
}

void CoeSdoClient::on_sdo(Slot& s, const CoeSdo& sdo) noexcept {
  if (s.kind != Kind::Sdo) {  // an SDO response while an SDO Information request runs
    ++counters_.unexpected;
    return;
  }
  if (sdo.command == SdoCommand::Abort) {
    ++counters_.aborts;
    finish(s, SlotState::Failed, sdo.abort_code);
    return;
  }
  const bool initiate = sdo.command == SdoCommand::UploadInitiateResponse ||
                        sdo.command == SdoCommand::DownloadInitiateResponse;
  const bool wanted = s.upload ? (expect_ == Expect::Initiate ? sdo.command == SdoCommand::UploadInitiateResponse
                                                              : sdo.command == SdoCommand::UploadSegmentResponse)
                               : (expect_ == Expect::Initiate ? sdo.command == SdoCommand::DownloadInitiateResponse
                                                              : sdo.command == SdoCommand::DownloadSegmentResponse);
  if (!wanted || (initiate && (sdo.index != s.index || sdo.subindex != s.subindex))) {
    ++counters_.unexpected;
    return;
  }
  if (!initiate && sdo.toggle != toggle_) {  // CiA 301 §7.2.4.3: toggle alternates per segment
    finish(s, SlotState::Failed, cia402::sdo_abort_code::kToggle);
    return;
  }
  if (!s.upload) {
    if (!initiate) toggle_ = !toggle_;
    if (s.done >= s.capacity) {
      finish(s, SlotState::Done, 0);
    } else {
      prepare_download_segment(s);
    }
    return;
  }
  // Upload: copy what came.
  if (s.done + sdo.data.size() > s.capacity) {
    finish(s, SlotState::Failed, cia402::sdo_abort_code::kOutOfMemory);
    return;
  }
  std::copy(sdo.data.begin(), sdo.data.end(), s.into + s.done);
  s.done += sdo.data.size();
  if (initiate) {
    if (sdo.expedited) {
      finish(s, SlotState::Done, 0);
      return;
    }
    // Normal upload: the response states the complete size [ETG.1000.6 §5.6.2.4]; without it the
    // end of the data cannot be known.
    if (!sdo.size_indicated) {
      finish(s, SlotState::Failed, cia402::sdo_abort_code::kUnknownCommand);
      return;
    }
    const std::size_t total = sdo.size;
    if (total > s.capacity) {
      finish(s, SlotState::Failed, cia402::sdo_abort_code::kOutOfMemory);
      return;
    }
    s.total = total;
    if (s.done >= total) {
      finish(s, SlotState::Done, 0);
    } else {
      prepare_upload_segment();
    }
    return;
  }
  toggle_ = !toggle_;
  if (s.done > s.total) {  // more than stated
    finish(s, SlotState::Failed, cia402::sdo_abort_code::kTooLong);
    return;
  }
  if (sdo.last) {
    // The last segment must complete the stated size: fewer bytes is a truncated object.
    finish(s, s.done == s.total ? SlotState::Done : SlotState::Failed,
           s.done == s.total ? 0 : cia402::sdo_abort_code::kTooShort);
  } else {
    prepare_upload_segment();
  }
}

}  // namespace drivegate::ethercat

namespace drivegate::ethercat {

void CoeSdoClient::take_indexes(Slot& s, std::span<const std::uint8_t> bytes) noexcept {
  // The fragments are one byte stream [ETG.1000.6 §5.6.3.2]: an index may straddle two of them.
  for (const std::uint8_t b : bytes) {
    if (!s.odd) {
      s.odd_byte = b;
      s.odd = true;
      continue;
    }
    s.odd = false;
    if (s.done >= s.capacity) {
      finish(s, SlotState::Failed, cia402::sdo_abort_code::kOutOfMemory);
      return;
    }
    s.indexes[s.done++] = static_cast<std::uint16_t>(s.odd_byte | (b << 8));
  }
}

void CoeSdoClient::take_name(Slot& s, std::span<const std::uint8_t> bytes) noexcept {
  const std::size_t n = std::min(bytes.size(), s.capacity - s.done);
  std::copy_n(bytes.begin(), n, s.name + s.done);
  s.done += n;
  if (n < bytes.size()) s.result.info.name_truncated = true;
}

void CoeSdoClient::on_info(Slot& s, std::span<const std::uint8_t> mb, std::span<const std::uint8_t> body) noexcept {
  if (body.size() < kInfoHeader) {
    ++counters_.malformed;
    return;
  }
  const auto op = static_cast<SdoInfoOpcode>(body[0] & 0x7F);
  const bool incomplete = (body[0] & kInfoIncomplete) != 0;
  const std::uint16_t left = core::get_u16(body, 2);
  const auto data = body.subspan(kInfoHeader);
  if (op == SdoInfoOpcode::Error) {  // SDO Info Error request: an abort code [ETG.1000.6 §5.6.3.7]
    if (data.size() < 4) {
      ++counters_.malformed;
      return;
    }
    ++counters_.aborts;
    finish(s, SlotState::Failed, core::get_u32(data, 0));
    return;
  }
  const SdoInfoOpcode wanted = s.kind == Kind::OdList   ? SdoInfoOpcode::GetOdListResponse
                               : s.kind == Kind::Object ? SdoInfoOpcode::GetObjectDescriptionResponse
                                                        : SdoInfoOpcode::GetEntryDescriptionResponse;
  if (op != wanted) {
    ++counters_.unexpected;
    return;
  }
  if (!s.first_fragment) {
    // Fragments count down to 0; a gap means one went missing (a repeated one is caught by the
    // mailbox counter): the rest would be joined wrongly.
    if (left + 1 != s.fragments_left) {
      finish(s, SlotState::Failed, cia402::sdo_abort_code::kGeneral);
      return;
    }
    if (s.kind == Kind::OdList) {
      take_indexes(s, data);
    } else {
      take_name(s, data);  // the name is the tail of a description
    }
  } else if (s.kind == Kind::OdList) {
    if (data.size() < 2) {
      ++counters_.malformed;
      return;
    }
    if (core::get_u16(data, 0) != s.list_type) {  // another list's answer
      ++counters_.unexpected;
      return;
    }
    take_indexes(s, data.subspan(2));
  } else {
    const SdoInfoView v = decode_sdo_info(mb);
    if (v.error != MailboxError::None) {
      ++counters_.malformed;
      return;
    }
    const bool same = s.kind == Kind::Object ? v.object.index == s.index
                                             : (v.entry.index == s.index && v.entry.subindex == s.subindex);
    if (!same) {
      ++counters_.unexpected;
      return;
    }
    CoeSdoInfo& i = s.result.info;
    if (s.kind == Kind::Object) {
      i.data_type = v.object.data_type;
      i.max_subindex = v.object.max_subindex;
      i.object_code = v.object.object_code;
      take_name(s, {reinterpret_cast<const std::uint8_t*>(v.object.name.data()), v.object.name.size()});
    } else {
      i.data_type = v.entry.data_type;
      i.bit_length = v.entry.bit_length;
      i.object_access = v.entry.object_access;
      i.value_info = v.entry.value_info;
      i.unit_type = v.entry.unit_type;
      take_name(s, {reinterpret_cast<const std::uint8_t*>(v.entry.name.data()), v.entry.name.size()});
    }
  }
  if (s.state != SlotState::InFlight) return;  // failed while taking the data
  s.first_fragment = false;
  s.fragments_left = left;
  if (incomplete && left > 0) return;  // the next fragment comes in the next mailbox
  if (s.kind == Kind::OdList && s.odd) {  // half an index at the end
    finish(s, SlotState::Failed, cia402::sdo_abort_code::kTooShort);
    return;
  }
  finish(s, SlotState::Done, 0);
}

}  // namespace drivegate::ethercat
