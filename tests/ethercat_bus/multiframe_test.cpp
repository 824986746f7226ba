// A line whose cyclic exchange spans several Ethernet frames per cycle: 64 generic CiA 402 drives
// (one LRW of 32 bytes each, plus DC's FRMW and the AL status check: 66 datagrams, two frames
// of at most 1514 bytes) reach OP on the in-memory simulated line with every slave's working
// counter right, the last slave (in the second frame) enables, nothing allocates per cycle, and the
// --check-config rows and refusals count the frames.
#include <gtest/gtest.h>

#include "config/describe.hpp"
#include "tests/ethercat_bus/bus_harness.hpp"
#include "tests/support/alloc_counter.hpp"

namespace drivegate::ethercat::test {
namespace {

using core::AxisState;
using core::CommandKind;
using core::ReplyStatus;

std::string drives_yaml(int n, const std::string& cycle_time = "1ms") {
  std::string y = "gateway: { name: ecat-test }\nbuses:\n  - name: ec0\n    type: ethercat\n    cycle_time: " + cycle_time +
                  "\n    options: { transport: sim, lost_cycles: 3 }\naxes:\n";
  for (int i = 1; i <= n; ++i)
    y += "  - { name: a" + std::to_string(i) + ", bus: ec0, address: " + std::to_string(i) +
         ", device: generic-cia402, mechanics: { encoder_counts_per_rev: 4096 } }\n";
  return y;
}

// One line for all the checks: 64 drives take a while to boot on the simulated line.
TEST(EthercatBusMultiFrame, SixtyFourDrivesInTwoFramesPerCycle) {
  EcatHarness h(drives_yaml(64), false);
  h.make_from_factory();
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 30s)) << h.details() << h.events_text();
  const ProcessImage& img = h.bus->image();
  ASSERT_EQ(img.slave_count(), 64U);
  ASSERT_EQ(img.frame_count(), 2U);
  EXPECT_EQ(img.expected_wkc(), 192);  // 64 × (LRW: read 1 + write 2)
  h.run_until([] { return false; }, 50ms);  // settle

  // Every slave's working counter right, cycle after cycle.
  const auto c0 = h.cx().counters();
  const auto b0 = h.bus->counters();
  for (int i = 0; i < 100; ++i) h.cycle();
  const auto c1 = h.cx().counters();
  const auto b1 = h.bus->counters();
  EXPECT_EQ(c1.good - c0.good, 100U);
  EXPECT_EQ(c1.wkc_errors - c0.wkc_errors, 0U);
  EXPECT_EQ(c1.lost - c0.lost, 0U);
  EXPECT_EQ(c1.refused - c0.refused, 0U);
  EXPECT_EQ(c1.last_wkc, 192);
  EXPECT_GE(b1.frames_sent - b0.frames_sent, 200U);  // two cyclic frames a cycle (+ mailbox polls)
  EXPECT_EQ(b1.frames_lost - b0.frames_lost, 0U);
  // Per slave: its own LRW came back with WKC 3 in the last cycle, and its inputs are that cycle's.
  for (std::size_t k = 0; k < 64; ++k) {
    EXPECT_EQ(h.cx().answered(k), SlaveAnswer::Answered) << "slave " << k + 1;
    EXPECT_EQ(h.cx().inputs_cycle(k), h.cx().last_completed_cycle()) << "slave " << k + 1;
    EXPECT_EQ(h.snap("a" + std::to_string(k + 1)).state, AxisState::SwitchOnDisabled) << "slave " << k + 1;
  }

  // Nothing allocates per cycle.
  {
    const auto good = h.cx().counters().good;
    const drivegate::test::AllocationScope scope;
    for (int i = 0; i < 200; ++i) {
      h.now += 1ms;
      h.runner->cycle(h.now);
    }
    EXPECT_EQ(scope.count(), 0U);
    EXPECT_EQ(h.cx().counters().good - good, 200U);
  }

  // The first slave (frame 1) and the last (frame 3) enable: outputs go out and inputs come back
  // in every frame of the cycle.
  for (const char* name : {"a1", "a64"}) {
    const auto id = h.push(name, CommandKind::Enable);
    ASSERT_EQ(h.wait_final(id, 3s), ReplyStatus::Completed) << name << ": " << h.reason(id) << h.events_text();
    EXPECT_EQ(h.snap(name).state, AxisState::OperationEnabled) << name;
  }
  EXPECT_EQ(h.snap("a32").state, AxisState::SwitchOnDisabled);
}

std::string row(const std::string& out, const std::string& label) {
  const std::size_t at = out.find("  " + label + ": ");
  if (at == std::string::npos) return "(no row " + label + ")";
  const std::size_t start = out.find_first_not_of(' ', at + label.size() + 4);
  return out.substr(start, out.find('\n', start) - start);
}

// --check-config: the frame row lists the frames (sizes as ProcessImage plans them:
// pdo_image_test.cpp SixtyFourSlavesTakeTwoFrames).
TEST(EthercatBusMultiFrameConfig, PrintoutCountsTheFrames) {
  const config::Plan plan = config::load_plan_from_string(drives_yaml(64), "ecat-test.yaml", load_options());
  const std::string out = config::describe_plan(plan);
  EXPECT_EQ(row(out, "image"), "2048 bytes (1088 out, 960 in) over 64 slaves, 64 datagrams, working counter 192") << out;
  EXPECT_EQ(row(out, "frame"),
            "2 frames (1502 + 1380 bytes), 234.4 us on the wire at 100 Mbit/s (round trip 298.4 us)")
      << out;
}

// Two frames that are not back within half the cycle, and a line that needs more frames than a
// cycle sends, are refused with the numbers.
TEST(EthercatBusMultiFrameConfig, RefusalsCountTheFrames) {
  try {
    config::load_plan_from_string(drives_yaml(64, "500us"), "fit.yaml", load_options());
    ADD_FAILURE() << "loaded";
  } catch (const config::ConfigError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("the 2 cyclic frames (2882 bytes, 298.4 us round trip with 64 slaves at 100 Mbit/s) do not fit "
                        "in half the cycle_time of 500.0 us"),
              std::string::npos)
        << what;
  }
  // Five I/O slaves of 1424 bytes: one whole-frame datagram each, five frames.
  std::string yaml = "gateway: { name: ecat-test }\nbuses:\n  - name: ec0\n    type: ethercat\n    cycle_time: 4ms\n"
                     "    options: { transport: sim }\n    io:\n";
  for (int i = 1; i <= 5; ++i)
    yaml += "      - { name: io" + std::to_string(i) + ", position: " + std::to_string(i) + ", inputs: 1024, outputs: 400 }\n";
  try {
    config::load_plan_from_string(yaml, "big.yaml", load_options());
    ADD_FAILURE() << "loaded";
  } catch (const config::ConfigError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("process image: process image of 7120 bytes: its 5 cyclic datagrams (and 2 more) need 5 Ethernet "
                        "frames, a cycle sends at most 4 (of 1514 bytes each)"),
              std::string::npos)
        << what;
  }
}

}  // namespace
}  // namespace drivegate::ethercat::test
