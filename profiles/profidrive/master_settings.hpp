#pragma once
// What the PROFIdrive master needs to know about its axis besides the telegram: timeouts and the
// settle time of the handshakes. Built from the axis spec before the cycle thread starts.
#include <algorithm>
#include <chrono>
#include <cstdint>

#include "core/axis_spec.hpp"
#include "core/clock.hpp"

namespace drivegate::profidrive {

struct MasterSettings {
  // Per state-machine step of an enable or fault reset walk (S1 -> S2, S2 -> S3, S3 -> S4).
  core::Duration step_timeout = std::chrono::seconds(2);
  // While the drive ramps or coasts down (S5, OFF2) towards the state a disable or quick stop asks for.
  core::Duration stop_timeout = std::chrono::seconds(10);
  // A drive that shows more power than the STW1 sent allows (operation enabled under OFF3 or a
  // cleared bit 3, switched on under OFF2) for longer than this no longer follows the gateway.
  // Under OFF1 the drive ramps first, so stop_timeout applies there.
  core::Duration follow_timeout = std::chrono::seconds(1);
  // The task handshakes: ZSW1 bit 12 following STW1 bit 6 (MDI, program mode), a homing run
  // starting, the previous acknowledge dropping [§16.2, §16.3, §16.4].
  core::Duration ack_timeout = std::chrono::milliseconds(500);
  core::Duration homing_timeout = std::chrono::seconds(60);
  // An actual telegram not refreshed for this long counts as lost: the AKD's fastest update time
  // is 16 ms [§2], so this is several updates at the usual 16..128 ms.
  core::Duration stale_timeout = std::chrono::milliseconds(500);
  // One record-47 exchange (write request, read response until ready). The acyclic channel is
  // non-real-time and typically above 100 ms [§2].
  core::Duration param_timeout = std::chrono::seconds(3);
  // This many actual telegrams after a new task went out may still carry the previous task's bits
  // (target reached, homed, drive stopped): completion ignores them. Counted in fresh telegrams, not
  // cycles, so a drive that updates slower than the bus cycle gets the same grace.
  std::uint32_t settle_telegrams = 3;
  // Native velocity units per XIST_A count per second, for the velocity derived from XIST_A where
  // the telegram carries no NIST_A (default: 65536 counts per rev, 2^31 = 200 rev/s).
  double velocity_per_count = 2147483648.0 / 200.0 / 65536.0;
};

inline MasterSettings settings_from(const core::AxisSpec& spec) {
  MasterSettings s;
  s.step_timeout = spec.enable_step_timeout;
  s.follow_timeout = std::min(spec.enable_step_timeout, s.follow_timeout);
  s.homing_timeout = spec.homing.timeout;
  s.velocity_per_count = spec.units.velocity_factor() / spec.units.position_factor();
  return s;
}

}  // namespace drivegate::profidrive
