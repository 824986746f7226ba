// The I/O topics (io_state, io_write, io_write_reply) end to end over real Fast DDS: DdsBridge
// against FakeRuntime's I/O slaves, read and written through the Client library and drivegatectl.
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "client/client.hpp"
#include "daemon/dds_bridge.hpp"
#include "fake_runtime.hpp"

namespace drivegate::dds_test {
namespace {

using client::Millis;
constexpr Millis kTimeout{10000};

std::uint32_t test_domain() { return 20U + static_cast<std::uint32_t>(::getpid() % 80); }  // see bridge_client_test
std::string test_namespace() {
  return "dgio_" + std::to_string(::getpid()) + "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name();
}

struct CtlRun {
  int status = -1;
  std::string output;  // stdout and stderr
};

CtlRun ctl(const std::string& args) {
  const std::string cmd = std::string(DRIVEGATECTL_PATH) + " --domain " + std::to_string(test_domain()) +
                          " --namespace " + test_namespace() + " --timeout 10 " + args + " 2>&1";
  CtlRun r;
  FILE* p = ::popen(cmd.c_str(), "r");
  if (p == nullptr) return r;
  std::array<char, 4096> buf{};
  std::size_t n = 0;
  while ((n = std::fread(buf.data(), 1, buf.size(), p)) > 0) r.output.append(buf.data(), n);
  const int ws = ::pclose(p);
  r.status = WIFEXITED(ws) ? WEXITSTATUS(ws) : -1;
  return r;
}

daemon::DdsBridgeOptions bridge_options() {
  daemon::DdsBridgeOptions o;
  o.domain = test_domain();
  o.ns = test_namespace();
  o.status_rate_hz = 20;
  return o;
}

client::ClientOptions client_options() {
  client::ClientOptions o;
  o.domain = test_domain();
  o.ns = test_namespace();
  return o;
}

class DdsIo : public ::testing::Test {
 protected:
  void SetUp() override {
    rt_.add_io("panel", 2, 2);
    rt_.add_io("valves", 1, 4);
    rt_.set_io_inputs(0, {0xA5, 0x3C});
    bridge_.start();
  }
  FakeRuntime rt_{"gw1", {"x"}};
  daemon::DdsBridge bridge_{rt_, bridge_options()};
};

TEST_F(DdsIo, StatesCarryTheBytesAndWritesReachTheRuntime) {
  client::Client c(client_options());
  ASSERT_TRUE(c.wait_until([&] { return c.io_states().size() == 2; }, kTimeout));
  auto st = c.io_state("panel");
  ASSERT_TRUE(st);
  EXPECT_EQ(st->gateway, "gw1");
  EXPECT_EQ(st->bus, "ec0");
  EXPECT_EQ(st->address, 2U);
  EXPECT_TRUE(st->valid);
  EXPECT_EQ(st->inputs, (std::vector<std::uint8_t>{0xA5, 0x3C}));
  EXPECT_EQ(st->outputs, (std::vector<std::uint8_t>{0x00, 0x00}));
  EXPECT_EQ(st->stamp_ns, FakeRuntime::kStampNs);

  client::IoWriteRequest w;
  w.slave = "valves";
  w.offset = 1;
  w.data = {0x12, 0x34};
  const auto r = c.io_write(w, kTimeout);
  EXPECT_TRUE(r.ok) << r.error;
  EXPECT_EQ(r.status, "ok");
  EXPECT_EQ(r.gateway, "gw1");
  EXPECT_EQ(rt_.io_outputs(1), (std::vector<std::uint8_t>{0x00, 0x12, 0x34, 0x00}));
  // The change is published (on change, not only at the keep-alive).
  EXPECT_TRUE(c.wait_until([&] {
    const auto v = c.io_state("valves");
    return v && v->outputs == std::vector<std::uint8_t>{0x00, 0x12, 0x34, 0x00};
  }, kTimeout));
  EXPECT_EQ(bridge_.stats().io_writes_routed, 1U);
}

TEST_F(DdsIo, RefusalsSayWhy) {
  client::Client c(client_options());
  ASSERT_TRUE(c.wait_until([&] { return c.io_states().size() == 2; }, kTimeout));
  client::IoWriteRequest w;
  w.gateway = "gw1";  // named: no discovery of the slave, so the gateway answers for unknown ones
  w.slave = "nope";
  w.data = {0x01};
  auto r = c.io_write(w, kTimeout);
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.status, "unknown_slave");
  EXPECT_NE(r.error.find("unknown I/O slave 'nope'"), std::string::npos) << r.error;
  EXPECT_NE(r.error.find("panel (bus ec0), valves (bus ec0)"), std::string::npos) << r.error;

