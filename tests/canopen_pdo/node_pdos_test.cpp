// NodePdos, the master's PDO exchange of one node, driven with byte-exact frames in virtual time.
#include "tests/canopen_pdo/pdo_harness.hpp"
#include "tests/support/alloc_counter.hpp"

namespace drivegate::canopen::test {
namespace {

constexpr NodeId kNord = 0x20;

// The NORD default maps (nord-sk500p-ds402.md §8.1): RxPDO1 padded to DLC 8, TxPDO1 of 7 bytes.
struct NordPdos {
  std::array<RpdoConfig, 2> rpdos{};
  std::array<TpdoConfig, 2> tpdos{};
  NodePdos pdos;
  TxQueue tx;
  NordPdos() {
    rpdos[0] = {cob::rpdo(0, kNord), layout({obj::kControlword, obj::kVlTargetVelocity, obj::kModesOfOperation}), 1, {}, 8};
    rpdos[1] = {cob::rpdo(1, kNord), layout({obj::kProfileAcceleration, obj::kProfileDeceleration}), 1, {}, 0};
    tpdos[0] = {cob::tpdo(0, kNord),
                layout({obj::kStatusword, obj::kVlVelocityActual, obj::kModesOfOperationDisplay, obj::kTorqueActual}),
                1,
                {}};
    tpdos[1] = {cob::tpdo(1, kNord), layout({obj::kPositionActual, obj::kVelocityActual}), 1, {}};
    EXPECT_TRUE(pdos.configure(rpdos, tpdos));
  }
};

TEST(NodePdos, NothingFlowsWhileNotEnabled) {
  NordPdos n;
  n.pdos.after_sync(kT0, n.tx);
  n.pdos.poll(kT0, n.tx);
  EXPECT_TRUE(n.tx.empty());
  EXPECT_TRUE(n.pdos.on_frame(make_frame(0x1A0, {0x37, 0x02, 0, 0, 1, 0, 0}), kT0));  // ours, but dropped
  EXPECT_EQ(n.pdos.image().get(obj::kStatusword.id), 0);
  EXPECT_EQ(n.pdos.counters().ignored, 1U);
  EXPECT_EQ(n.pdos.counters().tpdos_received, 0U);
  EXPECT_FALSE(n.pdos.inputs_fresh(kT0));
  EXPECT_EQ(n.pdos.next_deadline(), core::TimePoint::max());
}

TEST(NodePdos, SynchronousRpdosFollowEverySyncWithTheConfiguredDlc) {
  NordPdos n;
  n.pdos.enable(true, kT0);
  auto& img = n.pdos.image();
  img.set(obj::kControlword.id, 0x06);  // TV-B B1
  img.set(obj::kModesOfOperation.id, 6);
  img.set(obj::kProfileAcceleration.id, 750);  // TV-C C1
  img.set(obj::kProfileDeceleration.id, 750);
  n.pdos.poll(kT0, n.tx);  // synchronous PDOs wait for the SYNC
  EXPECT_TRUE(n.tx.empty());
  for (int cycle = 0; cycle < 3; ++cycle) {
    n.pdos.after_sync(kT0 + cycle * 1ms, n.tx);
    const auto frames = drain(n.tx);
    ASSERT_EQ(frames.size(), 2U);
    EXPECT_EQ(frames[0].id, 0x220U);
    EXPECT_EQ(frames[0].dlc, 8);  // 5 mapped bytes, padded
    EXPECT_EQ(payload(frames[0]), (Bytes{0x06, 0, 0, 0, 0x06, 0, 0, 0}));
    EXPECT_EQ(frames[1].id, 0x320U);
    EXPECT_EQ(payload(frames[1]), (Bytes{0xEE, 0x02, 0, 0, 0xEE, 0x02, 0, 0}));
  }
  EXPECT_EQ(n.pdos.counters().rpdos_sent, 6U);
}

// rpdo_refresh: after the drive's first TPDO, a synchronous RPDO goes after a SYNC only when its
// bytes changed or its refresh ran out; before it, and after every enable(), after every SYNC.
TEST(NodePdos, SynchronousRpdosWithARefreshGoOnlyWhenChangedOrDue) {
  NordPdos n;
  n.rpdos[0].refresh = 20ms;
  n.rpdos[1].refresh = 20ms;
  ASSERT_TRUE(n.pdos.configure(n.rpdos, n.tpdos));
  n.pdos.enable(true, kT0);
  auto& img = n.pdos.image();
  img.set(obj::kControlword.id, 0x06);
  const auto sync = [&](core::Duration at) {
    n.pdos.after_sync(kT0 + at, n.tx);
    return drain(n.tx);
  };
  // Nothing heard from the drive yet: every SYNC, unchanged or not.
  EXPECT_EQ(sync(0ms).size(), 2U);
  EXPECT_EQ(sync(4ms).size(), 2U);
  ASSERT_TRUE(n.pdos.on_frame(make_frame(0x1A0, {0x37, 0x02, 0, 0, 6, 0, 0}), kT0 + 5ms));
  EXPECT_TRUE(sync(8ms).empty());  // unchanged since 4 ms
  img.set(obj::kControlword.id, 0x0F);
  auto frames = sync(12ms);
  ASSERT_EQ(frames.size(), 1U);  // only the RPDO whose bytes changed
  EXPECT_EQ(frames[0].id, 0x220U);
  EXPECT_EQ(payload(frames[0]), (Bytes{0x0F, 0, 0, 0, 0, 0, 0, 0}));
  EXPECT_TRUE(sync(16ms).empty());
  // RPDO2 was last sent at 4 ms: due again at 24 ms; RPDO1 (sent at 12 ms) at 32 ms.
  EXPECT_TRUE(sync(20ms).empty());
  frames = sync(24ms);
  ASSERT_EQ(frames.size(), 1U);
  EXPECT_EQ(frames[0].id, 0x320U);
  EXPECT_TRUE(sync(28ms).empty());
  frames = sync(32ms);
  ASSERT_EQ(frames.size(), 1U);
  EXPECT_EQ(frames[0].id, 0x220U);
  EXPECT_EQ(payload(frames[0]), (Bytes{0x0F, 0, 0, 0, 0, 0, 0, 0}));
  // A drive that comes back (disable, enable: a new boot) gets every RPDO after every SYNC again
  // until it speaks.
  n.pdos.enable(false, kT0 + 33ms);
  n.pdos.enable(true, kT0 + 34ms);
  EXPECT_EQ(sync(36ms).size(), 2U);
  EXPECT_EQ(sync(40ms).size(), 2U);
  ASSERT_TRUE(n.pdos.on_frame(make_frame(0x1A0, {0x37, 0x02, 0, 0, 6, 0, 0}), kT0 + 41ms));
  EXPECT_TRUE(sync(44ms).empty());
}

// A frame the queue had no room for is not taken as sent: it goes at the next SYNC.
TEST(NodePdos, ARefusedRpdoWithARefreshGoesAtTheNextSync) {
  NordPdos n;
  n.rpdos[0].refresh = 1s;
  n.rpdos[1].refresh = 1s;
  ASSERT_TRUE(n.pdos.configure(n.rpdos, n.tpdos));
  n.pdos.enable(true, kT0);
  n.pdos.after_sync(kT0, n.tx);
  (void)drain(n.tx);
  ASSERT_TRUE(n.pdos.on_frame(make_frame(0x1A0, {0x37, 0x02, 0, 0, 6, 0, 0}), kT0 + 1ms));
  n.pdos.image().set(obj::kControlword.id, 0x0F);
  CanFrame filler;
  while (n.tx.push(filler)) {
  }
  n.pdos.after_sync(kT0 + 4ms, n.tx);
  EXPECT_EQ(n.pdos.counters().tx_full, 1U);
  (void)drain(n.tx);
  n.pdos.after_sync(kT0 + 8ms, n.tx);
  const auto frames = drain(n.tx);
  ASSERT_EQ(frames.size(), 1U);
  EXPECT_EQ(payload(frames[0]), (Bytes{0x0F, 0, 0, 0, 0, 0, 0, 0}));
}

TEST(NodePdos, TpdoFramesUpdateTheImageWithTheirTime) {
  NordPdos n;
  n.pdos.enable(true, kT0);
  n.pdos.after_sync(kT0, n.tx);
  EXPECT_TRUE(n.pdos.on_frame(make_frame(0x1A0, {0x37, 0x12, 0xDC, 0x05, 0x06, 0x10, 0x00}), kT0 + 300us));
  EXPECT_TRUE(n.pdos.on_frame(make_frame(0x2A0, {0x40, 0x0D, 0x03, 0x00, 0x18, 0xFC, 0xFF, 0xFF}), kT0 + 400us));
  const auto& img = n.pdos.image();
  EXPECT_EQ(img.get(obj::kStatusword.id), 0x1237);
  EXPECT_EQ(img.get(obj::kVlVelocityActual.id), 1500);
  EXPECT_EQ(img.get(obj::kModesOfOperationDisplay.id), 6);
  EXPECT_EQ(img.get(obj::kTorqueActual.id), 16);
  EXPECT_EQ(img.get(obj::kPositionActual.id), 200000);
  EXPECT_EQ(img.get(obj::kVelocityActual.id), -1000);
  EXPECT_EQ(n.pdos.last_received(0), kT0 + 300us);
  EXPECT_EQ(n.pdos.last_received(1), kT0 + 400us);
  EXPECT_EQ(n.pdos.last_received(2), core::TimePoint{});
  EXPECT_EQ(n.pdos.last_received(), kT0 + 400us);
  EXPECT_EQ(n.pdos.counters().tpdos_received, 2U);
}

TEST(NodePdos, ShortTpdosAreDroppedLongOnesUsedAndBothCounted) {
  NordPdos n;
  n.pdos.enable(true, kT0);
  n.pdos.image().set(obj::kStatusword.id, 0x0231);
  EXPECT_TRUE(n.pdos.on_frame(make_frame(0x1A0, {0x37, 0x02, 0, 0, 1, 0}), kT0));  // 6 of 7 bytes
  EXPECT_EQ(n.pdos.image().get(obj::kStatusword.id), 0x0231);
  EXPECT_EQ(n.pdos.counters().short_frames, 1U);
  EXPECT_EQ(n.pdos.counters().tpdos_received, 0U);
  EXPECT_EQ(n.pdos.last_received(0), core::TimePoint{});
  EXPECT_TRUE(n.pdos.on_frame(make_frame(0x1A0, {0x37, 0x02, 0, 0, 1, 0, 0, 0x55}), kT0));  // padded to 8
  EXPECT_EQ(n.pdos.image().get(obj::kStatusword.id), 0x0237);
  EXPECT_EQ(n.pdos.counters().long_frames, 1U);
  EXPECT_EQ(n.pdos.counters().tpdos_received, 1U);
}

TEST(NodePdos, ForeignImpossibleAndRemoteFramesAreNotTaken) {
  NordPdos n;
  n.pdos.enable(true, kT0);
  EXPECT_FALSE(n.pdos.on_frame(make_frame(0x1A1, {0x37, 0x02, 0, 0, 1, 0, 0}), kT0));  // another node
  EXPECT_FALSE(n.pdos.on_frame(make_frame(0x220, {0x06, 0, 0, 0, 6, 0, 0, 0}), kT0));  // our own RPDO
  auto ext = make_frame(0x1A0, {0x37, 0x02, 0, 0, 1, 0, 0});
  ext.extended = true;
  EXPECT_FALSE(n.pdos.on_frame(ext, kT0));
  auto rtr = make_frame(0x1A0, {});
  rtr.remote = true;
  rtr.dlc = 7;
  EXPECT_TRUE(n.pdos.on_frame(rtr, kT0));
  auto bad = make_frame(0x1A0, {0x37, 0x02, 0, 0, 1, 0, 0, 0});
  bad.dlc = 15;  // cannot exist on classic CAN
  EXPECT_TRUE(n.pdos.on_frame(bad, kT0));
  EXPECT_EQ(n.pdos.counters().ignored, 2U);
  EXPECT_EQ(n.pdos.counters().tpdos_received, 0U);
  EXPECT_EQ(n.pdos.image().get(obj::kStatusword.id), 0);
}

TEST(NodePdos, MissedSynchronousTpdosAreCountedAtTheNextSync) {
  NordPdos n;
  n.pdos.enable(true, kT0);
  const auto tx1 = make_frame(0x1A0, {0x37, 0x02, 0, 0, 1, 0, 0});
  const auto tx2 = make_frame(0x2A0, {0, 0, 0, 0, 0, 0, 0, 0});
  n.pdos.after_sync(kT0, n.tx);
  n.pdos.on_frame(tx1, kT0 + 200us);
  n.pdos.on_frame(tx2, kT0 + 300us);
  n.pdos.after_sync(kT0 + 1ms, n.tx);
  EXPECT_EQ(n.pdos.counters().missed, 0U);
  n.pdos.on_frame(tx1, kT0 + 1200us);  // TxPDO2 lost in this cycle
  EXPECT_EQ(n.pdos.counters().missed, 0U);  // not known before the cycle ends
  n.pdos.after_sync(kT0 + 2ms, n.tx);
  EXPECT_EQ(n.pdos.counters().missed, 1U);
  n.pdos.after_sync(kT0 + 3ms, n.tx);  // nothing at all in this cycle
  EXPECT_EQ(n.pdos.counters().missed, 3U);
}

TEST(NodePdos, FreshnessOfSynchronousTpdos) {
  NordPdos n;
  const auto tx1 = make_frame(0x1A0, {0x37, 0x02, 0, 0, 1, 0, 0});
  const auto tx2 = make_frame(0x2A0, {0, 0, 0, 0, 0, 0, 0, 0});
  n.pdos.enable(true, kT0);
  EXPECT_FALSE(n.pdos.inputs_fresh(kT0));  // nothing received yet
  n.pdos.after_sync(kT0, n.tx);
  n.pdos.on_frame(tx1, kT0 + 200us);
  EXPECT_FALSE(n.pdos.inputs_fresh(kT0 + 200us));  // TxPDO2 still missing
  n.pdos.on_frame(tx2, kT0 + 300us);
  EXPECT_TRUE(n.pdos.inputs_fresh(kT0 + 300us));
  EXPECT_TRUE(n.pdos.inputs_fresh(kT0 + 900us));  // no timeout within the cycle
  n.pdos.after_sync(kT0 + 1ms, n.tx);
  EXPECT_FALSE(n.pdos.inputs_fresh(kT0 + 1ms));  // this cycle's frames are not in yet
  n.pdos.on_frame(tx1, kT0 + 1200us);
  n.pdos.on_frame(tx2, kT0 + 1300us);
  EXPECT_TRUE(n.pdos.inputs_fresh(kT0 + 1300us));
  n.pdos.enable(false, kT0 + 1400us);
  EXPECT_FALSE(n.pdos.inputs_fresh(kT0 + 1400us));
  n.pdos.enable(true, kT0 + 1500us);  // a restart needs new frames
  EXPECT_FALSE(n.pdos.inputs_fresh(kT0 + 1500us));
}

TEST(NodePdos, EveryNthSyncTpdoIsFreshBetweenItsSlotsAndMissedOncePerSlot) {
  // AKD part 2 §12.10: TPDO1 (6064h) on every 2nd SYNC.
  const std::array<TpdoConfig, 1> tpdos{{{cob::tpdo(0, 3), layout({obj::kPositionActual}), 2, {}}}};
  NodePdos pdos;
  ASSERT_TRUE(pdos.configure({}, tpdos));
  TxQueue tx;
  pdos.enable(true, kT0);
  const auto frame = make_frame(0x183, {0xFE, 0x45, 0x01, 0x00});
  pdos.after_sync(kT0, tx);  // S1: not due
  EXPECT_FALSE(pdos.inputs_fresh(kT0 + 500us));
  pdos.after_sync(kT0 + 1ms, tx);  // S2: due
  pdos.on_frame(frame, kT0 + 1200us);
  EXPECT_TRUE(pdos.inputs_fresh(kT0 + 1200us));
  EXPECT_EQ(pdos.image().get(obj::kPositionActual.id), 83454);
  pdos.after_sync(kT0 + 2ms, tx);  // S3: not due, still fresh
  EXPECT_TRUE(pdos.inputs_fresh(kT0 + 2500us));
  pdos.after_sync(kT0 + 3ms, tx);  // S4: due, and lost
  EXPECT_FALSE(pdos.inputs_fresh(kT0 + 3500us));
  pdos.after_sync(kT0 + 4ms, tx);  // S5
  EXPECT_EQ(pdos.counters().missed, 1U);
  EXPECT_FALSE(pdos.inputs_fresh(kT0 + 4500us));  // stale until the drive is heard again
  pdos.after_sync(kT0 + 5ms, tx);  // S6: due
  pdos.on_frame(frame, kT0 + 5200us);
  EXPECT_TRUE(pdos.inputs_fresh(kT0 + 5200us));
  pdos.after_sync(kT0 + 6ms, tx);
  pdos.after_sync(kT0 + 7ms, tx);  // S8: due
  pdos.on_frame(frame, kT0 + 7200us);
  pdos.after_sync(kT0 + 8ms, tx);
  EXPECT_EQ(pdos.counters().missed, 1U);
  EXPECT_TRUE(tx.empty());  // no RPDOs configured
}

TEST(NodePdos, EventDrivenTpdoFreshWithinTwiceItsEventTimer) {
  const std::array<TpdoConfig, 2> tpdos{{{cob::tpdo(2, 1), layout({obj::kStatusword, obj::kPositionActual}), 255, 50ms},
                                         {cob::tpdo(3, 1), layout({obj::kStatusword, obj::kVelocityActual}), 255, {}}}};
  NodePdos pdos;
  ASSERT_TRUE(pdos.configure({}, tpdos));
  TxQueue tx;
  pdos.enable(true, kT0);
  pdos.on_frame(make_frame(0x381, {0x37, 0x02, 0xE8, 0x03, 0, 0}), kT0);  // AKD vector 31
  EXPECT_FALSE(pdos.inputs_fresh(kT0));  // TPDO4 never seen
  pdos.on_frame(make_frame(0x481, {0x37, 0x02, 0, 0, 0, 0}), kT0 + 1ms);
  EXPECT_TRUE(pdos.inputs_fresh(kT0 + 1ms));
  pdos.after_sync(kT0 + 2ms, tx);  // SYNCs do not matter to event-driven TPDOs
  EXPECT_TRUE(pdos.inputs_fresh(kT0 + 100ms));   // exactly twice the event timer
  EXPECT_FALSE(pdos.inputs_fresh(kT0 + 100ms + 1ns));
  EXPECT_FALSE(pdos.inputs_fresh(kT0 + 10s));
  pdos.on_frame(make_frame(0x381, {0x37, 0x02, 0xE8, 0x03, 0, 0}), kT0 + 10s);
  EXPECT_TRUE(pdos.inputs_fresh(kT0 + 10s));  // TPDO4 has no timer: once seen is enough
  EXPECT_EQ(pdos.counters().missed, 0U);
}

TEST(NodePdos, EventDrivenRpdoOnChangeAndOnItsEventTimer) {
  const std::array<RpdoConfig, 1> rpdos{{{cob::rpdo(0, 1), layout({obj::kControlword}), 255, 20ms, 0}}};
  NodePdos pdos;
  ASSERT_TRUE(pdos.configure(rpdos, {}));
  TxQueue tx;
  pdos.enable(true, kT0);
  EXPECT_LE(pdos.next_deadline(), kT0);  // the first frame is due at once
  pdos.image().set(obj::kControlword.id, 0x06);
  pdos.poll(kT0, tx);
  auto frames = drain(tx);
  ASSERT_EQ(frames.size(), 1U);
  EXPECT_EQ(frames[0].id, 0x201U);
  EXPECT_EQ(payload(frames[0]), (Bytes{0x06, 0x00}));
  EXPECT_EQ(pdos.next_deadline(), kT0 + 20ms);
  pdos.poll(kT0 + 5ms, tx);  // unchanged, timer running
  EXPECT_TRUE(tx.empty());
  pdos.image().set(obj::kControlword.id, 0x07);
  pdos.poll(kT0 + 6ms, tx);  // changed: sent at once, timer restarts
  frames = drain(tx);
  ASSERT_EQ(frames.size(), 1U);
  EXPECT_EQ(payload(frames[0]), (Bytes{0x07, 0x00}));
  EXPECT_EQ(pdos.next_deadline(), kT0 + 26ms);
  pdos.poll(kT0 + 26ms - 1ns, tx);
  EXPECT_TRUE(tx.empty());
  pdos.poll(kT0 + 26ms, tx);  // event timer: resent unchanged
  EXPECT_EQ(drain(tx).size(), 1U);
  pdos.after_sync(kT0 + 27ms, tx);  // a SYNC also checks event-driven RPDOs, but nothing is due
  EXPECT_TRUE(tx.empty());
  pdos.image().set(obj::kControlword.id, 0x0F);
  pdos.after_sync(kT0 + 28ms, tx);
  EXPECT_EQ(drain(tx).size(), 1U);
}

TEST(NodePdos, RefusedFramesAreCountedAndRetried) {
  const std::array<RpdoConfig, 2> rpdos{{{cob::rpdo(0, 1), layout({obj::kControlword}), 1, {}, 0},
                                         {cob::rpdo(1, 1), layout({obj::kTargetPosition}), 255, {}, 0}}};
  NodePdos pdos;
  ASSERT_TRUE(pdos.configure(rpdos, {}));
  pdos.enable(true, kT0);
  TxQueue full;
  for (std::size_t i = 0; i < 1024; ++i) ASSERT_TRUE(full.push(sync_frame()));
  pdos.after_sync(kT0, full);
  EXPECT_EQ(pdos.counters().tx_full, 2U);
  EXPECT_EQ(pdos.counters().rpdos_sent, 0U);
  TxQueue tx;
  pdos.poll(kT0 + 1ms, tx);  // the event-driven one was never sent: it goes now
  const auto frames = drain(tx);
  ASSERT_EQ(frames.size(), 1U);
  EXPECT_EQ(frames[0].id, 0x301U);
}

TEST(NodePdos, ConfigureRefusesWhatCannotWork) {
  NodePdos pdos;
  const auto cw = layout({obj::kControlword});
  const std::array<RpdoConfig, 5> five{};
  EXPECT_FALSE(pdos.configure(five, {}));
  const std::array<RpdoConfig, 1> short_dlc{{{0x201, layout({obj::kControlword, obj::kTargetPosition}), 1, {}, 4}}};
  EXPECT_FALSE(pdos.configure(short_dlc, {}));
  const std::array<RpdoConfig, 1> long_dlc{{{0x201, cw, 1, {}, 9}}};
  EXPECT_FALSE(pdos.configure(long_dlc, {}));
  const std::array<RpdoConfig, 1> extended_id{{{0x80000201, cw, 1, {}, 0}}};
  EXPECT_FALSE(pdos.configure(extended_id, {}));
  const std::array<TpdoConfig, 1> rtr_only{{{0x181, layout({obj::kStatusword}), 253, {}}}};
  EXPECT_FALSE(pdos.configure({}, rtr_only));
  // 4 + 4 PDOs of 8 one-byte objects each fill the image exactly; a conflicting type does not fit.
  std::array<RpdoConfig, 4> rx{};
  std::array<TpdoConfig, 4> txs{};
  for (std::uint8_t p = 0; p < 4; ++p) {
    for (std::uint8_t s = 0; s < 8; ++s) {
      const auto sub = static_cast<std::uint8_t>(p * 8 + s);
      ASSERT_EQ(rx[p].layout.add({{0x2000, sub}, DataType::U8}, 8), PdoLayout::Error::None);
      ASSERT_EQ(txs[p].layout.add({{0x2100, sub}, DataType::U8}, 8), PdoLayout::Error::None);
    }
    rx[p].cob_id = cob::rpdo(p, 1);
    txs[p].cob_id = cob::tpdo(p, 1);
  }
  EXPECT_TRUE(pdos.configure(rx, txs));
  txs[3].layout.fields[7].def = {{0x2000, 0}, DataType::I8};  // same object as an RPDO's, other type
  EXPECT_FALSE(pdos.configure(rx, txs));
  // The last good configuration stays.
  EXPECT_TRUE(pdos.image().contains({0x2100, 31}));
}

TEST(NodePdos, ReconfigureKeepsValuesOfObjectsStillMapped) {
  NordPdos n;
  n.pdos.image().set(obj::kControlword.id, 0x0F);
  n.pdos.image().set(obj::kProfileAcceleration.id, 750);
  const std::array<RpdoConfig, 1> rpdos{
      {{cob::rpdo(0, kNord), layout({obj::kControlword, obj::kTargetVelocity}), 1, {}, 0}}};
  ASSERT_TRUE(n.pdos.configure(rpdos, {}));
  EXPECT_EQ(n.pdos.image().get(obj::kControlword.id), 0x0F);
  EXPECT_FALSE(n.pdos.image().contains(obj::kProfileAcceleration.id));
  EXPECT_TRUE(n.pdos.image().contains(obj::kTargetVelocity.id));
}

TEST(NodePdos, CyclicCallsDoNotAllocate) {
  NordPdos n;
  const std::array<RpdoConfig, 1> ev{{{cob::rpdo(3, kNord), layout({obj::kTargetVelocity}), 255, 10ms, 0}}};
  std::array<RpdoConfig, 3> rpdos{n.rpdos[0], n.rpdos[1], ev[0]};
  ASSERT_TRUE(n.pdos.configure(rpdos, n.tpdos));
  const auto tx1 = make_frame(0x1A0, {0x37, 0x02, 0, 0, 1, 0, 0, 0});
  const auto tx2 = make_frame(0x2A0, {0, 0, 0, 0, 0, 0});  // short
  drivegate::test::AllocationScope scope;
  n.pdos.enable(true, kT0);
  for (int c = 0; c < 50; ++c) {
    const auto now = kT0 + c * 1ms;
    n.pdos.image().set(obj::kTargetVelocity.id, c / 5);
    n.pdos.after_sync(now, n.tx);
    n.pdos.poll(now + 100us, n.tx);
    n.pdos.on_frame(tx1, now + 200us);
    n.pdos.on_frame(tx2, now + 300us);
    static_cast<void>(n.pdos.inputs_fresh(now + 400us));
    static_cast<void>(n.pdos.next_deadline());
    n.tx.clear();
  }
  EXPECT_EQ(scope.count(), 0U);
  EXPECT_EQ(n.pdos.counters().short_frames, 50U);
  EXPECT_GT(n.pdos.counters().missed, 40U);
}

}  // namespace
}  // namespace drivegate::canopen::test
