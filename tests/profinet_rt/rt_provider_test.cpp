// RtProvider: the output CR's frame on the exact schedule (no drift over 1000 cycles, the cycle
// counter stepping by SendClockFactor × ReductionRatio), missed slots counted and never sent
// twice, the frame's header, C_SDU, IOPS/IOCS and DataStatus, and refused configs.
#include <gtest/gtest.h>

#include "tests/profinet_rt/rt_fixture.hpp"

namespace drivegate::profinet::test {
namespace {

using std::chrono::nanoseconds;

// An odd start (not on the 31.25 µs grid) so that the counter must come from the schedule.
const core::TimePoint kStart{nanoseconds(5'000'012'345)};

struct Sent {
  ApduStatus status;
  Bytes c_sdu;
  EthernetHeader header;
};

Sent decode(std::span<const std::uint8_t> frame, std::uint16_t c_sdu_length) {
  const EthernetView e = decode_ethernet(frame);
  EXPECT_TRUE(e.ok());
  const RtCyclicView v = decode_rt_cyclic(e.pdu, c_sdu_length);
  EXPECT_TRUE(v.ok());
  return {v.status, Bytes(v.c_sdu.begin(), v.c_sdu.end()), e.header};
}

TEST(PnRtProvider, ScheduleIsExactOverThousandCycles) {
  RtProvider p(iocr(kOutputFrameId));
  ASSERT_TRUE(p.ok()) << to_string(p.error());
  EXPECT_EQ(p.period(), std::chrono::milliseconds(2));
  EXPECT_EQ(p.next_deadline(), core::TimePoint::max());
  p.start(kStart);
  std::array<std::uint8_t, kMaxFrameSize> out{};
  const core::TimePoint first = kStart + std::chrono::milliseconds(1);  // phase 2: one send clock in
  std::uint16_t last_counter = 0;
  for (int n = 0; n < 1000; ++n) {
    const core::TimePoint due = first + std::chrono::milliseconds(2) * n;
    ASSERT_EQ(p.next_deadline(), due) << n;
    ASSERT_EQ(p.poll(due - nanoseconds(1), out), 0U) << n;
    const std::size_t len = p.poll(due, out);
    ASSERT_EQ(len, p.frame_size());
    ASSERT_EQ(p.poll(due, out), 0U);  // one frame per slot
    const Sent s = decode(std::span(out).first(len), 40);
    ASSERT_EQ(s.status.cycle_counter, cycle_counter_at(static_cast<std::uint64_t>(core::to_ns(due))));
    if (n > 0) {
      ASSERT_EQ(static_cast<std::uint16_t>(s.status.cycle_counter - last_counter), 64) << n;
    }
    last_counter = s.status.cycle_counter;
  }
  EXPECT_EQ(p.counters().frames_sent, 1000U);
  EXPECT_EQ(p.counters().missed_slots, 0U);
}

TEST(PnRtProvider, LatePollSendsOnceForTheLatestSlotAndCountsTheMissed) {
  RtProvider p(iocr(kOutputFrameId));
  p.start(kStart);
  std::array<std::uint8_t, kMaxFrameSize> out{};
  const core::TimePoint first = p.next_deadline();
  ASSERT_GT(p.poll(first, out), 0U);
  // 3.5 periods after the second slot: slots 2, 3 and 4 passed, slot 5 is due.
  const core::TimePoint late = first + std::chrono::milliseconds(2) + std::chrono::milliseconds(7);
  const std::size_t len = p.poll(late, out);
  ASSERT_GT(len, 0U);
  EXPECT_EQ(p.counters().missed_slots, 3U);
  const core::TimePoint slot5 = first + std::chrono::milliseconds(8);
  EXPECT_EQ(decode(std::span(out).first(len), 40).status.cycle_counter,
            cycle_counter_at(static_cast<std::uint64_t>(core::to_ns(slot5))));
  EXPECT_EQ(p.poll(late, out), 0U);
  EXPECT_EQ(p.next_deadline(), slot5 + std::chrono::milliseconds(2));  // the grid, not the late poll
  EXPECT_EQ(p.counters().frames_sent, 2U);
  // A buffer too small loses the slot, counted, and the schedule goes on.
  std::array<std::uint8_t, 63> small{};
  EXPECT_EQ(p.poll(p.next_deadline(), small), 0U);
  EXPECT_EQ(p.counters().tx_too_small, 1U);
  EXPECT_EQ(p.next_deadline(), slot5 + std::chrono::milliseconds(4));
  p.stop();
  EXPECT_EQ(p.next_deadline(), core::TimePoint::max());
  EXPECT_EQ(p.poll(slot5 + std::chrono::hours(1), out), 0U);
}

TEST(PnRtProvider, FrameCarriesDataIoxsAndDataStatus) {
  RtProvider p(iocr(kOutputFrameId));
  const auto pl = p.placements();
  ASSERT_EQ(pl.size(), 3U);
  ASSERT_EQ(p.data(kDrive).size(), 4U);
  EXPECT_TRUE(p.data(0).empty());
  EXPECT_TRUE(p.data(kSensor).empty());
  EXPECT_TRUE(p.data(7).empty());
  EXPECT_FALSE(p.set_iops(kSensor, iox_status::kGood));  // input only: no IOPS in the output CR
  EXPECT_FALSE(p.set_iocs(7, iox_status::kGood));
  const std::array<std::uint8_t, 4> stw{0x04, 0x7F, 0x40, 0x00};
  std::copy(stw.begin(), stw.end(), p.data(kDrive).begin());
  p.start(kStart);
  std::array<std::uint8_t, kMaxFrameSize> out{};
  std::size_t len = p.poll(p.next_deadline(), out);
  EXPECT_EQ(len, 64U);
  Sent s = decode(std::span(out).first(len), 40);
  EXPECT_TRUE(s.header.vlan);
  EXPECT_EQ(s.header.priority, kPriorityRtCyclic);
  EXPECT_EQ(s.header.vlan_id, 0);
  EXPECT_EQ(s.header.dst, kDevice);
  EXPECT_EQ(s.header.src, kController);
  EXPECT_EQ(s.header.frame_id, kOutputFrameId);
  EXPECT_EQ(s.status.data_status, data_status::kGood);
  EXPECT_EQ(s.status.transfer_status, 0);
  EXPECT_TRUE(std::equal(stw.begin(), stw.end(), s.c_sdu.begin() + pl[kDrive].data_offset));
  EXPECT_EQ(s.c_sdu[pl[kDrive].iops_offset], iox_status::kBadByController);  // until the application says good
  for (const std::size_t i : {std::size_t{0}, kDrive, kSensor}) EXPECT_EQ(s.c_sdu[pl[i].iocs_offset], iox_status::kGood);

  EXPECT_TRUE(p.set_iops(kDrive, iox_status::kGood));
  EXPECT_TRUE(p.set_iocs(kSensor, iox_status::kBadByController));
  p.set_provider_run(false);
  len = p.poll(p.next_deadline(), out);
  s = decode(std::span(out).first(len), 40);
  EXPECT_EQ(s.c_sdu[pl[kDrive].iops_offset], iox_status::kGood);
  EXPECT_EQ(s.c_sdu[pl[kSensor].iocs_offset], iox_status::kBadByController);
  EXPECT_FALSE(s.status.provider_run());
  EXPECT_TRUE(s.status.data_valid());
  EXPECT_TRUE(s.status.primary());
  EXPECT_FALSE(s.status.station_problem());
  EXPECT_EQ(s.status.data_status, 0x25);
}

TEST(PnRtProvider, RefusesBadConfigs) {
  const auto refused = [](auto edit) {
    RtIocrConfig c = iocr(kOutputFrameId);
    edit(c);
    RtProvider p(c);
    RtConsumer q(c);
    EXPECT_EQ(q.error(), p.error());
    p.start(kStart);
    std::array<std::uint8_t, kMaxFrameSize> out{};
    EXPECT_EQ(p.poll(kStart + std::chrono::hours(1), out) == 0, !p.ok());  // a refused config stays inert
    EXPECT_EQ(p.running(), p.ok());
    return p.error();
  };
  EXPECT_EQ(refused([](RtIocrConfig&) {}), RtConfigError::None);
  EXPECT_EQ(refused([](RtIocrConfig& c) { c.frame_id = frame_id::kAlarmHigh; }), RtConfigError::BadFrameId);
  EXPECT_EQ(refused([](RtIocrConfig& c) { c.send_clock_factor = 0; }), RtConfigError::BadSendClock);
  EXPECT_EQ(refused([](RtIocrConfig& c) { c.send_clock_factor = 129; }), RtConfigError::BadSendClock);
  EXPECT_EQ(refused([](RtIocrConfig& c) { c.reduction_ratio = 3; }), RtConfigError::BadReductionRatio);
  EXPECT_EQ(refused([](RtIocrConfig& c) { c.reduction_ratio = 1024; }), RtConfigError::BadReductionRatio);
  EXPECT_EQ(refused([](RtIocrConfig& c) { c.phase = 0; }), RtConfigError::BadPhase);
  EXPECT_EQ(refused([](RtIocrConfig& c) { c.phase = 3; }), RtConfigError::BadPhase);
  EXPECT_EQ(refused([](RtIocrConfig& c) { c.data_hold_factor = 0; }), RtConfigError::BadDataHold);
  EXPECT_EQ(refused([](RtIocrConfig& c) { c.data_hold_factor = 7681; }), RtConfigError::BadDataHold);
  static const std::array<IoSubmodule, kMaxRtSubmodules + 1> many{};
  EXPECT_EQ(refused([](RtIocrConfig& c) { c.submodules = many; }), RtConfigError::TooManySubmodules);
  static const std::array<IoSubmodule, 2> big{{{IoKind::Output, 0, 1000}, {IoKind::Output, 0, 1000}}};
  EXPECT_EQ(refused([](RtIocrConfig& c) { c.submodules = big; }), RtConfigError::DataTooLong);
  static const std::array<IoSubmodule, 1> lying{{{IoKind::Input, 2, 2}}};
  EXPECT_EQ(refused([](RtIocrConfig& c) { c.submodules = lying; }), RtConfigError::BadSubmodule);
  EXPECT_EQ(to_string(RtConfigError::BadReductionRatio), "ReductionRatio is not a power of two in 1..512");
}

}  // namespace
}  // namespace drivegate::profinet::test
