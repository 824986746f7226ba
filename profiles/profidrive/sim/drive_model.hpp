#pragma once
// A simulated PROFIdrive drive with the Kollmorgen AKD PROFINET persona (drive side), bus-independent:
// the PROFINET simulated device hands it the received setpoint telegram image each cycle and sends
// the actual-value image it writes, and routes record 47 (slot 1) to its parameter channel.
//
// Behaviour follows akd-profinet-profidrive.md (cited as §n): the general state machine S1..S5 driven
// by STW1 bits 0..3 with the AKD's rules (bit 10 must be set, fault acknowledge lands in S1, ON must
// go low before switching on again) [§7, §8, §25.17, §25.18]; speed mode (application class 1) with
// the ramp bits [§8.2, §15]; position mode (class 3): program mode, MDI, homing, jog and the AKD's
// real-time jog [§8.3, §16]; the telegrams 1, 7, 9, 350..353, 0 and 400 [§14]; the parameter channel
// with the AKD's PNUs [§5, §11]; the fault buffer PNU 944/947 [§18.2]; F702 when the controller's
// outputs become invalid [§18.3, §18.4]. Choices the digest leaves open are marked [sim] where made.
//
// step() and the record functions are cycle-thread safe: no allocation, no locks, no I/O.
//
// Units inside: motor revolutions, rev/s, rev/s^2. The signals carry the AKD's normalisation
// (scaling.hpp): NSOLL_A/NIST_A 2^15 = 12000 rpm, MDI_VELOCITY 2^32 = 12000 rpm, MDI_ACC/DEC 2^16 =
// 50e6 rpm/s (or PNU 1008), positions 2^(PNU 1002) counts per rev, ITIST_GLATT 2^14 = DRV.IPEAK.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

#include "core/clock.hpp"
#include "profiles/profidrive/fault_buffer.hpp"
#include "profiles/profidrive/param_access.hpp"
#include "profiles/profidrive/scaling.hpp"
#include "profiles/profidrive/telegram.hpp"

namespace drivegate::profidrive::sim {

// AKD fault numbers the model raises itself [§18.3; AKD fault list].
namespace fault_number {
inline constexpr std::uint16_t kCommunicationLost = 702;  // F702 fieldbus communication lost
inline constexpr std::uint16_t kFollowingError = 439;     // F439 following error
}  // namespace fault_number

// The general state machine [§7]; S5 split by what started it.
enum class State : std::uint8_t {
  S1SwitchingOnInhibited,
  S2ReadyForSwitchingOn,
  S3SwitchedOn,
  S4Operation,
  S5RampStop,   // OFF1 in S4: ramps down, then S2
  S5QuickStop,  // OFF3 in S4: quick stop, then S1
  Fault,        // ZSW1 bit 3; an acknowledge edge on STW1 bit 7 leads to S1
};

// DRV.OPMODE / PNU 930 [§11.1, §15, §16.1].
enum class OperatingMode : std::uint8_t { Speed = 1, Position = 2 };

// A stored motion task for program mode (traversing block) [§16.2], in the MDI signals' units
// (MT.P, MT.V_32, MT.ACC, MT.DEC and MT.CNTL through the parameter channel [sim]).
struct MotionTask {
  std::int32_t position = 0;   // counts, 2^(PNU 1002) per rev
  std::uint32_t velocity = 0;  // MDI_VELOCITY units; 0 = task not configured
  std::uint16_t acceleration = 0;  // MDI_ACC units
  std::uint16_t deceleration = 0;
  std::uint16_t control = 0;  // bit 0: 1 = absolute (as MDI_MOD [§12.2])
};
inline constexpr std::size_t kMotionTasks = 16;  // [sim] the AKD has more; enough for tests and demos

// PNU 964 [STD]: manufacturer, device type, firmware version, firmware year, firmware day/month.
struct Identification {
  std::uint16_t manufacturer = 0x0000;
  std::uint16_t device_type = 0;
  std::uint16_t firmware_version = 116;  // firmware 1.16, the digest's edition [§0]
  std::uint16_t firmware_year = 2017;
  std::uint16_t firmware_day_month = 0x0103;
};

struct DriveModelConfig {
  std::uint16_t telegram = 1;  // the module in slot 1 [§4.3]: 0, 1, 7, 9, 350..353, 400
  // Telegram 0: image words per direction, fixed by its module [§13]. Telegram 400: 12 each [§14.9].
  std::uint8_t free_setpoint_words = 12;
  std::uint8_t free_actual_words = 12;
  // Initial PNU 915/916 of telegrams 0 and 400; empty: telegram 400 "similar to telegram 9"
  // [§13, §14.9], telegram 0 STW1 / ZSW1 only.
  std::array<std::uint16_t, kMaxTelegramWords> pnu915{};
  std::array<std::uint16_t, kMaxTelegramWords> pnu916{};
  std::optional<OperatingMode> operating_mode;  // nullopt: speed for 1/350/351, position otherwise