  w.slave = "panel";
  w.offset = 1;
  w.data = {0x01, 0x02};
  r = c.io_write(w, kTimeout);
  EXPECT_EQ(r.status, "out_of_range");
  EXPECT_EQ(r.error, "out of range: 2 byte(s) at offset 1, but I/O slave 'panel' on bus ec0 has 2 output bytes");

  rt_.set_io_lost(0, true);
  w.offset = 0;
  w.data = {0x01};
  r = c.io_write(w, kTimeout);
  EXPECT_EQ(r.status, "slave_lost");
  EXPECT_EQ(r.error,
            "I/O slave 'panel' on bus ec0 is not exchanging process data (booting, lost or recovering): outputs not "
            "written");
  EXPECT_EQ(rt_.io_outputs(0), (std::vector<std::uint8_t>{0x00, 0x00}));
  EXPECT_TRUE(c.wait_until([&] { return !c.io_state("panel")->valid; }, kTimeout));  // stale inputs published

  // Without a gateway named, an unknown slave is the client's own answer.
  w.gateway.clear();
  w.slave = "nope";
  r = c.io_write(w, Millis(2000));
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.status, "");
  EXPECT_NE(r.error.find("no gateway publishes an I/O slave 'nope'"), std::string::npos) << r.error;
}

// A write the Runtime cannot queue waits in the bridge, then is answered busy (after 2 s).
TEST_F(DdsIo, AWriteThatFindsNoRoomIsAnsweredBusy) {
  client::Client c(client_options());
  ASSERT_TRUE(c.wait_until([&] { return c.io_states().size() == 2; }, kTimeout));
  rt_.set_busy(true);
  client::IoWriteRequest w;
  w.slave = "panel";
  w.data = {0x01};
  const auto r = c.io_write(w, kTimeout);
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.status, "busy");
  EXPECT_EQ(r.error, "busy: the gateway's I/O queue of bus ec0 stayed full for 2000 ms; send it again");
  rt_.set_busy(false);
  EXPECT_TRUE(c.io_write(w, kTimeout).ok);
  EXPECT_EQ(rt_.io_outputs(0), (std::vector<std::uint8_t>{0x01, 0x00}));
}

TEST_F(DdsIo, DrivegatectlListsShowsAndWrites) {
  auto r = ctl("io");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(r.output,
            "panel  gw1/ec0  address=2  valid  in=[A5 3C]  out=[00 00]\n"
            "valves  gw1/ec0  address=3  valid  in=[00]  out=[00 00 00 00]\n");

  r = ctl("io valves write 2 0xFF 01");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(r.output, "io valves (gw1/ec0): 2 byte(s) at offset 2 written: FF 01\n");
  EXPECT_EQ(rt_.io_outputs(1), (std::vector<std::uint8_t>{0x00, 0x00, 0xFF, 0x01}));

  r = ctl("io valves");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(r.output,
            "valves (gw1/ec0, address 3): inputs valid\n"
            "  inputs  (1 bytes): 00\n"
            "  outputs (4 bytes): 00 00 FF 01\n");

  r = ctl("--json io panel");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(r.output,
            "{\"gateway\":\"gw1\",\"bus\":\"ec0\",\"slave\":\"panel\",\"address\":2,\"valid\":true,\"input_size\":2,"
            "\"output_size\":2,\"inputs\":\"A5 3C\",\"outputs\":\"00 00\",\"stamp_ns\":100000000000}\n");

  r = ctl("--json io panel write 0 0102");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(r.output,
            "{\"slave\":\"panel\",\"gateway\":\"gw1\",\"bus\":\"ec0\",\"offset\":0,\"bytes\":\"01 02\",\"ok\":true,"
            "\"status\":\"ok\",\"error\":\"\"}\n");

  r = ctl("io panel write 2 01");
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_EQ(r.output,
            "drivegatectl: io panel write: out_of_range: out of range: 1 byte(s) at offset 2, but I/O slave 'panel' "
            "on bus ec0 has 2 output bytes\n");

  r = ctl("io nope");
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_EQ(r.output, "drivegatectl: no I/O slave 'nope'; I/O slaves: panel, valves\n");

  r = ctl("io panel write 0 zz");
  EXPECT_EQ(r.status, 2) << r.output;
}

}  // namespace
}  // namespace drivegate::dds_test
