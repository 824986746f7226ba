// Safety regressions of the master against the simulated drive: nothing moves after a bare enable,
// ip does not jump, abandoned acyclic requests do not exhaust the adapter, fault reset and disable
// do what the drive state allows.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>

#include "profiles/cia402/controlword.hpp"
#include "tests/cia402/model_bench.hpp"
#include "tests/support/param_request.hpp"

namespace drivegate::cia402::test {
namespace {

using core::CommandKind;
using core::Mode;

core::DriveCommand velocity(core::CommandId id, std::int32_t v) {
  auto c = command(id, CommandKind::Velocity, Mode::ProfileVelocity);
  c.target_velocity = v;
  c.profile_acceleration = 50000;
  c.profile_deceleration = 50000;
  return c;
}

std::size_t final_replies(const RecordingSink& s, core::CommandId id) {
  std::size_t n = 0;
  for (auto c : s.completed_ids) n += c == id ? 1U : 0U;
  for (const auto& f : s.failures) n += f.id == id ? 1U : 0U;
  return n;
}

TEST(SafetyVsModel, BareEnableAfterQuickStopDoesNotResumeTheOldVelocity) {
  ModelBench b;
  b.enable();
  ASSERT_TRUE(b.submit(velocity(2, 5000)));
  ASSERT_TRUE(b.run(2, 3000));
  // The quick stop the gateway sends when the commanding client goes silent.
  ASSERT_TRUE(b.submit(command(3, CommandKind::QuickStop)));
  ASSERT_TRUE(b.run(3, 3000));
  b.cycles(1000);
  ASSERT_EQ(b.model.state(), sim::DriveState::SwitchOnDisabled);  // 605Ah = 2: ramp, then disabled
  EXPECT_EQ(b.io.read(obj::kTargetVelocity.id), 0);
  const double stood_at = b.model.position();
  ASSERT_TRUE(b.submit(command(4, CommandKind::Enable)));
  ASSERT_TRUE(b.run(4, 100));
  b.cycles(2000);
  EXPECT_EQ(b.model.state(), sim::DriveState::OperationEnabled);
  EXPECT_NEAR(b.model.velocity(), 0.0, 1.0);
  EXPECT_NEAR(b.model.position(), stood_at, 5.0);
}

TEST(SafetyVsModel, BareEnableAfterDisableDoesNotResumeTheOldTorque) {
  ModelBench b;
  b.enable();
  auto c = command(2, CommandKind::Torque);
  c.target_torque = 100;
  c.torque_slope = 10000;
  ASSERT_TRUE(b.submit(c));
  ASSERT_TRUE(b.run(2, 2000));
  ASSERT_TRUE(b.submit(command(3, CommandKind::Disable)));
  ASSERT_TRUE(b.run(3, 100));
  b.cycles(500);
  ASSERT_TRUE(b.submit(command(4, CommandKind::Enable)));
  ASSERT_TRUE(b.run(4, 100));
  b.cycles(500);
  EXPECT_NEAR(b.model.torque(), 0.0, 1.0);
}

TEST(SafetyVsModel, BareEnableAfterLinkLossDoesNotResumeTheOldVelocity) {
  ModelBench b;
  b.enable();
  ASSERT_TRUE(b.submit(velocity(2, 5000)));
  ASSERT_TRUE(b.run(2, 3000));
  b.io.set_link_up(false);
  b.master.link_lost(b.now, b.sink);
  b.cycles(10);
  b.io.set_link_up(true);
  b.cycles(1000);  // controlword 0 reaches the drive: it coasts to a stop, disabled
  ASSERT_EQ(b.model.state(), sim::DriveState::SwitchOnDisabled);
  ASSERT_TRUE(b.submit(command(3, CommandKind::Enable)));
  ASSERT_TRUE(b.run(3, 100));
  b.cycles(2000);
  EXPECT_NEAR(b.model.velocity(), 0.0, 1.0);
}

TEST(SafetyVsModel, VlRunsOnlyAfterAVelocityCommandSinceTheEnable) {
  std::array<ObjectId, kModelMap.size() + 2> map{};
  std::copy(kModelMap.begin(), kModelMap.end(), map.begin());
  map[kModelMap.size()] = obj::kVlTargetVelocity.id;
  map[kModelMap.size() + 1] = obj::kVlVelocityActual.id;
  ModelBench b(map);
  b.enable();
  ASSERT_TRUE(b.submit(command(2, CommandKind::SetMode, Mode::Velocity)));
  ASSERT_TRUE(b.run(2, 100));
  auto c = command(3, CommandKind::Velocity, Mode::Velocity);
  c.target_velocity = 600;  // rpm
  ASSERT_TRUE(b.submit(c));
  ASSERT_TRUE(b.run(3, 5000));
  EXPECT_GT(b.model.velocity(), 1000.0);
  ASSERT_TRUE(b.submit(command(4, CommandKind::QuickStop)));
  ASSERT_TRUE(b.run(4, 5000));
  b.cycles(3000);
  ASSERT_TRUE(b.submit(command(5, CommandKind::Enable)));
  ASSERT_TRUE(b.run(5, 100));
  b.cycles(2000);
  EXPECT_NEAR(b.model.velocity(), 0.0, 1.0);
  EXPECT_EQ(b.master.feedback().controlword & cw::kModeBitsMask, 0);
}

sim::DriveModelConfig standing_at_200000() {
  auto c = model_config();
  c.positive_limit_position = 1e6;
  c.start_position = 200000.0;
  return c;
}

TEST(SafetyVsModel, IpWithout60C1IsRefused) {
  ModelBench b(kModelMap, standing_at_200000());
  b.boot();
  const auto a = b.master.submit(command(2, CommandKind::SetMode, Mode::InterpolatedPosition), b.now, b.sink);
  EXPECT_FALSE(a.accepted);
  EXPECT_EQ(a.reason.view(), "interpolated position needs 60C1h:1 in the cyclic image");
}

TEST(SafetyVsModel, DriveAlreadyInIpWithout60C1GetsNoEnableInterpolation) {
  auto config = standing_at_200000();
  config.initial_mode = op_mode::kInterpolatedPosition;
  ModelBench b(kModelMap, config);
  b.enable();
  b.cycles(300);
  EXPECT_EQ(b.master.feedback().controlword & cw::kEnableInterpolation, 0);
  EXPECT_EQ(b.model.state(), sim::DriveState::OperationEnabled);
  EXPECT_NEAR(b.model.position(), 200000.0, 5.0);
}

TEST(SafetyVsModel, IpStartsFromTheActualPosition) {
  std::array<ObjectId, kModelMap.size() + 1> map{};
  std::copy(kModelMap.begin(), kModelMap.end(), map.begin());
  map[kModelMap.size()] = obj::kIpDataRecord.id;
  ModelBench b(map, standing_at_200000());
  b.boot();
  ASSERT_TRUE(b.submit(command(2, CommandKind::SetMode, Mode::InterpolatedPosition)));
  ASSERT_TRUE(b.run(2, 100));
  ASSERT_TRUE(b.submit(command(3, CommandKind::Enable)));
  ASSERT_TRUE(b.run(3, 100));
  b.cycles(300);
  EXPECT_NE(b.master.feedback().controlword & cw::kEnableInterpolation, 0);
  EXPECT_EQ(b.model.state(), sim::DriveState::OperationEnabled);
  EXPECT_NEAR(b.model.position(), 200000.0, 5.0);
}

TEST(SafetyVsModel, SupersededMovesDoNotLeakRequestSlots) {
  // 6081h/6083h/6084h all go acyclically: every move stages three writes.
  std::array<ObjectId, kModelMap.size() - 1> map{};
  std::size_t n = 0;
  for (const ObjectId id : kModelMap) {
    if (id != obj::kProfileVelocity.id) map[n++] = id;
  }
  ModelBench b(map);
  b.enable();
  constexpr core::CommandId kFirst = 10;
  constexpr core::CommandId kLast = kFirst + 19;
  for (core::CommandId id = kFirst; id <= kLast; ++id) {
    auto c = command(id, CommandKind::Move);
    c.target_position = static_cast<std::int32_t>(1000 * (id - kFirst + 1));
    c.profile_velocity = 20000;
    c.profile_acceleration = 100000;
    c.profile_deceleration = 100000;
    ASSERT_TRUE(b.submit(c));
    b.cycle();
  }
  ASSERT_TRUE(b.run(kLast, 5000));
  EXPECT_NEAR(b.model.position(), 20000.0, 10.0);
  for (core::CommandId id = kFirst; id <= kLast; ++id) EXPECT_EQ(final_replies(b.sink, id), 1U) << "command " << id;
  core::ParamRequest rq;
  rq.id = 99;
  rq.index = 0x6041;
  rq.type = core::ParamType::U16;
  ASSERT_TRUE(b.master.parameter(rq, b.now).accepted);
  b.cycles(10);
  ASSERT_EQ(b.sink.params.size(), 1U);
  EXPECT_TRUE(b.sink.params[0].ok);
  EXPECT_EQ(b.io.requests_in_use(), 0U);
}

TEST(SafetyVsModel, FaultResetDuringEnableLetsTheEnableFinish) {
  ModelBench b;
  b.boot();
  ASSERT_TRUE(b.submit(command(1, CommandKind::Enable)));
  b.cycle();
  ASSERT_TRUE(b.submit(command(2, CommandKind::FaultReset)));
  EXPECT_TRUE(b.sink.done(2));  // not in fault: nothing to reset
  ASSERT_TRUE(b.run(1, 100));
  EXPECT_EQ(b.model.state(), sim::DriveState::OperationEnabled);
}

TEST(SafetyVsModel, DisableOnAFaultedAxisCompletesAtOnce) {
  ModelBench b;
  b.enable();
  b.model.inject_fault(0xFF01);
  b.cycles(20);
  ASSERT_EQ(b.master.feedback().state, core::AxisState::Fault);
  ASSERT_TRUE(b.submit(command(2, CommandKind::Disable)));
  EXPECT_TRUE(b.sink.done(2));
  b.cycles(5);
  EXPECT_EQ(b.master.feedback().controlword, cw::kDisableVoltage);
}

TEST(SafetyVsModel, ParameterWriteToTheVelocityTargetIsRefused) {
  ModelBench b;
  b.enable();
  ASSERT_TRUE(b.submit(command(2, CommandKind::SetMode, Mode::ProfileVelocity)));
  ASSERT_TRUE(b.run(2, 100));
  core::ParamRequest rq = drivegate::test::param_write(7, 0x60FF, 0, core::ParamType::I32, "20000");
  const auto a = b.master.parameter(rq, b.now);
  EXPECT_FALSE(a.accepted);
  EXPECT_EQ(a.reason.view(), "60FFh is driven by the CiA 402 profile; use the axis commands");
  b.cycles(500);
  EXPECT_NEAR(b.model.velocity(), 0.0, 1.0);
}

}  // namespace
}  // namespace drivegate::cia402::test
