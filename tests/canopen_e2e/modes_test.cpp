// Every mode each persona's device profile offers, commanded through the DDS client: enable, the
// modes one after the other, disable. Units are the axes' user units (three_drives_config()).
#include <cmath>

#include "tests/canopen_e2e/e2e_fixture.hpp"

namespace drivegate::test {
namespace {

using client::AxisState;
using client::Outcome;

class CanopenE2eModes : public CanopenE2eUp {
 protected:
  // Below the gateway's standstill window on every axis (10 drive units: 0.0008 mm/s on the AKD,
  // 0.001 rev/s on the SD6; the NORD counts whole rpm).
  static constexpr double kStandstill = 5e-4;

  void expect_completed(const client::CommandRequest& r, std::chrono::milliseconds timeout = 10s) {
    const auto result = send(r, timeout);
    ASSERT_EQ(result.outcome, Outcome::Completed)
        << r.axis << " " << r.kind << " " << r.mode << ": " << client::to_string(result.outcome) << ", "
        << result.reason << diagnostics();
  }
  void expect_completed(const std::string& axis, const std::string& kind) { expect_completed(request(axis, kind)); }
  void expect_running(const client::CommandRequest& r) {
    const auto result = start(r);
    ASSERT_EQ(result.outcome, Outcome::Accepted)
        << r.axis << " " << r.kind << ": " << client::to_string(result.outcome) << ", " << result.reason << diagnostics();
  }

  void enable(const std::string& axis) {
    ASSERT_NO_FATAL_FAILURE(expect_completed(axis, "enable"));
    ASSERT_TRUE(wait_axis(axis, [](const AxisState& s) { return s.state == "operation_enabled"; }, 2s))
        << diagnostics();
  }
  void disable(const std::string& axis) {
    ASSERT_NO_FATAL_FAILURE(expect_completed(axis, "disable"));
    ASSERT_TRUE(wait_axis(axis, [](const AxisState& s) { return s.state == "switch_on_disabled"; }, 2s))
        << diagnostics();
  }

  // pp: a move completes at its target, and the drive reports target reached there. The motor
  // settles a few cycles after "target reached" (a position window, not zero speed); the next
  // mode change waits for standstill, which the gateway requires [AKD digest §3.6].
  void move(const std::string& axis, double position, double tolerance) {
    auto mv = request(axis, "move");
    mv.position = position;
    ASSERT_NO_FATAL_FAILURE(expect_completed(mv, 20s));
    ASSERT_TRUE(wait_axis(axis, [&](const AxisState& s) {
      return s.mode == "profile_position" && s.target_reached && std::fabs(s.position - position) < tolerance &&
             std::fabs(s.velocity) < kStandstill;
    }, 2s)) << diagnostics();
  }

  // A velocity command (pv, or vl when `mode` says so) reaches its speed while the client keeps it
  // alive; stop brings it to standstill, still enabled.
  void jog(const std::string& axis, const std::string& mode, const std::string& shown, double velocity,
           double tolerance) {
    auto v = request(axis, "velocity");
    v.mode = mode;
    v.velocity = velocity;
    ASSERT_NO_FATAL_FAILURE(expect_running(v));
    ASSERT_TRUE(keep_alive_until(axis, 0, velocity, 0, [&](const AxisState& s) {
      return s.mode == shown && std::fabs(s.velocity - velocity) < tolerance;
    }, 5s)) << shown << diagnostics();
    ASSERT_NO_FATAL_FAILURE(stop(axis));
  }

  // tq: the drive reports the commanded torque while the client keeps it alive.
  void torque(const std::string& axis, double percent) {
    auto t = request(axis, "torque");
    t.torque = percent;
    ASSERT_NO_FATAL_FAILURE(expect_running(t));
    ASSERT_TRUE(keep_alive_until(axis, 0, 0, percent, [&](const AxisState& s) {
      return s.mode == "profile_torque" && std::fabs(s.torque - percent) < 0.2;
    }, 5s)) << diagnostics();
    ASSERT_NO_FATAL_FAILURE(stop(axis));
  }

