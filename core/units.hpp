#pragma once
// Conversion between user units and drive units, in one place (DESIGN.md §4).
//
// User side (per axis, from the configuration): positions in a user unit (mm, deg, rev, ...),
// velocities in user units per second, accelerations in user units per second squared, torque in
// percent of the motor's rated torque, or in Nm when the axis gives its rated torque.
// Mechanics: `feed` user units per load revolution and `gear_ratio` motor revolutions per load
// revolution (e.g. a 5 mm ball screw behind a 3:1 gearbox: feed 5, gear_ratio 3).
// Drive side (from the device profile, completed by the axis' encoder resolution): how many drive
// units one motor revolution, one motor rev/s, one motor rev/s^2 and the rated torque are.
#include <cstdint>
#include <optional>

namespace drivegate::core {

struct Mechanics {
  double feed = 1.0;        // user units per load revolution
  double gear_ratio = 1.0;  // motor revolutions per load revolution
  double rated_torque = 0;  // Nm; 0 means torque is given in percent of rated
};

struct NativeUnits {
  double position_per_rev = 1.0;       // drive position units per motor revolution
  double velocity_per_rps = 1.0;       // drive velocity units per motor rev/s
  double acceleration_per_rps2 = 1.0;  // drive acceleration units per motor rev/s^2
  double torque_per_rated = 1000.0;    // drive torque units at 100 % rated torque (CiA 402: per mille)
};

class UnitConverter {
 public:
  UnitConverter() = default;
  UnitConverter(const Mechanics& m, const NativeUnits& n) noexcept;

  // User -> drive, as exact doubles (callers round and range-check with to_int32/to_uint32).
  [[nodiscard]] double position_to_drive(double user) const noexcept { return user * pos_; }
  [[nodiscard]] double velocity_to_drive(double user) const noexcept { return user * vel_; }
  [[nodiscard]] double acceleration_to_drive(double user) const noexcept { return user * acc_; }
  [[nodiscard]] double torque_to_drive(double user) const noexcept { return user * tq_; }

  // Drive -> user.
  [[nodiscard]] double position_to_user(double drive) const noexcept { return drive / pos_; }
  [[nodiscard]] double velocity_to_user(double drive) const noexcept { return drive / vel_; }
  [[nodiscard]] double acceleration_to_user(double drive) const noexcept { return drive / acc_; }
  [[nodiscard]] double torque_to_user(double drive) const noexcept { return drive / tq_; }

  // Drive units per user unit, for the plan printout.
  [[nodiscard]] double position_factor() const noexcept { return pos_; }
  [[nodiscard]] double velocity_factor() const noexcept { return vel_; }
  [[nodiscard]] double acceleration_factor() const noexcept { return acc_; }
  [[nodiscard]] double torque_factor() const noexcept { return tq_; }
  // Torque in Nm (the axis gives its rated torque) rather than percent of rated.
  [[nodiscard]] bool torque_in_nm() const noexcept { return torque_in_nm_; }

 private:
  double pos_ = 1.0;
  double vel_ = 1.0;
  double acc_ = 1.0;
  double tq_ = 1.0;
  bool torque_in_nm_ = false;
};

// Rounded conversions that refuse values the drive's data type cannot hold (instead of wrapping).
std::optional<std::int32_t> to_int32(double v) noexcept;
std::optional<std::uint32_t> to_uint32(double v) noexcept;
std::optional<std::int16_t> to_int16(double v) noexcept;

}  // namespace drivegate::core
