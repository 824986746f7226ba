// Slave-side PDOs (slave_pdo.hpp).
#include "adapters/canopen/sim/slave_pdo.hpp"

#include <algorithm>
#include <stdexcept>

#include "adapters/canopen/wire/pdo_mapping.hpp"
#include "adapters/canopen/wire/sdo_codec.hpp"

namespace drivegate::canopen::sim {
namespace {

namespace abort = cia402::sdo_abort_code;

// The slot of a parameter object (RPDO 1..4 = 0..3, TPDO 1..4 = 4..7) and whether it is the
// mapping; -1 for other indices.
int slot_of(std::uint16_t index, bool& mapping) noexcept {
  const int pdo = index & 0xFF;
  if (pdo >= static_cast<int>(SlavePdos::kPdos)) return -1;
  mapping = false;
  switch (index & 0xFF00) {
    case 0x1400: return pdo;
    case 0x1800: return pdo + static_cast<int>(SlavePdos::kPdos);
    case 0x1600: mapping = true; return pdo;
    case 0x1A00: mapping = true; return pdo + static_cast<int>(SlavePdos::kPdos);
    default: return -1;
  }
}

std::uint8_t comm_size(std::uint8_t sub) noexcept {
  switch (sub) {
    case 1: return 4;
    case 3:
    case 5: return 2;
    default: return 1;
  }
}

constexpr std::uint32_t kCobReserved = 0x3FFFF800U;  // bit 29 (29-bit ids) and bits 28..11
constexpr core::Duration kInhibitUnit = std::chrono::microseconds(100);
constexpr core::Duration kEventTimerUnit = std::chrono::milliseconds(1);

}  // namespace

SlavePdos::SlavePdos(PdoObjects& objects, SlavePdoOptions options, std::span<const SlavePdoConfig> rpdos,
                     std::span<const SlavePdoConfig> tpdos)
    : objects_(objects), options_(options) {
  if (rpdos.size() > kPdos || tpdos.size() > kPdos) throw std::invalid_argument("more than 4 PDOs per direction");
  if (options_.max_entries < 1 || options_.max_entries > 8 || options_.fixed_count > options_.max_entries) {
    throw std::invalid_argument("PDO entry limit must be 1..8 and a fixed mapping count within it");
  }
  for (std::size_t i = 0; i < 2 * kPdos; ++i) {
    auto& pdo = defaults_[i];
    pdo.receive = i < kPdos;
    const auto given = pdo.receive ? rpdos : tpdos;
    const std::size_t n = i % kPdos;
    if (n < given.size()) {
      pdo.params = given[n];
    } else {
      pdo.params.transmission_type = options_.transmission_types.unused();
    }
    if (options_.fixed_count != 0) pdo.params.count = options_.fixed_count;
    const auto& p = pdo.params;
    const bool valid = (p.cob_id & cob::kInvalid) == 0;
    const bool bad_cob = (p.cob_id & kCobReserved) != 0 || (valid && (p.cob_id & cob::kIdMask) == 0);
    if (bad_cob || !options_.transmission_types.allows(p.transmission_type) || p.count > options_.max_entries) {
      throw std::invalid_argument("PDO default with a COB-ID, transmission type or entry count the persona refuses");
    }
    for (std::size_t e = 0; e < p.mapping.size(); ++e) {
      if (p.mapping[e] != 0 && (e >= options_.max_entries || check_entry(p.mapping[e], pdo.receive) != 0)) {
        throw std::invalid_argument("PDO default mapping with an entry the objects cannot map");
      }
    }
    if (resolve(p, pdo.receive, pdo.layout) != 0) throw std::invalid_argument("PDO default mapping refused");
  }
  restore_defaults();
}

void SlavePdos::restore_defaults() noexcept {
  pdos_ = defaults_;
  for (auto& pdo : pdos_) restart(pdo);
}

bool SlavePdos::owns(std::uint16_t index) noexcept {
  bool mapping = false;
  return slot_of(index, mapping) >= 0;
}

std::uint32_t SlavePdos::check_entry(std::uint32_t entry, bool receive) const noexcept {
  const auto e = decode_mapping(entry);
  const auto type = objects_.mappable(e.object, receive);
  // Whole objects only: every reference drive maps whole bytes (AKD part 1 §12.3, quirk 9).
  if (!type || e.bits != 8U * cia402::size_of(*type)) return abort::kNotMappable;
  return 0;
}

std::uint32_t SlavePdos::resolve(const SlavePdoConfig& params, bool receive, Layout& out) const noexcept {
  Layout layout;
  unsigned bits = 0;
  for (std::size_t i = 0; i < params.count; ++i) {
    const auto entry = params.mapping[i];
    if (entry == 0) {
      if (options_.fixed_count != 0) continue;  // an unused slot of a fixed-size mapping
      return abort::kNotMappable;
    }
    if (check_entry(entry, receive) != 0) return abort::kNotMappable;
    const auto e = decode_mapping(entry);
    bits += e.bits;
    if (bits > 64) return abort::kPdoLength;
    layout.fields[layout.count++] = Field{e.object, *objects_.mappable(e.object, receive), layout.bytes};
    layout.bytes = static_cast<std::uint8_t>(bits / 8U);
  }
  out = layout;
  return 0;
}

PdoObjectRead SlavePdos::read(cia402::ObjectId id) const noexcept {
  bool mapping = false;
  const int slot = slot_of(id.index, mapping);
  if (slot < 0) return {abort::kNoObject, 0, 0};
  const auto& pdo = pdos_[static_cast<std::size_t>(slot)];
  const auto& p = pdo.params;
  if (mapping) {
    if (id.sub == 0) return {0, p.count, 1};
    if (id.sub > options_.max_entries) return {abort::kNoSubIndex, 0, 0};
    return {0, p.mapping[id.sub - 1U], 4};
  }
  switch (id.sub) {
    case 0: return {0, pdo.receive ? 2U : 5U, 1};
    case 1: return {0, p.cob_id, 4};
    case 2: return {0, p.transmission_type, 1};
    case 3:
      if (!pdo.receive) return {0, p.inhibit_time, 2};
      break;
    case 5:
      if (!pdo.receive) return {0, p.event_timer, 2};
      break;
    default: break;
  }
  return {abort::kNoSubIndex, 0, 0};
}

std::uint32_t SlavePdos::write(cia402::ObjectId id, std::uint32_t value, std::uint8_t size) noexcept {
  bool mapping = false;
  const int slot = slot_of(id.index, mapping);
  if (slot < 0) return abort::kNoObject;
  auto& pdo = pdos_[static_cast<std::size_t>(slot)];
  return mapping ? write_mapping(pdo, id.sub, value, size) : write_comm(pdo, id.sub, value, size);
}

std::uint32_t SlavePdos::write_comm(Pdo& pdo, std::uint8_t sub, std::uint32_t value, std::uint8_t size) noexcept {
  auto& p = pdo.params;
  const bool exists = sub <= 2 || (!pdo.receive && (sub == 3 || sub == 5));
  if (!exists) return abort::kNoSubIndex;
  if (sub == 0) return abort::kReadOnly;
  const auto width = comm_size(sub);
  if (size != 0 && size != width) return abort::kTypeMismatch;
  if (width < 4 && value >> (8U * width) != 0) return abort::kValueRange;
  switch (sub) {
    case 1: {
      if ((value & kCobReserved) != 0) return abort::kValueRange;
      const bool valid = (value & cob::kInvalid) == 0;
      if (valid && (value & cob::kIdMask) == 0) return abort::kValueRange;
      // The id changes only while the PDO is invalid [CiA 301 §7.5.2.35].
      if (pdo.valid() && valid && (value & cob::kIdMask) != (p.cob_id & cob::kIdMask)) return abort::kValueRange;
      const bool was_valid = pdo.valid();
      p.cob_id = value;
      if (valid != was_valid) restart(pdo);
      return 0;
    }
    case 2:
      if (!options_.transmission_types.allows(static_cast<std::uint8_t>(value))) return abort::kValueRange;
      p.transmission_type = static_cast<std::uint8_t>(value);
      restart(pdo);
      return 0;
    case 3: p.inhibit_time = static_cast<std::uint16_t>(value); return 0;
    default: p.event_timer = static_cast<std::uint16_t>(value); return 0;
  }
}

std::uint32_t SlavePdos::write_mapping(Pdo& pdo, std::uint8_t sub, std::uint32_t value, std::uint8_t size) noexcept {
  auto& p = pdo.params;
  if (sub > options_.max_entries) return abort::kNoSubIndex;
  if (options_.fixed_count != 0) return abort::kReadOnly;  // SD6 quirk 4: save + restart in DS6
  if (size != 0 && size != (sub == 0 ? 1 : 4)) return abort::kTypeMismatch;
  if (pdo.valid()) return abort::kDeviceState;
  if (sub != 0) {
    if (value != 0) {
      if (const auto code = check_entry(value, pdo.receive); code != 0) return code;
    }
    p.mapping[sub - 1U] = value;
    return 0;
  }
  if (value > options_.max_entries) return abort::kValueRange;
  auto candidate = p;
  candidate.count = static_cast<std::uint8_t>(value);
  Layout layout;
  if (const auto code = resolve(candidate, pdo.receive, layout); code != 0) return code;
  p.count = candidate.count;
  pdo.layout = layout;
  return 0;
}

void SlavePdos::restart(Pdo& pdo) noexcept {
  pdo.pending = pdo.ever_sent = pdo.held = false;
  pdo.syncs = 0;
}

void SlavePdos::set_operational(bool on) noexcept {
  if (on == operational_) return;
  operational_ = on;
  for (auto& pdo : pdos_) restart(pdo);
}

void SlavePdos::apply(Pdo& pdo, std::span<const std::uint8_t> data) noexcept {
  for (std::size_t i = 0; i < pdo.layout.count; ++i) {
    const auto& f = pdo.layout.fields[i];
    objects_.write(f.id, cia402::normalise(f.type, get_le(data, f.offset, cia402::size_of(f.type))));
  }
  ++counters_.rpdos_applied;
}

void SlavePdos::pack(const Pdo& pdo, std::array<std::uint8_t, 8>& out) const noexcept {
  out = {};
  for (std::size_t i = 0; i < pdo.layout.count; ++i) {
    const auto& f = pdo.layout.fields[i];
    put_le(out, f.offset, cia402::size_of(f.type), static_cast<std::uint32_t>(objects_.read(f.id)));
  }
}

void SlavePdos::send(Pdo& pdo, const std::array<std::uint8_t, 8>& bytes, core::TimePoint now, TxQueue& tx) noexcept {
  CanFrame f;
  f.id = pdo.params.cob_id & cob::kIdMask;
  f.dlc = pdo.layout.bytes;
  f.data = bytes;
  if (!tx.push(f)) {
    ++counters_.tx_full;
    return;
  }
  ++counters_.tpdos_sent;
  pdo.data = bytes;
  pdo.ever_sent = true;
  pdo.held = pdo.pending = false;
  pdo.sent_at = now;
}

bool SlavePdos::on_frame(const CanFrame& frame, core::TimePoint /*now*/) noexcept {
  if (frame.extended) return false;
  for (std::size_t i = 0; i < kPdos; ++i) {
    auto& pdo = pdos_[i];
    if (!pdo.valid() || frame.id != (pdo.params.cob_id & cob::kIdMask)) continue;
    if (!operational_ || frame.remote || !frame.valid()) {
      ++counters_.ignored;
      return true;
    }
    if (frame.dlc < pdo.layout.bytes) {
      ++counters_.short_rpdos;
      length_error_ = true;
      return true;
    }
    if (frame.dlc > pdo.layout.bytes) ++counters_.long_rpdos;
    ++counters_.rpdos_received;
    if (pdo.params.transmission_type <= 240) {
      pdo.data = frame.data;
      pdo.pending = true;
    } else {
      apply(pdo, frame.payload());
    }
    if (options_.tpdo_254_on_rpdo) {
      for (std::size_t t = kPdos; t < 2 * kPdos; ++t) {
        if (pdos_[t].params.transmission_type == 254) pdos_[t].pending = true;
      }
    }
    return true;
  }
  return false;
}

void SlavePdos::on_sync(core::TimePoint now, TxQueue& tx) noexcept {
  if (!operational_) return;
  // RPDOs first: what the master sent in the closed cycle takes effect at this SYNC.
  for (std::size_t i = 0; i < kPdos; ++i) {
    auto& pdo = pdos_[i];
    const auto type = pdo.params.transmission_type;
    if (!pdo.valid() || type > 240) continue;
    if (options_.rpdo_every_nth_sync && type > 1) {
      if (++pdo.syncs < type) continue;
      pdo.syncs = 0;
    }
    if (pdo.pending) {
      apply(pdo, pdo.data);
      pdo.pending = false;
    }
  }
  for (std::size_t i = kPdos; i < 2 * kPdos; ++i) {
    auto& pdo = pdos_[i];
    const auto type = pdo.params.transmission_type;
    if (!pdo.valid() || type > 240) continue;
    std::array<std::uint8_t, 8> bytes{};
    if (type == 0) {
      pack(pdo, bytes);
      if (!pdo.ever_sent || bytes != pdo.data) send(pdo, bytes, now, tx);
      continue;
    }
    if (++pdo.syncs < type) continue;
    pdo.syncs = 0;
    pack(pdo, bytes);
    send(pdo, bytes, now, tx);
  }
}

void SlavePdos::poll(core::TimePoint now, TxQueue& tx) noexcept {
  if (!operational_) return;
  for (std::size_t i = kPdos; i < 2 * kPdos; ++i) {
    auto& pdo = pdos_[i];
    const auto type = pdo.params.transmission_type;
    if (!pdo.valid() || type <= 240) continue;
    std::array<std::uint8_t, 8> bytes{};
    pack(pdo, bytes);
    const bool on_rpdo = options_.tpdo_254_on_rpdo && type == 254;
    const bool event = !pdo.ever_sent || (on_rpdo ? pdo.pending : bytes != pdo.data);
    const auto timer = kEventTimerUnit * pdo.params.event_timer;
    const bool timed = timer > core::Duration::zero() && now - pdo.sent_at >= timer;
    pdo.held = false;
    if (!event && !timed) continue;
    // The inhibit time spaces every transmission [CiA 301 §7.5.2.35; AKD part 1 §12.2].
    if (pdo.ever_sent && now - pdo.sent_at < kInhibitUnit * pdo.params.inhibit_time) {
      pdo.held = true;
      continue;
    }
    send(pdo, bytes, now, tx);
  }
}

core::TimePoint SlavePdos::next_deadline() const noexcept {
  auto next = core::TimePoint::max();
  if (!operational_) return next;
  for (std::size_t i = kPdos; i < 2 * kPdos; ++i) {
    const auto& pdo = pdos_[i];
    if (!pdo.valid() || pdo.params.transmission_type <= 240) continue;
    if (!pdo.ever_sent) return core::TimePoint::min();  // the first send is due at once
    if (pdo.params.event_timer != 0) next = std::min(next, pdo.sent_at + kEventTimerUnit * pdo.params.event_timer);
    if (pdo.held) next = std::min(next, pdo.sent_at + kInhibitUnit * pdo.params.inhibit_time);
  }
  return next;
}

bool SlavePdos::take_length_error() noexcept {
  const bool e = length_error_;
  length_error_ = false;
  return e;
}

}  // namespace drivegate::canopen::sim
