// NORD SK 500P TV-B, TV-C and TV-D (nord-sk500p-ds402.md §10) through the master's NodePdos with
// the NORD maps of the device profile (§8.1): RxPDO1 CW | 6042h | 6060h sent with DLC 8, RxPDO2
// 6083h | 6084h, RxPDO3 607Ah | 6081h, all event-driven; TxPDO1 SW | 6044h | 6061h | 6077h. Every
// "data sent" row must be the frame the master sends, every "data received" row must decode to the
// statusword and mode the row states whatever its "xx" (don't care) bytes hold.
#include "tests/canopen_pdo/pdo_harness.hpp"

namespace drivegate::canopen::test {
namespace {

constexpr NodeId kNord = 0x20;

struct NordMaster {
  std::array<RpdoConfig, 3> rpdos{};
  std::array<TpdoConfig, 1> tpdos{};
  NodePdos pdos;
  TxQueue tx;
  core::TimePoint now = kT0;

  NordMaster() {
    rpdos[0] = {cob::rpdo(0, kNord), layout({obj::kControlword, obj::kVlTargetVelocity, obj::kModesOfOperation}), 255,
                {}, 8};
    rpdos[1] = {cob::rpdo(1, kNord), layout({obj::kProfileAcceleration, obj::kProfileDeceleration}), 255, {}, 0};
    rpdos[2] = {cob::rpdo(2, kNord), layout({obj::kTargetPosition, obj::kProfileVelocity}), 255, {}, 0};
    tpdos[0] = {cob::tpdo(0, kNord),
                layout({obj::kStatusword, obj::kVlVelocityActual, obj::kModesOfOperationDisplay, obj::kTorqueActual}),
                1,
                {}};
    EXPECT_TRUE(pdos.configure(rpdos, tpdos));
    pdos.enable(true, now);
  }
  std::vector<CanFrame> poll() {
    pdos.poll(now += 1ms, tx);
    return drain(tx);
  }
  // A TxPDO1 as printed; -1 marks "xx", filled with `fill`.
  void receive(const std::array<int, 7>& printed, std::uint8_t fill) {
    std::array<std::uint8_t, 7> b{};
    for (std::size_t i = 0; i < b.size(); ++i) b[i] = printed[i] < 0 ? fill : static_cast<std::uint8_t>(printed[i]);
    EXPECT_TRUE(pdos.on_frame(make_frame(cob::tpdo(0, kNord), b), now));
  }
};

struct Step {
  const char* name;
  int controlword;
  Bytes sent;                   // RxPDO1; empty: unchanged, the event-driven RxPDO1 is not sent again
  std::array<int, 7> received;  // TxPDO1
  int statusword;
  int mode_display;
};

void run(NordMaster& m, const std::vector<Step>& steps) {
  for (const auto& s : steps) {
    SCOPED_TRACE(s.name);
    m.pdos.image().set(obj::kControlword.id, s.controlword);
    std::vector<Bytes> rx1;
    for (const auto& f : m.poll()) {
      if (f.id == cob::rpdo(0, kNord)) rx1.push_back(payload(f));
    }
    if (s.sent.empty()) {
      EXPECT_TRUE(rx1.empty());
    } else {
      EXPECT_EQ(rx1, std::vector<Bytes>{s.sent});  // 5 mapped bytes, padded to 8
    }
    for (const std::uint8_t fill : {std::uint8_t{0x00}, std::uint8_t{0xFF}}) {
      m.receive(s.received, fill);
      EXPECT_EQ(m.pdos.image().get(obj::kStatusword.id), s.statusword);
      EXPECT_EQ(m.pdos.image().get(obj::kModesOfOperationDisplay.id), s.mode_display);
    }
  }
  EXPECT_EQ(m.pdos.counters().short_frames + m.pdos.counters().long_frames, 0U);
}

// TV-B: homing, method 24, mode 6; bit 4 held at 1 from B4 on (B5, B6 change only the statusword).
TEST(NordDigestPdo, TvbHoming) {
  NordMaster m;
  m.pdos.image().set(obj::kModesOfOperation.id, 6);
  run(m, {
             {"B1", 0x0006, {0x06, 0x00, 0x00, 0x00, 0x06, 0x00, 0x00, 0x00},
              {0x31, 0x02, -1, -1, 0x06, -1, -1}, 0x0231, 6},
             {"B2", 0x0007, {0x07, 0x00, 0x00, 0x00, 0x06, 0x00, 0x00, 0x00},
              {0x33, 0x02, -1, -1, 0x06, -1, -1}, 0x0233, 6},
             {"B3", 0x000F, {0x0F, 0x00, 0x00, 0x00, 0x06, 0x00, 0x00, 0x00},
              {0x37, 0x02, -1, -1, 0x06, -1, -1}, 0x0237, 6},
             {"B4", 0x001F, {0x1F, 0x00, 0x00, 0x00, 0x06, 0x00, 0x00, 0x00},
              {0x37, 0x02, -1, -1, 0x06, -1, -1}, 0x0237, 6},
             {"B5", 0x001F, {},
              {0x37, 0x12, -1, -1, 0x06, -1, -1}, 0x1237, 6},
             {"B6", 0x001F, {},
              {0x37, 0x16, -1, -1, 0x06, -1, -1}, 0x1637, 6},
         });
}

// TV-C: profile position, mode 1. C5's position bytes are the corrected 200.000 rev (raw 200000):
// the printed 03 D0 90 00 decode to 9 490 435 (§10 TV-C, §12 item 12).
TEST(NordDigestPdo, TvcProfilePosition) {
  NordMaster m;
  auto& img = m.pdos.image();
  img.set(obj::kModesOfOperation.id, 1);
  img.set(obj::kControlword.id, 0x0006);
  img.set(obj::kProfileAcceleration.id, 750);  // C1: 750 rpm/s both ways
  img.set(obj::kProfileDeceleration.id, 750);
  const auto first = m.poll();  // C1 and C2's RxPDO1: the first send of each event-driven RxPDO
  ASSERT_EQ(first.size(), 3U);
  EXPECT_EQ(first[1].id, 0x320U);
  EXPECT_EQ(payload(first[1]), (Bytes{0xEE, 0x02, 0x00, 0x00, 0xEE, 0x02, 0x00, 0x00}));
  EXPECT_EQ(payload(first[0]), (Bytes{0x06, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00}));  // C2
  EXPECT_EQ(first[2].id, 0x420U);  // RxPDO3 with target 0, before C5 sets it

  m.receive({0x31, 0x02, -1, -1, 0x01, -1, -1}, 0xAA);  // C2's answer
  EXPECT_EQ(img.get(obj::kStatusword.id), 0x0231);
  EXPECT_EQ(img.get(obj::kModesOfOperationDisplay.id), 1);
  run(m, {
             {"C3", 0x0007, {0x07, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00},
              {0x33, 0x02, -1, -1, 0x01, -1, -1}, 0x0233, 1},
             {"C4", 0x000F, {0x0F, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00},
              {0x37, 0x02, -1, -1, 0x01, -1, -1}, 0x0237, 1},
         });

  img.set(obj::kTargetPosition.id, 200000);  // C5
  img.set(obj::kProfileVelocity.id, 1000);
  const auto c5 = m.poll();
  ASSERT_EQ(c5.size(), 1U);
  EXPECT_EQ(c5[0].id, 0x420U);
  EXPECT_EQ(payload(c5[0]), (Bytes{0x40, 0x0D, 0x03, 0x00, 0xE8, 0x03, 0x00, 0x00}));

  run(m, {
             {"C6", 0x001F, {0x1F, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00},
              {0x37, 0x12, 0x00, 0x00, 0x01, 0x00, 0x00}, 0x1237, 1},
             {"C7", 0x000F, {0x0F, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00},
              {0x37, 0x02, 0x00, 0x00, 0x01, 0x00, 0x00}, 0x0237, 1},
             {"C8", 0x000F, {},
              {0x37, 0x06, 0x00, 0x00, 0x01, 0x00, 0x00}, 0x0637, 1},
         });
  EXPECT_EQ(img.get(obj::kVlVelocityActual.id), 0);  // C6-C8 print 6044h and 6077h as 0
  EXPECT_EQ(img.get(obj::kTorqueActual.id), 0);
}

// TV-D: the fault-reset edge, controlword bit 7 from 0 to 1, with the mode byte kept valid (0 is
// reserved on this drive, §13 step 6).
TEST(NordDigestPdo, TvdFaultResetEdge) {
  NordMaster m;
  auto& img = m.pdos.image();
  img.set(obj::kModesOfOperation.id, 2);
  img.set(obj::kVlTargetVelocity.id, 1500);
  for (const int cw : {0x0000, 0x0080}) {
    img.set(obj::kControlword.id, cw);
    const auto frames = m.poll();
    ASSERT_FALSE(frames.empty());
    const auto& rx1 = frames[0];
    EXPECT_EQ(rx1.id, 0x220U);
    EXPECT_EQ(rx1.data[0], cw);
    EXPECT_EQ(rx1.data[1], 0x00);
    EXPECT_EQ(rx1.data[4], 2);  // the mode byte
  }
}

}  // namespace
}  // namespace drivegate::canopen::test
