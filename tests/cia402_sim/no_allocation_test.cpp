// step() and the in-process access run on the cycle thread: prove they never allocate.
#include <gtest/gtest.h>

#include <array>

#include "profiles/cia402/sim/direct_access.hpp"
#include "tests/cia402_sim/drive_harness.hpp"
#include "tests/support/alloc_counter.hpp"

namespace drivegate::cia402::sim::test {
namespace {

TEST(NoAllocation, StepInEveryModeAndThroughFaults) {
  DriveModelConfig cfg;
  cfg.negative_limit_position = -30000;
  cfg.positive_limit_position = 30000;
  DriveHarness h(cfg);
  drivegate::test::AllocationScope scope;
  for (const std::int8_t mode : {op_mode::kProfilePosition, op_mode::kVelocity, op_mode::kProfileVelocity,
                                 op_mode::kProfileTorque, op_mode::kHoming, op_mode::kInterpolatedPosition,
                                 op_mode::kCyclicPosition, op_mode::kCyclicVelocity, op_mode::kCyclicTorque}) {
    h.set(obj::kModesOfOperation, mode);
    h.set(obj::kTargetPosition, 20000);
    h.set(obj::kTargetVelocity, 20000);
    h.set(obj::kTargetTorque, 50);
    h.set(obj::kVlTargetVelocity, 100);
    h.set(obj::kHomingMethod, 17);
    h.cw(0x000F);
    h.step(3);
    h.cw(0x007F);
    h.step(200);
    h.cw(0x017F);
    h.step(50);
  }
  h.drive.inject_fault(0x5530);
  h.step(20);
  h.drive.clear_fault_cause();
  h.cw(0x0080);
  h.step(2);
  while (h.drive.take_pending_emcy()) {
  }
  h.drive.power_cycle();
  h.step(2);
  EXPECT_EQ(scope.count(), 0U);
}

TEST(NoAllocation, DirectAccessCycle) {
  DriveModel drive{DriveModelConfig{}};
  const std::array<ObjectId, 3> map{obj::kControlword.id, obj::kStatusword.id, obj::kTargetVelocity.id};
  DirectObjectAccess access(drive, map, 1);
  drivegate::test::AllocationScope scope;
  for (int i = 0; i < 100; ++i) {
    access.begin_cycle();
    access.write(obj::kControlword.id, i < 2 ? 0x0006 : 0x000F);
    access.write(obj::kTargetVelocity.id, 1000);
    const RequestId id = access.submit_read(obj::kStatusword);
    (void)access.poll(id);
    (void)access.read(obj::kStatusword.id);
    access.end_cycle();
    drive.step(kStep);
  }
  EXPECT_EQ(scope.count(), 0U);
}

}  // namespace
}  // namespace drivegate::cia402::sim::test
