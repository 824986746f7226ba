// Faults and IO data on the wire with the real binaries (the set-up: e2e_fixture.hpp), injected
// and observed through drivegate-sim's console: a drive fault read from the AKD's fault buffer and
// acknowledged over DDS, a gateway killed outright whose devices end their ARs on their watchdog,
// and the IO device's bytes both ways.
#include <gtest/gtest.h>
#include <signal.h>

#include <cstdint>
#include <string>
#include <vector>

#include "tests/profinet_e2e/e2e_fixture.hpp"

namespace drivegate::test {
namespace {

// The AKD has no alarm for a drive fault: ZSW1 bit 3 says there is one, the gateway reads the
// fault buffer (PNU 944 -> 947 -> 944 over record 47) and names it with the device profile's text
// [akd-profinet §18.1, §18.2]. STW1 bit 7 acknowledges it, the drive goes to S1 and the AR runs
// on; the other drive is untouched.
TEST_F(ProfinetE2e, DriveFaultIsReadFromTheFaultBufferAndAcknowledged) {
  ASSERT_NO_FATAL_FAILURE(enable("x"));
  ASSERT_EQ(sim("drive-fault akd-x 235"), "ok drive-fault pn0:akd-x 235");
  const std::string text = "F235: Heat sink temperature too high";
  ASSERT_TRUE(wait_axis("x", [&](const client::AxisState& s) {
    return s.state == "fault" && s.fault_code == 235 && s.fault_text.find(text) != std::string::npos;
  }, 10s)) << diagnostics();
  EXPECT_TRUE(wait_event("x", "fault", text, 5s)) << diagnostics();
  EXPECT_EQ(state("x").link, "operational");
  EXPECT_EQ(state("y").state, "switch_on_disabled");

  const auto reset = send("x", "fault_reset");
  ASSERT_EQ(reset.outcome, client::Outcome::Completed) << reset.reason << diagnostics();
  ASSERT_TRUE(wait_axis("x", [](const client::AxisState& s) {
    return s.state == "switch_on_disabled" && s.fault_code == 0 && s.fault_text.empty();
  }, 5s)) << diagnostics();
  EXPECT_TRUE(wait_event("x", "fault_cleared", "", 5s)) << diagnostics();
  // The AR the fault came over is the one it went away over.
  const std::string status = sim("status");
  EXPECT_EQ(station_field(status, "akd-x", "ar"), "DataExchange") << status;
  EXPECT_EQ(station_field(status, "akd-x", "watchdog"), "0") << status;
  ASSERT_NO_FATAL_FAILURE(enable("x"));
}

// drivegated killed with SIGKILL (no Release, no STOP): the output frames stop, each device's data
// hold timer runs out and it ends its AR; a drive that lost its controller raises F702 "fieldbus
// communication lost" [akd-profinet §18.3] and keeps it. A new gateway finds the stations at their
// addresses, connects each with a new AR: the drives come back operational in F702 (the gateway
// does not acknowledge a fault by itself), are reset and enable again; the IO device's inputs are
// valid again.
TEST_F(ProfinetE2e, KilledGatewayTripsTheWatchdogsAndANewOneReconnects) {
  ASSERT_NO_FATAL_FAILURE(enable("x"));
  ASSERT_NO_FATAL_FAILURE(enable("y"));
  const auto rc = daemon_->terminate(SIGKILL, 5s);
  ASSERT_TRUE(rc.has_value());
  EXPECT_EQ(*rc, 128 + SIGKILL);
  std::string last;
  ASSERT_TRUE(wait_sim("status", [](const std::string& s) {
    for (const char* station : {"akd-x", "akd-y", "io-block"}) {
      if (station_field(s, station, "ar") != "NoAr" || station_field(s, station, "watchdog") != "1") return false;
    }
    return true;
  }, 10s, last)) << last << diagnostics();

  ASSERT_NO_FATAL_FAILURE(start_gateway());
  for (const char* axis : {"x", "y"}) {
    ASSERT_TRUE(wait_axis(axis, [](const client::AxisState& s) {
      return s.link == "operational" && s.state == "fault" && s.fault_code == 702 &&
             s.fault_text.find("F702: Fieldbus communication lost") != std::string::npos;
    }, kStartUp)) << axis << diagnostics();
  }
  ASSERT_TRUE(client_->wait_until([&] {
    const auto v = client_->io_state("valves");
    return v && v->valid;
  }, kStartUp)) << diagnostics();
  // A new AR each, over the same addresses; the devices' watchdogs ran out once.
  const std::string status = sim("status");
  for (const char* station : {"akd-x", "akd-y", "io-block"}) {
    EXPECT_EQ(station_field(status, station, "ar"), "DataExchange") << station << ": " << status;
    EXPECT_EQ(station_field(status, station, "watchdog"), "1") << station << ": " << status;
  }
  for (const char* axis : {"x", "y"}) {
    const auto reset = send(axis, "fault_reset");
    ASSERT_EQ(reset.outcome, client::Outcome::Completed) << axis << ": " << reset.reason << diagnostics();
    ASSERT_TRUE(wait_axis(axis, [](const client::AxisState& s) { return s.state == "switch_on_disabled"; }, 5s))
        << axis << diagnostics();
    ASSERT_NO_FATAL_FAILURE(enable(axis));
  }
}

// The IO device `valves` (slot 1: 2 input octets, slot 2: 2 output octets): outputs written over
// DDS reach the device (its console shows them, valid), inputs set at the device come back on
// io_state. The simulated device does not loop its outputs to its inputs.
TEST_F(ProfinetE2e, IoDeviceBytesGoBothWays) {
  const auto valves = [&] { return client_->io_state("valves"); };
  auto v = valves();
  ASSERT_TRUE(v);
  EXPECT_EQ(v->bus, "pn0");
  EXPECT_EQ(v->inputs, (std::vector<std::uint8_t>{0x00, 0x00}));
  EXPECT_EQ(v->outputs, (std::vector<std::uint8_t>{0x00, 0x00}));
  std::string last;
  // Until slot 2's answer at the simulator is `answer`.
  const auto outputs_become = [&](const std::string& answer) {
    return wait_sim("io io-block 2", [&](const std::string& a) { return a == answer; }, 5s, last);
  };
  // The outputs are valid from the first frames in data exchange on (the controller's IOPS good).
  ASSERT_TRUE(outputs_become("io pn0:io-block 2:1 out=0000 out-state=valid in=-")) << last << diagnostics();
  EXPECT_EQ(sim("io io-block 1"), "io pn0:io-block 1:1 out=- out-state=valid in=0000");

  client::IoWriteRequest w;
  w.slave = "valves";
  w.offset = 1;
  w.data = {0xC3};
  const auto r = client_->io_write(w, 10s);
  ASSERT_TRUE(r.ok) << r.status << ": " << r.error << diagnostics();
  ASSERT_TRUE(outputs_become("io pn0:io-block 2:1 out=00C3 out-state=valid in=-")) << last << diagnostics();
  EXPECT_TRUE(client_->wait_until([&] {
    const auto s = valves();
    return s && s->outputs == std::vector<std::uint8_t>{0x00, 0xC3};
  }, 5s)) << diagnostics();
  EXPECT_EQ(valves()->inputs, (std::vector<std::uint8_t>{0x00, 0x00}));  // not looped back

  EXPECT_EQ(sim("io io-block 1 0x5A 0xA5"), "ok io pn0:io-block 1:1 out=- out-state=valid in=5AA5");
  EXPECT_TRUE(client_->wait_until([&] {
    const auto s = valves();
    return s && s->valid && s->inputs == std::vector<std::uint8_t>{0x5A, 0xA5};
  }, 5s)) << diagnostics();

  w.offset = 0;
  w.data = {0x11, 0x22};
  ASSERT_TRUE(client_->io_write(w, 10s).ok) << diagnostics();
  EXPECT_TRUE(outputs_become("io pn0:io-block 2:1 out=1122 out-state=valid in=-")) << last;
  w.data = {0x01, 0x02, 0x03};
  const auto refused = client_->io_write(w, 10s);
  EXPECT_FALSE(refused.ok);
  EXPECT_EQ(refused.status, "out_of_range") << refused.error;
  EXPECT_EQ(sim("io io-block 2"), "io pn0:io-block 2:1 out=1122 out-state=valid in=-");
}

}  // namespace
}  // namespace drivegate::test
