#pragma once
// STW1/ZSW1 bits (PROFIdrive signals 1 and 2) and the STW1 words the gateway sends, with the AKD's
// rule that bit 10 ("control by PLC") is always set [akd-profinet-profidrive.md §8, §9, §25.18].
// Bits 4..6 and 8..15 mean different things in speed mode (application class 1) and position mode
// (application class 3); both names are given, the caller knows which class its telegram runs.
#include <cstdint>

namespace drivegate::profidrive {

namespace stw1 {
// General bits, all modes [§8.1].
inline constexpr std::uint16_t kOn = 1U << 0;              // OFF1 when 0
inline constexpr std::uint16_t kNoCoastStop = 1U << 1;     // OFF2 when 0
inline constexpr std::uint16_t kNoQuickStop = 1U << 2;     // OFF3 when 0
inline constexpr std::uint16_t kEnableOperation = 1U << 3;
inline constexpr std::uint16_t kFaultAcknowledge = 1U << 7;  // acts on the 0->1 edge [§8.1, §18.2]
inline constexpr std::uint16_t kControlByPlc = 1U << 10;     // 0: the AKD ignores the controller [§8.1]
inline constexpr std::uint16_t kStateMask = 0x000F;          // bits 0..3 drive the state machine [§7]

// Speed mode, application class 1 [§8.2].
inline constexpr std::uint16_t kEnableRampGenerator = 1U << 4;
inline constexpr std::uint16_t kUnfreezeRampGenerator = 1U << 5;
inline constexpr std::uint16_t kEnableSetpoint = 1U << 6;
inline constexpr std::uint16_t kJog1 = 1U << 8;  // both classes; needs bits 4..6 = 0 at standstill [§16.5]
inline constexpr std::uint16_t kJog2 = 1U << 9;
// Bits 4, 5, 6 together: ramp on, ramp running, set-point taken [§8.2, §15].
inline constexpr std::uint16_t kSpeedRunBits = kEnableRampGenerator | kUnfreezeRampGenerator | kEnableSetpoint;

// Position mode, application class 3 [§8.3].
inline constexpr std::uint16_t kDoNotRejectTask = 1U << 4;
inline constexpr std::uint16_t kNoIntermediateStop = 1U << 5;
inline constexpr std::uint16_t kActivateTask = 1U << 6;  // rising edge starts / loads a task
inline constexpr std::uint16_t kStartHoming = 1U << 11;  // level: clearing it aborts homing
// AKD vendor bits in position mode [§8.3, §16.5, §25.8].
inline constexpr std::uint16_t kRealTimeJog = 1U << 12;     // jog with MDI_VELOCITY/ACC/DEC
inline constexpr std::uint16_t kRealTimeJogCcw = 1U << 13;  // direction: 0 clockwise, 1 counter-clockwise
}  // namespace stw1

namespace zsw1 {
// General bits [§9.1].
inline constexpr std::uint16_t kReadyToSwitchOn = 1U << 0;
inline constexpr std::uint16_t kReadyToOperate = 1U << 1;
inline constexpr std::uint16_t kOperationEnabled = 1U << 2;
inline constexpr std::uint16_t kFault = 1U << 3;
inline constexpr std::uint16_t kNoCoastStop = 1U << 4;  // 0: coast stop (OFF2) active
inline constexpr std::uint16_t kNoQuickStop = 1U << 5;  // 0: quick stop (OFF3) active
inline constexpr std::uint16_t kSwitchingOnInhibited = 1U << 6;  // S1
inline constexpr std::uint16_t kWarning = 1U << 7;
inline constexpr std::uint16_t kControlRequested = 1U << 9;

// Speed mode, application class 1 [§9.2].
inline constexpr std::uint16_t kSpeedErrorInTolerance = 1U << 8;
inline constexpr std::uint16_t kSpeedReached = 1U << 10;  // "f or n reached"

// Position mode, application class 3 [§9.3].
inline constexpr std::uint16_t kFollowingErrorInTolerance = 1U << 8;  // polarity disputed [§23.8]
inline constexpr std::uint16_t kTargetReached = 1U << 10;
inline constexpr std::uint16_t kHomed = 1U << 11;              // reference point set
inline constexpr std::uint16_t kTaskAcknowledge = 1U << 12;    // follows STW1 bit 6 as a level [§25.9]
inline constexpr std::uint16_t kDriveStopped = 1U << 13;       // wording disputed [§23.7]
inline constexpr std::uint16_t kMotionTaskActive = 1U << 14;   // DRV.MOTIONSTAT bit 0
}  // namespace zsw1

// STW1 words for the state-machine steps, each with bit 10 set [§20.2 "recommended gateway
// sequence", §24 step 9]. Speed mode may add stw1::kSpeedRunBits to every word (§15.1: 0x0470,
// 0x0476, 0x0477, 0x047F).
namespace stw1_word {
inline constexpr std::uint16_t kIdle = stw1::kControlByPlc;  // 0x0400: S1, no request [§20.2 step 1]
// S1 -> S2, and OFF1 from S3/S4 (S4 ramps down through S5 to S2) [§7]: 0x0406.
inline constexpr std::uint16_t kShutdown = stw1::kControlByPlc | stw1::kNoCoastStop | stw1::kNoQuickStop;
inline constexpr std::uint16_t kSwitchOn = kShutdown | stw1::kOn;                     // S2 -> S3: 0x0407
inline constexpr std::uint16_t kEnableOperation = kSwitchOn | stw1::kEnableOperation;  // S3 -> S4: 0x040F
inline constexpr std::uint16_t kDisableOperation = kSwitchOn;                           // S4 -> S3: 0x0407
// Speed mode running: 0x047F [§15.1 step 4, §20.3].
inline constexpr std::uint16_t kSpeedRun = kEnableOperation | stw1::kSpeedRunBits;
// OFF3 from S4: quick stop, then S1 at standstill [§7]; bit 0 low so the drive does not go on
// to S2 by itself once in S1: 0x0402.
inline constexpr std::uint16_t kQuickStop = stw1::kControlByPlc | stw1::kNoCoastStop;
// OFF2: coast stop, straight to S1 [§7]: 0x0400 (bit 1 low).
inline constexpr std::uint16_t kCoastStop = stw1::kControlByPlc;
// Fault acknowledge with bit 0 low: the AKD lands in S1 [§8.1, §18.2] and, as bits 1 and 2 are
// set, may go on to S2; ON stays low until the enable walk asks for it [§25.17]: 0x0486.
inline constexpr std::uint16_t kFaultAcknowledge = kShutdown | stw1::kFaultAcknowledge;
// Position mode in S4 [§16.2, §16.3]: task accepted and running (0x043F), then the rising edge of
// bit 6 (0x047F) starts or loads it; homing raises bit 11 (0x0C0F) [§16.4].
inline constexpr std::uint16_t kTaskReady = kEnableOperation | stw1::kDoNotRejectTask | stw1::kNoIntermediateStop;
inline constexpr std::uint16_t kTaskActivate = kTaskReady | stw1::kActivateTask;
inline constexpr std::uint16_t kHoming = kEnableOperation | stw1::kStartHoming;
}  // namespace stw1_word

}  // namespace drivegate::profidrive
