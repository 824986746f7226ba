#pragma once
// The controller side of PROFIdrive for one axis (DESIGN.md §4) [akd-profinet-profidrive.md §24
// steps 9-12]: the general state machine through STW1/ZSW1, speed mode (application class 1),
// MDI, program mode, homing and real-time jog (application class 3), feedback from the actual
// telegram, the fault buffer and parameter access over record 47. Bus-independent: it sees the
// cyclic images through a TelegramPort and the acyclic channel through a ParamChannel.
//
// The telegram decides what the axis can do (README.md, "The master"): NSOLL_A gives speed mode,
// SATZANW gives position mode with program mode (traversing blocks) and homing, the MDI signals
// add MDI moves and real-time jog. A command the telegram cannot carry is refused in words.
//
// Command slots as in the CiA 402 master: a device command (enable, disable, quick_stop,
// fault_reset), a motion command (set_mode, move, velocity, home, run_block, stop) and a halt
// command (halt, resume) can be in flight at once; a newer one of the same slot supersedes the
// older one, disable and quick stop abort everything, a fault or a lost telegram fails what is in
// flight. Every command gets exactly one completed() or failed().
//
// Safety: until a client enables the axis, and again after a fault, a drive that left S4 on its
// own, a lost or stale actual telegram or link_lost(), the master sends STW1 0x0402 (OFF3: a drive
// still in S4 quick-stops and stays in S1) with zero set-points and no task bits.
//
// Nothing here allocates, locks or blocks: all state is inline, texts are FixedString.
#include <array>
#include <cstdint>
#include <span>
#include <string_view>

#include "core/axis_controller.hpp"
#include "core/command_slot.hpp"
#include "profiles/profidrive/fault_buffer.hpp"
#include "profiles/profidrive/master_settings.hpp"
#include "profiles/profidrive/param_access.hpp"
#include "profiles/profidrive/position_velocity.hpp"
#include "profiles/profidrive/param_channel.hpp"
#include "profiles/profidrive/state_machine.hpp"
#include "profiles/profidrive/telegram.hpp"
#include "profiles/profidrive/telegram_port.hpp"

namespace drivegate::profidrive {

// A fault number the drive reports in PNU 947 and its text (from the device profile).
struct FaultText {
  std::uint16_t number = 0;
  std::string_view text;  // must outlive the master (static data)
};

// What a telegram lets an axis do.
struct TelegramCapabilities {
  bool speed = false;        // NSOLL_A: application class 1 speed mode
  bool position = false;     // SATZANW: application class 3, program mode and homing
  bool mdi = false;          // SATZANW + MDI_TARPOS/VELOCITY/ACC/DEC/MOD: MDI moves, real-time jog
  bool home_dist = false;    // HOME_DIST (352, 353)
  bool home_mode = false;    // HOME_MODE (353)
  bool position_actual = false;  // XIST_A
};
TelegramCapabilities capabilities_of(const TelegramLayout& layout) noexcept;

class ProfidriveMaster final : public core::AxisController {
 public:
  static constexpr std::size_t kMaxParameterRequests = 4;

  // `layout` is the telegram the bus connected with (standard_layout() or free_layout()).
  ProfidriveMaster(TelegramPort& port, ParamChannel& channel, const TelegramLayout& layout,
                   const MasterSettings& settings) noexcept;

  // Texts for fault numbers, looked up when the fault buffer was read. The span's data must
  // outlive the master.
  void set_fault_table(std::span<const FaultText> table) noexcept { fault_table_ = table; }

  core::Admission submit(const core::DriveCommand& cmd, core::TimePoint now, core::ControllerSink& sink) noexcept override;
  void setpoint(const core::DriveSetpoint& sp, core::TimePoint now) noexcept override;
  core::Admission parameter(const core::ParamRequest& req, core::TimePoint now) noexcept override;
  void update(core::TimePoint now, core::ControllerSink& sink) noexcept override;
  void link_lost(core::TimePoint now, core::ControllerSink& sink) noexcept override;
  [[nodiscard]] const core::DriveFeedback& feedback() const noexcept override { return fb_; }

