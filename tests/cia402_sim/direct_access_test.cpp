// DirectObjectAccess: the in-process process image and SDO-like requests.
#include "profiles/cia402/sim/direct_access.hpp"

#include <gtest/gtest.h>

#include <array>

#include "tests/cia402_sim/drive_harness.hpp"

namespace drivegate::cia402::sim::test {
namespace {

constexpr std::array<ObjectId, 5> kMap{obj::kControlword.id, obj::kStatusword.id, obj::kModesOfOperation.id,
                                       obj::kModesOfOperationDisplay.id, obj::kPositionActual.id};

class DirectAccess : public ::testing::Test {
 protected:
  // One bus cycle as the sim bus runs it.
  void cycle() {
    access.begin_cycle();
    access.end_cycle();
    drive.step(kStep);
  }
  DriveModel drive{DriveModelConfig{}};
  DirectObjectAccess access{drive, kMap, 2};
};

TEST_F(DirectAccess, ProcessImageIsSnapshotAtBeginAndSentAtEnd) {
  EXPECT_TRUE(access.mapping_valid());
  EXPECT_TRUE(access.mapped(obj::kControlword.id));
  EXPECT_FALSE(access.mapped(obj::kTargetPosition.id));
  EXPECT_FALSE(access.inputs_fresh());
  drive.step(kStep);  // boot: Switch on disabled
  access.begin_cycle();
  EXPECT_TRUE(access.inputs_fresh());
  EXPECT_EQ(access.read(obj::kStatusword.id), 0x0240);
  access.write(obj::kControlword.id, 0x0006);
  access.write(obj::kModesOfOperation.id, op_mode::kProfileVelocity);
  EXPECT_EQ(drive.dictionary().get(obj::kControlword.id), 0);  // buffered until end_cycle
  access.end_cycle();
  EXPECT_EQ(drive.dictionary().get(obj::kControlword.id), 0x0006);
  drive.step(kStep);
  EXPECT_EQ(access.read(obj::kStatusword.id), 0x0240);  // old snapshot until the next begin_cycle
  access.begin_cycle();
  EXPECT_EQ(access.read(obj::kStatusword.id), 0x0231);
  EXPECT_EQ(access.read(obj::kModesOfOperationDisplay.id), op_mode::kProfileVelocity);
  access.end_cycle();
  drive.step(kStep);
  // The last output value is sent every cycle, like an RPDO.
  EXPECT_EQ(drive.dictionary().get(obj::kControlword.id), 0x0006);
}

TEST_F(DirectAccess, BadWritesAreCountedDrops) {
  access.write(obj::kStatusword.id, 1);      // mapped but an input
  access.write(obj::kTargetPosition.id, 1);  // not mapped
  EXPECT_EQ(access.dropped_writes(), 2U);
  access.write(obj::kModesOfOperation.id, 5);  // the drive refuses mode 5
  access.end_cycle();
  EXPECT_EQ(access.rejected_outputs(), 1U);
  EXPECT_EQ(access.last_output_abort(), 0x06090030U);
  EXPECT_EQ(drive.dictionary().get(obj::kModesOfOperation.id), 0);
}

TEST_F(DirectAccess, MappingAnAbsentObjectIsReported) {
  const std::array<ObjectId, 2> map{obj::kStatusword.id, ObjectId{0x2000, 0}};
  DirectObjectAccess bad(drive, map);
  EXPECT_FALSE(bad.mapping_valid());
}

TEST_F(DirectAccess, RequestsCompleteAfterTheLatencyAndReportOnce) {
  const RequestId w = access.submit_write(obj::kProfileVelocity, 12345);
  const RequestId r = access.submit_read(obj::kProfileVelocity);
  ASSERT_NE(w, kNoRequest);
  ASSERT_NE(r, kNoRequest);
  EXPECT_EQ(access.poll(w).state, RequestState::Pending);
  cycle();
  EXPECT_EQ(access.poll(w).state, RequestState::Pending);
  cycle();
  EXPECT_EQ(access.poll(w).state, RequestState::Done);
  EXPECT_EQ(access.poll(w).state, RequestState::Unknown);  // reported once
  const RequestResult rr = access.poll(r);
  EXPECT_EQ(rr.state, RequestState::Done);
  EXPECT_EQ(rr.value, 12345);  // requests run in submission order
  EXPECT_EQ(access.poll(kNoRequest).state, RequestState::Unknown);
}

TEST_F(DirectAccess, RequestAbortCodes) {
  const RequestId missing = access.submit_read({{0x2000, 0}, DataType::U32});
  const RequestId no_sub = access.submit_read({{0x6099, 7}, DataType::U32});
  const RequestId read_only = access.submit_write(obj::kStatusword, 1);
  const RequestId wrong_type = access.submit_read({obj::kStatusword.id, DataType::U32});
  const RequestId too_high = access.submit_write(obj::kHomingSpeedZero, 10'000'000);
  const RequestId signed_read = access.submit_read(obj::kIpTimePeriodIndex);
  cycle();
  cycle();
  EXPECT_EQ(access.poll(missing).abort_code, 0x06020000U);
  EXPECT_EQ(access.poll(no_sub).abort_code, 0x06090011U);
  EXPECT_EQ(access.poll(read_only).abort_code, 0x06010002U);
  EXPECT_EQ(access.poll(wrong_type).abort_code, 0x06070010U);
  const RequestResult high = access.poll(too_high);
  EXPECT_EQ(high.state, RequestState::Failed);
  EXPECT_EQ(high.abort_code, 0x06090031U);
  EXPECT_EQ(access.poll(signed_read).value, -3);  // sign-extended per type
}

TEST_F(DirectAccess, FullRequestTableRefuses) {
  for (std::size_t i = 0; i < DirectObjectAccess::kMaxRequests; ++i) {
    EXPECT_NE(access.submit_read(obj::kStatusword), kNoRequest);
  }
  EXPECT_EQ(access.submit_read(obj::kStatusword), kNoRequest);
}

TEST_F(DirectAccess, LinkLossMakesInputsStaleAndRequestsTimeOut) {
  drive.step(kStep);
  access.begin_cycle();
  ASSERT_TRUE(access.inputs_fresh());
  const RequestId id = access.submit_write(obj::kProfileVelocity, 777);
  access.set_link_up(false);
  access.write(obj::kControlword.id, 0x0006);
  access.end_cycle();
  EXPECT_EQ(drive.dictionary().get(obj::kControlword.id), 0);  // not delivered
  drive.step(kStep);
  access.begin_cycle();
  EXPECT_FALSE(access.inputs_fresh());
  const RequestResult r = access.poll(id);
  EXPECT_EQ(r.state, RequestState::Failed);
  EXPECT_EQ(r.abort_code, 0x05040000U);
  EXPECT_NE(drive.dictionary().get(obj::kProfileVelocity.id), 777);
  access.set_link_up(true);
  access.end_cycle();
  access.begin_cycle();
  EXPECT_TRUE(access.inputs_fresh());
  EXPECT_EQ(drive.dictionary().get(obj::kControlword.id), 0x0006);
}

TEST(DirectAccessLatency, ZeroLatencyCompletesAtSubmit) {
  DriveModel drive{DriveModelConfig{}};
  const std::array<ObjectId, 1> map{obj::kStatusword.id};
  DirectObjectAccess access(drive, map, 0);
  const RequestId id = access.submit_read(obj::kModesOfOperation);
  EXPECT_EQ(access.poll(id).state, RequestState::Done);
}

TEST_F(DirectAccess, CancelFreesTheSlotAndAnUndueWriteNeverLands) {
  std::array<RequestId, DirectObjectAccess::kMaxRequests> ids{};
  for (auto& id : ids) {
    id = access.submit_write(obj::kProfileAcceleration, 4321);
    ASSERT_NE(id, kNoRequest);
  }
  EXPECT_EQ(access.submit_read(obj::kStatusword), kNoRequest);  // queue full
  for (const auto id : ids) access.cancel(id);
  access.cancel(kNoRequest);  // ignored
  EXPECT_EQ(access.requests_in_use(), 0U);
  EXPECT_EQ(access.poll(ids[0]).state, RequestState::Unknown);
  for (int i = 0; i < 4; ++i) cycle();
  EXPECT_NE(drive.dictionary().get(obj::kProfileAcceleration.id), 4321);
  const RequestId read = access.submit_read(obj::kStatusword);
  EXPECT_NE(read, kNoRequest);
}

}  // namespace
}  // namespace drivegate::cia402::sim::test
