#pragma once
// The PROFIdrive general state machine seen from the controller [akd-profinet-profidrive.md §7]:
// ZSW1 (plus the last STW1 sent) -> the unified axis state (DESIGN.md §4), and the STW1 word for
// the next step of an enable walk. Pure functions; the caller keeps the last STW1 it sent.
//
//   S1 switching on inhibited -> SwitchOnDisabled      S2 ready for switching on -> ReadyToSwitchOn
//   S3 switched on            -> SwitchedOn            S4 operation              -> OperationEnabled
//   S5 after OFF3 (quick stop)        -> QuickStopActive, stopping
//   S5 after OFF1 (ramp down to S2)   -> ReadyToSwitchOn, stopping (the state it ramps towards)
//   ZSW1 bit 3 (fault present)        -> Fault
#include <cstdint>

#include "core/axis_types.hpp"
#include "profiles/profidrive/control_words.hpp"

namespace drivegate::profidrive {

struct DriveState {
  core::AxisState state = core::AxisState::Unknown;
  bool stopping = false;  // ramping or coasting towards `state` (S5, OFF2)
  bool operator==(const DriveState&) const = default;
};

// OFF2 and OFF3 show in ZSW1 bits 4 and 5; an OFF1 ramp (S5) shows the same ZSW1 bits 0..2 as S3
// or S4, so it is read from `last_stw1` (bit 0 low). AxisState::Unknown for patterns the standard
// does not define (e.g. "ready to operate" without "ready to switch on").
DriveState decode_state(std::uint16_t zsw1, std::uint16_t last_stw1) noexcept;

// ZSW1 flag bits other than the state bits. Bits 8 and 10 mean different things per class
// (zsw1::kSpeedErrorInTolerance / kFollowingErrorInTolerance, kSpeedReached / kTargetReached).
struct Zsw1Flags {
  bool warning = false;
  bool control_requested = false;
  bool bit8_in_tolerance = false;  // AC1 speed error / AC3 following error within tolerance
  bool bit10_reached = false;      // AC1 speed reached / AC3 target position reached
  bool homed = false;              // AC3
  bool task_acknowledge = false;   // AC3
  bool drive_stopped = false;      // AC3
  bool motion_task_active = false; // AC3
};
Zsw1Flags decode_flags(std::uint16_t zsw1) noexcept;

struct EnableStep {
  std::uint16_t stw1 = 0;
  bool done = false;  // the drive is in S4 (OperationEnabled); keep sending `stw1`
};

// The STW1 to send this cycle to bring the drive one legal step closer to S4 [§7, §24 step 9]:
// S1 0x0406, S2 0x0407, S3 0x040F, S4 0x040F (done); `mode_bits` (e.g. stw1::kSpeedRunBits for
// the §15.1 sequence 0x0476, 0x0477, 0x047F) are added to these. A fault is acknowledged with a
// 0->1 edge on bit 7 and bit 0 low (0x0406 first when the last word already had bit 7 set, then
// 0x0486), so the drive lands in S1 and is switched on again only through S2 [§18.2, §25.17].
// While the drive is stopping (S5, OFF2) the last word is repeated; during a quick stop bit 0 is
// dropped so S1 is reached with ON low. Unknown and NotReadyToSwitchOn send 0x0406 (S1 -> S2 once
// the drive gets there).
EnableStep enable_step(DriveState current, std::uint16_t last_stw1, std::uint16_t mode_bits = 0) noexcept;

// A fault reset on its own (no enable): 0x0400 while bit 7 must be seen low first (the last word
// had it), then 0x0480, the 0->1 edge with bits 0..3 low, so the drive lands in S1 and stays there
// [§8.1, §18.2]. Each level is held for telegrams, not toggled per cycle: the drive takes STW1 once
// per update time, which spans several controller cycles.
constexpr std::uint16_t fault_reset_stw1(bool acknowledge) noexcept {
  return acknowledge ? static_cast<std::uint16_t>(stw1_word::kIdle | stw1::kFaultAcknowledge) : stw1_word::kIdle;
}

}  // namespace drivegate::profidrive