  [[nodiscard]] const TelegramCapabilities& capabilities() const noexcept { return caps_; }
  // Set-points that arrived although no PROFIdrive mode takes streaming set-points (dropped).
  [[nodiscard]] std::uint64_t dropped_setpoints() const noexcept { return dropped_setpoints_; }
  // Telegram images of the wrong length: an actual one counts as no telegram, a setpoint one is
  // not written (the bus and the master disagree about the telegram).
  [[nodiscard]] std::uint64_t bad_telegrams() const noexcept { return bad_telegrams_; }

 private:
  using Slot = core::CommandSlot;
  enum class DeviceGoal : std::uint8_t { Hold, Enable, Disable, QuickStop, FaultReset };
  // What the motion slot runs on the drive.
  enum class Task : std::uint8_t {
    None,
    Speed,    // AC1: NSOLL_A with bits 4..6
    Mdi,      // AC3: SATZANW bit 15, MDI signals, bit 6 edge / ZSW1 bit 12
    Program,  // AC3: SATZANW = block, bit 6 edge
    Homing,   // AC3: STW1 bit 11
    Jog,      // AC3: real-time jog, STW1 bits 12/13 with the MDI signals
    Stop,     // standstill in the present task's way
  };
  enum class Phase : std::uint8_t {
    AckClear,  // bit 6 low, waiting for ZSW1 bit 12 to drop (the previous task's acknowledge)
    Prime,     // bits 4, 5 with the task's signals, bit 6 still low: the next cycle is the edge
    WaitAck,   // bit 6 high (homing: bit 11), waiting for the drive to take the task
    WaitDone,  // waiting for the task's completion
  };
  struct Motion {
    Slot slot;
    core::DriveCommand cmd{};
    Task task = Task::None;
    Phase phase = Phase::WaitDone;
    core::TimePoint since{};
    std::uint64_t settle_until = 0;  // in fresh telegrams (telegrams_)
    std::uint64_t primed_in = 0;     // the cycle whose outputs carried the task before its edge
  };
  struct PendingParam {
    bool active = false;
    core::ParamRequest req{};
  };
  enum class ChannelUser : std::uint8_t { None, FaultBuffer, Client };

  // profidrive_master.cpp: admission, bookkeeping, set-points, parameters, link loss.
  [[nodiscard]] core::Mode initial_mode() const noexcept;
  [[nodiscard]] core::Mode mode_of(const core::DriveCommand& cmd) const noexcept;
  [[nodiscard]] const char* missing_for(core::Mode mode) const noexcept;
  [[nodiscard]] core::Admission admit_motion(const core::DriveCommand& cmd, core::Mode mode) const noexcept;
  static const char* check_ramps(const core::DriveCommand& cmd) noexcept;
  [[nodiscard]] bool gateway_owns(std::uint16_t pnu) const noexcept;
  void start_device(DeviceGoal goal, const core::DriveCommand& cmd, core::TimePoint now) noexcept;
  void drop_drive(std::string_view reason, core::ControllerSink& sink) noexcept;
  void safe_outputs() noexcept;

  // profidrive_master_update.cpp: inputs, state and events, device control, outputs, feedback.
  bool read_inputs(core::TimePoint now, core::ControllerSink& sink) noexcept;
  void track_state(core::ControllerSink& sink) noexcept;
  void run_device(core::TimePoint now, core::ControllerSink& sink) noexcept;
  void supervise_control(core::TimePoint now, core::ControllerSink& sink) noexcept;
  void write_outputs() noexcept;
  [[nodiscard]] bool at_standstill() const noexcept;
  void fill_feedback() noexcept;

  // profidrive_master_modes.cpp: the task handshakes.
  void start_motion(const core::DriveCommand& cmd, core::Mode mode, core::TimePoint now) noexcept;
  void load_task() noexcept;
  [[nodiscard]] std::uint16_t task_bits() const noexcept;
  void run_motion(core::TimePoint now, core::ControllerSink& sink) noexcept;
  [[nodiscard]] bool motion_done() const noexcept;
  void end_motion() noexcept;
  void fail_motion(std::string_view reason, core::ControllerSink& sink) noexcept;

