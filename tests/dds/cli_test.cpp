// drivegatectl as a subprocess against an in-process bridge: exit codes, JSON output, reasons.
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <map>
#include <string>
#include <thread>

#include <fastdds/dds/publisher/DataWriter.hpp>
#include <gtest/gtest.h>

#include "daemon/dds_bridge.hpp"
#include "drivegate.h"
#include "fake_runtime.hpp"
#include "idl/dds_node.hpp"

namespace drivegate::dds_test {
namespace {

namespace dds = eprosima::fastdds::dds;

std::uint32_t test_domain() { return 20U + static_cast<std::uint32_t>(::getpid() % 80); }  // see bridge_client_test

std::string test_namespace() {
  return "dgcli_" + std::to_string(::getpid()) + "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name();
}

struct CtlRun {
  int status = -1;
  std::string output;  // stdout and stderr
};

CtlRun run_tool(const char* tool, const std::string& args) {
  const std::string cmd = std::string(tool) + " --domain " + std::to_string(test_domain()) +
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

CtlRun ctl(const std::string& args) { return run_tool(DRIVEGATECTL_PATH, args); }

class Drivegatectl : public ::testing::Test {
 protected:
  void SetUp() override { bridge_.start(); }
  FakeRuntime rt_{"gw1", {"x", "y"}};
  daemon::DdsBridge bridge_{rt_, bridge_options()};
};

TEST_F(Drivegatectl, MoveCompletesWithJsonResult) {
  const CtlRun r = ctl("--json move x 5 --velocity 2 --relative");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find(R"("status":"completed")"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(R"("gateway":"gw1")"), std::string::npos) << r.output;
  ASSERT_EQ(rt_.commands().size(), 1U);
  EXPECT_DOUBLE_EQ(rt_.commands()[0].command.position, 5);
  EXPECT_TRUE(rt_.commands()[0].command.relative);
}

TEST_F(Drivegatectl, UnknownAxisFailsWithTheKnownAxes) {
  const CtlRun r = ctl("enable nope");
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("no gateway owns axis 'nope'"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("gw1/x"), std::string::npos) << r.output;
}

TEST_F(Drivegatectl, RejectedCommandExitsNonZeroWithTheReason) {
  rt_.set_busy(true);
  const CtlRun r = ctl("reset y");
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("busy: the gateway's command queue"), std::string::npos) << r.output;
}

TEST_F(Drivegatectl, ListStatusAndParam) {
  CtlRun r = ctl("--json list");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find(R"("name":"y")"), std::string::npos) << r.output;
  r = ctl("status x");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("switch_on_disabled"), std::string::npos) << r.output;
  // The address (a CANopen node-ID in decimal and hex) and the link have columns of their own.
  EXPECT_NE(r.output.find("GATEWAY  AXIS  ADDRESS    LINK         STATE"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("x     35 (0x23)  operational  switch_on_disabled"), std::string::npos) << r.output;
  rt_.set_object(0, 0x6061, 0, core::ParamType::I8, "-3");
  r = ctl("param get x 6061h:0");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("x 6061h:00 = -3 (0xFD, INTEGER8)"), std::string::npos) << r.output;
  rt_.set_object(0, 0x6081, 0, core::ParamType::U32, "0");
  r = ctl("param set x 0x6081 70000");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("x 6081h:00 = 70000 (0x00011170, UNSIGNED32) written"), std::string::npos) << r.output;
  EXPECT_EQ(rt_.object(0, 0x6081, 0), (std::vector<std::uint8_t>{0x70, 0x11, 0x01, 0x00}));
}

// list shows each axis' address; JSON keeps the number.
TEST_F(Drivegatectl, ListShowsNodeIdsInDecimalAndHex) {
  CtlRun r = ctl("list");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("x  bus=can0  address=35 (0x23)  device=sim"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("y  bus=can0  address=36 (0x24)  device=sim"), std::string::npos) << r.output;
  r = ctl("--json list");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find(R"("name":"x","bus":"can0","bus_type":"canopen","address":35,)"), std::string::npos)
      << r.output;
}