  double max_speed_rps = 100.0;               // motor limit (6000 rpm)
  double speed_acc_rpm_per_s = 60000.0;        // DRV.ACC: speed-mode ramp [§8.2]
  double speed_dec_rpm_per_s = 60000.0;        // DRV.DEC
  double quick_stop_dec_rpm_per_s = 300000.0;  // CS.DEC: OFF3 and fault reaction
  double velocity_time_constant_s = 0.002;     // first-order velocity loop
  // Steady-state speed error of the speed loop under the load, as a fraction (0.03: 3 % slow). The
  // S7 example's drive ran at 158 for a setpoint of 163 [§20.3].
  double speed_droop = 0.0;
  double speed_tolerance_rpm = 1.0;     // ZSW1 bit 8 in speed mode [§9.2] [sim]
  double speed_reached_window_rpm = 1.0;  // ZSW1 bit 10 in speed mode [sim]
  double standstill_rpm = 1.0;            // ZSW1 bit 13 "drive stopped", jog precondition [sim]
  double acceleration_at_peak_current_rps2 = 2000.0;  // for ITIST_GLATT: load inertia against DRV.IPEAK
  double friction_per_rps = 0.002;        // viscous friction, fraction of peak current per rev/s
  double start_position_rev = 0.0;

  std::uint32_t following_error_fault_counts = 65536;   // PL.ERRFTHRESH (F439); 0 = off [§9.3]
  std::uint32_t following_error_warning_counts = 6554;  // PL.ERRWTHRESH (ZSW1 bit 8 in position mode)
  std::uint32_t position_window_counts = 100;            // ZSW1 bit 10 also needs the motor this close [sim]

  // Homing [§16.4]: HOME.MODE 0 takes the current position; 4 searches the home switch [sim: the
  // two modes modelled]. The reference point becomes HOME.P, then the drive moves HOME.DIST.
  std::uint16_t home_mode = 0;
  std::int32_t home_position_counts = 0;  // HOME.P
  std::int32_t home_dist_counts = 0;      // HOME.DIST (telegrams 352/353 carry it cyclically)
  double homing_speed_rps = 5.0;          // HOME.V
  double homing_acc_rps2 = 200.0;         // HOME.ACC/HOME.DEC
  std::optional<double> home_switch_rev;  // physical position of the home switch (active above it)

  std::int16_t jog1 = 1365;  // PNU 1004, NSOLL_A units [sim; units not stated §11.1]: 500 rpm
  std::int16_t jog2 = -1365; // PNU 1005
  std::uint16_t jog_acc_rpm_per_s = 60000 / 10;  // PNU 1006 [sim: rpm/s]
  std::uint16_t jog_dec_rpm_per_s = 60000 / 10;  // PNU 1007

  std::uint32_t fbus_param02 = 1;  // bit 0: F702 on controller RUN -> STOP [§18.4]
  std::uint32_t watchdog_ms = 48;  // PN.TIMEOUTFTHRESH, PNU 3022: what the controller's AR set [§19.3]
  Identification identification;
  std::array<MotionTask, kMotionTasks> motion_tasks{};
};

// What the controller's outputs are worth [§18.3, §18.4]. The PROFINET simulated device sets this
// from its AR: IOPS/data status of the output CR and its watchdog.
enum class Outputs : std::uint8_t {
  Valid,
  ControllerStop,  // provider state STOP (PLC RUN -> STOP) or IOPS bad
  Lost,            // watchdog expired or the AR went away
};

enum class RecordStatus : std::uint8_t {
  Ok,
  WriteLengthError,  // a request shorter than its header or longer than 240 bytes [STD]
  StateConflict,     // a request while the last response was not read yet, or a read with no
                     // response waiting: the PROFINET device answers "state conflict" (B5h) [STD]
  BufferTooSmall,    // the read's buffer cannot hold the response (it stays pending)
};
struct RecordRead {
  RecordStatus status = RecordStatus::Ok;
  std::size_t size = 0;
};

struct StepCounters {
  std::uint64_t steps = 0;
  std::uint64_t wrong_setpoint_length = 0;  // image dropped, the last setpoints stay
  std::uint64_t wrong_actual_length = 0;    // nothing written
  std::uint64_t not_controlled_by_plc = 0;  // STW1 bit 10 low: telegram ignored [§8.1, §25.18]
  std::uint64_t invalid_outputs = 0;        // steps with Outputs != Valid
};

class DriveModel {
 public:
  explicit DriveModel(const DriveModelConfig& config) noexcept;

