// The RTA and alarm decoders (adapters/profinet/wire/alarm.hpp) on whatever arrives with
// EtherType 8892h: decode_ethernet, decode_rta, rta_error_status, decode_alarm_notification,
// decode_alarm_ack, decode_channel_diagnosis. Invariants: every view lies inside the input; the
// channel diagnosis entries cover the item's data exactly; a decoded RTA-PDU (no reserved
// AddFlags bits) re-encodes byte for byte; a decoded AlarmNotification or AlarmAck (no reserved
// AlarmSpecifier bit) re-encodes into the same block; ack_for() of a notification gives an ack
// that decodes to itself.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "adapters/profinet/wire/alarm.hpp"
#include "adapters/profinet/wire/byte_order.hpp"
#include "adapters/profinet/wire/ethernet.hpp"

namespace {

using namespace drivegate::profinet;

std::span<const std::uint8_t> input;

void inside(std::span<const std::uint8_t> s) {
  if (s.empty()) return;
  if (s.data() < input.data() || s.data() + s.size() > input.data() + input.size()) std::abort();
}

bool equal(std::span<const std::uint8_t> a, std::span<const std::uint8_t> b) {
  return std::equal(a.begin(), a.end(), b.begin(), b.end());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 4096) return 0;
  input = std::span<const std::uint8_t>(data, size);
  const EthernetView e = decode_ethernet(input);
  if (!e.ok()) return 0;
  const RtaView r = decode_rta(e.pdu);
  if (!r.ok()) return 0;
  inside(r.var_part);
  static std::array<std::uint8_t, 1600> out{};
  if ((e.pdu[5] & 0xE0) == 0) {
    const std::size_t n = encode_rta(out, r.header, r.var_part);
    if (n != kRtaHeaderSize + r.var_part.size() || !equal(std::span(out).first(n), e.pdu.first(n))) std::abort();
  }
  (void)rta_error_status(r);
  const bool reserved_specifier = r.var_part.size() >= 26 && (r.var_part[24] & 0x40) != 0;
  const AlarmNotificationView n = decode_alarm_notification(r.var_part);
  if (n.ok()) {
    inside(n.notification.user_data);
    if (!reserved_specifier) {
      const std::size_t len = encode_alarm_notification(out, n.notification);
      if (len == 0 || !equal(std::span(out).first(len), r.var_part)) std::abort();
    }
    if (n.notification.has_user_structure) {
      const ChannelDiagnosisList l = decode_channel_diagnosis(n.notification.user_structure_id, n.notification.user_data);
      inside(l.data);
      ChannelDiagnosis c;
      std::size_t k = 0;
      while (l.get(k, c)) ++k;
      if (k != l.count() || (l.error == AlarmError::None && k * l.entry_size != l.data.size())) std::abort();
      (void)channel_error_type_name(c.error_type);
    }
    const AlarmAck a = ack_for(n.notification);
    const std::size_t len = encode_alarm_ack(out, a);
    const AlarmAckView back = decode_alarm_ack(std::span<const std::uint8_t>(out).first(len));
    if (!back.ok() || !(back.ack == a)) std::abort();
  }
  const AlarmAckView a = decode_alarm_ack(r.var_part);
  if (a.ok() && (r.var_part[16] & 0x40) == 0) {
    const std::size_t len = encode_alarm_ack(out, a.ack);
    if (len == 0 || !equal(std::span(out).first(len), r.var_part)) std::abort();
  }
  return 0;
}
