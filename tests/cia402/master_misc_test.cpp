// Parameter access, link loss, feedback, and the no-allocation guarantee of the cycle path.
#include <gtest/gtest.h>

#include "tests/cia402/master_harness.hpp"
#include "tests/support/alloc_counter.hpp"
#include "tests/support/param_request.hpp"

namespace drivegate::cia402::test {
namespace {

using core::CommandKind;

// A 1, 2 or 4-byte unsigned parameter request, the value encoded as the daemon encodes it.
core::ParamRequest param(core::CommandId id, std::uint16_t index, std::uint8_t sub, std::uint8_t size, bool write,
                         std::int64_t value = 0) {
  const auto type = *core::integer_param_type(size, false);
  return write ? drivegate::test::param_write(id, index, sub, type, std::to_string(value))
               : drivegate::test::param_read(id, index, sub, type);
}

TEST(Parameters, ReadAndWriteThroughAcyclicRequests) {
  Harness h;
  h.io.set_latency(1);
  h.io.set(ObjectId{0x6099, 1}, 10000);
  h.cycle(kSwSwitchOnDisabled);
  ASSERT_TRUE(h.master.parameter(param(11, 0x6099, 1, 4, false), h.now).accepted);
  ASSERT_TRUE(h.master.parameter(param(12, 0x6083, 0, 4, true, 50), h.now).accepted);
  h.cycle(kSwSwitchOnDisabled);
  EXPECT_TRUE(h.sink.params.empty());
  h.cycle(kSwSwitchOnDisabled);
  ASSERT_EQ(h.sink.params.size(), 2U);
  EXPECT_TRUE(h.sink.params[0].ok);
  EXPECT_EQ(h.sink.params[0].id, 11U);
  EXPECT_EQ(drivegate::test::reply_integer(h.sink.params[0]), 10000);
  EXPECT_TRUE(h.sink.params[1].ok);
  EXPECT_EQ(h.io.value(obj::kProfileAcceleration.id), 50);
}

TEST(Parameters, AbortCodeAndTextAreReported) {
  Harness h;
  h.io.set_latency(1);
  h.io.abort_on(ObjectId{0x6099, 1}, 0x06090031);  // AKD digest §12.8 row 56
  h.cycle(kSwSwitchOnDisabled);
  ASSERT_TRUE(h.master.parameter(param(11, 0x6099, 1, 4, true, 72000), h.now).accepted);
  h.cycle(kSwSwitchOnDisabled);
  h.cycle(kSwSwitchOnDisabled);
  ASSERT_EQ(h.sink.params.size(), 1U);
  EXPECT_FALSE(h.sink.params[0].ok);
  EXPECT_EQ(h.sink.params[0].error_code, 0x06090031U);
  EXPECT_EQ(h.sink.params[0].error.view(),
            "6099h:01: value of parameter written too high (download only) (abort code 0x06090031)");
}

TEST(Parameters, BadRequestsAreRejected) {
  Harness h;
  // A write whose bytes disagree with its type never reaches the drive cut short.
  auto wrong = param(2, 0x6081, 0, 4, true, 70000);
  wrong.size = 3;
  auto a = h.master.parameter(wrong, h.now);
  EXPECT_FALSE(a.accepted);
  EXPECT_EQ(a.reason.view(), "3 bytes do not fit a UNSIGNED32, which has 4");
  auto empty = param(3, 0x6081, 0, 4, true, 1);
  empty.size = 0;
  EXPECT_FALSE(h.master.parameter(empty, h.now).accepted);
  // Type unknown: a write of any length goes (the drive checks it).
  auto raw = drivegate::test::param_write(4, 0x2000, 0, core::ParamType::Domain, "01 02 03");
  raw.type = core::ParamType::Unknown;
  EXPECT_TRUE(h.master.parameter(raw, h.now).accepted);
  for (core::CommandId id = 5; id < 4 + Cia402Master::kMaxParameterRequests; ++id) {
    EXPECT_TRUE(h.master.parameter(param(id, 0x1000, 0, 4, false), h.now).accepted);
  }
  a = h.master.parameter(param(99, 0x1000, 0, 4, false), h.now);
  EXPECT_FALSE(a.accepted);
  EXPECT_TRUE(a.busy);
}

// Objects of any size travel as bytes; an upload whose size disagrees with the type is an error
// naming both sizes, never a value cut to size.
TEST(Parameters, StringsAndSizeMismatches) {
  Harness h;
  h.io.set_latency(1);
  const std::string name = "drivegate simulated servo drive";  // 31 bytes: segmented on CANopen
  h.io.set_bytes(ObjectId{0x1008, 0}, std::span(reinterpret_cast<const std::uint8_t*>(name.data()), name.size()));
  h.io.set_bytes(ObjectId{0x2001, 0}, std::array<std::uint8_t, 2>{0x34, 0x12});
  h.cycle(kSwSwitchOnDisabled);
  ASSERT_TRUE(h.master.parameter(drivegate::test::param_read(1, 0x1008, 0, core::ParamType::VisibleString), h.now).accepted);
  ASSERT_TRUE(h.master.parameter(drivegate::test::param_read(2, 0x1008, 0, core::ParamType::U32), h.now).accepted);
  ASSERT_TRUE(h.master.parameter(drivegate::test::param_read(3, 0x2001, 0, core::ParamType::U32), h.now).accepted);
  ASSERT_TRUE(h.master.parameter(drivegate::test::param_read(4, 0x2001, 0), h.now).accepted);
  ASSERT_TRUE(h.master.parameter(drivegate::test::param_write(5, 0x2002, 0, core::ParamType::U64, "0x1122334455667788"), h.now).accepted);
  h.cycle(kSwSwitchOnDisabled);
  h.cycle(kSwSwitchOnDisabled);
  ASSERT_EQ(h.sink.params.size(), 5U);
  const auto& str = h.sink.params[0];
  ASSERT_TRUE(str.ok) << str.error.view();
  EXPECT_EQ(str.type, core::ParamType::VisibleString);
  EXPECT_EQ(std::string(reinterpret_cast<const char*>(str.data.data()), str.size), name);
  EXPECT_FALSE(h.sink.params[1].ok);
  EXPECT_EQ(h.sink.params[1].error.view(), "1008h:00: the drive sent 31 bytes, a UNSIGNED32 has 4");
  EXPECT_FALSE(h.sink.params[2].ok);
  EXPECT_EQ(h.sink.params[2].error.view(), "2001h:00: the drive sent 2 bytes, a UNSIGNED32 has 4");
  ASSERT_TRUE(h.sink.params[3].ok);  // type unknown: the bytes as they came
  EXPECT_EQ(h.sink.params[3].size, 2U);
  EXPECT_EQ(h.sink.params[3].data[0], 0x34);
  ASSERT_TRUE(h.sink.params[4].ok);
  const auto written = h.io.bytes(ObjectId{0x2002, 0});
  ASSERT_EQ(written.size(), 8U);
  EXPECT_EQ(written[0], 0x88);
  EXPECT_EQ(written[7], 0x11);
}

TEST(Parameters, QueueFullIsRetried) {
  Harness h;
  h.io.set_latency(1);
  h.io.set_queue_full(true);
  h.cycle(kSwSwitchOnDisabled);
  ASSERT_TRUE(h.master.parameter(param(11, 0x1000, 0, 4, false), h.now).accepted);
  h.cycle(kSwSwitchOnDisabled);
  h.cycle(kSwSwitchOnDisabled);
  EXPECT_TRUE(h.sink.params.empty());
  h.io.set_queue_full(false);
  h.cycle(kSwSwitchOnDisabled);
  h.cycle(kSwSwitchOnDisabled);
  ASSERT_EQ(h.sink.params.size(), 1U);
  EXPECT_TRUE(h.sink.params[0].ok);
}

TEST(LinkLoss, FailsEverythingAndComesBackDisabled) {
  Harness h;
  h.enable();
  ASSERT_TRUE(h.submit(command(7, CommandKind::Move)).accepted);
  ASSERT_TRUE(h.submit(command(8, CommandKind::Halt)).accepted);
  ASSERT_TRUE(h.master.parameter(param(9, 0x1000, 0, 4, false), h.now).accepted);
  h.cycle(kSwEnabled);
  h.master.link_lost(h.now, h.sink);
  EXPECT_EQ(h.sink.failure(7), "link to drive lost");
  EXPECT_EQ(h.sink.failure(8), "link to drive lost");
  ASSERT_EQ(h.sink.params.size(), 1U);
  EXPECT_FALSE(h.sink.params[0].ok);
  EXPECT_EQ(h.sink.params[0].error.view(), "link to drive lost");
  EXPECT_EQ(h.cw(), 0x0000);
  EXPECT_FALSE(h.master.feedback().valid);
  EXPECT_EQ(h.master.feedback().state, core::AxisState::Unknown);
  EXPECT_FALSE(h.submit(command(10, CommandKind::Move)).accepted);
  // The drive comes back (still enabled, say): the master does not re-enable or move by itself.
  EXPECT_EQ(h.cycle(kSwSwitchOnDisabled), 0x0000);
  EXPECT_EQ(h.cycle(kSwSwitchOnDisabled), 0x0000);
}

TEST(Feedback, FilledEveryCycle) {
  Harness h;
  h.io.set(obj::kPositionActual.id, -1861);
  h.io.set(obj::kVelocityActual.id, 250);
  h.io.set(obj::kTorqueActual.id, -40);
  h.cycle(0x2E37);  // enabled + target reached + internal limit + bit 13
  const auto& fb = h.master.feedback();
  EXPECT_TRUE(fb.valid);
  EXPECT_EQ(fb.state, core::AxisState::OperationEnabled);
  EXPECT_EQ(fb.mode, core::Mode::ProfilePosition);
  EXPECT_EQ(fb.position, -1861);
  EXPECT_EQ(fb.velocity, 250);
  EXPECT_EQ(fb.torque, -40);
  EXPECT_EQ(fb.statusword, 0x2E37);
  EXPECT_TRUE(fb.target_reached);
  EXPECT_TRUE(fb.internal_limit);
  EXPECT_TRUE(fb.following_error);
}

TEST(Feedback, StaleInputsAreNotDecoded) {
  Harness h;
  h.io.set_fresh(false);
  h.cycle(kSwEnabled);
  EXPECT_FALSE(h.master.feedback().valid);
}

TEST(Feedback, UnmappedStatuswordIsPolled) {
  Harness h;
  h.io.unmap(obj::kStatusword.id);
  h.io.unmap(obj::kControlword.id);
  h.io.set_latency(1);
  h.cycle(kSwSwitchOnDisabled);
  h.cycle(kSwSwitchOnDisabled);
  EXPECT_EQ(h.master.feedback().state, core::AxisState::SwitchOnDisabled);
  ASSERT_TRUE(h.submit(command(1, CommandKind::Enable)).accepted);
  for (int i = 0; i < 3; ++i) h.cycle(kSwSwitchOnDisabled);
  EXPECT_EQ(h.io.value(obj::kControlword.id), 0x0006);  // written acyclically (AKD digest §12.2)
}

// The master resolves the image's objects once per mapping: when the adapter reconfigures the drive
// with another mapping (a new mapping generation), it follows at once. Here the controlword leaves
// the image (written acyclically from then on), then returns (written into the image again, no
// acyclic write any more).
TEST(ImageRefs, MasterFollowsAReconfiguredMapping) {
  Harness h;
  h.io.set_latency(1);
  h.cycle(kSwSwitchOnDisabled);
  ASSERT_TRUE(h.submit(command(1, CommandKind::Enable)).accepted);
  h.cycle(kSwSwitchOnDisabled);
  EXPECT_EQ(h.cw(), 0x0006);
  EXPECT_EQ(h.io.acyclic_writes(), 0U);

  h.io.unmap(obj::kControlword.id);
  h.io.set(obj::kControlword.id, 0);
  h.cycle(kSwSwitchOnDisabled);
  ASSERT_EQ(h.io.acyclic_writes(), 1U);
  EXPECT_EQ(h.io.acyclic_write(0).id, obj::kControlword.id);
  EXPECT_EQ(h.io.acyclic_write(0).value, 0x0006);
  h.cycle(kSwSwitchOnDisabled);  // the acyclic write completes
  EXPECT_EQ(h.cw(), 0x0006);

  h.io.map(obj::kControlword.id);
  h.io.set(obj::kControlword.id, 0);
  h.cycle(kSwReady);  // shutdown done: switch on goes out in the image
  EXPECT_EQ(h.cw(), 0x0007);
  h.cycle(kSwSwitchedOn);
  EXPECT_EQ(h.cw(), 0x000F);
  EXPECT_EQ(h.io.acyclic_writes(), 1U);
}

// A sink that records nothing, so that only the master's own allocations count.
struct CountingSink final : core::ControllerSink {
  std::size_t completed_n = 0, failed_n = 0, events_n = 0, params_n = 0;
  void completed(core::CommandId) noexcept override { ++completed_n; }
  void failed(core::CommandId, std::string_view) noexcept override { ++failed_n; }
  void event(core::EventKind, std::uint32_t, std::string_view) noexcept override { ++events_n; }
  void parameter_done(const core::ParamReply&) noexcept override { ++params_n; }
};

TEST(NoAllocation, UpdateSubmitSetpointAndParametersDoNotTouchTheHeap) {
  FakeObjectAccess io;
  for (const ObjectDef* d : {&obj::kControlword, &obj::kStatusword, &obj::kModesOfOperation, &obj::kModesOfOperationDisplay,
                             &obj::kPositionActual, &obj::kVelocityActual, &obj::kTargetPosition}) {
    io.map(d->id);
  }
  io.set(obj::kModesOfOperationDisplay.id, op_mode::kProfilePosition);
  io.set_latency(1);
  MasterSettings settings;
  Cia402Master master(io, settings);
  CountingSink sink;
  core::TimePoint now{};
  const auto cycle = [&](std::uint16_t sw) {
    io.set(obj::kStatusword.id, sw);
    master.update(now, sink);
    now += 1ms;
  };
  const ::drivegate::test::AllocationScope scope;
  cycle(kSwSwitchOnDisabled);
  (void)master.submit(command(1, CommandKind::Enable), now, sink);
  cycle(kSwSwitchOnDisabled);
  cycle(kSwReady);
  cycle(kSwSwitchedOn);
  cycle(kSwEnabled);
  auto mv = command(2, CommandKind::Move);
  mv.profile_velocity = 100;  // acyclic (6081h unmapped)
  (void)master.submit(mv, now, sink);
  (void)master.submit(command(3, CommandKind::Move), now, sink);  // supersedes: formats a reason
  for (int i = 0; i < 3; ++i) cycle(kSwEnabled);
  cycle(kSwEnabledAck);
  cycle(kSwEnabledReached);
  cycle(kSwEnabledReached);
  core::ParamRequest rq;
  rq.id = 4;
  rq.index = 0x1000;
  (void)master.parameter(rq, now);
  cycle(kSwEnabled);
  cycle(kSwEnabled);
  (void)master.submit(command(5, CommandKind::SetMode, core::Mode::CyclicPosition), now, sink);
  io.set(obj::kModesOfOperationDisplay.id, op_mode::kCyclicPosition);
  cycle(kSwEnabled);
  core::DriveSetpoint sp;
  sp.position = 7;
  master.setpoint(sp, now);
  cycle(kSwEnabled);
  cycle(kSwFault);
  (void)master.submit(command(6, CommandKind::FaultReset), now, sink);
  cycle(kSwFault);
  cycle(kSwSwitchOnDisabled);
  master.link_lost(now, sink);
  EXPECT_EQ(scope.count(), 0U);
  EXPECT_GE(sink.completed_n, 4U);
  EXPECT_GE(sink.failed_n, 1U);
  EXPECT_EQ(sink.params_n, 1U);
}

}  // namespace
}  // namespace drivegate::cia402::test
