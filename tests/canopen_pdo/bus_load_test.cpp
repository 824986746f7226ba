// Bus-load estimate against configurations computed by hand. Frame lengths with worst-case
// stuffing (wire/bit_timing.hpp): DLC 0 = 55 bits, 1 = 65, 6 = 115, 7 = 125, 8 = 135; an RTR = 55.
#include <gtest/gtest.h>

#include "adapters/canopen/wire/bus_load.hpp"

namespace drivegate::canopen {
namespace {

using namespace std::chrono_literals;

// 1 node, SYNC + 2 RPDOs of 8 + 2 TPDOs of 8 (type 1) at 500 kbit/s, 1 ms cycle:
// 55 + 4 * 135 = 595 bits = 1.19 ms -> 119 % of the cycle: the bus cannot carry it.
TEST(BusLoad, OneNodeFourFullPdosAt500kAnd1ms) {
  BusTraffic bus;
  bus.nodes.push_back({{8, 8}, {{8, 1, {}, {}}, {8, 1, {}, {}}}, NodeErrorControl::None, {}});
  const auto load = estimate_cycle_load(bus, 500000, 1ms);
  EXPECT_EQ(load.frames, 5U);
  EXPECT_EQ(load.bits, 595U);
  EXPECT_EQ(load.time, 1190us);
  EXPECT_DOUBLE_EQ(load.fraction, 1.19);
  EXPECT_EQ(load.unbounded, 0U);
  // At 1 Mbit/s the same traffic takes 595 us: 59.5 %.
  EXPECT_DOUBLE_EQ(estimate_cycle_load(bus, 1000000, 1ms).fraction, 0.595);
}

// 500 kbit/s, 2 ms cycle, SYNC, master heartbeat 100 ms.
// Node A (NORD-like): RxPDO1 DLC 8 (padded), TxPDO1 DLC 7 type 1, TxPDO2 DLC 8 type 2, an
//   event-driven DLC 6 TPDO with inhibit 10 ms and event timer 50 ms, heartbeat 100 ms.
// Node B (SD6-like): RPDO DLC 6, TPDO DLC 6 type 1, guarding every 100 ms.
// Per cycle (rates are cycle / period: 2 ms / 10 ms = 0.2, 2 ms / 100 ms = 0.02):
//   SYNC                         1     x 55  =  55
//   A: RxPDO1                    1     x 135 = 135
//      TxPDO1                    1     x 125 = 125
//      TxPDO2                    0.5   x 135 =  67.5
//      event TPDO                0.2   x 115 =  23
//      heartbeat                 0.02  x 65  =   1.3
//   B: RPDO + TPDO               2     x 115 = 230
//      guarding RTR + reply      0.02  x (55 + 65) = 2.4
//   master heartbeat             0.02  x 65  =   1.3
//   total                        5.78 frames, 640.5 bits -> 6 frames, 641 bits;
//   640.5 bits / 500 kbit/s = 1281 us = 64.05 % of 2 ms.
TEST(BusLoad, MixedConfigurationByHand) {
  BusTraffic bus;
  bus.master_heartbeat = 100ms;
  bus.nodes.push_back({{8}, {{7, 1, {}, {}}, {8, 2, {}, {}}, {6, 255, 10ms, 50ms}}, NodeErrorControl::Heartbeat, 100ms});
  bus.nodes.push_back({{6}, {{6, 1, {}, {}}}, NodeErrorControl::Guarding, 100ms});
  const auto load = estimate_cycle_load(bus, 500000, 2ms);
  EXPECT_EQ(load.frames, 6U);
  EXPECT_EQ(load.bits, 641U);
  EXPECT_EQ(load.time, 1281us);
  EXPECT_NEAR(load.fraction, 0.6405, 1e-12);
  EXPECT_EQ(load.unbounded, 0U);
}

// Without SYNC synchronous TPDOs never go out; an event-driven TPDO without an inhibit time is
// counted once per cycle (or per event timer when shorter) and flagged as unbounded.
// 250 kbit/s, 1 ms: RPDO 2 bytes (frame_bits(2) = 34 + 16 = 50 -> 50 + 12 + 13 = 75) +
// event TPDO DLC 2 with event timer 0.5 ms: 2 x 75 + event TPDO DLC 4 (34 + 32 = 66 -> 66 + 16 +
// 13 = 95) with a 5 ms event timer but no inhibit: 1 x 95 -> 75 + 150 + 95 = 320 bits = 1.28 ms.
TEST(BusLoad, WithoutSyncAndUnboundedEventDrivenTpdos) {
  BusTraffic bus;
  bus.sync = false;
  bus.nodes.push_back({{2}, {{8, 1, {}, {}}, {2, 254, {}, 500us}, {4, 255, {}, 5ms}}, NodeErrorControl::None, {}});
  const auto load = estimate_cycle_load(bus, 250000, 1ms);
  EXPECT_EQ(load.frames, 4U);
  EXPECT_EQ(load.bits, 320U);
  EXPECT_EQ(load.time, 1280us);
  EXPECT_DOUBLE_EQ(load.fraction, 1.28);
  EXPECT_EQ(load.unbounded, 2U);
}

TEST(BusLoad, TypeZeroCountsOncePerSyncAndHeartbeatsOnlyWithAPeriod) {
  BusTraffic bus;
  bus.nodes.push_back({{}, {{8, 0, {}, {}}}, NodeErrorControl::Heartbeat, {}});
  const auto load = estimate_cycle_load(bus, 1000000, 1ms);
  EXPECT_EQ(load.frames, 2U);  // SYNC + the TPDO
  EXPECT_EQ(load.bits, 55U + 135U);
}

TEST(BusLoad, DegenerateInputs) {
  BusTraffic bus;
  bus.nodes.push_back({{8}, {}, NodeErrorControl::None, {}});
  const auto no_cycle = estimate_cycle_load(bus, 500000, 0ms);
  EXPECT_EQ(no_cycle.bits, 0U);
  EXPECT_EQ(no_cycle.frames, 0U);
  EXPECT_EQ(no_cycle.fraction, 0.0);
  const auto no_rate = estimate_cycle_load(bus, 0, 1ms);
  EXPECT_EQ(no_rate.bits, 190U);
  EXPECT_EQ(no_rate.time, 0ns);
  EXPECT_EQ(no_rate.fraction, 0.0);
  const auto empty = estimate_cycle_load(BusTraffic{false, {}, {}}, 500000, 1ms);
  EXPECT_EQ(empty.frames, 0U);
  EXPECT_EQ(empty.bits, 0U);
}

}  // namespace
}  // namespace drivegate::canopen
