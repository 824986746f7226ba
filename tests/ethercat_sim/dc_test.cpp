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
  // With the delay from slave 0 (300 ns) in 0928h the difference is own - (received + delay) = 0
  // [ETG.1000.4 §6 DC: 0928h is added to the received time before the comparison].
  l.bus.fpwr32(Bus::station(1), reg::kDcSystemTimeDelay, 300);
  EXPECT_EQ(l.bus.send(Command::ARMW, physical_address(0, reg::kDcSystemTime), 8).wkc, 3);
  EXPECT_EQ(l.bus.fprd(Bus::station(1), reg::kDcSystemTimeDifference, 4).u32(), 0U);
  // A delay 100 ns too long: the own copy is 100 ns behind: sign bit set, magnitude 100.
  l.bus.fpwr32(Bus::station(1), reg::kDcSystemTimeDelay, 400);
  l.bus.send(Command::ARMW, physical_address(0, reg::kDcSystemTime), 8);
  EXPECT_EQ(l.bus.fprd(Bus::station(1), reg::kDcSystemTimeDifference, 4).u32(), 0x80000064U);
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

// A slave application that records SYNC0.
class Sync0App final : public SlaveApplication {
 public:
  std::size_t output_size() const noexcept override { return 0; }
  std::size_t input_size() const noexcept override { return 0; }
  void exchange(std::span<const std::uint8_t>, std::span<std::uint8_t>, AlState, std::uint64_t) noexcept override {}
  void on_sync0(std::uint64_t pulse_ns, std::uint64_t) noexcept override { pulses.push_back(pulse_ns); }
  std::vector<std::uint64_t> pulses;
};

TEST(EthercatSimDc, DriftAndControlLoop) {
  Bus bus;
  GenericIoSlave io(1, 1, SiiIdentity{1, 2, 3, 4});
  EscConfig ref_cfg;
  ref_cfg.dc_supported = true;
  EscConfig cfg = ref_cfg;
  cfg.drift_ppm = 100.0;  // runs 100 ns per ms fast
  EscSlave ref(ref_cfg, io.sii(), nullptr);
  EscSlave fast(cfg, io.sii(), nullptr);
  bus.line().add(ref, 0);
  bus.line().add(fast, 0);  // no hop delay: no 0928h needed
  bus.assign_addresses(2);
  bus.line().set_time(1'000'000);
  const std::uint64_t l0 = fast.local_time(1'000'000);
  EXPECT_NEAR(static_cast<double>(fast.local_time(11'000'000) - l0), 10'001'000.0, 1.0);  // 10 ms + 100 ppm
  // FRMW every ms: the loop finds the frequency and holds the difference near 0.
  for (std::uint64_t t = 1'000'000; t < 100'000'000; t += 1'000'000) {
    bus.line().set_time(t);
    EXPECT_EQ(bus.send(Command::FRMW, physical_address(Bus::station(0), reg::kDcSystemTime), 8).wkc, 2);
    bus.line().advance(t + 10'000);
  }
  EXPECT_NEAR(fast.dc_clock().frequency_ppm(), -100.0, 0.5);
  EXPECT_LT(std::abs(decode_system_time_difference(get_u32(fast.memory(), reg::kDcSystemTimeDifference))), 5);
  EXPECT_LT(std::llabs(static_cast<std::int64_t>(fast.system_time(100'000'000) - ref.system_time(100'000'000))), 5);
  // Without more samples the clock keeps the corrected frequency (it does not run away).
  EXPECT_LT(std::llabs(static_cast<std::int64_t>(fast.system_time(1'100'000'000) - ref.system_time(1'100'000'000))), 50);
  // A write to the speed counter start (0930h) resets the loop [ETG.1000.4 §6 DC].
  bus.fpwr16(Bus::station(1), reg::kDcSpeedCounterStart, 0x1000);
  EXPECT_EQ(fast.dc_clock().frequency_ppm(), 0.0);
}

TEST(EthercatSimDc, Sync0PulsesAfterActivation) {
  Bus bus;
  GenericIoSlave io(1, 1, SiiIdentity{1, 2, 3, 4});
  Sync0App app;
  EscConfig cfg;
  cfg.dc_supported = true;
  EscSlave esc(cfg, io.sii(), &app);
  bus.line().add(esc);
  bus.assign_addresses(1);
  bus.line().set_time(1'000'000);
  // System time = local (line time + 300 ns hop at the datagram; line time in the PDI cycle).
  std::array<std::uint8_t, 8> start{};
  put_u64(start, 0, 5'000'000);
  bus.fpwr(Bus::station(0), reg::kDcSync0StartTime, start);
  bus.fpwr32(Bus::station(0), reg::kDcSync0CycleTime, 1'000'000);
  const std::array<std::uint8_t, 1> act{0x03};
  bus.fpwr(Bus::station(0), reg::kDcActivation, act);
  EXPECT_EQ(bus.fprd(Bus::station(0), reg::kDcActivationStatus, 1).data[0], 0x01);  // first pulse pending
  bus.line().advance(4'999'999);
  EXPECT_TRUE(app.pulses.empty());
  bus.line().advance(5'000'000);
  ASSERT_EQ(app.pulses.size(), 1U);
  EXPECT_EQ(app.pulses[0], 5'000'000U);
  // Several cycles at once: counted, the hook gets the last; 0990h reads the next pulse.
  bus.line().advance(8'500'000);
  EXPECT_EQ(esc.sync0_pulses(), 4U);
  EXPECT_EQ(app.pulses.back(), 8'000'000U);
  EXPECT_EQ(bus.fprd(Bus::station(0), reg::kDcSync0StartTime, 8).u64(), 9'000'000U);
  EXPECT_EQ(bus.fprd(Bus::station(0), reg::kDcActivationStatus, 1).data[0], 0x00);
  // Off: no more pulses.
  const std::array<std::uint8_t, 1> off{0x00};
  bus.fpwr(Bus::station(0), reg::kDcActivation, off);
  bus.line().advance(20'000'000);
  EXPECT_EQ(esc.sync0_pulses(), 4U);
  // A start time already past: 0984h bit 2, never fires.
  bus.line().set_time(20'000'000);
  put_u64(start, 0, 19'000'000);
  bus.fpwr(Bus::station(0), reg::kDcSync0StartTime, start);
  bus.fpwr(Bus::station(0), reg::kDcActivation, act);
  EXPECT_EQ(bus.fprd(Bus::station(0), reg::kDcActivationStatus, 1).data[0], 0x04);
  bus.line().advance(30'000'000);
  EXPECT_EQ(esc.sync0_pulses(), 4U);
  EXPECT_FALSE(esc.sync0_running());
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