  // profidrive_master_params.cpp: the record-47 channel (fault buffer first, then clients).
  void run_channel(core::TimePoint now, core::ControllerSink& sink) noexcept;
  bool send_read(const ParamAddress& address, core::TimePoint now) noexcept;
  bool send_change(const ParamChange& change, core::TimePoint now) noexcept;
  bool send(std::uint8_t reference, RequestId id, const ParamAddress& address, std::size_t size,
            core::TimePoint now) noexcept;
  std::uint8_t next_reference() noexcept;
  void on_response(std::span<const std::uint8_t> bytes, core::ControllerSink& sink) noexcept;
  void on_failure(std::string_view why, std::uint16_t error_number, core::ControllerSink& sink) noexcept;
  void client_reply(PendingParam& p, const ValueBlock* block, std::string_view error, std::uint16_t error_number,
                    core::ControllerSink& sink) noexcept;
  void finish_fault_read(core::ControllerSink& sink) noexcept;
  void fault_read_failed(std::string_view why, core::ControllerSink& sink) noexcept;
  void cancel_fault_read() noexcept;
  void cancel_channel() noexcept;
  [[nodiscard]] std::string_view fault_text(std::uint16_t number) const noexcept;

  TelegramPort& port_;
  ParamChannel& channel_;
  TelegramLayout layout_;
  TelegramCapabilities caps_;
  MasterSettings settings_;
  std::span<const FaultText> fault_table_;
  std::uint64_t cycle_ = 0;

  // Inputs as last seen.
  bool actual_valid_ = false;
  Actuals actual_{};
  core::TimePoint fresh_at_{};
  std::uint64_t telegrams_ = 0;  // fresh actual telegrams decoded
  PositionVelocity derived_velocity_;  // from XIST_A, where the telegram carries no NIST_A
  std::int32_t velocity_ = 0;          // native units, from NIST_A or derived
  // A fault reset keeps STW1 bit 7 low until telegrams_ reaches this (the drive saw it low), then
  // high until the drive leaves its fault.
  std::uint64_t acknowledge_from_ = 0;
  DriveState state_{};
  bool warning_ = false;
  bool control_requested_ = true;  // ZSW1 bit 9 as last seen

  // Control supervision: since when the drive shows more power than the STW1 sent allows.
  bool follow_pending_ = false;
  core::TimePoint follow_since_{};
  bool control_lost_ = false;  // reported; again only after the drive was dropped
  std::uint64_t bad_telegrams_ = 0;

  // Device control.
  Slot device_slot_;
  DeviceGoal goal_ = DeviceGoal::Hold;
  std::uint16_t hold_stw1_ = stw1_word::kQuickStop;   // what Hold sends
  std::uint16_t device_stw1_ = stw1_word::kQuickStop;  // this cycle's state-machine word
  std::uint16_t stw1_ = stw1_word::kQuickStop;  // the word sent last cycle
  DriveState step_state_{};
  core::TimePoint step_since_{};
  core::Text failure_;

  // Motion.
  Motion motion_;
  core::Mode mode_ = core::Mode::None;  // what feedback reports: the class's mode, or the last task's
  Slot halt_slot_;
  bool halt_ = false;
  std::uint64_t halt_settle_until_ = 0;
  Setpoints out_{};  // signals besides STW1, as the task in flight set them
  std::uint64_t dropped_setpoints_ = 0;

  // Faults and the record-47 channel.
  bool fault_read_wanted_ = false;
  FaultBufferReader fault_reader_{};
  ChannelUser channel_user_ = ChannelUser::None;
  std::size_t channel_client_ = 0;
  ParamTicket ticket_ = kNoTicket;
  core::TimePoint ticket_since_{};
  std::uint8_t reference_ = 0;
  ParamRequest expected_{};  // what the request in flight asked, for check_response
  std::array<std::uint8_t, kMaxParamRecord> request_buf_{};
  std::array<PendingParam, kMaxParameterRequests> params_{};
  std::size_t params_active_ = 0;

  core::DriveFeedback fb_{};
};

}  // namespace drivegate::profidrive
