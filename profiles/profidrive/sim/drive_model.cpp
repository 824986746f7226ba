// DriveModel: the cycle, the general state machine, faults and the actual-value image.
#include "profiles/profidrive/sim/drive_model.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "profiles/profidrive/control_words.hpp"
#include "profiles/profidrive/scaling.hpp"

namespace drivegate::profidrive::sim {
namespace {

constexpr bool has(std::uint16_t word, std::uint16_t bits) noexcept { return (word & bits) == bits; }

constexpr bool is_free(std::uint16_t telegram) noexcept { return telegram == 0 || telegram == 400; }

// Telegram 400's default mapping is "similar to telegram 9" [§13, §14.9]: the same signals in the
// same words, the rest unused [sim: the exact default is not given].
constexpr std::array<std::uint16_t, 10> kDefault915{1, 32, 3, 34, 34, 35, 35, 36, 37, 38};
constexpr std::array<std::uint16_t, 5> kDefault916{2, 33, 4, 28, 28};

// Telegram 0 has no default [§13]: without a configured list it carries STW1 / ZSW1 only [sim].
constexpr std::array<std::uint16_t, 1> kMinimal915{1};
constexpr std::array<std::uint16_t, 1> kMinimal916{2};

template <std::size_t N>
void fill_default(std::array<std::uint16_t, kMaxTelegramWords>& list, const std::array<std::uint16_t, N>& def) noexcept {
  if (std::any_of(list.begin(), list.end(), [](std::uint16_t v) { return v != 0; })) return;
  std::copy(def.begin(), def.end(), list.begin());
}

// The effective control word while the controller's outputs are invalid: OFF3 with ON low, so the
// drive quick-stops to S1 and stays there [sim].
constexpr std::uint16_t kInvalidOutputsStw1 = stw1::kControlByPlc | stw1::kNoCoastStop;

}  // namespace

DriveModel::DriveModel(const DriveModelConfig& config) noexcept : config_(config) {
  const std::uint16_t t = config_.telegram;
  const bool speed_telegram = t == 1 || t == 350 || t == 351;
  mode_ = config_.operating_mode.value_or(speed_telegram ? OperatingMode::Speed : OperatingMode::Position);
  if (is_free(t)) {
    free_setpoint_words_ = t == 400 ? 12 : std::min<std::uint8_t>(config_.free_setpoint_words, kMaxTelegramWords);
    free_actual_words_ = t == 400 ? 12 : std::min<std::uint8_t>(config_.free_actual_words, kMaxTelegramWords);
    pnu915_ = config_.pnu915;
    pnu916_ = config_.pnu916;
    if (t == 400) {
      fill_default(pnu915_, kDefault915);
      fill_default(pnu916_, kDefault916);
    } else {
      fill_default(pnu915_, kMinimal915);
      fill_default(pnu916_, kMinimal916);
    }
  }
  rebuild_layout();
  single_turn_bits_ = kDefaultSingleTurnBits;
  jog_ = {config_.jog1, config_.jog2};
  jog_acc_ = config_.jog_acc_rpm_per_s;
  jog_dec_ = config_.jog_dec_rpm_per_s;
  pl_errfthresh_ = config_.following_error_fault_counts;
  pl_errwthresh_ = config_.following_error_warning_counts;
  home_mode_ = config_.home_mode;
  home_p_ = config_.home_position_counts;
  home_dist_ = config_.home_dist_counts;
  fbus_param02_ = config_.fbus_param02;
  tasks_ = config_.motion_tasks;
  pos_ = demand_pos_ = config_.start_position_rev;
  publish();
}

void DriveModel::rebuild_layout() noexcept {
  if (is_free(config_.telegram)) {
    const LayoutResult r = free_layout(config_.telegram, std::span<const std::uint16_t>(pnu915_).first(free_setpoint_words_),
                                       free_setpoint_words_, std::span<const std::uint16_t>(pnu916_).first(free_actual_words_),
                                       free_actual_words_);
    layout_error_ = r.error;
    layout_ = r.error == TelegramError::None ? r.layout : TelegramLayout{};
    return;
  }
  const auto fixed = standard_layout(config_.telegram);
  layout_error_ = fixed ? TelegramError::None : TelegramError::UnknownTelegram;
  layout_ = fixed.value_or(TelegramLayout{});
}

void DriveModel::step(core::Duration dt, std::span<const std::uint8_t> setpoint_image,
                      std::span<std::uint8_t> actual_image) noexcept {
  ++counters_.steps;
  std::uint16_t c = kInvalidOutputsStw1;
  if (outputs_ != Outputs::Valid) {
    ++counters_.invalid_outputs;
  } else {
    if (setpoint_image.size() != layout_.setpoint_bytes() || layout_.setpoint_words == 0) {
      ++counters_.wrong_setpoint_length;
    } else {
      Setpoints in = sp_;
      (void)decode_setpoints(layout_, setpoint_image, in);  // the size is checked above
      // Without "control by PLC" the AKD ignores the controller [§8.1, §25.18]: nothing of the
      // telegram is taken, the drive goes on with what it had.
      if (has(in.stw1, stw1::kControlByPlc)) sp_ = in;
      else ++counters_.not_controlled_by_plc;
    }
    c = sp_.stw1;
  }
  const double seconds = std::chrono::duration<double>(dt).count();
  if (seconds > 0.0) {
    update_state(c);
    run_motion(c, seconds);
    check_following_error();
  }
  prev_stw1_ = c;
  publish();
  if (actual_image.size() != layout_.actual_bytes() || encode_actuals(layout_, actuals_, actual_image) != TelegramError::None)
    ++counters_.wrong_actual_length;
}

void DriveModel::set_outputs(Outputs o) noexcept {
  if (o == outputs_) return;
  outputs_ = o;
  // F702 on a lost connection always, on a controller STOP only with FBUS.PARAM02 bit 0 [§18.3, §18.4].
  if (o == Outputs::Lost || (o == Outputs::ControllerStop && (fbus_param02_ & 1U) != 0))
    raise_fault(fault_number::kCommunicationLost);
}

// One transition at most per cycle [§7]. `c` is the effective STW1.
void DriveModel::update_state(std::uint16_t c) noexcept {
  const bool on = has(c, stw1::kOn);
  const bool no_coast = has(c, stw1::kNoCoastStop);
  const bool no_quick = has(c, stw1::kNoQuickStop);
  switch (state_) {
    case State::Fault:
      // The acknowledge acts on the 0->1 edge of bit 7 and lands in S1 [§8.1, §18.2].
      if (has(c, stw1::kFaultAcknowledge) && !has(prev_stw1_, stw1::kFaultAcknowledge) && !cause_persists_) {
        acknowledge_faults();
        enter(State::S1SwitchingOnInhibited);
      }
      return;
    case State::S1SwitchingOnInhibited:
      // ON must be low: a controller holding ON through a fault stays in S1 [§7, §25.17].
      if (!on && no_coast && no_quick) enter(State::S2ReadyForSwitchingOn);
      return;
    case State::S2ReadyForSwitchingOn:
      if (!no_coast || !no_quick) enter(State::S1SwitchingOnInhibited);
      else if (on) enter(State::S3SwitchedOn);
      return;
    case State::S3SwitchedOn:
      if (!no_coast || !no_quick) enter(State::S1SwitchingOnInhibited);
      else if (!on) enter(State::S2ReadyForSwitchingOn);
      else if (has(c, stw1::kEnableOperation)) enter(State::S4Operation);
      return;
    case State::S4Operation:
      if (!no_coast) enter(State::S1SwitchingOnInhibited);
      else if (!no_quick) enter(State::S5QuickStop);
      else if (!on) enter(State::S5RampStop);
      else if (!has(c, stw1::kEnableOperation)) enter(State::S3SwitchedOn);  // pulses off
      return;
    case State::S5RampStop:
      if (!no_coast) enter(State::S1SwitchingOnInhibited);
      else if (!no_quick) enter(State::S5QuickStop);
      else if (standstill()) enter(State::S2ReadyForSwitchingOn);
      return;
    case State::S5QuickStop:
      if (!no_coast || standstill()) enter(State::S1SwitchingOnInhibited);
      return;
  }
}

void DriveModel::enter(State s) noexcept {
  if (state_ == State::S4Operation && s != State::S4Operation) {
    // The extended (position-mode) state machine exists only in S4 [§7, §16.1].
    task_.reset();
    task_ack_ = false;
    jogging_ = false;
    if (homing_ == Homing::Search || homing_ == Homing::MoveToDist) homing_ = Homing::Failed;
  }
  state_ = s;
}

void DriveModel::raise_fault(std::uint16_t number) noexcept {
  // A new fault situation counts once in PNU 944; faults joining an open one only add their number
  // (up to 8) to subindex 0..7 of PNU 947 [§18.2].
  if (!situation_open_) {
    situation_open_ = true;
    ++fault_counter_;
  }
  const auto current = std::span(faults_).first(kFaultsPerSituation);
  if (std::find(current.begin(), current.end(), number) == current.end()) {
    const auto free_slot = std::find(current.begin(), current.end(), std::uint16_t{0});
    if (free_slot != current.end()) *free_slot = number;
  }
  if (state_ != State::Fault) enter(State::Fault);
}

void DriveModel::inject_fault(std::uint16_t number, bool persistent) noexcept {
  if (number == 0) return;  // 0 marks an empty entry in PNU 947
  cause_persists_ = cause_persists_ || persistent;
  raise_fault(number);
}

void DriveModel::acknowledge_faults() noexcept {
  // The acknowledged situation moves up by 8 entries, the oldest one drops out [§18.2].
  std::copy_backward(faults_.begin(), faults_.end() - kFaultsPerSituation, faults_.end());
  std::fill_n(faults_.begin(), kFaultsPerSituation, std::uint16_t{0});
  situation_open_ = false;
}

bool DriveModel::standstill() const noexcept { return std::abs(vel_) * 60.0 <= config_.standstill_rpm; }

std::uint16_t DriveModel::status_word() const noexcept {
  const std::uint16_t c = prev_stw1_;
  std::uint16_t w = zsw1::kControlRequested;  // 1 in normal operation in the S7 example [§9.1, §20.3]
  // Bits 4/5 report OFF2/OFF3 as STW1 bits 1/2 ask for them (§9.4).
  const std::uint16_t off_bits = static_cast<std::uint16_t>((has(c, stw1::kNoCoastStop) ? zsw1::kNoCoastStop : 0U) |
                                                            (has(c, stw1::kNoQuickStop) ? zsw1::kNoQuickStop : 0U));
  constexpr std::uint16_t kS2 = zsw1::kReadyToSwitchOn;
  constexpr std::uint16_t kS3 = kS2 | zsw1::kReadyToOperate;
  constexpr std::uint16_t kS4 = kS3 | zsw1::kOperationEnabled;
  switch (state_) {
    case State::S1SwitchingOnInhibited: w |= zsw1::kSwitchingOnInhibited | off_bits; break;
    case State::S2ReadyForSwitchingOn: w |= kS2 | off_bits; break;
    case State::S3SwitchedOn: w |= kS3 | off_bits; break;
    case State::S4Operation: w |= kS4 | off_bits; break;
    // S5: bit 2 drops while the drive stops [§7 table]; after OFF3 bit 5 shows the quick stop.
    case State::S5RampStop: w |= kS3 | off_bits; break;
    case State::S5QuickStop: w |= kS3 | zsw1::kNoCoastStop; break;
    case State::Fault: w |= zsw1::kFault | off_bits; break;
  }
  const bool s4 = state_ == State::S4Operation;
  const bool homing_runs = homing_ == Homing::Search || homing_ == Homing::MoveToDist;
  if (warning_ || (homing_ == Homing::Failed && has(c, stw1::kStartHoming))) w |= zsw1::kWarning;
  if (mode_ == OperatingMode::Speed) {
    if (s4 && std::abs(vel_ - demand_vel_) * 60.0 <= config_.speed_tolerance_rpm) w |= zsw1::kSpeedErrorInTolerance;
    if (s4 && speed_reached_) w |= zsw1::kSpeedReached;
    return w;
  }
  // Position mode [§9.3, §16.2-§16.4]: while homing runs bits 10, 11 and 13 are all 0.
  const double error_counts = std::abs(demand_pos_ - pos_) * cpr();
  if (s4 && error_counts <= static_cast<double>(pl_errwthresh_)) w |= zsw1::kFollowingErrorInTolerance;
  const bool in_position = std::abs(task_target_ - pos_) * cpr() <= static_cast<double>(config_.position_window_counts);
  if (s4 && ((target_reached_ && in_position && !homing_runs) || (homing_ == Homing::Done && has(c, stw1::kStartHoming))))
    w |= zsw1::kTargetReached;
  if (homed_) w |= zsw1::kHomed;
  if (s4 && task_ack_) w |= zsw1::kTaskAcknowledge;
  if (standstill() && !homing_runs) w |= zsw1::kDriveStopped;
  if (s4 && (task_.has_value() || homing_runs)) w |= zsw1::kMotionTaskActive;
  return w;
}

void DriveModel::publish() noexcept {
  actuals_.zsw1 = status_word();
  actuals_.zsw2 = 0;  // STW2/ZSW2 bits are undocumented on the AKD [§12.1, §25.7]
  actuals_.nist_a = nsoll_from_rpm_saturating(vel_ * 60.0);
  // XIST_A wraps like a 32-bit position counter [§11.2, §17.2].
  const double counts = std::round(pos_ * cpr());
  actuals_.xist_a = static_cast<std::int32_t>(static_cast<std::uint32_t>(static_cast<std::int64_t>(
      std::isfinite(counts) ? std::fmod(counts, 4294967296.0) : 0.0)));
  // Active current, N2 with 2^14 = DRV.IPEAK [§17.4]: acceleration and friction against the peak.
  double current = 0.0;
  if (control_ != Control::Coast) {
    current = blocked_ && v_cmd_ != 0.0 ? std::copysign(1.0, v_cmd_)
                                        : acc_ / config_.acceleration_at_peak_current_rps2 + config_.friction_per_rps * vel_;
  }
  actuals_.itist_glatt = static_cast<std::int16_t>(std::lround(std::clamp(current, -2.0, 1.99) * kCurrentFullScale));
  actuals_.aktsatz = aktsatz_;
  actuals_.xist_error =
      static_cast<std::int16_t>(std::clamp(std::round((demand_pos_ - pos_) * cpr()), -32768.0, 32767.0));
  // DRV.MOTIONSTAT's low word [§12.1 signal 105, §9.3]: bit 0 task active, bits 1 and 2 homing
  // done, bit 11 target reached [sim: the bits the digest names].
  actuals_.drive_motion_status = static_cast<std::uint16_t>((task_.has_value() ? 0x0001U : 0U) | (homed_ ? 0x0006U : 0U) |
                                                            (target_reached_ ? 0x0800U : 0U));
  actuals_.drive_inputs = 0;
}

}  // namespace drivegate::profidrive::sim
