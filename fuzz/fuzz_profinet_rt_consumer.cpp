// The controller's RtConsumer (adapters/profinet/controller/rt_cyclic.hpp) on frames from outside,
// on virtual time: the input CR 8002h of an AR with a DAP, a 4/4-octet drive submodule and a
// 2-octet input submodule from device 00:1b:1b:12:34:56, 1 ms send clock, ratio 2, data hold 3.
//
// Input: records [time step in 500 µs units u8, FFh: arm() instead of a step] [length u16
// big-endian] [length octets of frame]. Invariants: every frame with the CR's FrameID is counted
// in exactly one bucket (taken, wrong source, truncated, transfer status, repeated or old cycle,
// ignore, data invalid, backup, inactive) and on_frame() says so; other frames change no bucket;
// the data views keep the layout's lengths; Running only within the data hold time of a taken
// frame, Timeout only once the deadline passed.
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "adapters/profinet/controller/rt_cyclic.hpp"

namespace {

using namespace drivegate::profinet;
using drivegate::core::TimePoint;

constexpr std::array<IoSubmodule, 3> kSubmodules{{{IoKind::NoIo, 0, 0}, {IoKind::InputOutput, 4, 4}, {IoKind::Input, 2, 0}}};

std::uint64_t buckets(const RtConsumerCounters& c) {
  return c.frames + c.wrong_source + c.truncated + c.transfer_error + c.repeated_cycle + c.old_cycle + c.ignore +
         c.data_invalid + c.backup + c.inactive;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 16384) return 0;
  RtIocrConfig config;
  config.frame_id = 0x8002;
  config.controller_mac = {0x02, 0, 0, 0, 0, 1};
  config.device_mac = {0x00, 0x1B, 0x1B, 0x12, 0x34, 0x56};
  config.send_clock_factor = 32;
  config.reduction_ratio = 2;
  config.phase = 1;
  config.data_hold_factor = 3;
  config.submodules = kSubmodules;
  RtConsumer consumer(config);
  if (!consumer.ok()) std::abort();
  TimePoint now{std::chrono::seconds(1)};
  consumer.arm(now);

  std::size_t pos = 0;
  while (pos + 3 <= size) {
    if (data[pos] == 0xFF) {
      consumer.arm(now);
    } else {
      now += std::chrono::microseconds(500) * data[pos];
    }
    const std::size_t length = std::min<std::size_t>((std::size_t{data[pos + 1]} << 8) | data[pos + 2], size - pos - 3);
    const std::span<const std::uint8_t> frame(data + pos + 3, length);
    pos += 3 + length;

    const std::uint64_t before = buckets(consumer.counters());
    const bool ours = consumer.on_frame(frame, now);
    const std::uint64_t after = buckets(consumer.counters());
    if (after != before + (ours ? 1 : 0)) std::abort();
    const EthernetView e = decode_ethernet(frame);
    if (ours != (e.ok() && e.frame_class == FrameClass::RtCyclic && e.header.frame_id == config.frame_id)) std::abort();

    (void)consumer.poll(now);
    const TimePoint deadline = consumer.next_deadline();
    switch (consumer.state()) {
      case RtConsumerState::Running:
      case RtConsumerState::Waiting:
        if (deadline <= now || deadline > now + consumer.data_hold_time()) std::abort();
        break;
      case RtConsumerState::Timeout:
        if (deadline != TimePoint::max() || consumer.reason().empty()) std::abort();
        break;
      case RtConsumerState::Idle: std::abort();  // armed from the start
    }
    if (consumer.data(1).size() != 4 || consumer.data(2).size() != 2 || !consumer.data(0).empty()) std::abort();
  }
  return 0;
}
