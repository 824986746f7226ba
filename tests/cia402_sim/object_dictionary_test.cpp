#include "profiles/cia402/sim/object_dictionary.hpp"

#include <gtest/gtest.h>

#include "tests/support/alloc_counter.hpp"

namespace drivegate::cia402::sim {
namespace {

class ObjectDictionaryTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(od.add(obj::kStatusword, Access::ReadOnly, 0x0240));
    ASSERT_TRUE(od.add(obj::kControlword, Access::WriteOnly, 0));
    ASSERT_TRUE(od.add(obj::kTargetTorque, Access::ReadWrite, 0, -1000, 1000));
    ASSERT_TRUE(od.add(obj::kHomingSpeedSwitch, Access::ReadWrite, 10));
    ASSERT_TRUE(od.add(obj::kModesOfOperation, Access::ReadWrite, 0));
  }
  ObjectDictionary od{8};
};

TEST_F(ObjectDictionaryTest, GetAndTypeOf) {
  EXPECT_EQ(od.get(obj::kStatusword.id), 0x0240);
  EXPECT_EQ(od.type_of(obj::kTargetTorque.id), DataType::I16);
  EXPECT_FALSE(od.get(obj::kPositionActual.id).has_value());
  EXPECT_FALSE(od.type_of(obj::kPositionActual.id).has_value());
}

TEST_F(ObjectDictionaryTest, AbortCodes) {
  EXPECT_EQ(od.set({0x2000, 0}, 1), 0x06020000U);             // no such object
  EXPECT_EQ(od.set({0x6099, 3}, 1), 0x06090011U);             // object exists, sub-index does not
  EXPECT_EQ(od.set(obj::kStatusword.id, 1), 0x06010002U);     // read-only
  EXPECT_EQ(od.read(obj::kControlword.id).abort_code, 0x06010001U);  // write-only
  EXPECT_EQ(od.set(obj::kTargetTorque.id, 1001), 0x06090031U);  // above max
  EXPECT_EQ(od.set(obj::kTargetTorque.id, -1001), 0x06090032U);  // below min
  EXPECT_EQ(od.set(obj::kTargetTorque.id, 40000), 0x06090030U);  // outside INT16 at all
  EXPECT_EQ(od.set(obj::kHomingSpeedSwitch.id, -1), 0x06090030U);  // negative into UNSIGNED32
  EXPECT_EQ(od.set(obj::kModesOfOperation.id, 128), 0x06090030U);
  EXPECT_EQ(od.get(obj::kTargetTorque.id), 0);  // refused writes change nothing
  EXPECT_EQ(od.set(obj::kTargetTorque.id, -1000), 0U);
  EXPECT_EQ(od.get(obj::kTargetTorque.id), -1000);
  EXPECT_EQ(od.read({0x2000, 0}).abort_code, 0x06020000U);
}

TEST_F(ObjectDictionaryTest, StoreClampsAndResetRestoresDefaults) {
  EXPECT_TRUE(od.store(obj::kStatusword.id, 0x0237));
  EXPECT_FALSE(od.store(obj::kTargetTorque.id, 5000));  // clamped, never wrapped
  EXPECT_EQ(od.get(obj::kTargetTorque.id), 1000);
  od.reset_to_defaults();
  EXPECT_EQ(od.get(obj::kStatusword.id), 0x0240);
  EXPECT_EQ(od.get(obj::kTargetTorque.id), 0);
}

TEST_F(ObjectDictionaryTest, RefusesBadEntries) {
  EXPECT_FALSE(od.add(obj::kStatusword, Access::ReadOnly, 0));              // duplicate
  EXPECT_FALSE(od.add(obj::kMaxTorque, Access::ReadWrite, 70000));          // default outside U16
  EXPECT_FALSE(od.add(obj::kMaxTorque, Access::ReadWrite, 5, 10, 1));       // min > max
  EXPECT_TRUE(od.add(obj::kMaxTorque, Access::ReadWrite, 5));
  EXPECT_TRUE(od.add(obj::kTorqueActual, Access::ReadOnly, 0));
  EXPECT_TRUE(od.add(obj::kTorqueSlope, Access::ReadWrite, 0));
  EXPECT_FALSE(od.add(obj::kHomeOffset, Access::ReadWrite, 0));  // capacity 8 reached
  EXPECT_EQ(od.size(), 8U);
}

TEST_F(ObjectDictionaryTest, AccessDoesNotAllocate) {
  drivegate::test::AllocationScope scope;
  std::int64_t sum = 0;
  for (int i = 0; i < 100; ++i) {
    sum += od.get(obj::kStatusword.id).value_or(0);
    EXPECT_EQ(od.set(obj::kTargetTorque.id, i), 0U);
    sum += od.read(obj::kTargetTorque.id).value;
  }
  EXPECT_EQ(scope.count(), 0U);
  EXPECT_GT(sum, 0);
}

}  // namespace
}  // namespace drivegate::cia402::sim
