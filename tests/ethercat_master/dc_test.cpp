// Distributed clocks, the parts that need no line: the 092Ch sign-magnitude codec, the register
// decoders (0008h features, 0110h DL status), the line round trip from port receive times, the
// SYNC0 start time, the master's system time since 2000, and DcSetup's texts when nothing
// answers (its runs against the simulator are in tests/ethercat_sim/dc_master_test.cpp).
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <string>

#include "adapters/ethercat/master/dc.hpp"

namespace drivegate::ethercat {
namespace {

using namespace std::chrono_literals;

// 092Ch vectors derived from ETG.1000.4 §6 DC register "system time difference": bits 0-30 the
// magnitude in ns, bit 31 = 1 when the local copy is smaller than the received time (negative).
TEST(EthercatDcCodec, SystemTimeDifferenceSignMagnitude) {
  struct V {
    std::int64_t diff;
    std::uint32_t raw;
  };
  const V vectors[] = {
      {0, 0x00000000U},          {1, 0x00000001U},           {-1, 0x80000001U},
      {100, 0x00000064U},        {-100, 0x80000064U},        {0x12345678, 0x12345678U},
      {-0x12345678, 0x92345678U}, {0x7FFFFFFF, 0x7FFFFFFFU}, {-0x7FFFFFFF, 0xFFFFFFFFU},
  };
  for (const V& v : vectors) {
    EXPECT_EQ(encode_system_time_difference(v.diff), v.raw) << v.diff;
    EXPECT_EQ(decode_system_time_difference(v.raw), v.diff) << std::hex << v.raw;
  }
  // Not two's complement: FFFFFF9Ch (-100 as int32) reads as -0x7FFFFF9C.
  EXPECT_EQ(decode_system_time_difference(0xFFFFFF9CU), -0x7FFFFF9C);
  // "Minus zero" is zero.
  EXPECT_EQ(decode_system_time_difference(0x80000000U), 0);
  // Beyond 31 bits the magnitude saturates, the sign stays.
  EXPECT_EQ(encode_system_time_difference(5'000'000'000LL), 0x7FFFFFFFU);
  EXPECT_EQ(encode_system_time_difference(-5'000'000'000LL), 0xFFFFFFFFU);
  EXPECT_EQ(encode_system_time_difference(std::numeric_limits<std::int64_t>::min()), 0xFFFFFFFFU);
  EXPECT_EQ(encode_system_time_difference(std::numeric_limits<std::int64_t>::max()), 0x7FFFFFFFU);
}

// ESC features 0008h bit 2 DC, bit 3 64-bit [ETG.1000.4 Table 31]; DL status 0110h per port: bit
// 4+p link, bit 8+2p loop closed, bit 9+2p communication [ETG.1000.4 Table 34].
TEST(EthercatDcCodec, FeaturesAndOpenPorts) {
  EXPECT_TRUE(features_dc(0x01CC));
  EXPECT_TRUE(features_dc_64bit(0x01CC));
  EXPECT_TRUE(features_dc(0x0004));
  EXPECT_FALSE(features_dc_64bit(0x0004));
  EXPECT_FALSE(features_dc(0x01C8));
  // Middle of a line: PDI operational, ports 0 and 1 link + communication, loop open; ports 2 and
  // 3 loop closed.
  EXPECT_EQ(open_ports(0x5A31), 0x03);
  // End of the line: port 1 loop closed.
  EXPECT_EQ(open_ports(0x5611), 0x01);
  // EK1100-like: ports 0, 1 and 3 open, 2 closed.
  EXPECT_EQ(open_ports(0x9AB1), 0x0B);
  // Communication without an open loop does not count; nothing at all gives 0.
  EXPECT_EQ(open_ports(0x0300), 0x00);
  EXPECT_EQ(open_ports(0x0000), 0x00);
}

TEST(EthercatDcCodec, LineRoundTrip) {
  EXPECT_EQ(line_round_trip({1000, 1600, 0, 0}, 0x03), 600U);
  EXPECT_EQ(line_round_trip({1000, 1600, 0, 0}, 0x01), 0U);          // end of the line
  EXPECT_EQ(line_round_trip({1000, 0, 0, 1400}, 0x09), 400U);        // out through port 3
  EXPECT_EQ(line_round_trip({0xFFFFFF00U, 0x100, 0, 0}, 0x03), 0x200U);  // 32-bit wrap
  EXPECT_FALSE(line_round_trip({1000, 1600, 0, 1200}, 0x0B).has_value());  // branch
  EXPECT_FALSE(line_round_trip({1000, 1600, 1700, 0}, 0x07).has_value());
}

TEST(EthercatDcCodec, Sync0StartTime) {
  // 1.234567890 s + 100 ms lead = 1.334567890 s, rounded up to the 1 ms grid: 1.335 s.
  EXPECT_EQ(sync0_start_time(1'234'567'890, 100'000'000, 1'000'000, 0), 1'335'000'000U);
  EXPECT_EQ(sync0_start_time(1'234'567'890, 100'000'000, 1'000'000, 250'000), 1'335'250'000U);
  EXPECT_EQ(sync0_start_time(1'234'567'890, 100'000'000, 1'000'000, -250'000), 1'334'750'000U);
  // Already on the grid: no extra cycle.
  EXPECT_EQ(sync0_start_time(1'900'000'000, 100'000'000, 1'000'000, 0), 2'000'000'000U);
  // 250 µs cycle; cycle 0: no rounding.
  EXPECT_EQ(sync0_start_time(1'000'000'001, 0, 250'000, 0), 1'000'250'000U);
  EXPECT_EQ(sync0_start_time(1'000'000'001, 5, 0, -6), 1'000'000'000U);
  // Large system times (2024 is about 7.6e17 ns after 2000).
  EXPECT_EQ(sync0_start_time(760'000'000'123'456'789ULL, 100'000'000, 2'000'000, 0), 760'000'000'224'000'000ULL);
  EXPECT_EQ(DcCyclic::sync0_phase(1'335'400'000, 1'335'000'000, 1'000'000), 400'000U);
  EXPECT_EQ(DcCyclic::sync0_phase(1'334'900'000, 1'335'000'000, 1'000'000), 900'000U);  // before the start
  EXPECT_EQ(DcCyclic::sync0_phase(5, 0, 0), 0U);
}

TEST(EthercatDcCodec, MasterSystemTimeSince2000) {
  // 2000-01-01 00:00:05 UTC on the realtime clock while the monotonic clock reads 2 s: base 3 s.
  const std::int64_t realtime = kEtherCatEpochUnixNs + 5'000'000'000;
  const std::int64_t base = system_time_base(realtime, 2'000'000'000);
  EXPECT_EQ(base, 3'000'000'000);
  EXPECT_EQ(master_system_time(core::TimePoint{2'000'000'001ns}, base), 5'000'000'001U);
  EXPECT_EQ(kEtherCatEpochUnixNs, 946'684'800LL * 1'000'000'000LL);  // 30 years incl. 7 leap days
}

TEST(EthercatDcSetup, NoDcSlaveIsDoneAtOnce) {
  const std::array<DcSlaveInfo, 2> infos{{{0x1001, false, true, 0x03, 0, 0}, {0x1002, false, true, 0x01, 0, 0}}};
  DcSetup setup(infos, DcConfig{});
  setup.start(core::TimePoint{});
  EXPECT_EQ(setup.status(), DcSetupStatus::Done);
  EXPECT_TRUE(setup.ok());
  EXPECT_FALSE(setup.reference().has_value());
  EXPECT_EQ(setup.slave(1).status, DcSlaveStatus::NotDc);
  DcCyclic cyclic;
  EXPECT_FALSE(cyclic.configure(setup, DcCyclicConfig{}));
}

TEST(EthercatDcSetup, StepTimeoutWhenFramesNeverReturn) {
  // Frames are taken but neither answered nor expired (a link that swallows them): the step's
  // own deadline ends it.
  const std::array<DcSlaveInfo, 1> infos{{{0x1001, true, true, 0x01, 1'000'000, 0}}};
  DcConfig cfg;
  cfg.step_timeout = 50ms;
  DcSetup setup(infos, cfg);
  Transactions tx;
  core::TimePoint now{};
  setup.start(now);
  for (int i = 0; i < 100 && setup.status() == DcSetupStatus::Running; ++i) {
    setup.poll(now, tx);
    (void)tx.take_frames(now + 1h);
    now += 1ms;
  }
  ASSERT_EQ(setup.status(), DcSetupStatus::Failed);
  EXPECT_EQ(setup.line_text(), "DC: no answer to the receive time latch (BWR 0900h) within 50 ms");
  EXPECT_EQ(setup.step(), DcStep::Latch);
}

TEST(EthercatDcSetup, LostFramesAreRetriedThenReported) {
  const std::array<DcSlaveInfo, 1> infos{{{0x1001, true, true, 0x01, 0, 0}}};
  DcConfig cfg;
  cfg.retries = 2;
  DcSetup setup(infos, cfg);
  Transactions tx;
  core::TimePoint now{};
  setup.start(now);
  int frames = 0;
  for (int i = 0; i < 100 && setup.status() == DcSetupStatus::Running; ++i) {
    setup.poll(now, tx);
    frames += static_cast<int>(tx.take_frames(now + 1ms).size());
    now += 1ms;
    tx.expire(now);
  }
  ASSERT_EQ(setup.status(), DcSetupStatus::Failed);
  EXPECT_EQ(frames, 3);
  EXPECT_EQ(setup.line_text(), "DC: no answer to the receive time latch (BWR 0900h), frame lost 3 times");
}

}  // namespace
}  // namespace drivegate::ethercat
