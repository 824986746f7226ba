// ProfidriveMaster: the task handshakes of speed mode and position mode [akd-profinet-profidrive.md
// §15, §16]: NSOLL_A, MDI and program mode (the STW1 bit 6 edge, ZSW1 bit 12 acknowledge), homing
// (STW1 bit 11), real-time jog (STW1 bits 12/13) and stop.
#include <cstdlib>

#include "profiles/profidrive/master_helpers.hpp"
#include "profiles/profidrive/profidrive_master.hpp"
#include "profiles/profidrive/scaling.hpp"

namespace drivegate::profidrive {

using core::CommandKind;
using core::Mode;

namespace {
constexpr std::uint16_t kMdiSelect = 0x8000;  // SATZANW bit 15 [§16.3]
constexpr std::uint16_t kMdiAbsolute = 0x0001;  // MDI_MOD bit 0 [§12.2]
constexpr std::uint16_t kTaskRun = stw1::kDoNotRejectTask | stw1::kNoIntermediateStop;
}  // namespace

void ProfidriveMaster::start_motion(const core::DriveCommand& cmd, Mode mode, core::TimePoint now) noexcept {
  const Task previous = motion_.task;
  motion_.slot = Slot{true, cmd.id, cmd.kind};
  motion_.cmd = cmd;
  motion_.since = now;
  motion_.settle_until = telegrams_ + settings_.settle_telegrams;
  motion_.primed_in = cycle_ + 1;  // the next update writes the task's outputs
  motion_.phase = Phase::WaitDone;
  if (cmd.kind != CommandKind::Stop) mode_ = mode;
  // Anything the previous task drove stops being driven unless the new one drives it too.
  if (previous == Task::Homing) out_.home_dist = 0;
  switch (cmd.kind) {
    case CommandKind::Velocity:
      if (caps_.speed) {
        motion_.task = Task::Speed;
        out_.nsoll_a = nsoll_from_native(cmd.target_velocity).value_or(0);
      } else if (cmd.target_velocity == 0) {
        motion_.task = Task::Stop;  // real-time jog at 0 is a stop
      } else {
        motion_.task = Task::Jog;
        const auto speed = static_cast<std::uint32_t>(std::llabs(static_cast<long long>(cmd.target_velocity)));
        out_.mdi_velocity = mdi_velocity_from_native(speed).value_or(0);
        out_.mdi_acc = mdi_acc_from_native(cmd.profile_acceleration).value_or(0);
        out_.mdi_dec = mdi_acc_from_native(cmd.profile_deceleration).value_or(0);
      }
      return;
    case CommandKind::Move:
    case CommandKind::RunBlock:
      motion_.task = cmd.kind == CommandKind::Move ? Task::Mdi : Task::Program;
      // The acknowledge of the previous task must drop before the next edge [§16.3 on-the-fly].
      motion_.phase = (actual_.zsw1 & zsw1::kTaskAcknowledge) != 0 ? Phase::AckClear : Phase::Prime;
      if (motion_.phase == Phase::Prime) load_task();
      return;
    case CommandKind::Home:
      motion_.task = Task::Homing;
      if (caps_.home_dist) out_.home_dist = cmd.home_offset;
      if (caps_.home_mode) out_.home_mode = static_cast<std::uint16_t>(cmd.homing_method);
      return;
    default:  // Stop
      motion_.task = Task::Stop;
      if (caps_.speed) out_.nsoll_a = 0;
      return;
  }
}

// The task's signals go out together with bits 4 and 5, one cycle before the bit 6 edge that makes
// the drive take them [§16.2 steps 1-3, §16.3 steps 1-4].
void ProfidriveMaster::load_task() noexcept {
  const core::DriveCommand& c = motion_.cmd;
  if (motion_.task == Task::Program) {
    out_.satzanw = static_cast<std::uint16_t>(c.block);
    return;
  }
  out_.satzanw = kMdiSelect;
  out_.mdi_tarpos = c.target_position;
  out_.mdi_velocity = mdi_velocity_from_native(c.profile_velocity).value_or(0);
  out_.mdi_acc = mdi_acc_from_native(c.profile_acceleration).value_or(0);
  out_.mdi_dec = mdi_acc_from_native(c.profile_deceleration).value_or(0);
  out_.mdi_mod = c.relative ? 0 : kMdiAbsolute;
}

std::uint16_t ProfidriveMaster::task_bits() const noexcept {
  if (caps_.speed) {
    // Ramp on, running, set-point taken [§8.2, §15]; halt takes the set-point away (0 -> ramp to
    // standstill), the ramp generator itself stays on. NSOLL_A is 0 until a velocity command.
    return halt_ ? static_cast<std::uint16_t>(stw1::kEnableRampGenerator | stw1::kUnfreezeRampGenerator)
                 : stw1::kSpeedRunBits;
  }
  // Bit 5 low is the intermediate stop of a task; setting it again resumes [§8.3, §16.2].
  const std::uint16_t run = halt_ ? stw1::kDoNotRejectTask : kTaskRun;
  switch (motion_.task) {
    case Task::Mdi:
    case Task::Program:
      switch (motion_.phase) {
        case Phase::AckClear:
        case Phase::Prime: return run;
        default: return static_cast<std::uint16_t>(run | stw1::kActivateTask);  // a level the acknowledge follows
      }
    case Task::Homing:
      return motion_.slot.active ? stw1::kStartHoming : std::uint16_t{0};
    case Task::Jog:
      // Real-time jog with MDI_VELOCITY/ACC/DEC, bit 13 the direction [§8.3, §16.5]; halt drops it.
      if (halt_) return 0;
      return static_cast<std::uint16_t>(stw1::kRealTimeJog | (motion_.cmd.target_velocity < 0 ? stw1::kRealTimeJogCcw : 0));
    default:
      return 0;  // bit 4 low rejects a running task, bit 11 low aborts homing [§8.3]
  }
}

void ProfidriveMaster::run_motion(core::TimePoint now, core::ControllerSink& sink) noexcept {
  if (!motion_.slot.active) return;
  const core::Duration elapsed = now - motion_.since;
  const bool ack = (actual_.zsw1 & zsw1::kTaskAcknowledge) != 0;
  const char* what = motion_.task == Task::Program ? "traversing block" : "MDI task";
  switch (motion_.phase) {
    case Phase::AckClear:
      if (!ack) {
        load_task();
        motion_.phase = Phase::Prime;
        motion_.primed_in = cycle_;
        motion_.since = now;
      } else if (elapsed > settings_.ack_timeout) {
        core::Text reason;
        reason.format("drive still acknowledges the previous task (ZSW1 bit 12) %lld ms after STW1 bit 6 dropped",
                      ms(elapsed));
        fail_motion(reason.view(), sink);
      }
      return;
    case Phase::Prime:
      // Bits 4, 5 and the signals went out with an earlier cycle: now the edge.
      if (cycle_ > motion_.primed_in) {
        motion_.phase = Phase::WaitAck;
        motion_.since = now;
      }
      return;
    case Phase::WaitAck: {
      // Program mode: the drive may also show the block running (AKTSATZ with bit 14) [§16.2].
      const bool running = motion_.task == Task::Program && (actual_.zsw1 & zsw1::kMotionTaskActive) != 0 &&
                           actual_.aktsatz == static_cast<std::uint16_t>(motion_.cmd.block);
      if (ack || running) {
        motion_.phase = Phase::WaitDone;
        motion_.since = now;
        motion_.settle_until = telegrams_ + settings_.settle_telegrams;
      } else if (elapsed > settings_.ack_timeout) {
        core::Text reason;
        reason.format("drive did not acknowledge the %s (ZSW1 bit 12) within %lld ms after the STW1 bit 6 edge: "
                      "refused (position mode? homed? block configured?)",
                      what, ms(settings_.ack_timeout));
        fail_motion(reason.view(), sink);
      }
      return;
    }
    case Phase::WaitDone:
      break;
  }
  if (motion_.task == Task::Homing) {
    if (elapsed > settings_.homing_timeout) {
      core::Text reason;
      reason.format("homing did not finish within %lld ms (ZSW1 0x%04X)", ms(settings_.homing_timeout),
                    static_cast<unsigned>(actual_.zsw1));
      fail_motion(reason.view(), sink);
      return;
    }
  }
  if (!motion_done()) return;
  if (motion_.task == Task::Homing) motion_.task = Task::None;  // bit 11 back to 0 once homed
  motion_.slot.complete(sink);
}

bool ProfidriveMaster::motion_done() const noexcept {
  if (telegrams_ < motion_.settle_until) return false;  // the telegram may still describe the previous task
  const Zsw1Flags f = decode_flags(actual_.zsw1);
  switch (motion_.task) {
    case Task::Speed: return f.bit10_reached;  // speed reached [§9.2]
    case Task::Mdi: return f.bit10_reached;    // target position reached [§16.3 step 7]
    case Task::Program: return f.bit10_reached && !f.motion_task_active;
    case Task::Homing: {
      constexpr std::uint16_t kHomedBits = zsw1::kTargetReached | zsw1::kHomed | zsw1::kDriveStopped;
      return (actual_.zsw1 & kHomedBits) == kHomedBits;  // [§16.4 step 3]
    }
    case Task::Jog: return true;  // running; it goes on until stop or a new command
    default: return at_standstill();
  }
}

void ProfidriveMaster::end_motion() noexcept {
  motion_.task = Task::None;
  motion_.phase = Phase::WaitDone;
  out_.satzanw = 0;
  out_.nsoll_a = 0;
  out_.home_dist = 0;
}

void ProfidriveMaster::fail_motion(std::string_view reason, core::ControllerSink& sink) noexcept {
  end_motion();
  motion_.slot.fail(reason, sink);
}

}  // namespace drivegate::profidrive