// status AXIS says why the link is in its state (node-IDs in hex too) and since when; --json
// carries the detail as the gateway wrote it and the numbers.
TEST_F(Drivegatectl, StatusOfAnAxisShowsWhyItsLinkIsInItsState) {
  const std::string why =
      "node 35: identity: 1018h:01 reads 0x0000006A, expected 0x00000059; vendor-ID (1018h:01) of a generic-cia402";
  rt_.set_link(0, core::LinkState::Offline, why, FakeRuntime::kStampNs - 2'400'000'000);
  CtlRun r = ctl("status x");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("x     35 (0x23)  offline"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("x: link offline for 2.4 s (since "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("  node 35 (0x23): identity: 1018h:01 reads 0x0000006A, expected 0x00000059; vendor-ID"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(r.output.find("y: link"), std::string::npos) << "only the axes asked for: " << r.output;

  r = ctl("--json status x");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find(R"("link":"offline","bus":"can0","bus_type":"canopen","address":35,)"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find(R"("link_detail":")" + why + R"(")"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(R"("link_since_ns":97600000000,)"), std::string::npos) << r.output;

}

// Event texts of a canopen axis show node-IDs in hex too.
TEST_F(Drivegatectl, EventsShowNodeIdsInDecimalAndHex) {
  rt_.push_event(0, core::EventKind::LinkChanged, "link operational -> lost: node 35 stopped answering (heartbeat)");
  const CtlRun r = ctl("events x");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("link_changed  link operational -> lost: node 35 (0x23) stopped answering"),
            std::string::npos)
      << r.output;
}

// Every type prints the way people read it: identity in hex first, strings quoted, long byte
// strings as a dump; --json carries the typed value, its hex and the raw bytes. A value that does
// not fit fails with the reason and exit code 1.
TEST_F(Drivegatectl, ParamTypesPrintAsTheyRead) {
  rt_.set_object(0, 0x1018, 1, core::ParamType::U32, "0x6A");
  CtlRun r = ctl("param get x 1018:1");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("x 1018h:01 = 0x0000006A (106, UNSIGNED32)"), std::string::npos) << r.output;
  rt_.set_object(0, 0x1008, 0, core::ParamType::VisibleString, "drivegate simulated servo drive");
  r = ctl("param get x 0x1008");
  EXPECT_NE(r.output.find("x 1008h:00 = \"drivegate simulated servo drive\" (VISIBLE_STRING, 31 bytes)"),
            std::string::npos)
      << r.output;
  r = ctl("--json param get x 0x1008");
  EXPECT_NE(r.output.find(R"("type":"string","size":31,"bytes":"64 72)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(R"("value":"drivegate simulated servo drive")"), std::string::npos) << r.output;
  rt_.set_object(0, 0x2001, 0, core::ParamType::U64, "0xFFFFFFFFFFFFFFF6");
  r = ctl("--json param get x 2001");
  EXPECT_NE(r.output.find(R"("value":18446744073709551606,"hex":"0xFFFFFFFFFFFFFFF6")"), std::string::npos)
      << r.output;
  rt_.set_object(0, 0x2002, 0, core::ParamType::R64, "-2.5e-3");
  r = ctl("param get x 2002");
  EXPECT_NE(r.output.find("x 2002h:00 = -0.0025 (REAL64)"), std::string::npos) << r.output;
  rt_.set_object(0, 0x2003, 0, core::ParamType::Domain, "00 01 02 03 04 05 06 07 08 09 0a 0b 0c 0d 0e 0f 10 11");
  r = ctl("param get x 2003");
  EXPECT_NE(r.output.find("(DOMAIN, 18 bytes)\n  0000: 00 01 02 03 04 05 06 07 08 09 0A 0B 0C 0D 0E 0F\n  0010: 10 11"),
            std::string::npos)
      << r.output;
  rt_.set_object(0, 0x2004, 0, core::ParamType::Unknown, "0102");
  r = ctl("param get x 2004");
  EXPECT_NE(r.output.find("= 01 02 (2 bytes; type not known: give --type to decode)"), std::string::npos) << r.output;
  r = ctl("param get x 2004 --type i16");
  EXPECT_NE(r.output.find("= 513 (0x0201, INTEGER16)"), std::string::npos) << r.output;
  r = ctl("param set x 2001 -5");
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("outside the range of UNSIGNED64"), std::string::npos) << r.output;
  r = ctl("param get x 2001 --type quad");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("--type: unknown type 'quad'"), std::string::npos) << r.output;
}

TEST_F(Drivegatectl, ParamByName) {
  daemon::ParameterLookup a83;
  a83.index = 0x2053;
  rt_.add_name("A83", a83);
  rt_.set_object(0, 0x2053, 0, core::ParamType::U8, "9");
  CtlRun r = ctl("param get x A83");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("x A83 (2053h:00) = 9 (0x09, UNSIGNED8)"), std::string::npos) << r.output;
  r = ctl("param get x A999");
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("param get x A999: no object named 'A999'"), std::string::npos) << r.output;
  // With the h suffix a word that starts with a letter is an index.
  rt_.set_object(0, 0xA83, 0, core::ParamType::U8, "5");
  r = ctl("param get x A83h");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("0A83h:00 = 5"), std::string::npos) << r.output;
}

