#pragma once
// The master side of CiA 402 for one axis (DESIGN.md §4): device control, mode handshakes, faults,
// parameter access and feedback, over ObjectAccess so that it runs the same on CANopen and EtherCAT.
//
// Command slots: a device-control command (enable, disable, quick_stop, fault_reset), a motion
// command (set_mode, move, velocity, torque, home, stop) and a halt command (halt, resume) can be in
// flight at the same time. A newer command of the same kind supersedes the older one ("superseded
// by a newer move command"); a newer conflicting one aborts it ("aborted by a stop command"). Disable and
// quick stop abort everything. A new motion command clears halt (it implies resume). Acyclic
// requests of a command that ends early are cancelled (ObjectAccess::cancel).
//
// Safe holds: when an enable walk starts, and on disable, quick stop, fault and link loss, the
// motion targets in the cyclic image are reset (60FFh/6071h/6042h = 0; 607Ah in csp and 60C1h:1 in
// ip = actual position), so that a later bare enable does not resume an old motion.
//
// Nothing here allocates, locks or blocks: all state is inline, texts are FixedString.
#include <array>
#include <cstdint>
#include <span>

#include "core/axis_controller.hpp"
#include "core/command_slot.hpp"
#include "profiles/cia402/error_codes.hpp"
#include "profiles/cia402/master_settings.hpp"
#include "profiles/cia402/object_access.hpp"
#include "profiles/cia402/state_machine.hpp"
#include "profiles/cia402/write_batch.hpp"

namespace drivegate::cia402 {

class Cia402Master final : public core::AxisController {
 public:
  static constexpr std::size_t kMaxParameterRequests = 8;

  Cia402Master(ObjectAccess& io, const MasterSettings& settings) noexcept;

  // Vendor fault texts from the device profile, looked up before the standard table. The span's
  // data must outlive the master.
  void set_fault_table(std::span<const FaultText> table) noexcept { vendor_faults_ = table; }

  core::Admission submit(const core::DriveCommand& cmd, core::TimePoint now, core::ControllerSink& sink) noexcept override;
  void setpoint(const core::DriveSetpoint& sp, core::TimePoint now) noexcept override;
  core::Admission parameter(const core::ParamRequest& req, core::TimePoint now) noexcept override;
  void update(core::TimePoint now, core::ControllerSink& sink) noexcept override;
  void link_lost(core::TimePoint now, core::ControllerSink& sink) noexcept override;
  [[nodiscard]] const core::DriveFeedback& feedback() const noexcept override { return fb_; }

  // Set-points that arrived for an object that is not in the cyclic image (dropped, counted).
  [[nodiscard]] std::uint64_t dropped_setpoints() const noexcept { return dropped_setpoints_; }

 private:
  using Slot = core::CommandSlot;
  enum class Phase : std::uint8_t {
    SwitchMode,    // 6060h written, waiting for 6061h
    Stage,         // object writes that must land before the handshake
    WaitAckClear,  // pp/hm: bit 4 low, waiting for SW bit 12 to drop before the next rising edge
    WaitAck,       // pp: bit 4 high, waiting for set-point acknowledge
    WaitDone,      // waiting for the mode's completion condition
  };
  struct Motion {
    Slot slot;
    core::DriveCommand cmd{};
    core::Mode mode = core::Mode::None;
    Phase phase = Phase::Stage;
    core::TimePoint since{};
    std::uint64_t settle_until = 0;  // cycle from which the status counts for completion
  };
  struct ModeRequest {
    std::int8_t value = 0;
    RequestId write = kNoRequest;
    bool written = false;
  };
  // A parameter request from admission to reply; an upload lands in req.data (unused by a read).
  struct PendingParam {
    bool active = false;
    core::ParamRequest req{};
    RequestId request = kNoRequest;
  };

  // The objects of the cyclic image the profile reads and writes in its cycle, resolved once per
  // mapping of the adapter (ObjectAccess::mapping_generation()), so that an access is no lookup by
  // object id. !mapped(): the object is not in the image.
  struct ImageRefs {
    std::uint32_t generation = 0;
    ImageRef statusword, display, modes, controlword, error_code;
    ImageRef position_actual, velocity_actual, vl_velocity_actual, torque_actual;
    ImageRef target_position, target_velocity, target_torque, vl_target_velocity, ip_target;
  };

  // cia402_master.cpp: image references, admission and command bookkeeping.
  void resolve_refs() noexcept;
  // Resolves the references again when the adapter's mapping changed (a reconfiguration): at the
  // start of every entry point that touches the image.
  void follow_mapping() noexcept {
    if (io_.mapping_generation() != refs_.generation) resolve_refs();
  }
  core::Admission admit_motion(const core::DriveCommand& cmd, core::Mode mode) const noexcept;
  [[nodiscard]] core::Mode motion_mode(const core::DriveCommand& cmd) const noexcept;
  [[nodiscard]] bool at_standstill() const noexcept;
  [[nodiscard]] bool profile_owns(ObjectId id) const noexcept;
  void start_motion(const core::DriveCommand& cmd, core::Mode mode, core::TimePoint now) noexcept;

