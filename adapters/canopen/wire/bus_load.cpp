// Bus-load estimate (bus_load.hpp).
#include "adapters/canopen/wire/bus_load.hpp"

#include <cmath>

#include "adapters/canopen/wire/bit_timing.hpp"

namespace drivegate::canopen {
namespace {

struct Tally {
  double frames = 0;
  double bits = 0;
  void add(double per_cycle, std::uint32_t bits_per_frame) noexcept {
    frames += per_cycle;
    bits += per_cycle * bits_per_frame;
  }
};

// Frames per cycle of something sent once per `period`.
double per_cycle(core::Duration cycle, core::Duration period) noexcept {
  return static_cast<double>(cycle.count()) / static_cast<double>(period.count());
}

// Rounds up, forgiving the binary fraction error of sums like 0.1 + 0.2.
std::uint64_t round_up(double v) noexcept { return static_cast<std::uint64_t>(std::ceil(v - 1e-9)); }

}  // namespace

CycleLoad estimate_cycle_load(const BusTraffic& traffic, std::uint32_t bitrate, core::Duration cycle_time) noexcept {
  CycleLoad load;
  if (cycle_time <= core::Duration::zero()) return load;
  const auto zero = core::Duration::zero();
  const std::uint32_t heartbeat_bits = frame_bits(1);
  Tally t;
  if (traffic.sync) t.add(1, frame_bits(0));
  if (traffic.master_heartbeat > zero) t.add(per_cycle(cycle_time, traffic.master_heartbeat), heartbeat_bits);
  for (const auto& node : traffic.nodes) {
    for (const auto dlc : node.rpdo_dlcs) t.add(1, frame_bits(dlc));
    for (const auto& tpdo : node.tpdos) {
      const auto type = tpdo.transmission_type;
      if (type <= 240) {
        if (traffic.sync) t.add(type == 0 ? 1.0 : 1.0 / type, frame_bits(tpdo.dlc));
        continue;
      }
      auto interval = tpdo.inhibit_time;
      if (interval <= zero) {
        ++load.unbounded;
        interval = tpdo.event_timer > zero && tpdo.event_timer < cycle_time ? tpdo.event_timer : cycle_time;
      }
      t.add(per_cycle(cycle_time, interval), frame_bits(tpdo.dlc));
    }
    if (node.error_control_period <= zero) continue;
    const double rate = per_cycle(cycle_time, node.error_control_period);
    switch (node.error_control) {
      case NodeErrorControl::Heartbeat: t.add(rate, heartbeat_bits); break;
      case NodeErrorControl::Guarding:
        t.add(rate, frame_bits(1, false, true));  // the master's RTR
        t.add(rate, heartbeat_bits);             // the drive's reply: state and toggle, 1 byte
        break;
      case NodeErrorControl::None: break;
    }
  }
  load.frames = static_cast<std::uint32_t>(round_up(t.frames));
  load.bits = round_up(t.bits);
  if (bitrate == 0) return load;
  // One division each, so exact inputs give exact results (595 bits at 500 kbit/s: 1.19).
  const double rate = bitrate;
  load.time = core::Duration(static_cast<std::int64_t>(std::llround(t.bits * 1e9 / rate)));
  load.fraction = t.bits * 1e9 / (rate * static_cast<double>(cycle_time.count()));
  return load;
}

}  // namespace drivegate::canopen
