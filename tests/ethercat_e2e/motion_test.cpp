// Streamed set-points from the DDS client through drivegated onto the wire: interpolated position
// on the ESR TrioDrive (60C1h:01 each cycle) and cyclic synchronous position on the generic drive
// with distributed clocks (SYNC0 from its ESC). Each test checks that the axis follows the stream
// as the gateway reports it, and that the simulated drive's own position moved by as much.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "tests/ethercat_e2e/ecat_fixture.hpp"

namespace drivegate::test {
namespace {

constexpr double kCountsPerRev = 4096;  // the axes' mechanics in config_text(); user unit: rev

class EthercatE2eMotion : public EthercatE2eUp {
 protected:
  // The simulated drive's position (encoder counts) from `drive K`.
  static double sim_position(const std::string& answer) {
    const std::string p = field(answer, "pos");
    EXPECT_FALSE(p.empty()) << answer;
    return p.empty() ? 0.0 : std::stod(p);
  }

  // Streams a 1 s ramp at `speed` rev/s in `mode` and checks the axis and the simulated drive at
  // `position` follow: within a quarter second of travel at the end of the stream (DDS both ways,
  // the 50 Hz state publication, the cycle, a loaded machine), then on the last set-point.
  void follow(const std::string& axis, int position, const std::string& mode, const std::string& shown,
              double speed) {
    ASSERT_NO_FATAL_FAILURE(enable(axis));
    ASSERT_NO_FATAL_FAILURE(set_mode(axis, mode));
    const std::string drive = "drive " + std::to_string(position);
    const double start = state(axis).position;
    const double sim_start = sim_position(sim(drive));
    const double target = stream_ramp(axis, speed, 1000ms);
    const auto end_of_stream = state(axis);
    EXPECT_EQ(end_of_stream.mode, shown);
    EXPECT_LT(std::fabs(target - end_of_stream.position), 0.25 * std::fabs(speed))
        << shown << ": " << end_of_stream.position << " behind " << target;
    ASSERT_TRUE(wait_axis(axis, [&](const client::AxisState& s) {
      return s.mode == shown && std::fabs(s.position - target) < 0.01 * std::fabs(speed);
    }, 3s)) << shown << ": from " << start << " to " << target << diagnostics();
    EXPECT_GT(std::fabs(state(axis).position - start), 0.9 * std::fabs(speed)) << shown;
    // The drive itself moved by the streamed distance (in its counts), in the streamed direction.
    const std::string after = sim(drive);
    const double moved = sim_position(after) - sim_start;
    EXPECT_NEAR(moved, (target - start) * kCountsPerRev, 0.02 * std::fabs(speed) * kCountsPerRev)
        << after << diagnostics();
    EXPECT_EQ(field(after, "state"), "operation_enabled") << after;
    EXPECT_EQ(state(axis).link, "operational");
    const auto r = send(axis, "disable");
    EXPECT_EQ(r.outcome, client::Outcome::Completed) << r.reason;
  }
};

// ip on the ESR: no DC on this drive (its profile says so), it runs free.
TEST_F(EthercatE2eMotion, EsrInterpolatedPositionFollowsStreamedSetpoints) {
  EXPECT_EQ(field(sim("drive 1"), "sync0"), "off");
  follow("esr", 1, "ip", "interpolated_position", 2.0);
}

// csp on the generic drive with distributed clocks: the gateway set the line's DC up (the bus'
// Info event names the reference clock and SYNC0), the drive's ESC pulses SYNC0 (the count goes
// on), and the axis follows.
TEST_F(EthercatE2eMotion, GenericCspWithDistributedClocksFollowsStreamedSetpoints) {
  ASSERT_TRUE(wait_event("", "info", "distributed clocks: reference clock slave 3", 5s)) << diagnostics();
  std::string dc;
  for (const auto& e : events())
    if (e.text.find("distributed clocks:") != std::string::npos) dc = e.text;
  EXPECT_NE(dc.find("SYNC0 every 2000000 ns"), std::string::npos) << dc;
  std::string last;
  ASSERT_TRUE(wait_sim("drive 3", [](const std::string& d) {
    const std::string n = field(d, "sync0");
    return !n.empty() && n != "off" && std::stoull(n) > 0;
  }, 5s, last)) << last << diagnostics();
  const auto first = std::stoull(field(last, "sync0"));
  ASSERT_NO_FATAL_FAILURE(follow("gen", 3, "csp", "cyclic_position", -2.0));
  // SYNC0 kept pulsing through the motion: about one pulse per cycle (2 ms) for more than a second.
  const std::string after = sim("drive 3");
  EXPECT_GT(std::stoull(field(after, "sync0")), first + 500) << after;
  EXPECT_EQ(field(sim("drive 1"), "sync0"), "off");
}

}  // namespace
}  // namespace drivegate::test
