#pragma once
// A simulated CiA 402 drive (drive side): object dictionary, device control state machine, the
// operating modes pp/vl/pv/tq/hm/ip/csp/csv/cst, a rigid-inertia motor/load model, limit switches
// and fault injection. Bus simulators (the in-process sim bus, the CANopen and EtherCAT slave
// simulators) wrap it; the master-side profile is tested against it.
//
// Behaviour follows CiA 402 as digested in akd-canopen-part2-ds402.md §1, §3, §5-§10 and
// nord-sk500p-ds402.md §3, §5, §6. Choices where the standard leaves room are documented at the
// member that implements them. step() is cycle-thread safe: no allocation, no locks, no I/O.
//
// Units: positions in position units (config.position_units_per_rev per motor rev); velocity
// objects (6081h, 606Ch, 60FFh, 6099h, ...) in velocity units (config.velocity_units_per_rps per
// motor rev/s; by default position units per second); accelerations (6083h-6085h, 609Ah) in velocity
// units per second; vl objects (6042h-6044h, 6048h/6049h) in config.vl_units_per_rps (rpm by
// default); torque in per mille of rated torque.
#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "core/axis_types.hpp"
#include "core/clock.hpp"
#include "profiles/cia402/objects.hpp"
#include "profiles/cia402/sim/object_dictionary.hpp"

namespace drivegate::cia402::sim {

// The drive runs the same CiA 402 states the master reports (never Unknown).
using DriveState = core::AxisState;

struct DriveIdentity {  // 1018h:1..4
  std::uint32_t vendor_id = 0;
  std::uint32_t product_code = 0;
  std::uint32_t revision = 0;
  std::uint32_t serial = 0;
};

struct DriveModelConfig {
  std::vector<std::int8_t> supported_modes{1, 2, 3, 4, 6, 7, 8, 9, 10};  // 6060h values
  std::vector<std::int8_t> homing_methods{1, 2, 17, 18, 33, 34, 35, 37};  // 6098h values that run
  DriveIdentity identity;
  std::uint32_t device_type = 0x00020192;  // 1000h: CiA 402 servo drive
  std::int8_t initial_mode = 0;            // 6060h after power-up

  double position_units_per_rev = 10000.0;
  double velocity_units_per_rps = 0.0;  // 0: position units per second
  double vl_units_per_rps = 60.0;       // vl objects in rpm
  double max_velocity_rps = 50.0;       // motor speed limit
  double velocity_time_constant_s = 0.002;  // first-order velocity loop
  double torque_acceleration_rps2 = 1000.0;  // motor+load acceleration at rated torque
  double viscous_friction = 0.002;           // friction torque, fraction of rated per rev/s

  std::uint32_t following_error_window = 10000;  // 6065h default (position units)
  std::uint16_t following_error_timeout_ms = 10;  // 6066h default
  std::uint32_t position_window = 10;            // 6067h default
  std::uint16_t velocity_window = 100;           // 606Dh default (velocity units)

  // Switches at physical motor positions (position units at power-up, before any homing). The
  // home switch is active at and above its position, a limit switch at and beyond its own.
  double start_position = 0.0;  // where the motor stands at construction (position units)
  std::optional<double> home_switch_position;
  std::optional<double> negative_limit_position;
  std::optional<double> positive_limit_position;
  double index_pulse_offset = 0.0;  // index pulses at offset + k * position_units_per_rev

  std::int16_t quick_stop_option = 2;       // 605Ah default
  bool keep_position_on_power_cycle = true;  // absolute encoder (true) or incremental (false)
};

// A fault appearing (error_code != 0) or all faults clearing (error_code == 0), for a bus simulator
// to turn into an EMCY frame.
struct EmcyEvent {
  std::uint16_t error_code = 0;
  std::uint8_t error_register = 0;
};

// Error codes the model raises itself.
namespace fault_code {
inline constexpr std::uint16_t kFollowingError = 0x8611;
}  // namespace fault_code

class DriveModel {
 public:
  explicit DriveModel(DriveModelConfig config);

  // One simulation step of dt (> 0): one state-machine transition at most, the active mode, the
  // motor model, then 6041h and the actual values.
  void step(core::Duration dt) noexcept;

