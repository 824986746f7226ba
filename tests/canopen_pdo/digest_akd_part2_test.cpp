// AKD part 2 §12 (akd-canopen-part2-ds402.md) with the PDO engines: each example's PDO set-up, as
// the corrected SDO frames, is written into a slave with the AKD's default PDOs and rules, then the
// example's PDO and SYNC rows run between the slave and the master's NodePdos and come out byte
// for byte. The SDO frames themselves are tested in tests/canopen_wire/digest_akd_part2_test.cpp.
#include <optional>
#include <tuple>
#include <utility>

#include "tests/canopen_pdo/pdo_harness.hpp"

namespace drivegate::canopen::test {
namespace {

// Objects of the examples beyond the AKD defaults: 6063h (position in increments, §12.12) and the
// dummy 2100h:00 that masks the other axis' half of a group RPDO (§12.12: "only described here").
constexpr ObjectDef kPositionIncrements{{0x6063, 0}, DataType::I32};
constexpr ObjectDef kDummy{{0x2100, 0}, DataType::U32};

// The reply to every download of the examples: 60h with the request's index and sub-index.
Bytes ok(const Bytes& request) { return {0x60, request[1], request[2], request[3], 0, 0, 0, 0}; }

// One AKD axis (node n): the drive's objects and PDOs with the defaults of part 1 §12.5, and the
// master's PDOs of the same node, joined by a wire.
struct Axis {
  explicit Axis(NodeId n) : node(n) {
    drive.add(kPositionIncrements, false, true);
    drive.add(kDummy, true, false);
    drive.add(obj::kIpDataRecord, true, false);
    rpdos = {slave_pdo(cob::rpdo(0, n), 255, {obj::kControlword}),
             slave_pdo(cob::rpdo(1, n), 255, {obj::kControlword, obj::kModesOfOperation}),
             slave_pdo(cob::rpdo(2, n), 255, {obj::kControlword, obj::kTargetPosition}),
             slave_pdo(cob::rpdo(3, n), 255, {obj::kControlword, obj::kTargetVelocity})};
    tpdos = {slave_pdo(cob::tpdo(0, n), 255, {obj::kStatusword}),
             slave_pdo(cob::tpdo(1, n), 255, {obj::kStatusword, obj::kModesOfOperationDisplay}),
             slave_pdo(cob::tpdo(2, n), 255, {obj::kStatusword, obj::kPositionActual}),
             slave_pdo(cob::tpdo(3, n), 255, {obj::kStatusword, obj::kVelocityActual})};
    sim::SlavePdoOptions options;
    options.rpdo_every_nth_sync = true;  // AKD part 1 §12.2, quirk 8
    slave.emplace(drive, options, rpdos, tpdos);
  }

  // SDO downloads to the slave's PDO objects in order, each confirmed.
  void set_up(const std::vector<Bytes>& requests) {
    for (std::size_t i = 0; i < requests.size(); ++i) {
      SCOPED_TRACE(testing::Message() << "set-up write " << i + 1);
      EXPECT_EQ(sdo(*slave, requests[i]), ok(requests[i]));
    }
  }
  // The master's event-driven RPDOs due at `now`, delivered to the drive.
  std::vector<CanFrame> master_poll(core::TimePoint now) {
    master.poll(now, master_tx);
    auto frames = drain(master_tx);
    for (const auto& f : frames) EXPECT_TRUE(slave->on_frame(f, now)) << std::hex << f.id;
    return frames;
  }
  // The drive's event-driven TPDOs due at `now`, delivered to the master.
  std::vector<CanFrame> drive_poll(core::TimePoint now) {
    slave->poll(now, drive_tx);
    return to_master(now);
  }
  // A SYNC at the drive: what it applies and sends, delivered to the master.
  std::vector<CanFrame> sync(core::TimePoint now) {
    slave->on_sync(now, drive_tx);
    return to_master(now);
  }
  std::vector<CanFrame> to_master(core::TimePoint now) {
    auto frames = drain(drive_tx);
    for (const auto& f : frames) EXPECT_TRUE(master.on_frame(f, now)) << std::hex << f.id;
    return frames;
  }