  // One cycle of dt: takes the setpoint image (the configured telegram's exact size), runs the state
  // machine (one transition at most), the mode and the motor, and writes the actual-value image.
  void step(core::Duration dt, std::span<const std::uint8_t> setpoint_image, std::span<std::uint8_t> actual_image) noexcept;

  // The controller's outputs (see Outputs). Lost raises F702; ControllerStop raises F702 when
  // FBUS.PARAM02 bit 0 is set, otherwise the drive quick-stops to S1 [sim: the digest names no
  // other reaction] and waits there for valid outputs and a new enable.
  void set_outputs(Outputs o) noexcept;
  // The watchdog the controller's AR set (PN.TIMEOUTFTHRESH, PNU 3022 [§19.3]).
  void set_watchdog_ms(std::uint32_t ms) noexcept { config_.watchdog_ms = ms; }

  // Record 47 [§5.1]: the write of a parameter request, then the read of its response.
  RecordStatus write_parameter_record(std::span<const std::uint8_t> request) noexcept;
  RecordRead read_parameter_record(std::span<std::uint8_t> out) noexcept;

  // Fault injection: an AKD fault number into the current fault situation [§18.2]. A persistent
  // cause keeps the fault until clear_fault_causes(); otherwise the next acknowledge clears it.
  void inject_fault(std::uint16_t number, bool persistent = false) noexcept;
  void clear_fault_causes() noexcept { cause_persists_ = false; }
  void set_warning(bool on) noexcept { warning_ = on; }
  void set_motor_blocked(bool on) noexcept { blocked_ = on; }

  // --- Observation (tests, simulators) ---
  [[nodiscard]] State state() const noexcept { return state_; }
  [[nodiscard]] OperatingMode operating_mode() const noexcept { return mode_; }
  [[nodiscard]] std::uint16_t zsw1() const noexcept { return actuals_.zsw1; }
  [[nodiscard]] const Actuals& actuals() const noexcept { return actuals_; }
  [[nodiscard]] const Setpoints& setpoints() const noexcept { return sp_; }
  [[nodiscard]] const TelegramLayout& layout() const noexcept { return layout_; }
  // Why the configured telegram has no layout (an unknown number, a PNU 915/916 list free_layout
  // refuses); every cycle is then a counted drop.
  [[nodiscard]] TelegramError layout_error() const noexcept { return layout_error_; }
  [[nodiscard]] double position_rev() const noexcept { return pos_; }
  [[nodiscard]] double velocity_rps() const noexcept { return vel_; }
  [[nodiscard]] std::uint16_t fault_counter() const noexcept { return fault_counter_; }
  [[nodiscard]] std::span<const std::uint16_t> fault_numbers() const noexcept { return faults_; }
  [[nodiscard]] const StepCounters& counters() const noexcept { return counters_; }
  [[nodiscard]] bool homed() const noexcept { return homed_; }

 private:
  enum class Control : std::uint8_t { Coast, Position, Velocity };
  enum class Homing : std::uint8_t { Idle, Search, MoveToDist, Done, Failed };
  struct Task {
    double target = 0;  // rev
    double velocity = 0, acceleration = 0, deceleration = 0;
  };

  // State machine and faults (drive_model.cpp).
  void update_state(std::uint16_t c) noexcept;
  void enter(State s) noexcept;
  void raise_fault(std::uint16_t number) noexcept;
  void acknowledge_faults() noexcept;
  void publish() noexcept;
  [[nodiscard]] std::uint16_t status_word() const noexcept;
  [[nodiscard]] bool standstill() const noexcept;
  void rebuild_layout() noexcept;