  // --- Master access (SDO or PDO) with the drive's own checks on top of the dictionary's. ---
  [[nodiscard]] ReadResult read_object(ObjectId id) const noexcept;
  std::uint32_t write_object(ObjectId id, std::int64_t value) noexcept;
  [[nodiscard]] const ObjectDictionary& dictionary() const noexcept { return od_; }

  // --- Observation (tests, simulators) ---
  [[nodiscard]] DriveState state() const noexcept { return state_; }
  [[nodiscard]] std::uint16_t statusword() const noexcept;
  [[nodiscard]] double position() const noexcept { return pos_; }  // position units
  [[nodiscard]] double velocity() const noexcept { return vel_; }  // position units per second
  [[nodiscard]] double torque() const noexcept { return torque_; }  // per mille of rated
  [[nodiscard]] std::int8_t active_mode() const noexcept { return mode_; }
  [[nodiscard]] const DriveModelConfig& config() const noexcept { return config_; }

  // --- Fault injection and environment ---
  // Raises a fault whose cause persists: Fault reaction active, then Fault, 603Fh = code, 1001h
  // bits per the code's class. A fault reset succeeds only after clear_fault_cause(). Faults the
  // model raises itself (following error) have no lasting cause and reset at once.
  void inject_fault(std::uint16_t error_code) noexcept;
  void clear_fault_cause() noexcept;
  void set_warning(bool on) noexcept { warning_ = on; }
  // Power off and on: dictionary back to defaults, Not ready to switch on, then Switch on disabled
  // (or straight into the fault again while an injected cause persists). The motor stops; the
  // reported position keeps or restarts at 0 per config.keep_position_on_power_cycle.
  void power_cycle() noexcept;
  // Hardware enable low: no leaving Switch on disabled; from any powered state the drive drops to
  // Switch on disabled without a fault (AKD digest §3.7 point 5).
  void set_hardware_enable(bool on) noexcept { hardware_enable_ = on; }
  // A jammed load: the motor cannot move (provokes following errors).
  void set_motor_blocked(bool on) noexcept { blocked_ = on; }
  void set_limit_switch_positions(std::optional<double> negative, std::optional<double> positive) noexcept;
  void set_home_switch_position(std::optional<double> position) noexcept { config_.home_switch_position = position; }
  // Pending EMCY events, oldest first; nullopt when none. A full queue drops the newest event and
  // counts it.
  std::optional<EmcyEvent> take_pending_emcy() noexcept;
  [[nodiscard]] std::uint32_t emcy_overflows() const noexcept { return emcy_overflows_; }

 private:
  enum class Control : std::uint8_t { Coast, Position, Velocity, Torque };
  enum class OeStop : std::uint8_t { None, DisableOperation, Shutdown };
  enum class HomingPhase : std::uint8_t { Idle, Search, BackOff, Index, MoveToHome, Attained, Error, Interrupted };

  struct Setpoint {  // one pp job, taken at the new-set-point edge
    double target = 0;
    double velocity = 0;
    double acceleration = 0;
    double deceleration = 0;
  };

  struct ModeBits {  // what the active mode reports in 6041h
    bool target_reached = false;
    bool internal_limit = false;
    bool bit12 = false;
    bool bit13 = false;
  };

  void populate_dictionary();
  [[nodiscard]] std::int64_t od(ObjectDef def) const noexcept;

  // State machine (drive_model.cpp).
  void update_state(std::uint16_t cw) noexcept;
  void enter_state(DriveState s) noexcept;
  void raise_fault(std::uint16_t code) noexcept;
  void push_emcy(std::uint16_t code) noexcept;
  [[nodiscard]] bool standstill() const noexcept;
  void publish() noexcept;

  // Motion (drive_motion.cpp).
  void run_motion(std::uint16_t cw, double dt) noexcept;
  void run_mode(std::uint16_t cw, double dt) noexcept;
  void stop_ramp(double dec, double dt) noexcept;
  void hold() noexcept;
  void apply_limit_switches() noexcept;
  void motor_update(double dt) noexcept;
  void check_following_error(double dt) noexcept;
  void change_mode(std::int8_t mode) noexcept;
  [[nodiscard]] double halt_deceleration() const noexcept;
  [[nodiscard]] double quick_stop_deceleration(std::int64_t option) const noexcept;