  NodeId node;
  FakeObjects drive;
  std::array<sim::SlavePdoConfig, 4> rpdos;
  std::array<sim::SlavePdoConfig, 4> tpdos;
  std::optional<sim::SlavePdos> slave;
  NodePdos master;
  TxQueue master_tx;
  TxQueue drive_tx;
};

::testing::AssertionResult is_pdo(const CanFrame& f, std::uint32_t id, const Bytes& bytes) {
  if (f.id != id || payload(f) != bytes) {
    auto r = ::testing::AssertionFailure() << std::hex << "frame " << f.id << ":";
    for (const auto b : payload(f)) r << ' ' << unsigned{b};
    return r << ", expected " << id;
  }
  return ::testing::AssertionSuccess();
}

// §12.5 rows 3-38 and 46-48: RPDO1 = 60FFh, TPDO1 = 6064h + 606Ch on every SYNC, the rest off.
TEST(AkdPart2DigestPdo, JogViaPdo) {
  Axis a(3);
  const std::vector<Bytes> writes = {
      {0x23, 0x00, 0x14, 0x01, 0x03, 0x02, 0x00, 0xC0}, {0x2F, 0x00, 0x16, 0x00, 0x00, 0x00, 0x00, 0x00},
      {0x23, 0x00, 0x16, 0x01, 0x20, 0x00, 0xFF, 0x60}, {0x2F, 0x00, 0x16, 0x00, 0x01, 0x00, 0x00, 0x00},
      {0x23, 0x00, 0x14, 0x01, 0x03, 0x02, 0x00, 0x00}, {0x23, 0x00, 0x18, 0x01, 0x83, 0x01, 0x00, 0xC0},
      {0x2F, 0x00, 0x1A, 0x00, 0x00, 0x00, 0x00, 0x00}, {0x23, 0x00, 0x1A, 0x01, 0x20, 0x00, 0x64, 0x60},
      {0x23, 0x00, 0x1A, 0x02, 0x20, 0x00, 0x6C, 0x60}, {0x2F, 0x00, 0x1A, 0x00, 0x02, 0x00, 0x00, 0x00},
      {0x23, 0x00, 0x18, 0x01, 0x83, 0x01, 0x00, 0x00}, {0x2F, 0x00, 0x18, 0x02, 0x01, 0x00, 0x00, 0x00},
      {0x23, 0x01, 0x18, 0x01, 0x83, 0x02, 0x00, 0xC0}, {0x23, 0x02, 0x18, 0x01, 0x83, 0x03, 0x00, 0xC0},
      {0x23, 0x03, 0x18, 0x01, 0x83, 0x04, 0x00, 0xC0}, {0x23, 0x01, 0x14, 0x01, 0x03, 0x03, 0x00, 0xC0},
      {0x23, 0x02, 0x14, 0x01, 0x03, 0x04, 0x00, 0xC0}, {0x23, 0x03, 0x14, 0x01, 0x03, 0x05, 0x00, 0xC0},
  };
  a.set_up(writes);
  a.slave->set_operational(true);  // row 39: NMT start node 3
  EXPECT_TRUE(a.drive_poll(kT0).empty());  // no event-driven TPDO is left

  const std::array<RpdoConfig, 1> rx{{{0x203, layout({obj::kTargetVelocity}), 255, {}, 0}}};
  const std::array<TpdoConfig, 1> tx{{{0x183, layout({obj::kPositionActual, obj::kVelocityActual}), 1, {}}}};
  ASSERT_TRUE(a.master.configure(rx, tx));
  a.master.enable(true, kT0);
  a.master.image().set(obj::kTargetVelocity.id, 0x4000);
  auto frames = a.master_poll(kT0 + 1ms);  // row 46
  ASSERT_EQ(frames.size(), 1U);
  EXPECT_TRUE(is_pdo(frames[0], 0x203, {0x00, 0x40, 0x00, 0x00}));
  EXPECT_EQ(a.drive.get(obj::kTargetVelocity.id), 16384);  // type 255: applied on reception

  a.drive.set(obj::kPositionActual.id, 83454);
  a.drive.set(obj::kVelocityActual.id, 1747878);
  frames = a.sync(kT0 + 2ms);  // rows 47, 48
  ASSERT_EQ(frames.size(), 1U);
  EXPECT_TRUE(is_pdo(frames[0], 0x183, {0xFE, 0x45, 0x01, 0x00, 0xA6, 0xAB, 0x1A, 0x00}));
  EXPECT_EQ(a.master.image().get(obj::kPositionActual.id), 83454);
  EXPECT_EQ(a.master.image().get(obj::kVelocityActual.id), 1747878);
}

// §12.6 rows 3-36 (TPDO1 COB-ID corrected to 183h, §13 item 28) and 44-46: RPDO1 = 6071h,
// TPDO1 = 6077h on every SYNC. With the printed 383h the TPDO would leave on 383h, not on the
// 183h the example receives it on.
TEST(AkdPart2DigestPdo, TorqueViaPdo) {
  for (const bool corrected : {true, false}) {
    SCOPED_TRACE(corrected ? "corrected" : "as printed");
    Axis a(3);
    const std::uint8_t id = corrected ? 0x01 : 0x03;
    const std::vector<Bytes> writes = {
        {0x23, 0x00, 0x14, 0x01, 0x03, 0x02, 0x00, 0xC0}, {0x2F, 0x00, 0x16, 0x00, 0x00, 0x00, 0x00, 0x00},
        {0x23, 0x00, 0x16, 0x01, 0x10, 0x00, 0x71, 0x60}, {0x2F, 0x00, 0x16, 0x00, 0x01, 0x00, 0x00, 0x00},
        {0x23, 0x00, 0x14, 0x01, 0x03, 0x02, 0x00, 0x00}, {0x23, 0x00, 0x18, 0x01, 0x83, id, 0x00, 0xC0},
        {0x2F, 0x00, 0x1A, 0x00, 0x00, 0x00, 0x00, 0x00}, {0x23, 0x00, 0x1A, 0x01, 0x10, 0x00, 0x77, 0x60},
        {0x2F, 0x00, 0x1A, 0x00, 0x01, 0x00, 0x00, 0x00}, {0x23, 0x00, 0x18, 0x01, 0x83, id, 0x00, 0x00},
        {0x2F, 0x00, 0x18, 0x02, 0x01, 0x00, 0x00, 0x00}, {0x23, 0x01, 0x18, 0x01, 0x83, 0x02, 0x00, 0xC0},
        {0x23, 0x02, 0x18, 0x01, 0x83, 0x03, 0x00, 0xC0}, {0x23, 0x03, 0x18, 0x01, 0x83, 0x04, 0x00, 0xC0},
        {0x23, 0x01, 0x14, 0x01, 0x03, 0x03, 0x00, 0xC0}, {0x23, 0x02, 0x14, 0x01, 0x03, 0x04, 0x00, 0xC0},
        {0x23, 0x03, 0x14, 0x01, 0x03, 0x05, 0x00, 0xC0},
    };
    a.set_up(writes);
    a.slave->set_operational(true);  // row 37

    const std::array<RpdoConfig, 1> rx{{{0x203, layout({obj::kTargetTorque}), 255, {}, 0}}};
    const std::array<TpdoConfig, 1> tx{{{0x183, layout({obj::kTorqueActual}), 1, {}}}};
    ASSERT_TRUE(a.master.configure(rx, tx));
    a.master.enable(true, kT0);
    a.master.image().set(obj::kTargetTorque.id, 530);
    auto frames = a.master_poll(kT0 + 1ms);  // row 44
    ASSERT_EQ(frames.size(), 1U);
    EXPECT_TRUE(is_pdo(frames[0], 0x203, {0x12, 0x02}));
    EXPECT_EQ(a.drive.get(obj::kTargetTorque.id), 530);

    a.drive.set(obj::kTorqueActual.id, 537);
    a.slave->on_sync(kT0 + 2ms, a.drive_tx);  // row 45
    frames = drain(a.drive_tx);
    ASSERT_EQ(frames.size(), 1U);
    EXPECT_TRUE(is_pdo(frames[0], corrected ? 0x183 : 0x383, {0x19, 0x02}));  // row 46
  }
}

// §12.8 rows 1-44 (corrected: TPDO2 on 283h, clear-mapping data 0, §13 item 30), 49-50, 59-70,
// 77-86: RPDO2 = 607Ah + 6081h, TPDO1 = statusword (event-driven), TPDO2 = 6064h + 606Ch on every
// SYNC. The manual prints only 4 of TPDO2's 8 bytes (rows 79, 86); those are the position, the
// velocity bytes are not given and not compared.
TEST(AkdPart2DigestPdo, ProfilePositionWithHoming) {
  Axis a(3);
  const std::vector<Bytes> writes = {
      {0x23, 0x01, 0x14, 0x01, 0x03, 0x03, 0x00, 0xC0}, {0x2F, 0x01, 0x16, 0x00, 0x00, 0x00, 0x00, 0x00},
      {0x23, 0x01, 0x16, 0x01, 0x20, 0x00, 0x7A, 0x60}, {0x23, 0x01, 0x16, 0x02, 0x20, 0x00, 0x81, 0x60},
      {0x2F, 0x01, 0x16, 0x00, 0x02, 0x00, 0x00, 0x00}, {0x23, 0x01, 0x14, 0x01, 0x03, 0x03, 0x00, 0x00},
      {0x23, 0x00, 0x18, 0x01, 0x83, 0x01, 0x00, 0xC0}, {0x2F, 0x00, 0x1A, 0x00, 0x00, 0x00, 0x00, 0x00},
      {0x23, 0x00, 0x1A, 0x01, 0x10, 0x00, 0x41, 0x60}, {0x2F, 0x00, 0x1A, 0x00, 0x01, 0x00, 0x00, 0x00},
      {0x23, 0x00, 0x18, 0x01, 0x83, 0x01, 0x00, 0x00}, {0x23, 0x01, 0x18, 0x01, 0x83, 0x02, 0x00, 0xC0},
      {0x2F, 0x01, 0x1A, 0x00, 0x00, 0x00, 0x00, 0x00}, {0x23, 0x01, 0x1A, 0x01, 0x20, 0x00, 0x64, 0x60},
      {0x23, 0x01, 0x1A, 0x02, 0x20, 0x00, 0x6C, 0x60}, {0x2F, 0x01, 0x1A, 0x00, 0x02, 0x00, 0x00, 0x00},
      {0x23, 0x01, 0x18, 0x01, 0x83, 0x02, 0x00, 0x00}, {0x2F, 0x01, 0x18, 0x02, 0x01, 0x00, 0x00, 0x00},
      {0x23, 0x02, 0x18, 0x01, 0x83, 0x03, 0x00, 0xC0}, {0x23, 0x03, 0x18, 0x01, 0x83, 0x04, 0x00, 0xC0},
      {0x23, 0x02, 0x14, 0x01, 0x03, 0x04, 0x00, 0xC0}, {0x23, 0x03, 0x14, 0x01, 0x03, 0x05, 0x00, 0xC0},
  };
  a.set_up(writes);

  const std::array<RpdoConfig, 2> rx{{{0x203, layout({obj::kControlword}), 255, {}, 0},
                                      {0x303, layout({obj::kTargetPosition, obj::kProfileVelocity}), 255, {}, 0}}};
  const std::array<TpdoConfig, 2> tx{{{0x183, layout({obj::kStatusword}), 255, {}},
                                      {0x283, layout({obj::kPositionActual, obj::kVelocityActual}), 1, {}}}};
  ASSERT_TRUE(a.master.configure(rx, tx));

  // Row 49 NMT start, row 50: the event-driven TPDO1 goes out once on entering Operational.
  a.drive.set(obj::kStatusword.id, 0x0240);
  a.slave->set_operational(true);
  a.master.enable(true, kT0);
  auto t = kT0;
  auto frames = a.drive_poll(t);
  ASSERT_EQ(frames.size(), 1U);
  EXPECT_TRUE(is_pdo(frames[0], 0x183, {0x40, 0x02}));
  // Rows 59, 62, 65, 68, 69: the statusword while the controlword goes by SDO and homing runs.
  const std::pair<int, Bytes> homing[] = {{0x0221, {0x21, 0x02}},
                                          {0x0233, {0x33, 0x02}},
                                          {0x0237, {0x37, 0x02}},
                                          {0x0637, {0x37, 0x06}},
                                          {0x1637, {0x37, 0x16}}};
  for (const auto& [sw, bytes] : homing) {
    a.drive.set(obj::kStatusword.id, sw);
    frames = a.drive_poll(t += 1ms);
    ASSERT_EQ(frames.size(), 1U) << std::hex << sw;
    EXPECT_TRUE(is_pdo(frames[0], 0x183, bytes));
    EXPECT_EQ(a.master.image().get(obj::kStatusword.id), sw);
  }
  EXPECT_TRUE(a.drive_poll(t += 1ms).empty());  // no change, no frame

  // Rows 70 and 77: RPDO1 ends the homing command, RPDO2 carries the move (the SDO writes of
  // rows 71-76 between them do not touch the PDOs; the master sends both on enabling).
  a.master.image().set(obj::kControlword.id, 0x000F);
  a.master.image().set(obj::kTargetPosition.id, 36000);
  a.master.image().set(obj::kProfileVelocity.id, 20000);
  frames = a.master_poll(t += 1ms);
  ASSERT_EQ(frames.size(), 2U);
  EXPECT_TRUE(is_pdo(frames[0], 0x203, {0x0F, 0x00}));
  EXPECT_TRUE(is_pdo(frames[1], 0x303, {0xA0, 0x8C, 0x00, 0x00, 0x20, 0x4E, 0x00, 0x00}));
  EXPECT_EQ(a.drive.get(obj::kTargetPosition.id), 36000);
  EXPECT_EQ(a.drive.get(obj::kProfileVelocity.id), 20000);

  // Rows 78-79: SYNC, TPDO2 with the position -1861.
  a.drive.set(obj::kPositionActual.id, -1861);
  frames = a.sync(t += 1ms);
  ASSERT_EQ(frames.size(), 1U);
  EXPECT_EQ(frames[0].id, 0x283U);
  ASSERT_EQ(frames[0].dlc, 8);
  EXPECT_EQ(Bytes(frames[0].data.begin(), frames[0].data.begin() + 4), (Bytes{0xBB, 0xF8, 0xFF, 0xFF}));
  EXPECT_EQ(a.master.image().get(obj::kPositionActual.id), -1861);

  // Rows 80-84: the set-point handshake.
  const std::tuple<int, Bytes, int, Bytes> handshake[] = {
      {0x001F, {0x1F, 0x00}, 0x1237, {0x37, 0x12}},  // rows 80, 81
      {0x000F, {0x0F, 0x00}, 0x0237, {0x37, 0x02}},  // rows 82, 83
  };
  for (const auto& [cw, rpdo, sw, tpdo] : handshake) {
    a.master.image().set(obj::kControlword.id, cw);
    frames = a.master_poll(t += 1ms);
    ASSERT_EQ(frames.size(), 1U);
    EXPECT_TRUE(is_pdo(frames[0], 0x203, rpdo));
    EXPECT_EQ(a.drive.get(obj::kControlword.id), cw);
    a.drive.set(obj::kStatusword.id, sw);
    frames = a.drive_poll(t += 1ms);
    ASSERT_EQ(frames.size(), 1U);
    EXPECT_TRUE(is_pdo(frames[0], 0x183, tpdo));
  }
  a.drive.set(obj::kStatusword.id, 0x0637);  // row 84: target reached
  frames = a.drive_poll(t += 1ms);
  ASSERT_EQ(frames.size(), 1U);
  EXPECT_TRUE(is_pdo(frames[0], 0x183, {0x37, 0x06}));

  // Rows 85-86: SYNC, TPDO2 with the position -878.
  a.drive.set(obj::kPositionActual.id, -878);
  frames = a.sync(t += 1ms);
  ASSERT_EQ(frames.size(), 1U);
  EXPECT_EQ(frames[0].id, 0x283U);
  EXPECT_EQ(Bytes(frames[0].data.begin(), frames[0].data.begin() + 4), (Bytes{0x92, 0xFC, 0xFF, 0xFF}));
  EXPECT_EQ(a.master.image().get(obj::kPositionActual.id), -878);
  EXPECT_EQ(a.master.counters().short_frames + a.master.counters().long_frames, 0U);
}

// §12.10: the corrected set-up (rows 1-38, §13 item 32) gives TPDO1 (6064h, type 2) after every 2nd
// SYNC and TPDO2 (SW + 1002h, type 3) after every 3rd (row 39). The printed rows 33 and 37 are
// refused by a CiA 301 slave: a mapping count on a valid RPDO2 (08000022h) and a new COB-ID on a
// valid TPDO1 (06090030h).
TEST(AkdPart2DigestPdo, SyncTest) {
  Axis a(3);
  const std::vector<Bytes> writes = {
      {0x23, 0x01, 0x14, 0x01, 0x03, 0x03, 0x00, 0xC0}, {0x2F, 0x01, 0x16, 0x00, 0x00, 0x00, 0x00, 0x00},
      {0x23, 0x01, 0x16, 0x01, 0x20, 0x00, 0x7A, 0x60}, {0x23, 0x01, 0x16, 0x02, 0x20, 0x00, 0x81, 0x60},
      {0x2F, 0x01, 0x16, 0x00, 0x02, 0x00, 0x00, 0x00}, {0x23, 0x01, 0x14, 0x01, 0x03, 0x03, 0x00, 0x00},
      {0x23, 0x00, 0x18, 0x01, 0x83, 0x01, 0x00, 0xC0}, {0x2F, 0x00, 0x1A, 0x00, 0x00, 0x00, 0x00, 0x00},
      {0x23, 0x00, 0x1A, 0x01, 0x20, 0x00, 0x64, 0x60}, {0x2F, 0x00, 0x1A, 0x00, 0x01, 0x00, 0x00, 0x00},
      {0x2F, 0x00, 0x18, 0x02, 0x02, 0x00, 0x00, 0x00}, {0x23, 0x00, 0x18, 0x01, 0x83, 0x01, 0x00, 0x00},
      {0x23, 0x01, 0x18, 0x01, 0x83, 0x02, 0x00, 0xC0}, {0x2F, 0x01, 0x1A, 0x00, 0x00, 0x00, 0x00, 0x00},
      {0x23, 0x01, 0x1A, 0x01, 0x10, 0x00, 0x41, 0x60}, {0x23, 0x01, 0x1A, 0x02, 0x20, 0x00, 0x02, 0x10},
      {0x2F, 0x01, 0x1A, 0x00, 0x02, 0x00, 0x00, 0x00}, {0x2F, 0x01, 0x18, 0x02, 0x03, 0x00, 0x00, 0x00},
      {0x23, 0x01, 0x18, 0x01, 0x83, 0x02, 0x00, 0x00},
  };
  a.set_up(writes);
  EXPECT_EQ(sdo(*a.slave, {0x2F, 0x01, 0x16, 0x00, 0x02, 0x00, 0x00, 0x00}),
            (Bytes{0x80, 0x01, 0x16, 0x00, 0x22, 0x00, 0x00, 0x08}));
  EXPECT_EQ(sdo(*a.slave, {0x23, 0x00, 0x18, 0x01, 0x83, 0x03, 0x00, 0x00}),
            (Bytes{0x80, 0x00, 0x18, 0x01, 0x30, 0x00, 0x09, 0x06}));

  a.slave->set_operational(true);
  a.drive.set(obj::kPositionActual.id, 83454);
  a.drive.set(obj::kStatusword.id, 0x0237);
  a.drive.set(kManufacturerStatus.id, 0x44030000);
  std::vector<std::pair<int, std::uint32_t>> seen;
  for (int s = 1; s <= 6; ++s) {
    a.slave->on_sync(kT0 + s * 1ms, a.drive_tx);
    for (const auto& f : drain(a.drive_tx)) {
      seen.emplace_back(s, f.id);
      const Bytes expected_bytes = f.id == 0x183 ? Bytes{0xFE, 0x45, 0x01, 0x00} : Bytes{0x37, 0x02, 0x00, 0x00, 0x03, 0x44};
      EXPECT_EQ(payload(f), expected_bytes) << std::hex << f.id;
    }
  }
  const std::vector<std::pair<int, std::uint32_t>> expected{{2, 0x183}, {3, 0x283}, {4, 0x183}, {6, 0x183}, {6, 0x283}};
  EXPECT_EQ(seen, expected);
}

// §12.12: two axes, one group RPDO on 301h (axis 1 bytes 0-3, axis 2 bytes 4-7, the other half a
// dummy), each answering with 6063h + 1002h on its own TPDO2 (281h/282h, corrected from the
// printed 181h/182h, §13 item 33). Set-up as the digest's corrected table; rows 60-67 enable the
// axes through RPDO1/TPDO1, row 68 is the group frame, rows 69-70 the answers to its SYNC.
TEST(AkdPart2DigestPdo, TwoAxesOneGroupRpdo) {
  Axis axis1(1);
  Axis axis2(2);
  using Entry = std::array<std::uint8_t, 4>;
  const auto writes = [](NodeId n, const Entry& entry1, const Entry& entry2) {
    const auto b = static_cast<std::uint8_t>(0x80 + n);
    return std::vector<Bytes>{
        {0x23, 0x01, 0x14, 0x01, 0x01, 0x03, 0x00, 0xC0},
        {0x2F, 0x01, 0x16, 0x00, 0x00, 0x00, 0x00, 0x00},
        {0x23, 0x01, 0x16, 0x01, entry1[0], entry1[1], entry1[2], entry1[3]},
        {0x23, 0x01, 0x16, 0x02, entry2[0], entry2[1], entry2[2], entry2[3]},
        {0x2F, 0x01, 0x16, 0x00, 0x02, 0x00, 0x00, 0x00},
        {0x2F, 0x01, 0x14, 0x02, 0x01, 0x00, 0x00, 0x00},
        {0x23, 0x01, 0x14, 0x01, 0x01, 0x03, 0x00, 0x00},
        {0x23, 0x01, 0x18, 0x01, b, 0x02, 0x00, 0xC0},
        {0x2F, 0x01, 0x1A, 0x00, 0x00, 0x00, 0x00, 0x00},
        {0x23, 0x01, 0x1A, 0x01, 0x20, 0x00, 0x63, 0x60},
        {0x23, 0x01, 0x1A, 0x02, 0x20, 0x00, 0x02, 0x10},
        {0x2F, 0x01, 0x1A, 0x00, 0x02, 0x00, 0x00, 0x00},
        {0x2F, 0x01, 0x18, 0x02, 0x01, 0x00, 0x00, 0x00},
        {0x23, 0x01, 0x18, 0x01, b, 0x02, 0x00, 0x00},
        {0x23, 0x02, 0x18, 0x01, b, 0x03, 0x00, 0xC0},
        {0x23, 0x03, 0x18, 0x01, b, 0x04, 0x00, 0xC0},
    };
  };
  const Entry ip{0x20, 0x01, 0xC1, 0x60};     // 60C1h:01, 32 bit
  const Entry dummy{0x20, 0x00, 0x00, 0x21};  // 2100h:00, 32 bit
  axis1.set_up(writes(1, ip, dummy));
  axis2.set_up(writes(2, dummy, ip));

  for (Axis* a : {&axis1, &axis2}) {
    SCOPED_TRACE(testing::Message() << "node " << int{a->node});
    const std::array<RpdoConfig, 1> rx{{{cob::rpdo(0, a->node), layout({obj::kControlword}), 255, {}, 0}}};
    const std::array<TpdoConfig, 2> tx{
        {{cob::tpdo(0, a->node), layout({obj::kStatusword}), 255, {}},
         {cob::tpdo(1, a->node), layout({kPositionIncrements, kManufacturerStatus}), 1, {}}}};
    ASSERT_TRUE(a->master.configure(rx, tx));
    // NMT start all nodes (row 59 corrected): TPDO1 reports the statusword once.
    a->drive.set(obj::kStatusword.id, 0x0240);
    a->slave->set_operational(true);
    a->master.enable(true, kT0);
    EXPECT_EQ(a->drive_poll(kT0).size(), 1U);
    // Rows 60-67 (node 1; the same on 202h/182h for node 2).
    const std::tuple<int, Bytes, int, Bytes> enable[] = {{0x0006, {0x06, 0x00}, 0x0231, {0x31, 0x02}},
                                                         {0x0007, {0x07, 0x00}, 0x0233, {0x33, 0x02}},
                                                         {0x000F, {0x0F, 0x00}, 0x0237, {0x37, 0x02}},
                                                         {0x001F, {0x1F, 0x00}, 0x1237, {0x37, 0x12}}};
    auto t = kT0;
    for (const auto& [cw, rpdo, sw, tpdo] : enable) {
      a->master.image().set(obj::kControlword.id, cw);
      auto frames = a->master_poll(t += 1ms);
      ASSERT_EQ(frames.size(), 1U);
      EXPECT_TRUE(is_pdo(frames[0], cob::rpdo(0, a->node), rpdo));
      a->drive.set(obj::kStatusword.id, sw);
      frames = a->drive_poll(t += 1ms);
      ASSERT_EQ(frames.size(), 1U);
      EXPECT_TRUE(is_pdo(frames[0], cob::tpdo(0, a->node), tpdo));
      EXPECT_EQ(a->master.image().get(obj::kStatusword.id), sw);
    }
  }

  // Row 68: one frame for both axes, taken at the next SYNC (type 1).
  const auto group = make_frame(0x301, {0xF4, 0x01, 0x00, 0x00, 0xE8, 0x03, 0x00, 0x00});
  const auto now = kT0 + 10ms;
  EXPECT_TRUE(axis1.slave->on_frame(group, now));
  EXPECT_TRUE(axis2.slave->on_frame(group, now));
  EXPECT_EQ(axis1.drive.get(obj::kIpDataRecord.id), 0);
  axis1.drive.set(kPositionIncrements.id, 291);
  axis2.drive.set(kPositionIncrements.id, 677);
  for (Axis* a : {&axis1, &axis2}) a->drive.set(kManufacturerStatus.id, 0x44030000);
  const auto answer1 = axis1.sync(now + 1ms);
  const auto answer2 = axis2.sync(now + 1ms);
  EXPECT_EQ(axis1.drive.get(obj::kIpDataRecord.id), 500);
  EXPECT_EQ(axis2.drive.get(obj::kIpDataRecord.id), 1000);
  // Rows 69-70.
  ASSERT_EQ(answer1.size(), 1U);
  ASSERT_EQ(answer2.size(), 1U);
  EXPECT_TRUE(is_pdo(answer1[0], 0x281, {0x23, 0x01, 0x00, 0x00, 0x00, 0x00, 0x03, 0x44}));
  EXPECT_TRUE(is_pdo(answer2[0], 0x282, {0xA5, 0x02, 0x00, 0x00, 0x00, 0x00, 0x03, 0x44}));
  EXPECT_EQ(axis1.master.image().get(kPositionIncrements.id), 291);
  EXPECT_EQ(axis2.master.image().get(kPositionIncrements.id), 677);
  EXPECT_EQ(axis2.master.image().get(kManufacturerStatus.id), 0x44030000);
}

}  // namespace
}  // namespace drivegate::canopen::test