TEST_F(Drivegatectl, VelocityStreamsKeepAliveThenStops) {
  const CtlRun r = ctl("velocity y -4.5 --for 0.4");
  EXPECT_EQ(r.status, 0) << r.output;
  const auto cmds = rt_.commands();
  ASSERT_EQ(cmds.size(), 2U) << r.output;
  EXPECT_EQ(cmds[0].command.kind, core::CommandKind::Velocity);
  EXPECT_DOUBLE_EQ(cmds[0].command.velocity, -4.5);
  EXPECT_EQ(cmds[1].command.kind, core::CommandKind::Stop);
  // Set-points are best effort; at 20 Hz for 0.4 s at least one arrives in-process.
  ASSERT_FALSE(rt_.setpoints().empty());
  EXPECT_DOUBLE_EQ(rt_.setpoints().back().second.velocity, -4.5);
}

// A gateway without an axis_link writer (its DDS Security permissions predate the topic): list
// and status do not wait their whole --timeout (10 s here) for links that never come.
TEST(DrivegatectlWithoutLinks, ListAndStatusDoNotWaitForLinksNobodyPublishes) {
  msg::DdsOptions o;
  o.domain = test_domain();
  o.ns = test_namespace();
  o.participant_name = "gateway-without-axis-link";
  msg::DdsNode gateway(o);
  msg::GatewayInfo info;
  info.gateway("old");
  info.host("host");
  info.pid(1);
  msg::AxisDescription axis;
  axis.name("x");
  axis.bus("can0");
  axis.device("sim");
  axis.unit("mm");
  info.axes().push_back(axis);
  ASSERT_TRUE(gateway.writer(msg::TopicId::GatewayInfo).write(&info));
  msg::AxisState state;
  state.gateway("old");
  state.axis("x");
  state.state("operation_enabled");
  state.link("operational");
  dds::DataWriter& state_w = gateway.writer(msg::TopicId::AxisState);

  const auto start = std::chrono::steady_clock::now();
  CtlRun r = ctl("list");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("x  bus=can0"), std::string::npos) << r.output;
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(6)) << r.output;

  // axis_state is volatile: written until status has read it (as a gateway publishes it).
  std::atomic<bool> done{false};
  std::thread publisher([&] {
    while (!done) {
      state_w.write(&state);
      std::this_thread::sleep_for(std::chrono::milliseconds(20));  // the publication rate
    }
  });
  const auto status_start = std::chrono::steady_clock::now();
  r = ctl("status x");
  done = true;
  publisher.join();
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("operation_enabled"), std::string::npos) << r.output;
  EXPECT_LT(std::chrono::steady_clock::now() - status_start, std::chrono::seconds(6)) << r.output;
}

