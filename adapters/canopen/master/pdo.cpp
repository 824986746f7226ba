// PDO layout, process image and the master's PDO exchange (pdo.hpp).
#include "adapters/canopen/master/pdo.hpp"

#include <algorithm>

namespace drivegate::canopen {
namespace {

constexpr bool synchronous(std::uint8_t transmission_type) noexcept { return transmission_type <= 240; }
constexpr bool rtr_only(std::uint8_t transmission_type) noexcept {
  return transmission_type > 240 && transmission_type < 254;
}

}  // namespace

PdoLayout::Error PdoLayout::add(cia402::ObjectDef def, std::uint8_t bits) noexcept {
  // Byte-granular 8/16/32-bit objects only: every reference drive maps whole bytes (AKD part 1
  // §12.3, quirk 9), and the image holds the CiA 402 integer types.
  if ((bits != 8 && bits != 16 && bits != 32) || bits != 8U * cia402::size_of(def.type)) return Error::BadLength;
  if (count == kMaxPdoEntries) return Error::TooManyEntries;
  const auto length = static_cast<std::uint8_t>(bits / 8U);
  if (bytes + length > kMaxDlc) return Error::TooLong;
  fields[count] = PdoField{def, bytes};
  ++count;
  bytes = static_cast<std::uint8_t>(bytes + length);
  return Error::None;
}

const char* to_string(PdoLayout::Error e) noexcept {
  switch (e) {
    case PdoLayout::Error::None: return "ok";
    case PdoLayout::Error::TooManyEntries: return "more than 8 mapped objects";
    case PdoLayout::Error::TooLong: return "mapped objects exceed 8 bytes";
    case PdoLayout::Error::BadLength: return "bit length is not 8, 16 or 32 or does not match the object's type";
  }
  return "?";
}

bool ProcessImage::add(cia402::ObjectDef def) noexcept {
  for (std::size_t i = 0; i < size_; ++i) {
    if (entries_[i].def.id == def.id) return entries_[i].def.type == def.type;
  }
  if (size_ == kCapacity) return false;
  entries_[size_++] = Entry{def, 0};
  return true;
}

std::size_t ProcessImage::index_of(cia402::ObjectId id) const noexcept {
  for (std::size_t i = 0; i < size_; ++i) {
    if (entries_[i].def.id == id) return i;
  }
  return kNotFound;
}

void ProcessImage::set_at(std::size_t index, std::int64_t value) noexcept {
  if (index < size_) entries_[index].value = cia402::normalise(entries_[index].def.type, value);
}

void ProcessImage::pack(const PdoLayout& layout, std::span<std::uint8_t, 8> out) const noexcept {
  // Bytes past the mapping stay zero: that is the padding of a frame sent longer than its mapping
  // (NORD RxPDO1, nord-sk500p-ds402.md §8.1).
  std::fill(out.begin(), out.end(), std::uint8_t{0});
  for (std::size_t i = 0; i < layout.count; ++i) {
    const auto& f = layout.fields[i];
    put_le(out, f.offset, cia402::size_of(f.def.type), static_cast<std::uint32_t>(get(f.def.id)));
  }
}

void ProcessImage::unpack(const PdoLayout& layout, std::span<const std::uint8_t> in) noexcept {
  for (std::size_t i = 0; i < layout.count; ++i) {
    const auto& f = layout.fields[i];
    const std::size_t size = cia402::size_of(f.def.type);
    if (f.offset + size > in.size()) continue;  // never read past the frame
    set(f.def.id, std::int64_t{get_le(in, f.offset, size)});
  }
}

bool NodePdos::configure(std::span<const RpdoConfig> rpdos, std::span<const TpdoConfig> tpdos) noexcept {
  if (rpdos.size() > kPdosPerDirection || tpdos.size() > kPdosPerDirection) return false;
  ProcessImage image;
  // Registers a layout's objects; values the profile already set (a reconfiguration after a
  // reboot) survive.
  const auto register_layout = [&](const PdoLayout& layout) {
    for (std::size_t i = 0; i < layout.count; ++i) {
      const auto def = layout.fields[i].def;
      if (!image.add(def)) return false;
      if (image_.contains(def.id)) image.set(def.id, image_.get(def.id));
    }
    return true;
  };
  for (const auto& r : rpdos) {
    if (r.cob_id > kMaxStandardId || rtr_only(r.transmission_type)) return false;
    if (r.dlc != 0 && (r.dlc < r.layout.bytes || r.dlc > kMaxDlc)) return false;
    if (!register_layout(r.layout)) return false;
  }
  for (const auto& t : tpdos) {
    if (t.cob_id > kMaxStandardId || rtr_only(t.transmission_type)) return false;
    if (!register_layout(t.layout)) return false;
  }
  image_ = image;
  ++image_generation_;
  rpdo_count_ = rpdos.size();
  tpdo_count_ = tpdos.size();
  for (std::size_t i = 0; i < rpdo_count_; ++i) rpdos_[i] = RpdoState{rpdos[i], {}, {}, false};
  for (std::size_t i = 0; i < tpdo_count_; ++i) tpdos_[i] = TpdoState{tpdos[i], {}, false, false, false, 0};
  restart();
  return true;
}

void NodePdos::enable(bool on, core::TimePoint /*now*/) noexcept {
  if (on == enabled_) return;
  enabled_ = on;
  if (on) restart();
}

void NodePdos::restart() noexcept {
  // Event-driven RPDOs go out at the first poll, and inputs are stale until the drive has sent
  // them again.
  for (std::size_t i = 0; i < rpdo_count_; ++i) rpdos_[i].ever_sent = false;
  for (std::size_t i = 0; i < tpdo_count_; ++i) {
    auto& t = tpdos_[i];
    t.seen = t.due = t.stale = false;
    t.countdown = t.config.transmission_type;
  }
}

void NodePdos::send(RpdoState& r, const std::array<std::uint8_t, 8>& bytes, core::TimePoint now, TxQueue& tx) noexcept {
  CanFrame f;
  f.id = r.config.cob_id;
  f.dlc = r.config.dlc != 0 ? r.config.dlc : r.config.layout.bytes;
  f.data = bytes;
  if (!tx.push(f)) {
    ++counters_.tx_full;
    return;
  }
  ++counters_.rpdos_sent;
  r.sent = bytes;
  r.sent_at = now;
  r.ever_sent = true;
}

void NodePdos::send_event_driven(core::TimePoint now, TxQueue& tx) noexcept {
  for (std::size_t i = 0; i < rpdo_count_; ++i) {
    auto& r = rpdos_[i];
    if (synchronous(r.config.transmission_type)) continue;
    std::array<std::uint8_t, 8> bytes{};
    image_.pack(r.config.layout, bytes);
    const bool changed = !r.ever_sent || bytes != r.sent;
    const bool timer = r.config.event_timer > core::Duration::zero() && now - r.sent_at >= r.config.event_timer;
    // A refused frame leaves the PDO "changed", so the next poll tries again.
    if (changed || timer) send(r, bytes, now, tx);
  }
}

void NodePdos::after_sync(core::TimePoint now, TxQueue& tx) noexcept {
  if (!enabled_) return;
  // A TPDO since enable() shows the drive operational: from then on RPDOs with a refresh wait for a change.
  const bool heard = std::any_of(tpdos_.begin(), tpdos_.begin() + static_cast<std::ptrdiff_t>(tpdo_count_),
                                 [](const TpdoState& t) { return t.seen; });
  for (std::size_t i = 0; i < rpdo_count_; ++i) {
    auto& r = rpdos_[i];
    if (!synchronous(r.config.transmission_type)) continue;
    std::array<std::uint8_t, 8> bytes{};
    image_.pack(r.config.layout, bytes);
    const bool every_sync = r.config.refresh <= core::Duration::zero() || !heard || !r.ever_sent;
    if (every_sync || bytes != r.sent || now - r.sent_at >= r.config.refresh) send(r, bytes, now, tx);
  }
  send_event_driven(now, tx);
  // The cycle that this SYNC closes: a synchronous TPDO that was due and did not come is missed.
  for (std::size_t i = 0; i < tpdo_count_; ++i) {
    auto& t = tpdos_[i];
    const auto type = t.config.transmission_type;
    if (type == 0 || !synchronous(type)) continue;
    if (t.due) {
      ++counters_.missed;
      t.due = false;
    }
    if (--t.countdown == 0) {
      t.countdown = type;
      t.due = t.stale = true;
    }
  }
}

void NodePdos::poll(core::TimePoint now, TxQueue& tx) noexcept {
  if (enabled_) send_event_driven(now, tx);
}

core::TimePoint NodePdos::next_deadline() const noexcept {
  auto next = core::TimePoint::max();
  if (!enabled_) return next;
  for (std::size_t i = 0; i < rpdo_count_; ++i) {
    const auto& r = rpdos_[i];
    if (synchronous(r.config.transmission_type)) continue;
    if (!r.ever_sent) return core::TimePoint::min();  // the first one is due at once
    if (r.config.event_timer <= core::Duration::zero()) continue;
    if (r.sent_at + r.config.event_timer < next) next = r.sent_at + r.config.event_timer;
  }
  return next;
}

bool NodePdos::on_frame(const CanFrame& frame, core::TimePoint now) noexcept {
  if (frame.extended) return false;
  for (std::size_t i = 0; i < tpdo_count_; ++i) {
    auto& t = tpdos_[i];
    if (frame.id != t.config.cob_id) continue;
    if (!enabled_ || frame.remote || !frame.valid()) {
      ++counters_.ignored;
      return true;
    }
    if (frame.dlc < t.config.layout.bytes) {
      ++counters_.short_frames;
      return true;
    }
    if (frame.dlc > t.config.layout.bytes) ++counters_.long_frames;
    image_.unpack(t.config.layout, frame.payload());
    ++counters_.tpdos_received;
    t.received_at = now;
    last_rx_ = now;
    t.seen = true;
    t.due = t.stale = false;
    // The drive's SYNC phase is the one its frames show (it counts SYNCs from its own start).
    t.countdown = t.config.transmission_type;
    return true;
  }
  return false;
}

bool NodePdos::inputs_fresh(core::TimePoint now) const noexcept {
  if (!enabled_) return false;
  for (std::size_t i = 0; i < tpdo_count_; ++i) {
    const auto& t = tpdos_[i];
    if (!t.seen || t.stale) return false;
    const auto type = t.config.transmission_type;
    const bool timed = (type == 0 || !synchronous(type)) && t.config.event_timer > core::Duration::zero();
    if (timed && now - t.received_at > 2 * t.config.event_timer) return false;
  }
  return true;
}

core::TimePoint NodePdos::last_received(std::size_t index) const noexcept {
  return index < tpdo_count_ ? tpdos_[index].received_at : core::TimePoint{};
}

}  // namespace drivegate::canopen