  // cia402_master_update.cpp: inputs, device control, events, outputs, feedback.
  void read_inputs() noexcept;
  void track_state(core::TimePoint now, core::ControllerSink& sink) noexcept;
  void track_fault_code(core::ControllerSink& sink) noexcept;
  void supervise_control(core::TimePoint now, core::ControllerSink& sink) noexcept;
  void run_device(core::TimePoint now, core::ControllerSink& sink) noexcept;
  void run_parameters(core::ControllerSink& sink) noexcept;
  void write_outputs() noexcept;
  void fill_feedback() noexcept;

  // cia402_master_modes.cpp: mode switch, handshakes, cyclic holds.
  void run_motion(core::TimePoint now, core::ControllerSink& sink) noexcept;
  bool run_mode_switch(core::TimePoint now, core::ControllerSink& sink) noexcept;
  void enter_stage(core::TimePoint now) noexcept;
  void begin_handshake(core::TimePoint now, core::ControllerSink& sink) noexcept;
  void run_handshake(core::TimePoint now, core::ControllerSink& sink) noexcept;
  [[nodiscard]] bool motion_done() const noexcept;
  void finish_motion(core::ControllerSink& sink) noexcept;
  void fail_motion(std::string_view reason, core::ControllerSink& sink) noexcept;
  void abandon_motion_requests() noexcept;
  void write_safe_holds() noexcept;
  void set_velocity_target(std::int64_t value) noexcept;
  void run_halt(core::ControllerSink& sink) noexcept;
  void hold_cyclic() noexcept;
  void restart_cyclic_hold() noexcept;

  ObjectAccess& io_;
  ImageRefs refs_;
  MasterSettings settings_;
  DeviceControl device_;
  std::span<const FaultText> vendor_faults_;

  // Inputs as last seen.
  bool status_valid_ = false;
  std::uint16_t statusword_ = 0;
  RequestId status_read_ = kNoRequest;  // 6041h poll when it is not mapped
  core::AxisState state_ = core::AxisState::Unknown;
  std::int8_t display_mode_ = 0;  // 6061h
  bool display_known_ = false;
  RequestId display_read_ = kNoRequest;
  std::uint64_t cycle_ = 0;

  // Commands in flight.
  Slot device_slot_;
  Motion motion_;
  Slot halt_slot_;
  std::uint64_t halt_settle_until_ = 0;
  ModeRequest mode_req_;
  bool mode_switching_ = false;
  core::TimePoint mode_since_{};
  WriteBatch batch_;

  // Outputs besides device control.
  std::int8_t mode_out_ = 0;
  bool mode_out_valid_ = false;
  bool bit4_ = false;          // pp new set-point, hm homing start, ip enable interpolation
  std::uint16_t pp_bits_ = 0;  // pp change immediately / relative for the set-point in flight
  bool halt_ = false;
  bool vl_armed_ = false;  // vl run bits 4..6: only once a velocity command was staged since enable
  std::uint16_t last_cw_ = 0;
  RequestId cw_write_ = kNoRequest;  // 6040h write when it is not mapped
  std::uint16_t cw_inflight_ = 0;
  std::uint16_t cw_written_ = 0;
  bool cw_written_valid_ = false;

  // Cyclic modes: what the drive gets before the first set-point arrives.
  bool cyclic_has_setpoint_ = false;
  bool cyclic_hold_frozen_ = false;
  bool ip_target_valid_ = false;  // 60C1h:1 holds the actual position or a client set-point
  std::int32_t hold_position_ = 0;
  std::uint64_t dropped_setpoints_ = 0;

  // pv/vl velocity target the drive was last given (standstill check without 606Ch).
  std::int64_t velocity_target_ = 0;
  std::uint64_t velocity_settle_until_ = 0;

  // Faults and flags.
  bool fault_event_pending_ = false;
  RequestId fault_read_ = kNoRequest;
  bool homed_ = false;
  bool last_warning_ = false;
  bool last_remote_ = true;
  bool flags_seen_ = false;  // warning/remote edges are reported from the second status on

  // Control supervision: since when the drive has stayed in a state its controlword tells it to
  // leave (towards less power); reported once per loss, until the link is lost and comes back.
  bool follow_pending_ = false;
  core::AxisState follow_state_ = core::AxisState::Unknown;
  std::uint16_t follow_cw_ = 0;
  core::TimePoint follow_since_{};
  bool control_lost_ = false;

  std::array<PendingParam, kMaxParameterRequests> params_{};
  // How many of params_ are active: the cycle skips the array (4 KiB a request) while none is.
  std::size_t params_active_ = 0;
  core::DriveFeedback fb_{};
};

}  // namespace drivegate::cia402