// A PROFINET axis: list shows its device's I&M0 from the link detail (a second line; --json an
// object), the CANopen axis nothing more. Records go by rec:SLOT:SUBSLOT:INDEX as bytes or typed;
// bad syntax stops drivegatectl before it sends anything, and a CANopen axis refuses a record.
TEST(DrivegatectlProfinet, ListShowsI_M0AndParamTakesRecords) {
  FakeRuntime rt("gw1", {"x", "pn"});
  rt.put_on_bus(1, "pn0", "profinet");
  rt.set_link(1, core::LinkState::Operational,
              "station \"akd-x\" (02:1b:1b:00:0a:01 at 192.168.0.10): in data exchange (AR 1); I&M0 order "
              "6ES7 155-6AU01 serial SIM 0001 hw 3 sw V1.2.3",
              FakeRuntime::kStampNs);
  rt.add_io("valves", 2, 2);  // on an EtherCAT bus
  daemon::DdsBridge bridge(rt, bridge_options());
  bridge.start();
  CtlRun r = ctl("list");
  EXPECT_EQ(r.status, 0) << r.output;
  const auto x_line = r.output.find("  x  bus=can0");
  ASSERT_NE(x_line, std::string::npos) << r.output;
  EXPECT_EQ(r.output.compare(r.output.find('\n', x_line), 14, "\n  pn  bus=pn0"), 0) << "x has no second line: " << r.output;
  EXPECT_NE(r.output.find("\n      order 6ES7 155-6AU01  serial SIM 0001  hw 3  sw V1.2.3\n"), std::string::npos)
      << r.output;
  r = ctl("--json list");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find(R"("bus_type":"profinet","address":36,"identity":{"order_id":"6ES7 155-6AU01",)"
                          R"("serial_number":"SIM 0001","hardware_revision":"3","software_revision":"V1.2.3"},)"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(r.output.find(R"("bus_type":"canopen","address":35,"identity")"), std::string::npos) << r.output;

  rt.set_object(1, 0xAFF0, 0, core::ParamType::OctetString, "00 20 00 38 01 00");
  r = ctl("param get pn rec:0:1:0xAFF0");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("pn rec:0:1:0xAFF0 = 00 20 00 38 01 00 (OCTET_STRING)"), std::string::npos) << r.output;
  r = ctl("param set pn rec:1:1:0x1000@0x3A00 0x0102 --type u16");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(rt.object(1, 0x1000, 0), (std::vector<std::uint8_t>{0x02, 0x01}));  // little-endian: the bus swaps
  r = ctl("param get pn rec:0:1");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("record address 'rec:0:1': a slot, a subslot and an index are needed; write "
                          "rec:SLOT:SUBSLOT:INDEX[@API]"),
            std::string::npos)
      << r.output;
  r = ctl("param get pn rec:0:1:0x10000");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("the index '0x10000' is no number of 0..0xFFFF"), std::string::npos) << r.output;
  r = ctl("param get x rec:0:1:0xAFF0");
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("axis 'x' is on canopen bus 'can0': 'rec:0:1:0xAFF0' is a PROFINET record address"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(rt.object(0, 0xAFF0, 0), std::vector<std::uint8_t>{});
  // An IO device is a record's target by its name too (found through its io_state); this one is
  // no PROFINET device.
  r = ctl("param get valves rec:0:1:0xAFF0");
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("IO device 'valves' is on ethercat bus 'ec0': 'rec:0:1:0xAFF0' is a PROFINET record address"),
            std::string::npos)
      << r.output;
}

