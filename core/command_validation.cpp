#include "core/command_validation.hpp"

#include <cmath>
#include <cstdarg>

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
      const auto pos = to_int32(u.position_to_drive(end));
      const auto pv = to_uint32(u.velocity_to_drive(v.value));
      const auto pa = to_uint32(u.acceleration_to_drive(a.value));
      const auto pd = to_uint32(u.acceleration_to_drive(dc.value));
      if (!pos || !pv || !pa || !pd) return reject("move values do not fit the drive's 32-bit objects after unit conversion");
      d.target_position = *pos;
      d.relative = false;  // resolved above
      d.profile_velocity = *pv;
      d.profile_acceleration = *pa;
      d.profile_deceleration = *pd;
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
      const auto v = to_int32(u.velocity_to_drive(cmd.velocity));
      const auto pa = to_uint32(u.acceleration_to_drive(a.value));
      const auto pd = to_uint32(u.acceleration_to_drive(dc.value));
      if (!v || !pa || !pd) return reject("velocity values do not fit the drive's objects after unit conversion");
      d.target_velocity = *v;
      d.profile_acceleration = *pa;
      d.profile_deceleration = *pd;
      break;
    }
    case CommandKind::Torque: {
      if (lim.max_torque > 0 && std::fabs(cmd.torque) > lim.max_torque)
        return reject("torque %.6g exceeds the limit of axis '%s' (%.6g)", cmd.torque, spec.name.c_str(),
                      lim.max_torque);
      const auto t = to_int16(u.torque_to_drive(cmd.torque));
      const auto slope = to_uint32(u.torque_to_drive(spec.defaults.torque_slope));
      if (!t || !slope) return reject("torque does not fit the drive's 16-bit object after unit conversion");
      d.target_torque = *t;
      d.torque_slope = *slope;
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
      const auto off = to_int32(u.position_to_drive(offset));
      const auto v1 = to_uint32(u.velocity_to_drive(s1.value));
      const auto v2 = to_uint32(u.velocity_to_drive(s2.value));
      const auto acc = to_uint32(u.acceleration_to_drive(h.acceleration));
      if (!off || !v1 || !v2 || !acc) return reject("homing values do not fit the drive's objects after unit conversion");
      d.homing_method = static_cast<std::int8_t>(method);
      d.home_offset = *off;
      d.homing_search_velocity = *v1;
      d.homing_zero_velocity = *v2;
      d.homing_acceleration = *acc;
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
