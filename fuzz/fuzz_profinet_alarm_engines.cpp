// The alarm engines (adapters/profinet/controller/alarm_channel.hpp, sim/alarm_sender.hpp) on
// frames from outside: the controller's AlarmChannel (02:00:00:00:00:01, alarm reference 1) and a
// simulated device's AlarmSender (00:1b:1b:12:34:56, reference 3; it always has an alarm queued,
// high and low in turn, some with channel diagnosis) see every input frame; the frames each gives
// out go to the other, on virtual time.
//
// Input: records [time step in 10 ms units u8] [length u16 big-endian] [length octets of frame].
// Invariants: every frame an engine gives is one Ethernet frame (60..1518 octets) from its own MAC
// to the other's, an alarm frame whose RTA-PDU decodes with the AR's endpoints; every alarm the
// controller counts reached the listener with a non-empty text; the controller confirms no more
// AlarmAcks than it took alarms; a channel that is not open has a reason when aborted.
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "adapters/profinet/controller/alarm_channel.hpp"
#include "adapters/profinet/sim/alarm_sender.hpp"

namespace {

using namespace drivegate::profinet;
using drivegate::core::TimePoint;

constexpr MacAddress kController{0x02, 0, 0, 0, 0, 1};
constexpr MacAddress kDevice{0x00, 0x1B, 0x1B, 0x12, 0x34, 0x56};
constexpr std::uint16_t kControllerRef = 1;
constexpr std::uint16_t kDeviceRef = 3;

class Listener final : public AlarmListener {
 public:
  void on_alarm(const AlarmEvent& e) noexcept override {
    if (e.text.empty()) std::abort();
    ++alarms;
  }
  std::uint64_t alarms = 0;
};

void check_out(std::span<const std::uint8_t> frame, const MacAddress& from, const MacAddress& to, std::uint16_t src_ref,
               std::uint16_t dst_ref) {
  if (frame.size() < kMinFrameSize || frame.size() > kMaxFrameSize) std::abort();
  const EthernetView e = decode_ethernet(frame);
  if (!e.ok() || !is_alarm(e.frame_class) || e.header.src != from || e.header.dst != to) std::abort();
  const RtaView r = decode_rta(e.pdu);
  if (!r.ok() || r.header.src_endpoint != src_ref || r.header.dst_endpoint != dst_ref) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 16384) return 0;
  AlarmCrBlockReq cr;
  cr.local_alarm_reference = kControllerRef;
  Listener listener;
  AlarmChannel controller(AlarmChannelConfig{kController, kDevice, cr, kDeviceRef}, &listener);
  AlarmSender device(AlarmSenderConfig{kDevice, kController, cr, kDeviceRef});
  controller.open();
  device.open();
  const std::array<std::uint8_t, 6> diagnosis{0x00, 0x01, 0x28, 0x00, 0x00, 0x05};

  TimePoint now{std::chrono::seconds(1)};
  std::array<std::uint8_t, kMaxFrameSize> out{};
  const auto exchange = [&] {
    for (int round = 0; round < 16; ++round) {
      bool any = false;
      while (const std::size_t n = controller.poll(now, out)) {
        check_out(std::span(out).first(n), kController, kDevice, kControllerRef, kDeviceRef);
        device.on_frame(std::span(out).first(n), now);
        any = true;
      }
      while (const std::size_t n = device.poll(now, out)) {
        check_out(std::span(out).first(n), kDevice, kController, kDeviceRef, kControllerRef);
        controller.on_frame(std::span(out).first(n), now);
        any = true;
      }
      if (!any) break;
    }
  };

  std::size_t pos = 0;
  unsigned turn = 0;
  while (pos + 3 <= size) {
    const AlarmPriority p = turn % 2 == 0 ? AlarmPriority::High : AlarmPriority::Low;
    if (device.pending(p) == 0) {
      AlarmNotification n;
      n.priority = p;
      n.alarm_type = turn % 3 == 0 ? alarm_type::kDiagnosis : alarm_type::kPull;
      n.slot = 1;
      n.subslot = 1;
      n.has_user_structure = turn % 3 == 0;
      n.user_structure_id = user_structure::kChannelDiagnosis;
      if (n.has_user_structure) n.user_data = diagnosis;
      (void)device.send(n);
    }
    ++turn;
    now += std::chrono::milliseconds(10 * data[pos]);
    const std::size_t length = std::min<std::size_t>((std::size_t{data[pos + 1]} << 8) | data[pos + 2], size - pos - 3);
    const std::span<const std::uint8_t> frame(data + pos + 3, length);
    pos += 3 + length;
    controller.on_frame(frame, now);
    device.on_frame(frame, now);
    exchange();
    const AlarmChannelCounters& c = controller.counters();
    if (c.alarms != listener.alarms || c.acks_confirmed > c.alarms) std::abort();
    if (controller.state() == AlarmChannelState::Aborted && controller.reason().empty()) std::abort();
    if (device.state() == AlarmSenderState::Aborted && device.reason().empty()) std::abort();
  }
  return 0;
}
