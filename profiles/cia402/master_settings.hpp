#pragma once
// What the CiA 402 master needs to know about its axis besides the drive itself: timeouts and the
// few device-dependent choices. Built from the axis spec before the cycle thread starts.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>

#include "core/axis_spec.hpp"
#include "core/clock.hpp"

namespace drivegate::cia402 {

struct MasterSettings {
  core::Duration enable_step_timeout = std::chrono::seconds(2);  // per state-machine step, and fault reset
  // A drive that stays in a state its controlword tells it to leave towards less power (quick
  // stop, disable, shutdown) for longer than this no longer follows the gateway: control is lost.
  core::Duration follow_timeout = std::chrono::seconds(1);
  core::Duration mode_confirm_timeout = std::chrono::milliseconds(500);  // 6061h must echo 6060h
  core::Duration setpoint_ack_timeout = std::chrono::milliseconds(500);  // pp SW bit 12 handshake
  core::Duration homing_timeout = std::chrono::seconds(60);
  // Object writes a command stages before its handshake (acyclic when not mapped) must all have
  // landed within this time, or the command fails naming the object.
  core::Duration stage_timeout = std::chrono::seconds(1);
  // |velocity actual| (606Ch, 6044h in vl) at or below this counts as standstill for mode changes
  // [AKD digest §3.6], in drive units. Real drives jitter a few counts at rest, so 0 would refuse
  // every mode change on a servo holding position; 10 is a few encoder counts/s (0.01 rpm on the
  // AKD's 1/1000 rpm). settings_from() widens it to 0.2% of the axis' velocity limit (or 0.01 user
  // units per second for an axis without one).
  std::int32_t standstill_velocity = 10;
  // Status words received within this many cycles after a new target was handed over may still
  // carry the previous target's "reached" bit; completion ignores them.
  std::uint32_t settle_cycles = 2;
  // Profile torque: wait for SW bit 10 "target torque reached" (CiA 402, NORD digest §5.4). Drives
  // without it complete the torque command once 6071h was written.
  bool torque_reached_bit = true;
  // vl has no target-reached bit on NORD [NORD digest §5.2]: done when |6044h - 6042h| <= this
  // (only when 6044h is mapped; otherwise done once 6042h was written).
  std::int32_t vl_velocity_window = 5;
  // Profile position: controlword bit 6 set means an absolute move, not a relative one (device
  // quirk pp_bit6_absolute: ESR/Dunker, dunker-ethercat-coe.md §14 item 14 [EXT]).
  bool pp_bit6_absolute = false;
};

inline MasterSettings settings_from(const core::AxisSpec& spec) {
  MasterSettings s;
  s.enable_step_timeout = spec.enable_step_timeout;
  s.follow_timeout = std::min(spec.enable_step_timeout, s.follow_timeout);
  s.homing_timeout = spec.homing.timeout;
  // 0.2% of the velocity limit (6 rpm on a 3000 rpm axis): well below any commanded motion, well
  // above encoder jitter. Without a limit, 0.01 user units per second (0.01 mm/s, 0.6 rpm on a
  // rev axis): a drive settling after a move in 1/1000 rpm units is not held up by the 10.
  const double factor = std::fabs(spec.units.velocity_factor());
  const double window = spec.limits.max_velocity > 0 ? std::fabs(spec.limits.max_velocity) * factor * 0.002 : 0.01 * factor;
  if (window > s.standstill_velocity && window < 1e9) s.standstill_velocity = static_cast<std::int32_t>(window);
  return s;
}

}  // namespace drivegate::cia402
