#include "adapters/link/link.hpp"

#include "core/bytes.hpp"

namespace drivegate::link {

FrameCheck check_frame(std::span<const std::uint8_t> frame, const FrameRules& rules) noexcept {
  const bool tagged = rules.vlan_tags && has_vlan_tag(frame);
  if (!sendable(frame, rules)) {
    return frame.size() < rules.min_frame_bytes + (tagged ? kVlanTagBytes : 0) ? FrameCheck::TooShort : FrameCheck::TooLong;
  }
  const std::size_t at = kEtherTypeOffset + (tagged ? kVlanTagBytes : 0);
  return core::get_be16(frame, at) == rules.ether_type ? FrameCheck::Ok : FrameCheck::WrongEtherType;
}

const char* to_string(LinkState s) noexcept {
  switch (s) {
    case LinkState::Closed: return "closed";
    case LinkState::Up: return "up";
    case LinkState::AdminDown: return "interface down";
    case LinkState::NoCarrier: return "no carrier";
    case LinkState::Gone: return "interface gone";
  }
  return "?";
}

LinkCounters LinkCounterCells::snapshot() const noexcept {
  LinkCounters c;
  c.tx_frames = tx_frames.get();
  c.tx_invalid = tx_invalid.get();
  c.tx_busy = tx_busy.get();
  c.tx_down = tx_down.get();
  c.rx_frames = rx_frames.get();
  c.rx_too_short = rx_too_short.get();
  c.rx_too_long = rx_too_long.get();
  c.rx_wrong_ethertype = rx_wrong_ethertype.get();
  c.rx_own = rx_own.get();
  c.rx_overflow = rx_overflow.get();
  c.link_downs = link_downs.get();
  c.link_ups = link_ups.get();
  return c;
}

void LinkCounterCells::count_drop(FrameCheck c) noexcept {
  switch (c) {
    case FrameCheck::Ok: break;
    case FrameCheck::TooShort: rx_too_short.add(); break;
    case FrameCheck::TooLong: rx_too_long.add(); break;
    case FrameCheck::WrongEtherType: rx_wrong_ethertype.add(); break;
  }
}

void LinkCounterCells::count_transition(LinkState before, LinkState after) noexcept {
  if (before == LinkState::Up && after != LinkState::Up) link_downs.add();
  if (before != LinkState::Up && before != LinkState::Closed && after == LinkState::Up) link_ups.add();
}

}  // namespace drivegate::link