  // Modes (drive_modes.cpp).
  void run_pp(std::uint16_t cw, double dt) noexcept;
  void run_pv(double dt) noexcept;
  void run_vl(std::uint16_t cw, double dt) noexcept;
  void run_tq(double dt) noexcept;
  void run_ip(std::uint16_t cw, double dt) noexcept;
  void run_csp(double dt) noexcept;
  void run_csv() noexcept;
  void run_cst() noexcept;
  void pp_accept(std::uint16_t cw) noexcept;
  bool window_reached(bool inside, std::int64_t time_ms, double dt) noexcept;
  [[nodiscard]] double mode_deceleration() const noexcept;
  [[nodiscard]] double vl_rate(ObjectDef delta_speed, ObjectDef delta_time) const noexcept;

  // Homing (drive_homing.cpp).
  void run_homing(std::uint16_t cw, double dt) noexcept;
  void start_homing() noexcept;
  void homing_event(double physical_home) noexcept;
  void homing_fail() noexcept;

  // Units.
  [[nodiscard]] double vel_from_od(std::int64_t v) const noexcept { return static_cast<double>(v) / vel_scale_; }
  [[nodiscard]] double vel_to_od(double v) const noexcept { return v * vel_scale_; }
  [[nodiscard]] double physical(double reported) const noexcept { return reported - coord_offset_; }
  [[nodiscard]] bool negative_limit_active() const noexcept;
  [[nodiscard]] bool positive_limit_active() const noexcept;
  [[nodiscard]] bool home_switch_active() const noexcept;
  [[nodiscard]] bool mode_supported(std::int64_t mode) const noexcept;
  [[nodiscard]] double max_velocity() const noexcept { return config_.max_velocity_rps * config_.position_units_per_rev; }

  DriveModelConfig config_;
  ObjectDictionary od_;
  double vel_scale_ = 1.0;  // velocity units per (position unit / s)
  double vl_scale_ = 1.0;   // vl units per (position unit / s)

  DriveState state_ = DriveState::NotReadyToSwitchOn;
  std::uint16_t prev_cw_ = 0;
  bool hardware_enable_ = true;
  bool blocked_ = false;
  bool warning_ = false;
  bool fault_cause_active_ = false;
  std::uint16_t pending_fault_ = 0;  // raised outside step(), taken at the next step
  std::uint16_t fault_code_ = 0;
  std::uint16_t cause_code_ = 0;  // the injected fault whose cause persists
  OeStop oe_stop_ = OeStop::None;

  // Motor and demand (reported coordinates: physical + coord_offset_).
  double pos_ = 0;
  double vel_ = 0;
  double torque_ = 0;
  double demand_pos_ = 0;
  double demand_vel_ = 0;
  double torque_demand_ = 0;
  double coord_offset_ = 0;
  Control control_ = Control::Coast;
  Control prev_control_ = Control::Coast;
  bool limit_blocks_positive_ = false;
  bool limit_blocks_negative_ = false;
  double following_error_time_ = 0;
  bool following_error_ = false;
  ModeBits bits_;
  double window_time_ = 0;  // time inside the position/velocity window

  std::int8_t mode_ = 0;
  // pp
  bool pp_moving_ = false;
  bool pp_buffered_valid_ = false;
  bool pp_ack_ = false;
  Setpoint pp_active_;
  Setpoint pp_buffered_;
  double pp_last_target_ = 0;
  // vl
  double vl_output_ = 0;
  // hm
  HomingPhase homing_ = HomingPhase::Idle;
  double homing_dir_ = 1;
  std::int8_t homing_method_ = 0;
  double homing_prev_position_ = 0;  // physical, for index pulse crossings

  static constexpr std::size_t kEmcyCapacity = 8;
  std::array<EmcyEvent, kEmcyCapacity> emcy_{};
  std::size_t emcy_head_ = 0;
  std::size_t emcy_count_ = 0;
  std::uint32_t emcy_overflows_ = 0;
};

}  // namespace drivegate::cia402::sim
