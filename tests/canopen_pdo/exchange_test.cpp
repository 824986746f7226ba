// Master NodePdos against a SlavePdos over TxQueues, with SYNCs in virtual time.
#include "tests/canopen_pdo/pdo_harness.hpp"

namespace drivegate::canopen::test {
namespace {

constexpr NodeId kNode = 1;

// One master, one slave, one wire: frames of each side are delivered to the other in order.
struct Wire {
  FakeObjects drive;
  NodePdos master;
  std::optional<sim::SlavePdos> slave;
  TxQueue master_tx;
  TxQueue slave_tx;
  std::uint32_t drop_id = 0;  // a slave frame to lose once
  std::vector<CanFrame> master_frames;
  std::vector<std::pair<core::TimePoint, std::uint32_t>> slave_frames;

  void to_slave(core::TimePoint now) {
    for (const auto& f : drain(master_tx)) {
      master_frames.push_back(f);
      if (f.id == cob::kSync) {
        slave->on_sync(now, slave_tx);
      } else {
        EXPECT_TRUE(slave->on_frame(f, now)) << std::hex << f.id;
      }
    }
  }
  void to_master(core::TimePoint now) {
    for (const auto& f : drain(slave_tx)) {
      slave_frames.emplace_back(now, f.id);
      if (f.id == drop_id) {
        drop_id = 0;
        continue;
      }
      EXPECT_TRUE(master.on_frame(f, now)) << std::hex << f.id;
    }
  }
  // One SYNC cycle: SYNC and RPDOs out, the slave answers, its TPDOs come back before the next.
  void sync_cycle(core::TimePoint now) {
    ASSERT_TRUE(master_tx.push(sync_frame()));
    master.after_sync(now, master_tx);
    to_slave(now + 100us);
    slave->poll(now + 200us, slave_tx);
    to_master(now + 300us);
  }
  // Without SYNC: both sides poll at `now`.
  void step(core::TimePoint now) {
    master.poll(now, master_tx);
    to_slave(now);
    slave->poll(now, slave_tx);
    to_master(now);
  }
};

TEST(PdoExchange, SynchronousTypesOneAndTwo) {
  Wire w;
  // RPDO1 CW + mode (type 1: applied at the next SYNC); TPDO1 SW every SYNC, TPDO2 position every
  // 2nd SYNC (AKD part 2 §12.10).
  const std::array<sim::SlavePdoConfig, 1> srx{
      slave_pdo(cob::rpdo(0, kNode), 1, {obj::kControlword, obj::kModesOfOperation})};
  const std::array<sim::SlavePdoConfig, 2> stx{slave_pdo(cob::tpdo(0, kNode), 1, {obj::kStatusword}),
                                               slave_pdo(cob::tpdo(1, kNode), 2, {obj::kPositionActual})};
  w.slave.emplace(w.drive, sim::SlavePdoOptions{}, srx, stx);
  const std::array<RpdoConfig, 1> mrx{
      {{cob::rpdo(0, kNode), layout({obj::kControlword, obj::kModesOfOperation}), 1, {}, 0}}};
  const std::array<TpdoConfig, 2> mtx{{{cob::tpdo(0, kNode), layout({obj::kStatusword}), 1, {}},
                                       {cob::tpdo(1, kNode), layout({obj::kPositionActual}), 2, {}}}};
  ASSERT_TRUE(w.master.configure(mrx, mtx));
  w.slave->set_operational(true);
  w.master.enable(true, kT0);
  w.master.image().set(obj::kModesOfOperation.id, 8);

  for (int c = 1; c <= 10; ++c) {
    const auto now = kT0 + c * 1ms;
    w.master.image().set(obj::kControlword.id, 0x100 + c);
    w.drive.set(obj::kStatusword.id, 0x200 + c);
    w.drive.set(obj::kPositionActual.id, -c);
    w.sync_cycle(now);
    // The CW of cycle c arrived after this SYNC: the drive applies it at the next one.
    EXPECT_EQ(w.drive.get(obj::kControlword.id), c == 1 ? 0 : 0x100 + c - 1) << c;
    EXPECT_EQ(w.master.image().get(obj::kStatusword.id), 0x200 + c);
    EXPECT_EQ(w.master.image().get(obj::kPositionActual.id), -(c - c % 2)) << c;  // sampled at even SYNCs
    EXPECT_EQ(w.master.inputs_fresh(now + 400us), c >= 2) << c;
  }
  EXPECT_EQ(w.drive.get(obj::kModesOfOperation.id), 8);
  EXPECT_EQ(w.master.counters().missed, 0U);
  EXPECT_EQ(w.master.counters().tpdos_received, 15U);  // 10 + 5
  EXPECT_EQ(w.master.counters().rpdos_sent, 10U);

  // TPDO2 lost at SYNC 12: inputs are stale until the drive's next one, the loss counted once.
  w.drop_id = cob::tpdo(1, kNode);
  w.sync_cycle(kT0 + 11ms);
  w.sync_cycle(kT0 + 12ms);
  EXPECT_FALSE(w.master.inputs_fresh(kT0 + 12400us));
  EXPECT_EQ(w.master.counters().missed, 0U);
  w.sync_cycle(kT0 + 13ms);
  EXPECT_EQ(w.master.counters().missed, 1U);
  EXPECT_FALSE(w.master.inputs_fresh(kT0 + 13400us));
  w.sync_cycle(kT0 + 14ms);
  EXPECT_TRUE(w.master.inputs_fresh(kT0 + 14400us));
  EXPECT_EQ(w.master.counters().missed, 1U);

  // The drive leaves Operational: no more TPDOs, every one is missed.
  w.slave->set_operational(false);
  w.sync_cycle(kT0 + 15ms);
  w.sync_cycle(kT0 + 16ms);
  EXPECT_FALSE(w.master.inputs_fresh(kT0 + 16400us));
  EXPECT_EQ(w.master.counters().missed, 2U);  // TPDO1 of SYNC 15 (TPDO2 is due at 16)
  EXPECT_EQ(w.slave->counters().ignored, 2U);  // the master's RPDOs
}

TEST(PdoExchange, EventDrivenWithInhibitTimeAndEventTimers) {
  Wire w;
  // Slave TPDO3 (AKD default SW + position) with inhibit 10 ms and event timer 50 ms (AKD part 1
  // §14 vectors 27/28); master RPDO1 CW event-driven with a 20 ms event timer.
  auto tpdo3 = slave_pdo(cob::tpdo(2, kNode), 255, {obj::kStatusword, obj::kPositionActual});
  tpdo3.inhibit_time = 100;
  tpdo3.event_timer = 50;
  const std::array<sim::SlavePdoConfig, 1> srx{slave_pdo(cob::rpdo(0, kNode), 255, {obj::kControlword})};
  const std::array<sim::SlavePdoConfig, 3> stx{sim::SlavePdoConfig{}, sim::SlavePdoConfig{}, tpdo3};
  w.slave.emplace(w.drive, sim::SlavePdoOptions{}, srx, stx);
  const std::array<RpdoConfig, 1> mrx{{{cob::rpdo(0, kNode), layout({obj::kControlword}), 255, 20ms, 0}}};
  const std::array<TpdoConfig, 1> mtx{{{cob::tpdo(2, kNode), layout({obj::kStatusword, obj::kPositionActual}), 255, 50ms}}};
  ASSERT_TRUE(w.master.configure(mrx, mtx));
  w.slave->set_operational(true);
  w.master.enable(true, kT0);

  std::vector<core::Duration> rpdo_at;
  std::uint64_t rpdos = 0;
  for (auto at = 0ms; at <= 200ms; at += 1ms) {
    const auto now = kT0 + at;
    w.drive.set(obj::kPositionActual.id, std::min<std::int64_t>(at / 1ms, 35));
    if (at == 5ms) w.master.image().set(obj::kControlword.id, 0x0F);
    w.step(now);
    if (w.slave->counters().rpdos_received != rpdos) {
      rpdos = w.slave->counters().rpdos_received;
      rpdo_at.push_back(at);
      EXPECT_EQ(w.drive.get(obj::kControlword.id), w.master.image().get(obj::kControlword.id));  // applied at once
    }
    // The inhibit time holds the last changes (31..35) back until 40 ms.
    if (at % 10ms == 0ms && at <= 30ms) {
      EXPECT_EQ(w.master.image().get(obj::kPositionActual.id), at / 1ms);
    }
    if (at > 30ms && at < 40ms) {
      EXPECT_EQ(w.master.image().get(obj::kPositionActual.id), 30);
    }
    if (at >= 40ms) {
      EXPECT_EQ(w.master.image().get(obj::kPositionActual.id), 35);
    }
    if (at > 0ms) {
      EXPECT_TRUE(w.master.inputs_fresh(now)) << at.count();
    }
  }
  std::vector<core::Duration> tpdo_at;
  for (const auto& [t, id] : w.slave_frames) {
    EXPECT_EQ(id, cob::tpdo(2, kNode));
    tpdo_at.push_back(t - kT0);
  }
  EXPECT_EQ(tpdo_at, (std::vector<core::Duration>{0ms, 10ms, 20ms, 30ms, 40ms, 90ms, 140ms, 190ms}));
  EXPECT_EQ(rpdo_at, (std::vector<core::Duration>{0ms, 5ms, 25ms, 45ms, 65ms, 85ms, 105ms, 125ms, 145ms, 165ms, 185ms}));
  EXPECT_EQ(w.master.last_received(), kT0 + 190ms);
  // The drive stops talking: the input is stale after twice the event timer.
  w.slave->set_operational(false);
  EXPECT_TRUE(w.master.inputs_fresh(kT0 + 290ms));
  EXPECT_FALSE(w.master.inputs_fresh(kT0 + 290ms + 1ns));
}

// NORD TV-B B1..B3 (nord-sk500p-ds402.md §10), node 20h: the master pads RxPDO1 (5 bytes mapped)
// to DLC 8, which the drive uses and counts; TxPDO1 comes back with its 7 mapped bytes.
TEST(PdoExchange, NordTvbPaddedRxPdo1AndSevenByteTxPdo1) {
  constexpr NodeId kNord = 0x20;
  Wire w;
  const std::array<sim::SlavePdoConfig, 1> srx{
      slave_pdo(cob::rpdo(0, kNord), 1, {obj::kControlword, obj::kVlTargetVelocity, obj::kModesOfOperation})};
  const std::array<sim::SlavePdoConfig, 1> stx{
      slave_pdo(cob::tpdo(0, kNord), 1,
                {obj::kStatusword, obj::kVlVelocityActual, obj::kModesOfOperationDisplay, obj::kTorqueActual})};
  w.slave.emplace(w.drive, sim::SlavePdoOptions{}, srx, stx);
  const std::array<RpdoConfig, 1> mrx{
      {{cob::rpdo(0, kNord), layout({obj::kControlword, obj::kVlTargetVelocity, obj::kModesOfOperation}), 1, {}, 8}}};
  const std::array<TpdoConfig, 1> mtx{{{cob::tpdo(0, kNord),
                                        layout({obj::kStatusword, obj::kVlVelocityActual, obj::kModesOfOperationDisplay,
                                                obj::kTorqueActual}),
                                        1,
                                        {}}}};
  ASSERT_TRUE(w.master.configure(mrx, mtx));
  w.slave->set_operational(true);
  w.master.enable(true, kT0);
  w.master.image().set(obj::kModesOfOperation.id, 6);
  w.drive.set(obj::kModesOfOperationDisplay.id, 6);

  const std::pair<int, int> steps[] = {{0x06, 0x0231}, {0x07, 0x0233}, {0x0F, 0x0237}};  // CW / SW of B1..B3
  auto now = kT0;
  for (const auto& [cw, sw] : steps) {
    w.master.image().set(obj::kControlword.id, cw);
    w.sync_cycle(now += 1ms);  // RxPDO1 reaches the drive, which applies it at the next SYNC
    const auto& rx = w.master_frames.back();
    EXPECT_EQ(rx.id, 0x220U);
    EXPECT_EQ(payload(rx), (Bytes{static_cast<std::uint8_t>(cw), 0, 0, 0, 0x06, 0, 0, 0}));
    w.drive.set(obj::kStatusword.id, sw);  // the drive's answer (the fake object store has no model)
    w.sync_cycle(now += 1ms);
    EXPECT_EQ(w.drive.get(obj::kControlword.id), cw);
    EXPECT_EQ(w.master.image().get(obj::kStatusword.id), sw);
    EXPECT_EQ(w.master.image().get(obj::kModesOfOperationDisplay.id), 6);
  }
  EXPECT_EQ(w.slave->counters().long_rpdos, 6U);
  EXPECT_EQ(w.slave->counters().short_rpdos, 0U);
  EXPECT_EQ(w.master.counters().long_frames, 0U);
  EXPECT_EQ(w.master.counters().short_frames, 0U);
}

}  // namespace
}  // namespace drivegate::canopen::test
