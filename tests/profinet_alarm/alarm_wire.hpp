#pragma once
// The controller's AlarmChannel and a simulated device's AlarmSender on a cable of two
// link::MemoryLinks (PROFINET frame rules), on virtual time: run_until() polls both engines,
// sends what they give (unless `drop` says the frame is lost), hands every received frame to the
// engine on that end, and moves the time to the earliest deadline. Every frame sent is logged
// (for tshark).
#include <array>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "adapters/link/memory_link.hpp"
#include "adapters/profinet/controller/alarm_channel.hpp"
#include "adapters/profinet/link/profinet_link.hpp"
#include "adapters/profinet/sim/alarm_sender.hpp"

namespace drivegate::profinet::test {

using Bytes = std::vector<std::uint8_t>;
using namespace std::chrono_literals;

inline constexpr MacAddress kControllerMac{0x02, 0x00, 0x00, 0x00, 0x00, 0x01};
inline constexpr MacAddress kDeviceMac{0x00, 0x1B, 0x1B, 0x12, 0x34, 0x56};
inline constexpr std::uint16_t kControllerRef = 0x0001;
inline constexpr std::uint16_t kDeviceRef = 0x0003;

// The Connect's AlarmCR: 100 ms timeout, 3 retries, priorities 6 and 5.
inline AlarmCrBlockReq alarm_cr() {
  AlarmCrBlockReq c;
  c.local_alarm_reference = kControllerRef;
  c.rta_timeout_factor = 1;
  c.rta_retries = 3;
  return c;
}

inline AlarmChannelConfig channel_config() {
  return AlarmChannelConfig{kControllerMac, kDeviceMac, alarm_cr(), kDeviceRef};
}
inline AlarmSenderConfig sender_config() { return AlarmSenderConfig{kDeviceMac, kControllerMac, alarm_cr(), kDeviceRef}; }

// What the listener got: the text and the notification's fixed fields.
struct Taken {
  std::string text;
  AlarmNotification n;
};

class Recorder final : public AlarmListener {
 public:
  void on_alarm(const AlarmEvent& e) noexcept override {
    AlarmNotification n = e.notification;
    n.user_data = {};
    alarms.push_back({std::string(e.text), n});
  }
  std::vector<Taken> alarms;
};

class AlarmWire {
 public:
  AlarmWire() : controller_link_(kFrameRules, 64), device_link_(kFrameRules, 64) {
    link::MemoryLink::connect(controller_link_, device_link_);
    controller_link_.open();
    device_link_.open();
    controller.open();
    device.open();
  }

  // Until `done` or `limit` of virtual time; true when done.
  bool run_until(const std::function<bool()>& done, core::Duration limit = 60s) {
    const core::TimePoint end = now + limit;
    for (;;) {
      pump();
      if (done()) return true;
      const core::TimePoint next = std::min(controller.next_deadline(), device.next_deadline());
      if (next == core::TimePoint::max() || next > end) return false;
      if (next > now) now = next;
    }
  }
  // Runs until both engines have nothing due but timers (and the device nothing queued).
  bool settle() {
    return run_until([&] {
      return device.pending(AlarmPriority::High) == 0 && device.pending(AlarmPriority::Low) == 0 &&
             controller.next_deadline() == core::TimePoint::max() && device.next_deadline() == core::TimePoint::max();
    });
  }
  // A frame from outside, to the controller.
  void inject(std::span<const std::uint8_t> frame) { (void)controller.on_frame(frame, now); }

  core::TimePoint now{std::chrono::seconds(10)};
  Recorder recorder;
  AlarmChannel controller{channel_config(), &recorder};
  AlarmSender device{sender_config()};
  std::vector<Bytes> log;
  std::function<bool(std::span<const std::uint8_t>)> drop;  // true: lost on the wire

 private:
  template <typename Engine>
  bool send_from(Engine& e, link::MemoryLink& l) {
    bool any = false;
    while (const std::size_t n = e.poll(now, buf_)) {
      any = true;
      const auto frame = std::span<const std::uint8_t>(buf_).first(n);
      log.emplace_back(frame.begin(), frame.end());
      if (!drop || !drop(frame)) (void)l.send(frame);
    }
    return any;
  }
  template <typename Engine>
  bool receive_into(Engine& e, link::MemoryLink& l) {
    std::array<link::FrameBuffer, 8> in{};
    bool any = false;
    while (const std::size_t n = l.receive(in)) {
      any = true;
      for (std::size_t i = 0; i < n; ++i) (void)e.on_frame(in[i].view(), now);
    }
    return any;
  }
  void pump() {
    bool any = true;
    while (any) {
      any = send_from(controller, controller_link_);
      any = send_from(device, device_link_) || any;
      any = receive_into(device, device_link_) || any;
      any = receive_into(controller, controller_link_) || any;
    }
  }

  link::MemoryLink controller_link_;
  link::MemoryLink device_link_;
  std::array<std::uint8_t, kMaxFrameSize> buf_{};
};

// Frame predicates for `drop`: the RTA PDU type and the block of a DATA.
inline RtaView rta_of(std::span<const std::uint8_t> frame) { return decode_rta(decode_ethernet(frame).pdu); }
inline bool is_pdu(std::span<const std::uint8_t> f, const MacAddress& from, RtaPduType t) {
  const EthernetView e = decode_ethernet(f);
  return e.header.src == from && rta_of(f).header.type == t;
}
inline bool is_block(std::span<const std::uint8_t> f, std::uint16_t block_type) {
  const RtaView v = rta_of(f);
  return v.header.type == RtaPduType::Data && alarm_block_type(v.var_part) == block_type;
}

// A notification as a device sends it.
inline AlarmNotification alarm(std::uint16_t type, AlarmPriority p = AlarmPriority::High, std::uint16_t slot = 1,
                               std::uint16_t subslot = 1) {
  AlarmNotification n;
  n.priority = p;
  n.alarm_type = type;
  n.api = 0;
  n.slot = slot;
  n.subslot = subslot;
  n.module_ident = 0x00000010;
  n.submodule_ident = 0x00000011;
  return n;
}

}  // namespace drivegate::profinet::test
