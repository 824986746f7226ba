// The endpoint on an in-memory wire (MemoryLink pair: the master's end and the simulator's), no
// root needed: frames are answered in service(), the PDI ticks every 1 ms without frames, and
// nothing allocates while frames pass or ticks run.
#include <gtest/gtest.h>

#include <array>

#include "adapters/ethercat/link/ethercat_link.hpp"
#include "adapters/ethercat/sim/sim_endpoint.hpp"
#include "tests/ethercat_simtool/support.hpp"
#include "tests/support/alloc_counter.hpp"

namespace drivegate::ethercat::sim {
namespace {

using namespace std::chrono_literals;

struct Wire {
  Wire() : plan(test::plan_of(test::three_io_config("eth1"))), line(build_line(plan.buses.at(0))), endpoint(sim, *line) {
    MemoryLink::connect(master, sim);
    master.open();
    sim.open();
  }
  // A BRD from the master; its working counter when an answer is waiting after service(now).
  std::optional<std::uint16_t> count(core::TimePoint now) {
    std::array<std::uint8_t, kMaxFrameSize> tx{};
    FrameBuilder b(tx, test::kMasterMac, test::kMasterMac);
    EXPECT_TRUE(b.add(Command::BRD, 0x11, 0, 2).ok());
    const auto frame = b.finish();
    master.send(FrameView(frame.data(), frame.size()));
    endpoint.service(now);
    if (master.receive(rx) != 1) return std::nullopt;
    FrameParser p(rx[0].view());
    Datagram d;
    if (!p.next(d)) return std::nullopt;
    return d.wkc;
  }

  MemoryLink master{16};
  MemoryLink sim{16};
  config::Plan plan;
  std::unique_ptr<BuiltLine> line;
  SimEndpoint endpoint;
  std::array<FrameBuffer, 1> rx{};
};

TEST(EthercatEndpointMemory, AnswersFramesAndTicksWithoutThem) {
  Wire w;
  const core::TimePoint t0{std::chrono::seconds(5)};
  EXPECT_EQ(w.count(t0), 3);
  EXPECT_EQ(w.endpoint.counters().frames_in, 1U);
  EXPECT_EQ(w.endpoint.counters().frames_out, 1U);
  EXPECT_EQ(w.endpoint.counters().ticks, 1U);  // the first service() starts the schedule
  EXPECT_EQ(w.endpoint.next_tick(), t0 + 1ms);
  w.endpoint.service(t0 + 500us);
  EXPECT_EQ(w.endpoint.counters().ticks, 1U);
  w.endpoint.service(t0 + 1ms);
  EXPECT_EQ(w.endpoint.counters().ticks, 2U);
  // A stall of 10 ms: one tick, the schedule starts again from now.
  w.endpoint.service(t0 + 11ms + 200us);
  EXPECT_EQ(w.endpoint.counters().ticks, 3U);
  EXPECT_EQ(w.endpoint.next_tick(), t0 + 12ms + 200us);

  // A frame the line does not return (dropped) is counted, and nothing goes back.
  w.line->drop(1);
  EXPECT_FALSE(w.count(t0 + 13ms));
  EXPECT_EQ(w.endpoint.counters().no_answer, 1U);
  EXPECT_EQ(w.endpoint.counters().frames_out, 1U);
}

TEST(EthercatEndpointMemory, NothingAllocatesWhileFramesPass) {
  Wire w;
  core::TimePoint now{std::chrono::seconds(1)};
  EXPECT_EQ(w.count(now), 3);  // warm up
  std::array<std::uint8_t, kMaxFrameSize> tx{};
  FrameBuilder b(tx, test::kMasterMac, test::kMasterMac);
  ASSERT_TRUE(b.add(Command::BRD, 0x11, 0, 2).ok());
  const auto frame = b.finish();
  std::size_t answered = 0;
  const drivegate::test::AllocationScope scope;
  for (int i = 0; i < 200; ++i) {
    now += 500us;
    w.master.send(FrameView(frame.data(), frame.size()));
    w.endpoint.service(now);
    answered += w.master.receive(w.rx);
  }
  EXPECT_EQ(scope.count(), 0U);
  EXPECT_EQ(answered, 200U);
  EXPECT_EQ(w.line->slave(2).frames_seen, 201U);
}

}  // namespace
}  // namespace drivegate::ethercat::sim
