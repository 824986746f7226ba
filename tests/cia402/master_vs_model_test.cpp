// The master against the simulated drive (profiles/cia402/sim) through DirectObjectAccess, with
// virtual time (tests/cia402/model_bench.hpp).
#include <gtest/gtest.h>

#include "tests/cia402/model_bench.hpp"

namespace drivegate::cia402::test {
namespace {

using core::CommandKind;
using core::Mode;


TEST(MasterVsModel, Enable) {
  ModelBench b;
  b.enable();
  EXPECT_EQ(b.master.feedback().state, core::AxisState::OperationEnabled);
}

TEST(MasterVsModel, ProfilePositionMove) {
  ModelBench b;
  b.enable();
  auto c = command(2, CommandKind::Move);
  c.target_position = 10000;
  c.profile_velocity = 20000;
  c.profile_acceleration = 100000;
  c.profile_deceleration = 100000;
  ASSERT_TRUE(b.submit(c));
  ASSERT_TRUE(b.run(2, 5000));
  EXPECT_NEAR(b.model.position(), 10000.0, 10.0);
  // A second, relative move.
  c.id = 3;
  c.target_position = -2500;
  c.relative = true;
  ASSERT_TRUE(b.submit(c));
  ASSERT_TRUE(b.run(3, 5000));
  EXPECT_NEAR(b.model.position(), 7500.0, 10.0);
}

TEST(MasterVsModel, ProfileVelocityThenStopAndQuickStop) {
  ModelBench b;
  b.enable();
  auto c = command(2, CommandKind::Velocity, Mode::ProfileVelocity);
  c.target_velocity = 5000;
  c.profile_acceleration = 50000;
  c.profile_deceleration = 50000;
  ASSERT_TRUE(b.submit(c));
  ASSERT_TRUE(b.run(2, 3000));
  EXPECT_NEAR(b.model.velocity(), 5000.0, 150.0);
  ASSERT_TRUE(b.submit(command(3, CommandKind::Stop)));
  ASSERT_TRUE(b.run(3, 3000));
  EXPECT_NEAR(b.model.velocity(), 0.0, 150.0);
  c.id = 4;
  ASSERT_TRUE(b.submit(c));
  ASSERT_TRUE(b.run(4, 3000));
  ASSERT_TRUE(b.submit(command(5, CommandKind::QuickStop)));
  ASSERT_TRUE(b.run(5, 3000));
  for (int i = 0; i < 2000; ++i) b.cycle();
  EXPECT_NEAR(b.model.velocity(), 0.0, 1.0);
}

TEST(MasterVsModel, ProfileTorque) {
  ModelBench b;
  b.enable();
  auto c = command(2, CommandKind::Torque);
  c.target_torque = 100;
  c.torque_slope = 10000;
  ASSERT_TRUE(b.submit(c));
  ASSERT_TRUE(b.run(2, 2000));
  EXPECT_NEAR(b.model.torque(), 100.0, 5.0);
  ASSERT_TRUE(b.submit(command(3, CommandKind::Stop)));
  ASSERT_TRUE(b.run(3, 2000));
}

TEST(MasterVsModel, HomingCurrentPosition) {
  ModelBench b;
  b.enable();
  auto c = command(2, CommandKind::Home);
  c.homing_method = 35;
  c.home_offset = 1234;
  ASSERT_TRUE(b.submit(c));
  ASSERT_TRUE(b.run(2, 1000));
  EXPECT_TRUE(b.master.feedback().homed);
}

TEST(MasterVsModel, HomingOnNegativeLimitSwitch) {
  ModelBench b;
  b.enable();
  auto c = command(2, CommandKind::Home);
  c.homing_method = 17;
  c.homing_search_velocity = 5000;
  c.homing_zero_velocity = 1000;
  c.homing_acceleration = 50000;
  ASSERT_TRUE(b.submit(c));
  ASSERT_TRUE(b.run(2, 20000));
  EXPECT_TRUE(b.master.feedback().homed);
}

TEST(MasterVsModel, FaultThenReset) {
  ModelBench b;
  b.enable();
  b.model.inject_fault(0x2310);
  for (int i = 0; i < 20; ++i) b.cycle();
  EXPECT_EQ(b.master.feedback().state, core::AxisState::Fault);
  EXPECT_EQ(b.master.feedback().fault_code, 0x2310U);
  EXPECT_EQ(b.master.feedback().fault_text.view(), "continuous overcurrent (output)");
  ASSERT_TRUE(b.submit(command(2, CommandKind::FaultReset)));
  for (int i = 0; i < 20; ++i) b.cycle();
  EXPECT_FALSE(b.sink.done(2));  // the cause is still there
  b.model.clear_fault_cause();
  ASSERT_TRUE(b.submit(command(3, CommandKind::FaultReset)));
  ASSERT_TRUE(b.run(3, 100));
  EXPECT_EQ(b.sink.count(core::EventKind::FaultCleared), 1U);
  ASSERT_TRUE(b.submit(command(4, CommandKind::Enable)));
  ASSERT_TRUE(b.run(4, 100));
}

TEST(MasterVsModel, CyclicSynchronousPosition) {
  ModelBench b;
  b.enable();
  ASSERT_TRUE(b.submit(command(2, CommandKind::SetMode, Mode::CyclicPosition)));
  ASSERT_TRUE(b.run(2, 100));
  for (int i = 0; i < 50; ++i) b.cycle();
  EXPECT_NEAR(b.model.position(), 0.0, 1.0);  // held where it stood
  core::DriveSetpoint sp;
  for (int i = 1; i <= 500; ++i) {
    sp.position = i * 10;
    b.master.setpoint(sp, b.now);
    b.cycle();
  }
  for (int i = 0; i < 50; ++i) b.cycle();
  EXPECT_NEAR(b.model.position(), 5000.0, 20.0);
}

}  // namespace
}  // namespace drivegate::cia402::test
