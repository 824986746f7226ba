#include "core/command_validation.hpp"

#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <limits>

namespace drivegate::core {

namespace {

// Appends the supported modes in their short form, e.g. " (this axis supports: pp, pv, hm)".
void append_modes(Text& t, const ModeSet& modes) noexcept {
  char list[64] = "none";
  std::size_t n = 0;
  for (std::size_t i = 1; i < kModeCount; ++i) {
    const auto m = static_cast<Mode>(i);
    if (!modes.contains(m)) continue;
    const auto name = mode_short_name(m);
    if (n + name.size() + 3 > sizeof(list)) break;  // ", " + name + NUL
    if (n != 0) {
      list[n++] = ',';
      list[n++] = ' ';
    }
    for (char c : name) list[n++] = c;
    list[n] = '\0';
  }
  Text out;
  out.format("%s (this axis supports: %s)", t.c_str(), list);
  t = out;
}

__attribute__((format(printf, 1, 2))) Conversion reject(const char* fmt, ...) noexcept {
  Conversion c;
  c.ok = false;
  va_list args;
  va_start(args, fmt);
  c.reason.vformat(fmt, args);
  va_end(args);
  return c;
}

bool finite_all(const Command& c) noexcept {
  return std::isfinite(c.position) && std::isfinite(c.velocity) && std::isfinite(c.acceleration) &&
         std::isfinite(c.deceleration) && std::isfinite(c.torque) && std::isfinite(c.home_offset) &&
         std::isfinite(c.homing_search_velocity) && std::isfinite(c.homing_zero_velocity);
}

// A rate that is 0 takes the default; negative rates are refused; the limit caps nothing, it
// rejects (a silently reduced speed would surprise the user).
struct Rate {
  bool ok;
  double value;
};
Rate resolve_rate(double given, double fallback, double limit) noexcept {
  const double v = given == 0 ? fallback : given;
  if (v < 0) return {false, v};
  if (limit > 0 && v > limit) return {false, v};
  return {true, v};
}

const char* unit_of(const AxisSpec& s) noexcept { return s.user_unit.c_str(); }

// How a value must survive the conversion into a drive object (DESIGN.md §4: commands are
// validated in drive units). Rates, accelerations, torques and homing speeds are Magnitudes: a
// non-zero request that rounds to 0 is refused, because many drives read 0 in those objects as
// "keep the previous value" (a move at 1e-300 mm/s ran at the last profile velocity). Positions
// are Positions: rounding to the drive's resolution is the normal quantisation, only overflow is
// refused.
enum class Kind { Position, Magnitude };

// Converts `user` (in `unit`) by `factor` drive units per user unit into the drive object type T.
// On refusal fills `c` and returns false.
template <typename T>
bool to_drive(double user, double factor, Kind kind, const char* what, const char* unit, T& out,
              Conversion& c) noexcept {
  const double drive = std::round(user * factor);
  constexpr double lo = static_cast<double>(std::numeric_limits<T>::lowest());
  constexpr double hi = static_cast<double>(std::numeric_limits<T>::max());
  if (!std::isfinite(drive) || drive < lo || drive > hi) {
    c.ok = false;
    if (user < 0 && lo == 0)
      c.reason.format("%s %.6g %s must not be negative", what, user, unit);
    else
      c.reason.format("%s %.6g %s does not fit the drive's %d-bit object after unit conversion (range %.6g to %.6g %s)",
                      what, user, unit, static_cast<int>(sizeof(T) * 8), lo / factor, hi / factor, unit);
    return false;
  }
  if (kind == Kind::Magnitude && user != 0 && drive == 0) {
    c.ok = false;
    c.reason.format("%s %.6g %s is 0 in drive units (the drive's resolution is %.6g %s); refused, since 0 would make the "
                    "drive keep its previous value",
                    what, user, unit, 1.0 / factor, unit);
    return false;
  }
  out = static_cast<T>(drive);
  return true;
}

// "mm", "mm/s", "mm/s^2" for the axis.
struct Units {
  char pos[40];
  char vel[44];
  char acc[48];
  explicit Units(const AxisSpec& s) noexcept {
    std::snprintf(pos, sizeof pos, "%s", unit_of(s));
    std::snprintf(vel, sizeof vel, "%s/s", unit_of(s));
    std::snprintf(acc, sizeof acc, "%s/s^2", unit_of(s));
  }
};

}  // namespace

Mode mode_for(CommandKind kind, const ModeSet& modes, Mode requested) noexcept {
  switch (kind) {
    case CommandKind::Move: return Mode::ProfilePosition;
    case CommandKind::Velocity:
      // A drive with both (NORD SK 500P) jogs in the one asked for; pv otherwise.
      if ((requested == Mode::Velocity || requested == Mode::ProfileVelocity) && modes.contains(requested))
        return requested;
      if (modes.contains(Mode::ProfileVelocity)) return Mode::ProfileVelocity;
      if (modes.contains(Mode::Velocity)) return Mode::Velocity;
      return Mode::ProfileVelocity;
    case CommandKind::Torque: return Mode::ProfileTorque;
    case CommandKind::Home: return Mode::Homing;
    case CommandKind::RunBlock: return Mode::TraversingBlock;
    case CommandKind::SetMode: return requested;
    default: return Mode::None;
  }
}

Conversion validate_and_convert(const AxisSpec& spec, const Command& cmd, double relative_base) noexcept {
  if (!finite_all(cmd)) return reject("command for axis '%s' contains NaN or infinity; every number must be finite",
                                      spec.name.c_str());
  Conversion out;
  DriveCommand& d = out.drive;
  d.id = cmd.id;
  d.kind = cmd.kind;
  d.relative = cmd.relative;
  d.immediate = cmd.immediate;
  d.mode = mode_for(cmd.kind, spec.modes, cmd.mode);

  if (d.mode != Mode::None) {
    if (cmd.kind == CommandKind::SetMode && cmd.mode == Mode::None)
      return reject("set_mode needs a mode");
    if (!spec.modes.contains(d.mode)) {
      Conversion c;
      c.reason.format("axis '%s' (device %s) does not support mode %s", spec.name.c_str(), spec.device.c_str(),
                      to_string(d.mode).data());
      append_modes(c.reason, spec.modes);
      return c;
    }
  }

  const auto& lim = spec.limits;
  const auto& u = spec.units;
  const Units un(spec);
  switch (cmd.kind) {
    case CommandKind::Move: {
      const double end = cmd.relative ? relative_base + cmd.position : cmd.position;
      if (lim.has_position_limits() && (end < lim.min_position || end > lim.max_position))
        return reject("move target %.6g %s is outside the limits of axis '%s' [%.6g, %.6g] %s", end, unit_of(spec),
                      spec.name.c_str(), lim.min_position, lim.max_position, unit_of(spec));
      const Rate v = resolve_rate(cmd.velocity, spec.defaults.velocity, lim.max_velocity);
      if (!v.ok) return reject("move velocity %.6g %s/s is not allowed: it must be > 0 and at most %.6g %s/s", v.value,
                               unit_of(spec), lim.max_velocity, unit_of(spec));
      if (v.value <= 0) return reject("move needs a velocity > 0 (the axis has no default velocity configured)");
      const Rate a = resolve_rate(cmd.acceleration, spec.defaults.acceleration, lim.max_acceleration);
      const Rate dc = resolve_rate(cmd.deceleration, spec.defaults.deceleration, lim.max_acceleration);
      if (!a.ok || !dc.ok)
        return reject("acceleration/deceleration must be >= 0 and at most %.6g %s/s^2", lim.max_acceleration,
                      unit_of(spec));
      if (!to_drive(end, u.position_factor(), Kind::Position, "move target", un.pos, d.target_position, out) ||
          !to_drive(v.value, u.velocity_factor(), Kind::Magnitude, "move velocity", un.vel, d.profile_velocity, out) ||
          !to_drive(a.value, u.acceleration_factor(), Kind::Magnitude, "acceleration", un.acc, d.profile_acceleration,
                    out) ||
          !to_drive(dc.value, u.acceleration_factor(), Kind::Magnitude, "deceleration", un.acc,
                    d.profile_deceleration, out))
        return out;
      d.relative = false;  // resolved above
      break;
    }
    case CommandKind::Velocity: {
      if (lim.max_velocity > 0 && std::fabs(cmd.velocity) > lim.max_velocity)
        return reject("velocity %.6g %s/s exceeds the limit of axis '%s' (%.6g %s/s)", cmd.velocity, unit_of(spec),
                      spec.name.c_str(), lim.max_velocity, unit_of(spec));
      const Rate a = resolve_rate(cmd.acceleration, spec.defaults.acceleration, lim.max_acceleration);
      const Rate dc = resolve_rate(cmd.deceleration, spec.defaults.deceleration, lim.max_acceleration);
      if (!a.ok || !dc.ok)
        return reject("acceleration/deceleration must be >= 0 and at most %.6g %s/s^2", lim.max_acceleration,
                      unit_of(spec));
      if (!to_drive(cmd.velocity, u.velocity_factor(), Kind::Magnitude, "velocity", un.vel, d.target_velocity, out) ||
          !to_drive(a.value, u.acceleration_factor(), Kind::Magnitude, "acceleration", un.acc, d.profile_acceleration,
                    out) ||
          !to_drive(dc.value, u.acceleration_factor(), Kind::Magnitude, "deceleration", un.acc,
                    d.profile_deceleration, out))
        return out;
      break;
    }
    case CommandKind::Torque: {
      if (lim.max_torque > 0 && std::fabs(cmd.torque) > lim.max_torque)
        return reject("torque %.6g exceeds the limit of axis '%s' (%.6g)", cmd.torque, spec.name.c_str(),
                      lim.max_torque);
      const char* tq_unit = u.torque_in_nm() ? "Nm" : "%";
      char slope_unit[8];
      std::snprintf(slope_unit, sizeof slope_unit, "%s/s", tq_unit);
      if (!to_drive(cmd.torque, u.torque_factor(), Kind::Magnitude, "torque", tq_unit, d.target_torque, out) ||
          !to_drive(spec.defaults.torque_slope, u.torque_factor(), Kind::Magnitude, "torque slope", slope_unit,
                    d.torque_slope, out))
        return out;
      break;
    }
    case CommandKind::Home: {
      const auto& h = spec.homing;
      const std::int16_t method = cmd.homing_method != 0 ? cmd.homing_method : h.method;
      if (method < -128 || method > 127) return reject("homing method %d is not a valid CiA 402 method", method);
      if (!spec.homing_methods.empty()) {
        bool found = false;
        for (auto m : spec.homing_methods) found = found || m == method;
        if (!found)
          return reject("homing method %d is not supported by device %s", method, spec.device.c_str());
      }
      const double offset = cmd.homing_method != 0 || cmd.home_offset != 0 ? cmd.home_offset : h.offset;
      const Rate s1 = resolve_rate(cmd.homing_search_velocity, h.search_velocity, lim.max_velocity);
      const Rate s2 = resolve_rate(cmd.homing_zero_velocity, h.zero_velocity, lim.max_velocity);
      if (!s1.ok || !s2.ok)
        return reject("homing speeds must be >= 0 and at most %.6g %s/s", lim.max_velocity, unit_of(spec));
      d.homing_method = static_cast<std::int8_t>(method);
      if (!to_drive(offset, u.position_factor(), Kind::Position, "home offset", un.pos, d.home_offset, out) ||
          !to_drive(s1.value, u.velocity_factor(), Kind::Magnitude, "homing search velocity", un.vel,
                    d.homing_search_velocity, out) ||
          !to_drive(s2.value, u.velocity_factor(), Kind::Magnitude, "homing zero velocity", un.vel,
                    d.homing_zero_velocity, out) ||
          !to_drive(h.acceleration, u.acceleration_factor(), Kind::Magnitude, "homing acceleration", un.acc,
                    d.homing_acceleration, out))
        return out;
      break;
    }
    case CommandKind::RunBlock:
      if (cmd.block < 0) return reject("traversing block number must be >= 0");
      d.block = cmd.block;
      break;
    case CommandKind::SetMode:
      d.mode = cmd.mode;
      break;
    default:
      break;
  }
  out.ok = true;
  return out;
}

std::optional<DriveSetpoint> convert_setpoint(const AxisSpec& spec, Mode mode, const Setpoint& sp,
                                              Text& reason) noexcept {
  if (!std::isfinite(sp.position) || !std::isfinite(sp.velocity) || !std::isfinite(sp.torque)) {
    reason.format("set-point for axis '%s' contains NaN or infinity", spec.name.c_str());
    return std::nullopt;
  }
  const auto& lim = spec.limits;
  DriveSetpoint d;
  switch (mode) {
    case Mode::CyclicPosition:
    case Mode::InterpolatedPosition: {
      if (lim.has_position_limits() && (sp.position < lim.min_position || sp.position > lim.max_position)) {
        reason.format("set-point position %.6g is outside the limits [%.6g, %.6g]", sp.position, lim.min_position,
                      lim.max_position);
        return std::nullopt;
      }
      const auto p = to_int32(spec.units.position_to_drive(sp.position));
      if (!p) break;
      d.position = *p;
      return d;
    }
    case Mode::CyclicVelocity:
    case Mode::ProfileVelocity:
    case Mode::Velocity: {
      if (lim.max_velocity > 0 && std::fabs(sp.velocity) > lim.max_velocity) {
        reason.format("set-point velocity %.6g exceeds the limit %.6g", sp.velocity, lim.max_velocity);
        return std::nullopt;
      }
      const auto v = to_int32(spec.units.velocity_to_drive(sp.velocity));
      if (!v) break;
      d.velocity = *v;
      return d;
    }
    case Mode::CyclicTorque:
    case Mode::ProfileTorque: {
      if (lim.max_torque > 0 && std::fabs(sp.torque) > lim.max_torque) {
        reason.format("set-point torque %.6g exceeds the limit %.6g", sp.torque, lim.max_torque);
        return std::nullopt;
      }
      const auto t = to_int16(spec.units.torque_to_drive(sp.torque));
      if (!t) break;
      d.torque = *t;
      return d;
    }
    default:
      reason.format("axis '%s' is in %s, which takes no streamed set-points", spec.name.c_str(),
                    to_string(mode).data());
      return std::nullopt;
  }
  reason.format("set-point for axis '%s' does not fit the drive's objects after unit conversion", spec.name.c_str());
  return std::nullopt;
}

}  // namespace drivegate::core