  // Motion (drive_motion.cpp).
  void run_motion(std::uint16_t c, double dt) noexcept;
  void run_speed_mode(std::uint16_t c, double dt) noexcept;
  void run_position_mode(std::uint16_t c, double dt) noexcept;
  bool run_jog(std::uint16_t c, double dt) noexcept;
  void start_task(std::uint16_t c) noexcept;
  void run_homing(std::uint16_t c, double dt) noexcept;
  void ramp_demand(double target_velocity, double acc, double dec, double dt) noexcept;
  // Bounds the motor's integration steps per update (a 1 s update on a 2 ms loop).
  static constexpr int kMaxMotorSteps = 2048;
  void motor_update(double dt, double demand_from) noexcept;
  void check_following_error() noexcept;
  [[nodiscard]] double cpr() const noexcept;  // counts per rev (PNU 1002)
  [[nodiscard]] double acc_full_scale() const noexcept;
  [[nodiscard]] std::optional<Task> task_from(std::int32_t position, std::uint32_t velocity, std::uint16_t acc,
                                               std::uint16_t dec, std::uint16_t control) const noexcept;

  // Parameters (parameters.cpp).
  void process_request(std::span<const std::uint8_t> in) noexcept;
  void reject_request(std::span<const std::uint8_t> in, std::uint16_t error) noexcept;
  std::uint16_t read_parameter(const ParamAddress& a, std::span<std::uint8_t> data, std::uint8_t& fmt) noexcept;
  std::uint16_t change_parameter(const ParamAddress& a, const ValueBlock& values) noexcept;
  [[nodiscard]] std::optional<std::uint32_t> pnu_value(std::uint16_t pnu, std::uint16_t sub) const noexcept;
  std::uint16_t set_pnu(std::uint16_t pnu, std::uint32_t value) noexcept;

  DriveModelConfig config_;
  TelegramLayout layout_;
  TelegramError layout_error_ = TelegramError::None;
  std::array<std::uint16_t, kMaxTelegramWords> pnu915_{};
  std::array<std::uint16_t, kMaxTelegramWords> pnu916_{};
  std::uint8_t free_setpoint_words_ = 0;  // 0 for the fixed telegrams
  std::uint8_t free_actual_words_ = 0;

  State state_ = State::S1SwitchingOnInhibited;
  OperatingMode mode_ = OperatingMode::Speed;
  Outputs outputs_ = Outputs::Valid;
  Setpoints sp_;              // the last setpoints taken
  std::uint16_t prev_stw1_ = 0;
  Actuals actuals_;
  StepCounters counters_;
  bool warning_ = false;
  bool blocked_ = false;

  // Faults [§18.2].
  std::array<std::uint16_t, kFaultBufferEntries> faults_{};
  std::uint16_t fault_counter_ = 0;
  bool situation_open_ = false;  // entries 0..7 belong to a fault situation not yet acknowledged
  bool cause_persists_ = false;

  // Motor and demand, in revolutions.
  double pos_ = 0, vel_ = 0, acc_ = 0, v_cmd_ = 0;
  double demand_pos_ = 0, demand_vel_ = 0;
  double home_offset_ = 0;  // reported - physical
  Control control_ = Control::Coast;
  bool speed_reached_ = false;

  // Position mode.
  std::optional<Task> task_;  // the task being run
  double task_target_ = 0;    // the last task's target, for ZSW1 bit 10
  bool task_ack_ = false;
  bool target_reached_ = false;
  bool homed_ = false;
  Homing homing_ = Homing::Idle;
  double homing_target_ = 0;
  bool jogging_ = false;
  std::uint16_t aktsatz_ = 0;
  std::uint16_t home_mode_ = 0;
  std::int32_t home_dist_ = 0;

  // Parameters.
  std::uint16_t single_turn_bits_ = kDefaultSingleTurnBits;
  std::uint16_t pnu1008_ = 0;  // 0: the default full scale 50e6 rpm/s [sim, §17.3]
  std::array<std::int16_t, 2> jog_{};
  std::uint16_t jog_acc_ = 0, jog_dec_ = 0;
  std::uint32_t pl_errfthresh_ = 0, pl_errwthresh_ = 0;
  std::int32_t home_p_ = 0;
  std::uint32_t fbus_param02_ = 0;
  std::uint32_t posscale_ = 1000;  // PN.POSSCALE [§19.1]
  std::array<MotionTask, kMotionTasks> tasks_{};
  MotionTask mt_edit_;       // MT.P/MT.V_32/MT.ACC/MT.DEC/MT.CNTL before MT.SET
  std::uint8_t mt_num_ = 0;  // MT.NUM
  std::array<std::uint8_t, kMaxParamRecord> response_{};
  std::size_t response_size_ = 0;  // 0: no response waiting
  std::array<std::uint8_t, kMaxParamRecord> values_{};  // value bytes the response blocks point into
};

}  // namespace drivegate::profidrive::sim
