// The line brought up by the real drivegated over a veth pair: every slave in OP, each drive
// enabled through the DDS client; drive parameters over CoE and the I/O panel's bytes while the
// cycle runs.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "tests/ethercat_e2e/ecat_fixture.hpp"

namespace drivegate::test {
namespace {

using EthercatE2eBringUp = EthercatE2eUp;

// drivegate-sim sees every slave in OP, the gateway enables each drive, and the drive models (not
// only the gateway's view of them) are then operation enabled.
TEST_F(EthercatE2eBringUp, EverySlaveInOpAndEachDriveEnables) {
  std::string last;
  ASSERT_TRUE(wait_sim("status", [](const std::string& s) {
    return s.find("ec0:1 esr-triodrive station=0x1001 state=OP code=0x0000") != std::string::npos &&
           s.find("ec0:2 generic-io station=0x1002 state=OP code=0x0000") != std::string::npos &&
           s.find("ec0:3 generic-cia402 station=0x1003 state=OP code=0x0000") != std::string::npos;
  }, 10s, last)) << last << diagnostics();
  for (const char* axis : {"esr", "gen"}) {
    const auto info = client_->link(axis);
    ASSERT_TRUE(info) << axis;
    EXPECT_EQ(info->bus_type, "ethercat");
    EXPECT_NE(info->detail.find(": in OP"), std::string::npos) << axis << ": " << info->detail;
  }
  for (const auto& [axis, position] : {std::pair{"esr", 1}, std::pair{"gen", 3}}) {
    EXPECT_EQ(field(sim("drive " + std::to_string(position)), "state"), "switch_on_disabled") << axis;
    ASSERT_NO_FATAL_FAILURE(enable(axis));
    ASSERT_TRUE(wait_sim("drive " + std::to_string(position),
                         [](const std::string& d) { return field(d, "state") == "operation_enabled"; }, 5s, last))
        << axis << ": " << last << diagnostics();
  }
  const auto bus = bus_status();
  ASSERT_TRUE(bus);
  EXPECT_TRUE(bus->running);
  EXPECT_GT(bus->frames_received, 0U);
  for (const char* axis : {"esr", "gen"}) {
    const auto r = send(axis, "disable");
    EXPECT_EQ(r.outcome, client::Outcome::Completed) << axis << ": " << r.reason;
  }
}

// Drive parameters over CoE through the DDS client while the process data runs: a write read back
// on each drive, the identity object read, an object named as the drive's dictionary names it, and
// the cyclic exchange not disturbed by it.
TEST_F(EthercatE2eBringUp, ParametersOverDdsWhileCycling) {
  ASSERT_NO_FATAL_FAILURE(enable("gen"));
  const auto before = bus_status();
  ASSERT_TRUE(before);
  std::uint32_t value = 20000;
  for (const char* axis : {"esr", "gen"}) {
    ++value;
    client::ParamRequest w;
    w.axis = axis;
    w.write = true;
    w.index = 0x6065;  // following error window, UNSIGNED32 (the type from the device profile)
    w.value = std::to_string(value);
    const auto wr = client_->param(w, 10s);
    ASSERT_TRUE(wr.ok) << axis << ": " << wr.error << diagnostics();
    client::ParamRequest r;
    r.axis = axis;
    r.index = 0x6065;
    const auto rd = client_->param(r, 10s);
    ASSERT_TRUE(rd.ok) << axis << ": " << rd.error;
    ASSERT_TRUE(rd.integer()) << axis;
    EXPECT_EQ(*rd.integer(), value) << axis;
  }
  // 1018h:01, the vendor ID: ESR's 0000000Fh from the simulated drive's object dictionary.
  client::ParamRequest id;
  id.axis = "esr";
  id.index = 0x1018;
  id.subindex = 1;
  id.type = "u32";
  const auto vendor = client_->param(id, 10s);
  ASSERT_TRUE(vendor.ok) << vendor.error;
  EXPECT_EQ(vendor.integer(), 0x0F);
  // An object the drive does not have: the CoE abort comes back as the error.
  client::ParamRequest missing;
  missing.axis = "gen";
  missing.index = 0x2FFF;
  missing.type = "u32";
  const auto abort = client_->param(missing, 10s);
  EXPECT_FALSE(abort.ok);
  EXPECT_NE(abort.error_code, 0U) << abort.error;
  // By name without an ESI: the ESR's manufacturer object from its own dictionary, read over SDO
  // Information after OP (the answer says so while it is being read).
  client::ParamRequest named;
  named.axis = "esr";
  named.name = "acceleration_time";
  client::ParamResult by_name;
  ASSERT_TRUE(client_->wait_until([&] {
    by_name = client_->param(named, 10s);
    return by_name.ok || by_name.error.find("still being read") == std::string::npos;
  }, 30s)) << by_name.error;
  ASSERT_TRUE(by_name.ok) << by_name.error << diagnostics();
  EXPECT_EQ(by_name.integer(), 100);  // 5EF4h's power-on value in the simulated ESR
  // The cycle ran on meanwhile: the enabled drive stayed enabled, the frames kept returning.
  EXPECT_EQ(state("gen").state, "operation_enabled");
  EXPECT_EQ(state("gen").link, "operational");
  ASSERT_TRUE(client_->wait_until([&] {
    const auto b = bus_status();
    return b && b->frames_received > before->frames_received + 100;
  }, 5s)) << diagnostics();
}

// The panel's bytes: outputs written over DDS reach the simulated slave (its console shows them),
// inputs set at the slave come back on io_state. The simulated generic I/O slave does not loop
// its outputs to its inputs: its inputs stay zero until the console sets them.
TEST_F(EthercatE2eBringUp, IoBytesWrittenAndRead) {
  auto p = panel();
  ASSERT_TRUE(p);
  EXPECT_EQ(p->address, 2U);
  EXPECT_EQ(p->inputs, (std::vector<std::uint8_t>{0x00, 0x00}));
  EXPECT_EQ(p->outputs, (std::vector<std::uint8_t>{0x00, 0x00}));
  EXPECT_EQ(sim("io 2"), "io ec0:2 out=0000 in=0000");

  client::IoWriteRequest w;
  w.slave = "panel";
  w.offset = 1;
  w.data = {0xC3};
  const auto r = client_->io_write(w, 10s);
  ASSERT_TRUE(r.ok) << r.status << ": " << r.error << diagnostics();
  std::string last;
  ASSERT_TRUE(wait_sim("io 2", [](const std::string& a) { return a == "io ec0:2 out=00c3 in=0000"; }, 5s, last))
      << last << diagnostics();
  EXPECT_TRUE(client_->wait_until([&] { return panel()->outputs == std::vector<std::uint8_t>{0x00, 0xC3}; }, 5s));
  // Not looped back.
  EXPECT_EQ(panel()->inputs, (std::vector<std::uint8_t>{0x00, 0x00}));

  EXPECT_EQ(sim("io 2 0x5A 0xA5"), "ok io ec0:2 out=00c3 in=5aa5");
  EXPECT_TRUE(client_->wait_until([&] {
    const auto s = panel();
    return s && s->valid && s->inputs == std::vector<std::uint8_t>{0x5A, 0xA5};
  }, 5s)) << diagnostics();

  w.offset = 0;
  w.data = {0x11, 0x22};
  ASSERT_TRUE(client_->io_write(w, 10s).ok);
  EXPECT_TRUE(wait_sim("io 2", [](const std::string& a) { return a == "io ec0:2 out=1122 in=5aa5"; }, 5s, last))
      << last;
  w.data = {0x01, 0x02, 0x03};
  const auto refused = client_->io_write(w, 10s);
  EXPECT_FALSE(refused.ok);
  EXPECT_EQ(refused.status, "out_of_range") << refused.error;
}

}  // namespace
}  // namespace drivegate::test