  // The axis comes to standstill and stays enabled, ready for a mode change.
  void stop(const std::string& axis) {
    ASSERT_NO_FATAL_FAILURE(expect_completed(axis, "stop"));
    ASSERT_TRUE(wait_axis(axis, [&](const AxisState& s) {
      return s.state == "operation_enabled" && std::fabs(s.velocity) < kStandstill;
    }, 5s)) << diagnostics();
  }

  // hm: the configured method ends with the axis homed at the home offset (0).
  void home(const std::string& axis) {
    ASSERT_NO_FATAL_FAILURE(expect_completed(request(axis, "home"), 30s));
    ASSERT_TRUE(wait_axis(axis, [](const AxisState& s) {
      return s.homed && s.mode == "homing" && std::fabs(s.position) < 0.01 && std::fabs(s.velocity) < kStandstill;
    }, 2s)) << diagnostics();
  }

  // ip / csp: positions streamed every 10 ms for a second; the axis follows the ramp close behind
  // (within 250 ms of travel: DDS both ways, the 50 Hz state publication, a SYNC cycle, the drive's
  // interpolation, a loaded machine) and ends at its last set-point.
  void follow(const std::string& axis, const std::string& mode, const std::string& shown, double speed) {
    auto m = request(axis, "set_mode");
    m.mode = mode;
    ASSERT_NO_FATAL_FAILURE(expect_completed(m));
    const double start = state(axis).position;
    const double target = stream_ramp(axis, speed, 1000ms);
    const auto end_of_stream = state(axis);
    EXPECT_EQ(end_of_stream.mode, shown);
    EXPECT_LT(std::fabs(target - end_of_stream.position), 0.25 * speed)
        << shown << ": " << end_of_stream.position << " behind " << target;
    ASSERT_TRUE(wait_axis(axis, [&](const AxisState& s) {
      return s.mode == shown && std::fabs(s.position - target) < 0.01 * speed;
    }, 1s)) << shown << ": from " << start << " to " << target << diagnostics();
    EXPECT_GT(std::fabs(state(axis).position - start), 0.9 * speed) << shown;
    // Stop before the command timeout notices the ended stream.
    ASSERT_NO_FATAL_FAILURE(stop(axis));
  }
};

TEST_F(CanopenE2eModes, AkdEveryMode) {
  ASSERT_NO_FATAL_FAILURE(enable("akd"));
  ASSERT_NO_FATAL_FAILURE(move("akd", 12.5, 0.001));
  ASSERT_NO_FATAL_FAILURE(jog("akd", "", "profile_velocity", 20, 0.5));
  ASSERT_NO_FATAL_FAILURE(torque("akd", 5));
  ASSERT_NO_FATAL_FAILURE(home("akd"));
  ASSERT_NO_FATAL_FAILURE(follow("akd", "ip", "interpolated_position", 10));
  ASSERT_NO_FATAL_FAILURE(follow("akd", "csp", "cyclic_position", 10));
  ASSERT_NO_FATAL_FAILURE(disable("akd"));
}

TEST_F(CanopenE2eModes, NordEveryMode) {
  ASSERT_NO_FATAL_FAILURE(enable("nord"));
  ASSERT_NO_FATAL_FAILURE(move("nord", 2.5, 0.002));  // 0.001 rev resolution (nord-sk500p-ds402.md §4)
  ASSERT_NO_FATAL_FAILURE(jog("nord", "", "profile_velocity", 3, 0.1));
  ASSERT_NO_FATAL_FAILURE(jog("nord", "vl", "velocity", 5, 0.1));  // 6042h in rpm, INTEGER16 (§5.2)
  ASSERT_NO_FATAL_FAILURE(torque("nord", 5));
  ASSERT_NO_FATAL_FAILURE(home("nord"));
  ASSERT_NO_FATAL_FAILURE(disable("nord"));
}

TEST_F(CanopenE2eModes, Sd6EveryMode) {
  ASSERT_NO_FATAL_FAILURE(enable("sd6"));
  ASSERT_NO_FATAL_FAILURE(move("sd6", 2.5, 0.001));
  ASSERT_NO_FATAL_FAILURE(jog("sd6", "", "profile_velocity", 3, 0.1));
  ASSERT_NO_FATAL_FAILURE(home("sd6"));
  ASSERT_NO_FATAL_FAILURE(disable("sd6"));
}

}  // namespace
}  // namespace drivegate::test
