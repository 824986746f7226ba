// The in-process bus emulates the wire: timing, arbitration, queues, bus-off, loss and load.
#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <vector>

#include "adapters/canopen/transport/inproc_bus.hpp"
#include "adapters/canopen/wire/bit_timing.hpp"
#include "tests/support/alloc_counter.hpp"

namespace drivegate::canopen {
namespace {

using namespace std::chrono_literals;

constexpr core::TimePoint t0 = core::TimePoint{} + 1s;
constexpr auto kEightBytes = 270us;  // 135 bits at 500 kbit/s (wire/bit_timing.hpp)

CanFrame frame(std::uint32_t id, std::uint8_t dlc = 8, std::uint8_t fill = 0) {
  CanFrame f;
  f.id = id;
  f.dlc = dlc;
  f.data.fill(fill);
  return f;
}

std::vector<CanFrame> drain(Transport& t, core::TimePoint now) {
  std::array<CanFrame, 64> buf{};
  std::vector<CanFrame> out;
  for (std::size_t n; (n = t.receive(buf, now)) > 0;) out.insert(out.end(), buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n));
  return out;
}

std::vector<std::uint32_t> ids(const std::vector<CanFrame>& frames) {
  std::vector<std::uint32_t> out;
  for (const auto& f : frames) out.push_back(f.id);
  return out;
}

struct ThreeNodes : ::testing::Test {
  InprocBus bus{500'000};
  std::unique_ptr<InprocEndpoint> a = bus.connect();
  std::unique_ptr<InprocEndpoint> b = bus.connect();
  std::unique_ptr<InprocEndpoint> c = bus.connect();
  void SetUp() override {
    a->open();
    b->open();
    c->open();
  }
};

TEST_F(ThreeNodes, EightByteFrameArrivesAfter270usAtEveryOtherNode) {
  static_assert(frame_time(8, 500'000) == kEightBytes);
  ASSERT_EQ(a->send(frame(0x181, 8, 0x5A), t0), SendResult::Sent);
  EXPECT_TRUE(drain(*b, t0 + kEightBytes - 1ns).empty());
  const auto got = drain(*b, t0 + kEightBytes);
  ASSERT_EQ(got.size(), 1U);
  EXPECT_EQ(got[0].id, 0x181U);
  EXPECT_EQ(got[0].data[7], 0x5A);
  EXPECT_EQ(got[0].timestamp, t0 + kEightBytes);  // reception = end of transmission
  EXPECT_EQ(drain(*c, t0 + 1ms).size(), 1U);
  EXPECT_TRUE(drain(*a, t0 + 1ms).empty());  // a sender does not hear itself
  EXPECT_EQ(a->counters().tx_frames, 1U);
  EXPECT_EQ(b->counters().rx_frames, 1U);
  EXPECT_TRUE(bus.idle());
}

TEST_F(ThreeNodes, NextChangeAndAvailableLetACallerRunTheWireOnAClock) {
  EXPECT_EQ(bus.next_change(), core::TimePoint::max());
  ASSERT_EQ(a->send(frame(0x181, 8), t0), SendResult::Sent);
  EXPECT_EQ(bus.next_change(), t0 + 1ns);  // it starts once time has moved past its queueing
  bus.advance(t0 + 1ns);
  EXPECT_EQ(bus.next_change(), t0 + kEightBytes);  // then it ends
  bus.advance(t0 + kEightBytes - 1ns);
  EXPECT_EQ(b->available(), 0U);
  bus.advance(bus.next_change());
  EXPECT_EQ(b->available(), 1U);
  EXPECT_EQ(c->available(), 1U);
  EXPECT_EQ(a->available(), 0U);
  EXPECT_EQ(bus.next_change(), core::TimePoint::max());
  EXPECT_EQ(drain(*b, t0 + 1ms).size(), 1U);
  EXPECT_EQ(b->available(), 0U);
}

TEST_F(ThreeNodes, FramesQueueBackToBackAtTheirLength) {
  // Three frames from one node: FIFO, each starts when the previous ends.
  ASSERT_EQ(a->send(frame(0x201, 8), t0), SendResult::Sent);
  ASSERT_EQ(a->send(frame(0x80, 0), t0), SendResult::Sent);  // SYNC: 55 bits = 110 us
  ASSERT_EQ(a->send(frame(0x301, 2), t0), SendResult::Sent);
  const auto got = drain(*b, t0 + 10ms);
  ASSERT_EQ(ids(got), (std::vector<std::uint32_t>{0x201, 0x80, 0x301}));
  EXPECT_EQ(got[0].timestamp, t0 + 270us);
  EXPECT_EQ(got[1].timestamp, t0 + 270us + 110us);
  EXPECT_EQ(got[2].timestamp, t0 + 380us + frame_time(2, 500'000));
}

TEST_F(ThreeNodes, LowestIdWinsAmongFramesWaitingWhenTheBusFrees) {
  // Sent at the same instant on an idle bus: arbitration, not call order, decides.
  ASSERT_EQ(a->send(frame(0x300), t0), SendResult::Sent);
  ASSERT_EQ(b->send(frame(0x100), t0), SendResult::Sent);
  // While 0x100 is on the wire, more arrive; a's queue is FIFO, so its 0x050 waits behind 0x300
  // until 0x300 is sent, and only then beats 0x200.
  ASSERT_EQ(a->send(frame(0x050), t0 + 10us), SendResult::Sent);
  ASSERT_EQ(b->send(frame(0x200), t0 + 20us), SendResult::Sent);
  const auto got = drain(*c, t0 + 10ms);
  EXPECT_EQ(ids(got), (std::vector<std::uint32_t>{0x100, 0x200, 0x300, 0x050}));
  // A frame sent after the bus freed up does not pre-empt the one already on the wire.
  ASSERT_EQ(a->send(frame(0x700), t0 + 20ms), SendResult::Sent);
  ASSERT_EQ(b->send(frame(0x001), t0 + 20ms + 1us), SendResult::Sent);
  EXPECT_EQ(ids(drain(*c, t0 + 30ms)), (std::vector<std::uint32_t>{0x700, 0x001}));
}

TEST_F(ThreeNodes, ArbitrationFollowsTheBitOrderOfFormatAndRtr) {
  CanFrame rtr = frame(0x100, 1);
  rtr.remote = true;
  CanFrame ext = frame(0x100U << 18, 1);  // the same 11 leading bits, extended
  ext.extended = true;
  ASSERT_EQ(a->send(ext, t0), SendResult::Sent);
  ASSERT_EQ(b->send(rtr, t0), SendResult::Sent);
  ASSERT_EQ(c->send(frame(0x100, 1), t0), SendResult::Sent);
  auto got = drain(*a, t0 + 10ms);
  auto more = drain(*b, t0 + 10ms);
  // a hears c's data frame first, then b's remote frame; b hears the data frame, then a's.
  ASSERT_EQ(got.size(), 2U);
  EXPECT_FALSE(got[0].remote);
  EXPECT_TRUE(got[1].remote);
  ASSERT_EQ(more.size(), 2U);
  EXPECT_FALSE(more[0].extended);
  EXPECT_TRUE(more[1].extended);
  EXPECT_EQ(more[1].timestamp,
            t0 + frame_time(1, 500'000) + frame_time(1, 500'000, false, true) + frame_time(1, 500'000, true));
}

TEST(InprocBus, InstantBusDeliversWithinSend) {
  InprocBus bus(0);
  auto a = bus.connect();
  auto b = bus.connect();
  a->open();
  b->open();
  ASSERT_EQ(a->send(frame(0x181), t0), SendResult::Sent);
  const auto got = drain(*b, t0);
  ASSERT_EQ(got.size(), 1U);
  EXPECT_EQ(got[0].timestamp, t0);
  EXPECT_EQ(a->describe(), "inproc bus (instant), endpoint 0");
}

TEST_F(ThreeNodes, TxQueueLimitGivesBusyUntilFramesLeave) {
  bus.set_tx_queue_limit(*a, 2);
  ASSERT_EQ(a->send(frame(0x181), t0), SendResult::Sent);
  ASSERT_EQ(a->send(frame(0x182), t0), SendResult::Sent);
  EXPECT_EQ(a->send(frame(0x183), t0), SendResult::Busy);
  EXPECT_EQ(a->counters().tx_overflows, 1U);
  // Once 0x181 is on the wire (time has passed t0) it has left the queue: one place is free.
  EXPECT_EQ(a->send(frame(0x183), t0 + 1us), SendResult::Sent);
  EXPECT_EQ(a->send(frame(0x184), t0 + 2us), SendResult::Busy);
  EXPECT_EQ(a->send(frame(0x184), t0 + 300us), SendResult::Sent);  // 0x182 followed at 270 us
  EXPECT_EQ(ids(drain(*b, t0 + 10ms)), (std::vector<std::uint32_t>{0x181, 0x182, 0x183, 0x184}));
  EXPECT_EQ(a->counters().tx_frames, 4U);
  EXPECT_EQ(a->counters().tx_overflows, 2U);
}

TEST_F(ThreeNodes, BusOffStopsTheNodeAndRecoveryCountsARestart) {
  ASSERT_EQ(a->send(frame(0x181), t0), SendResult::Sent);
  ASSERT_EQ(a->send(frame(0x182), t0), SendResult::Sent);
  ASSERT_EQ(a->send(frame(0x183), t0), SendResult::Sent);
  bus.advance(t0 + 1us);  // 0x181 is on the wire
  bus.set_bus_off(*a, true);
  EXPECT_EQ(a->controller_state(), ControllerState::BusOff);
  EXPECT_EQ(a->send(frame(0x184), t0 + 2us), SendResult::Down);
  ASSERT_EQ(b->send(frame(0x281), t0 + 2us), SendResult::Sent);
  // The frame on the wire completes; the queued ones are abandoned; a hears nothing.
  EXPECT_EQ(ids(drain(*c, t0 + 10ms)), (std::vector<std::uint32_t>{0x181, 0x281}));
  EXPECT_TRUE(drain(*a, t0 + 10ms).empty());
  EXPECT_EQ(bus.stats().flushed, 2U);
  auto counters = a->counters();
  EXPECT_EQ(counters.bus_off, 1U);
  EXPECT_EQ(counters.error_frames, 1U);
  EXPECT_EQ(counters.restarts, 0U);
  EXPECT_EQ(b->controller_state(), ControllerState::Active);

  bus.set_bus_off(*a, true);  // no change, nothing counted
  EXPECT_EQ(a->counters().bus_off, 1U);
  bus.set_bus_off(*a, false);
  EXPECT_EQ(a->controller_state(), ControllerState::Active);
  counters = a->counters();
  EXPECT_EQ(counters.restarts, 1U);
  EXPECT_EQ(counters.error_frames, 2U);
  ASSERT_EQ(a->send(frame(0x185), t0 + 20ms), SendResult::Sent);
  ASSERT_EQ(b->send(frame(0x282), t0 + 20ms), SendResult::Sent);
  EXPECT_EQ(ids(drain(*c, t0 + 30ms)), (std::vector<std::uint32_t>{0x185, 0x282}));
  EXPECT_EQ(ids(drain(*a, t0 + 30ms)), (std::vector<std::uint32_t>{0x282}));
}

TEST_F(ThreeNodes, DropHookLosesFramesButTheyStillTakeBusTime) {
  bus.drop_next(0x181, 2);
  for (int i = 0; i < 3; ++i) ASSERT_EQ(a->send(frame(0x181, 8, static_cast<std::uint8_t>(i)), t0), SendResult::Sent);
  ASSERT_EQ(a->send(frame(0x182), t0), SendResult::Sent);
  const auto got = drain(*b, t0 + 10ms);
  ASSERT_EQ(ids(got), (std::vector<std::uint32_t>{0x181, 0x182}));
  EXPECT_EQ(got[0].data[0], 2);  // the third one
  EXPECT_EQ(got[0].timestamp, t0 + 3 * kEightBytes);
  EXPECT_EQ(bus.stats().dropped, 2U);
  EXPECT_EQ(bus.stats().frames, 4U);
  // Used up: the next one goes through.
  ASSERT_EQ(a->send(frame(0x181), t0 + 20ms), SendResult::Sent);
  EXPECT_EQ(drain(*b, t0 + 30ms).size(), 1U);
}

TEST_F(ThreeNodes, CorruptHookAltersDataAndLength) {
  Corruption how;
  how.xor_mask = {0x01, 0, 0, 0, 0, 0, 0, 0x80};
  how.dlc = 3;
  bus.corrupt_next(0x601, 1, how);
  ASSERT_EQ(a->send(frame(0x601, 8, 0x10), t0), SendResult::Sent);
  ASSERT_EQ(a->send(frame(0x601, 8, 0x10), t0), SendResult::Sent);
  const auto got = drain(*b, t0 + 10ms);
  ASSERT_EQ(got.size(), 2U);
  EXPECT_EQ(got[0].dlc, 3);
  EXPECT_EQ(got[0].data[0], 0x11);
  EXPECT_EQ(got[0].data[1], 0x10);
  EXPECT_EQ(got[0].data[7], 0x90);
  EXPECT_EQ(got[1].dlc, 8);  // only the next one
  EXPECT_EQ(got[1].data[0], 0x10);
  EXPECT_EQ(bus.stats().corrupted, 1U);
  EXPECT_THROW(bus.corrupt_next(0x601, 1, Corruption{.xor_mask = {}, .dlc = 9}), std::invalid_argument);
  for (int i = 0; i < 16; ++i) bus.drop_next(0x700, 1);
  EXPECT_THROW(bus.drop_next(0x700, 1), std::length_error);
}

TEST_F(ThreeNodes, LoadIsTheBusyShareOfTheWindow) {
  bus.start_load_window(t0);
  // One 8-byte frame every millisecond for 100 ms: 270 us of 1000 us.
  for (int i = 0; i < 100; ++i) {
    ASSERT_EQ(a->send(frame(0x181), t0 + i * 1ms), SendResult::Sent);
    drain(*b, t0 + i * 1ms);
  }
  EXPECT_NEAR(bus.load(t0 + 100ms), 0.27, 1e-9);
  // Mid-frame: only the part already on the wire counts.
  bus.start_load_window(t0 + 100ms);
  ASSERT_EQ(a->send(frame(0x181), t0 + 100ms), SendResult::Sent);
  EXPECT_NEAR(bus.load(t0 + 100ms + 100us), 1.0, 1e-9);
  EXPECT_NEAR(bus.load(t0 + 100ms + 540us), 0.5, 1e-9);
  // A window opened during a frame counts that frame's remainder.
  ASSERT_EQ(a->send(frame(0x181), t0 + 200ms), SendResult::Sent);
  bus.start_load_window(t0 + 200ms + 70us);
  EXPECT_NEAR(bus.load(t0 + 200ms + 470us), 0.5, 1e-9);
  EXPECT_EQ(bus.stats().frames, 102U);
  EXPECT_EQ(bus.stats().busy, 102 * kEightBytes);
}

TEST_F(ThreeNodes, ClosedAndInvalidAreRefusedAndAFullReceiveQueueCountsOverruns) {
  c->close();
  EXPECT_EQ(c->send(frame(0x181), t0), SendResult::Down);
  CanFrame bad = frame(0x800);
  EXPECT_EQ(a->send(bad, t0), SendResult::Invalid);
  bad = frame(0x181);
  bad.dlc = 9;
  EXPECT_EQ(a->send(bad, t0), SendResult::Invalid);
  ASSERT_EQ(a->send(frame(0x181), t0), SendResult::Sent);
  EXPECT_TRUE(drain(*c, t0 + 1ms).empty());  // closed: not delivered
  EXPECT_EQ(drain(*b, t0 + 1ms).size(), 1U);

  InprocBus small(0, InprocBusOptions{.max_endpoints = 2, .tx_queue_capacity = 4, .rx_queue_capacity = 2});
  auto x = small.connect();
  auto y = small.connect();
  EXPECT_THROW(small.connect(), std::length_error);
  x->open();
  y->open();
  for (int i = 0; i < 3; ++i) ASSERT_EQ(x->send(frame(0x181), t0), SendResult::Sent);
  EXPECT_EQ(drain(*y, t0).size(), 2U);
  EXPECT_EQ(small.stats().rx_overruns, 1U);
}

TEST_F(ThreeNodes, SendReceiveAndAdvanceAllocateNothing) {
  std::array<CanFrame, 16> buf{};
  std::size_t received = 0;
  bus.drop_next(0x183, 1);
  test::AllocationScope scope;
  for (int i = 0; i < 200; ++i) {
    const auto now = t0 + i * 1ms;
    a->send(frame(0x181), now);
    b->send(frame(0x182), now);
    c->send(frame(0x183), now);
    bus.advance(now + 100us);
    received += a->receive(buf, now + 500us) + b->receive(buf, now + 500us) + c->receive(buf, now + 900us);
  }
  const auto end = t0 + 1s;
  received += a->receive(buf, end) + b->receive(buf, end) + c->receive(buf, end);
  const auto allocations = scope.count();
  EXPECT_EQ(allocations, 0U);
  EXPECT_EQ(received, 200U * 6 - 2);  // each frame reaches two nodes; one 0x183 dropped
}

// A batch that finds the transmit queue full stops there: what went out and what was refused for
// good are taken, the frame that found no room is neither (one overflow counted), so the caller
// keeps it and the rest for later.
TEST(InprocBus, SendBatchStopsAtAFullQueueAndCountsIt) {
  InprocBus bus(500'000);
  auto a = bus.connect();
  auto b = bus.connect();
  a->open();
  b->open();
  bus.set_tx_queue_limit(*a, 4);
  std::vector<CanFrame> frames;
  for (std::uint32_t i = 0; i < 10; ++i) frames.push_back(frame(0x100 + i));
  frames[1].dlc = 9;  // invalid: refused, taken
  const auto r = a->send_batch(frames, t0);
  EXPECT_TRUE(r.busy);
  EXPECT_EQ(r.taken, 5U);  // four queued and the invalid one; frames[5] found the queue full
  EXPECT_EQ(r.sent, 4U);
  EXPECT_EQ(a->counters().tx_overflows, 1U);
  EXPECT_EQ(a->counters().tx_frames, 4U);
  bus.advance(t0 + 10ms);
  EXPECT_EQ(ids(drain(*b, t0 + 10ms)), (std::vector<std::uint32_t>{0x100, 0x102, 0x103, 0x104}));
  // The rest goes once there is room, in order.
  const auto rest = a->send_batch(std::span<const CanFrame>(frames).subspan(r.taken), t0 + 10ms);
  EXPECT_TRUE(rest.busy);
  EXPECT_EQ(rest.taken, 4U);
  bus.advance(t0 + 20ms);
  EXPECT_EQ(ids(drain(*b, t0 + 20ms)), (std::vector<std::uint32_t>{0x105, 0x106, 0x107, 0x108}));
}

}  // namespace
}  // namespace drivegate::canopen
