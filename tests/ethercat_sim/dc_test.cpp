// Distributed clock registers of simulated slaves [ETG.1000.4 §6 DC]: receive time latch on a
// write to 0900h with the line's per-hop delay, system time and offset, ARMW on 0910h, SYNC0
// registers; and a slave without DC.
#include <gtest/gtest.h>

#include "tests/ethercat_sim/harness.hpp"

namespace drivegate::ethercat::sim {
namespace {

using test::Bus;
using test::Reply;

struct DcLine {
  explicit DcLine(bool dc) {
    for (std::size_t k = 0; k < 3; ++k) {
      apps.push_back(std::make_unique<GenericIoSlave>(1, 1, SiiIdentity{1, 2, 3, 4}));
      EscConfig cfg;
      cfg.dc_supported = dc;
      cfg.clock_offset_ns = static_cast<std::int64_t>(k) * 1'000'000;  // slaves powered up 1 ms apart
      escs.push_back(std::make_unique<EscSlave>(cfg, apps.back()->sii(), apps.back().get()));
      bus.line().add(*escs.back());
    }
    bus.assign_addresses(3);
  }
  Bus bus;
  std::vector<std::unique_ptr<GenericIoSlave>> apps;
  std::vector<std::unique_ptr<EscSlave>> escs;
};

TEST(EthercatSimDc, ReceiveTimesGivePropagationDelays) {
  DcLine l(true);
  constexpr std::uint64_t kT = 5'000'000;
  constexpr std::uint64_t kHop = 300;  // SimLineConfig default
  l.bus.line().set_time(kT);
  const std::array<std::uint8_t, 4> zero{};
  EXPECT_EQ(l.bus.send(Command::BWR, physical_address(0, reg::kDcReceiveTimePort0), 4, zero).wkc, 3);
  for (std::size_t k = 0; k < 3; ++k) {
    const Reply r = l.bus.fprd(Bus::station(k), reg::kDcReceiveTimePort0, 8);
    const std::uint64_t local0 = kT + (k + 1) * kHop + k * 1'000'000;
    EXPECT_EQ(r.u32(0), static_cast<std::uint32_t>(local0)) << k;
    if (k < 2) {
      // Port 1 sees the frame on its way back: 2·(last-k) hops later.
      EXPECT_EQ(r.u32(4) - r.u32(0), 2 * (2 - k) * kHop) << k;
    } else {
      EXPECT_EQ(r.u32(4), 0U);  // last slave: port 1 closed, nothing latched
    }
    EXPECT_EQ(l.bus.fprd(Bus::station(k), reg::kDcReceiveTimeProcessingUnit, 8).u64(), local0);
  }
  // ESC features bit 2 (DC) and bit 3 (64 bit) set.
  EXPECT_EQ(l.bus.fprd(Bus::station(0), reg::kEscFeatures, 2).u16() & 0x000C, 0x000C);
}

TEST(EthercatSimDc, SystemTimeOffsetArmwAndSyncRegisters) {
  DcLine l(true);
  constexpr std::uint64_t kT = 7'000'000;
  l.bus.line().set_time(kT);
  // Offset of slave 1 so that its system time equals slave 0's local time: -1 ms.
  std::array<std::uint8_t, 8> off{};
  put_u64(off, 0, static_cast<std::uint64_t>(-1'000'000LL));
  EXPECT_EQ(l.bus.fpwr(Bus::station(1), reg::kDcSystemTimeOffset, off).wkc, 1);
  // System time 0910h = local + offset: slave 1 at port 0 time T + 600.
  EXPECT_EQ(l.bus.fprd(Bus::station(1), reg::kDcSystemTime, 8).u64(), kT + 600);
  // ARMW: slave 0 (ADP 0) reads its system time, slaves 1 and 2 write it; WKC 3.
  const Reply r = l.bus.send(Command::ARMW, physical_address(0, reg::kDcSystemTime), 8);
  EXPECT_EQ(r.wkc, 3);
  EXPECT_EQ(r.u64(), kT + 300);
  // Slave 1's local copy (T + 600) is 300 ns ahead of the received time: +300 in 092Ch.
  EXPECT_EQ(decode_system_time_difference(l.bus.fprd(Bus::station(1), reg::kDcSystemTimeDifference, 4).u32()), 300);
  // SYNC0 registers stored and readable [ETG.1000.4 §6: 0980h, 0981h, 0990h, 09A0h].
  const std::array<std::uint8_t, 2> act{0x00, dc_activation::kCyclicOperation | dc_activation::kSync0};
  EXPECT_EQ(l.bus.fpwr(Bus::station(2), reg::kDcCyclicUnitControl, act).wkc, 1);
  std::array<std::uint8_t, 8> start{};
  put_u64(start, 0, 123'456'789'000ULL);
  l.bus.fpwr(Bus::station(2), reg::kDcSync0StartTime, start);
  l.bus.fpwr32(Bus::station(2), reg::kDcSync0CycleTime, 1'000'000);
  EXPECT_EQ(l.bus.fprd(Bus::station(2), reg::kDcActivation, 1).data[0], 0x03);
  EXPECT_EQ(l.bus.fprd(Bus::station(2), reg::kDcSync0StartTime, 8).u64(), 123'456'789'000ULL);
  EXPECT_EQ(l.bus.fprd(Bus::station(2), reg::kDcSync0CycleTime, 4).u32(), 1'000'000U);
}

TEST(EthercatSimDc, SlaveWithoutDcLatchesNothing) {
  DcLine l(false);
  l.bus.line().set_time(1'000'000);
  const std::array<std::uint8_t, 4> zero{};
  l.bus.send(Command::BWR, physical_address(0, reg::kDcReceiveTimePort0), 4, zero);
  EXPECT_EQ(l.bus.fprd(Bus::station(1), reg::kDcReceiveTimePort0, 8).u64(), 0U);
  EXPECT_EQ(l.bus.fprd(Bus::station(1), reg::kDcSystemTime, 8).u64(), 0U);
  EXPECT_EQ(l.bus.fprd(Bus::station(1), reg::kEscFeatures, 2).u16() & 0x0004, 0);
}

}  // namespace
}  // namespace drivegate::ethercat::sim