TEST(DrivegateDemo, RunsTheWholeSequenceAndLeavesAxesDisabled) {
  FakeRuntime rt("demo", {"x", "y", "spindle", "turntable"});
  daemon::DdsBridge bridge(rt, bridge_options());
  bridge.start();
  const CtlRun r = run_tool(DRIVEGATE_DEMO_PATH, "--plain --jog-seconds 0.3");
  EXPECT_EQ(r.status, 0) << r.output;
  std::map<core::CommandKind, int> kinds;
  for (const auto& c : rt.commands()) ++kinds[c.command.kind];
  EXPECT_EQ(kinds[core::CommandKind::Enable], 4);
  EXPECT_EQ(kinds[core::CommandKind::Home], 1);
  EXPECT_EQ(kinds[core::CommandKind::Move], 8);
  EXPECT_EQ(kinds[core::CommandKind::Velocity], 1);
  EXPECT_EQ(kinds[core::CommandKind::Stop], 1);
  EXPECT_EQ(kinds[core::CommandKind::Disable], 4);
  EXPECT_EQ(rt.commands().back().command.kind, core::CommandKind::Disable);
}

// `buses` prints the distributed clocks' line only for a bus that has the figures; --json has
// the two fields only then.
TEST(DrivegatectlBuses, ClockFiguresShownOnlyForTheBusThatHasThem) {
  FakeRuntime rt("gw1", {"x"});
  daemon::BusStatus ec;
  ec.name = "ec0";
  ec.type = "ethercat";
  ec.running = true;
  ec.clock_sync = core::ClockSync{true, 42, -900};
  rt.add_bus(ec);
  daemon::DdsBridge bridge(rt, bridge_options());
  bridge.start();
  // bus_status is published at 1 Hz and each run of drivegatectl listens afresh: run it until it
  // has heard both buses.
  const auto until_both = [](const std::string& args, const char* first, const char* second) {
    CtlRun run;
    for (int i = 0; i < 20; ++i) {
      run = ctl(args);
      if (run.output.find(first) != std::string::npos && run.output.find(second) != std::string::npos) break;
    }
    return run;
  };
  CtlRun r = until_both("buses", "gw1/ec0", "gw1/can0");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("  distributed clocks: max difference 42ns  master - reference -900ns\n"), std::string::npos)
      << r.output;
  EXPECT_EQ(r.output.find("distributed clocks"), r.output.rfind("distributed clocks")) << r.output;  // ec0's only
  r = until_both("--json buses", R"("bus":"ec0")", R"("bus":"can0")");
  EXPECT_EQ(r.status, 0) << r.output;
  const auto ec_line = r.output.find(R"("bus":"ec0")");
  const auto can_line = r.output.find(R"("bus":"can0")");
  ASSERT_NE(ec_line, std::string::npos) << r.output;
  ASSERT_NE(can_line, std::string::npos) << r.output;
  const std::string ec_json = r.output.substr(ec_line, r.output.find('\n', ec_line) - ec_line);
  const std::string can_json = r.output.substr(can_line, r.output.find('\n', can_line) - can_line);
  EXPECT_NE(ec_json.find(R"("clock_difference_ns":42,"clock_master_offset_ns":-900)"), std::string::npos) << r.output;
  EXPECT_EQ(can_json.find("clock_"), std::string::npos) << r.output;
}

TEST(DrivegatectlUsage, BadUsageExitsWithTwo) {
  EXPECT_EQ(ctl("move x").status, 2);
  EXPECT_EQ(ctl("move x 1 --bogus 3").status, 2);
  EXPECT_EQ(ctl("frobnicate").status, 2);
  // A bad record address stops drivegatectl before discovery (no gateway runs here).
  const CtlRun bad = ctl("param get x rec:0:1:0xAFF0@api");
  EXPECT_EQ(bad.status, 2) << bad.output;
  EXPECT_NE(bad.output.find("record address 'rec:0:1:0xAFF0@api': the API 'api' is no 32-bit number"), std::string::npos)
      << bad.output;
  const CtlRun help = ctl("move --help");
  EXPECT_EQ(help.status, 0);
  EXPECT_NE(help.output.find("--relative"), std::string::npos);
}

}  // namespace
}  // namespace drivegate::dds_test
