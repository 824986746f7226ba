// The personas against their digests: byte-exact SDO vectors, objects present or absent, PDO
// defaults and the vendor behaviours of each reference drive.
#include <gtest/gtest.h>

#include "tests/canopen_sim/sim_test_support.hpp"

namespace drivegate::canopen::sim::test {
namespace {

constexpr std::uint32_t kNoObject = 0x06020000;
constexpr std::uint32_t kNoSubIndex = 0x06090011;
constexpr std::uint32_t kReadOnly = 0x06010002;
constexpr std::uint32_t kValueRange = 0x06090030;

// --- STÖBER SD6 (stoeber-sd6-canopen.md) --------------------------------------------------------

TEST(Sd6Persona, AnswersDeviceTypeAndVendorIdWith42h) {
  Drive d(sd6(5));
  ASSERT_TRUE(is_frame(d.boot().at(0), 0x705, {0x00}));  // TV-4
  // D-1 and D-2 with the [EXT] expedited response without size indication.
  auto r = d.sdo(SdoBytes{0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0});
  EXPECT_TRUE(is_frame(r.frame, 0x585, {0x42, 0x00, 0x10, 0x00, 0x92, 0x01, 0x02, 0x00}));
  r = d.sdo(SdoBytes{0x40, 0x18, 0x10, 0x01, 0, 0, 0, 0});
  EXPECT_TRUE(is_frame(r.frame, 0x585, {0x42, 0x18, 0x10, 0x01, 0xB9, 0x00, 0x00, 0x00}));
  // D-11: A83 (2053h) is the node-ID.
  r = d.sdo(SdoBytes{0x40, 0x53, 0x20, 0x00, 0, 0, 0, 0});
  EXPECT_TRUE(is_frame(r.frame, 0x585, {0x42, 0x53, 0x20, 0x00, 0x05, 0x00, 0x00, 0x00}));
}

TEST(Sd6Persona, HasNoConsumerHeartbeat) {
  Drive d(sd6(5));
  d.boot();
  // D-13 layout: 0602 0000h for 1016h (quirk 7).
  const auto r = d.sdo(SdoBytes{0x40, 0x16, 0x10, 0x00, 0, 0, 0, 0});
  EXPECT_TRUE(is_frame(r.frame, 0x585, {0x80, 0x16, 0x10, 0x00, 0x00, 0x00, 0x02, 0x06}));
  EXPECT_EQ(d.write({0x1016, 1}, (127U << 16) | 300U, 4), kNoObject);
}

TEST(Sd6Persona, MappingIsFixedAtSixEntriesFromTheProfile) {
  Drive d(sd6(5));
  d.boot();
  EXPECT_EQ(d.value({0x1600, 0}), 6U);  // constant 6 (quirk 4)
  EXPECT_EQ(d.value({0x1600, 1}), 0x60400010U);
  EXPECT_EQ(d.value({0x1600, 2}), 0x60600008U);
  EXPECT_EQ(d.value({0x1600, 3}), 0x607A0020U);
  EXPECT_EQ(d.value({0x1600, 4}), 0U);
  EXPECT_EQ(d.value({0x1A01, 1}), 0x606C0020U);
  EXPECT_EQ(d.read({0x1600, 7}).abort, kNoSubIndex);  // six entries at most (quirk 5)
  // The CiA 301 remapping sequence is refused, also on a disabled PDO.
  EXPECT_EQ(d.write({0x1400, 1}, 0x80000205U, 4), 0U);
  EXPECT_EQ(d.write({0x1600, 0}, 0, 1), kReadOnly);
  EXPECT_EQ(d.write({0x1600, 1}, 0x60400010U, 4), kReadOnly);
  EXPECT_EQ(d.value({0x1600, 0}), 6U);
  // Channels 3 and 4 are off; the verified ones are valid with the profile's type.
  EXPECT_EQ(d.value({0x1802, 1}) & cob::kInvalid, cob::kInvalid);
  EXPECT_EQ(d.value({0x1800, 1}) & (cob::kInvalid | cob::kIdMask), 0x185U);
  EXPECT_EQ(d.value({0x1800, 2}), 1U);
}

TEST(Sd6Persona, TakesOnlyTransmissionTypes1To240And254) {
  Drive d(sd6(5));
  d.boot();
  EXPECT_EQ(d.write({0x1800, 2}, 255, 1), kValueRange);  // quirk 3
  EXPECT_EQ(d.write({0x1800, 2}, 0, 1), kValueRange);
  EXPECT_EQ(d.write({0x1800, 2}, 254, 1), 0U);
  EXPECT_EQ(d.write({0x1800, 2}, 240, 1), 0U);
}

TEST(Sd6Persona, Type254TxPdoIsSentWhenAnRxPdoArrives) {
  Drive d(sd6(5));
  d.boot();
  ASSERT_EQ(d.write({0x1800, 2}, 254, 1), 0U);
  ASSERT_EQ(d.write({0x1400, 2}, 254, 1), 0U);
  d.send(nmt(NmtCommand::Start, 5));
  d.run(5ms);  // the first transmission after Start
  // The mapped data does not change; only the RxPDO triggers the TxPDO (quirk 3).
  EXPECT_TRUE(on_id(d.run(20ms), 0x185).empty());
  const auto frames = d.send(make_frame(0x205, {0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x00}));
  ASSERT_EQ(on_id(frames, 0x185).size(), 1U);
  EXPECT_EQ(on_id(frames, 0x185)[0].dlc, 7);
}

TEST(Sd6Persona, AnswersOnSdoChannelsTwoToFourForSmallNodeIds) {
  Drive d(sd6(5));
  d.boot();
  // TV-8: RxSDO2 625h, TxSDO2 5A5h; RxSDO4 665h, TxSDO4 5E5h.
  auto r = d.sdo(sdo_upload_request({0x1000, 0}), 2);
  EXPECT_TRUE(is_frame(r.frame, 0x5A5, {0x42, 0x00, 0x10, 0x00, 0x92, 0x01, 0x02, 0x00}));
  r = d.sdo(sdo_upload_request({0x1018, 1}), 4);
  EXPECT_EQ(r.frame.id, 0x5E5U);
  EXPECT_EQ(r.value, 0xB9U);
  EXPECT_EQ(d.value({0x1201, 1}), 0x625U);
  EXPECT_EQ(d.value({0x1200, 1}), 0x605U);

  // Node-IDs above 31: channel 2's COB-IDs belong to channel 1 of other nodes (quirk 1).
  Drive big(sd6(40));
  big.boot();
  EXPECT_EQ(big.node.sdo(2), nullptr);
  EXPECT_TRUE(big.send(make_frame(0x600 + 0x20 + 40, sdo_upload_request({0x1000, 0}))).empty());
  EXPECT_EQ(big.value({0x1201, 1}) & cob::kInvalid, cob::kInvalid);
}

TEST(Sd6Persona, SdoChannelCobIdsChangeOnlyInPreOperational) {
  Drive d(sd6(5));
  d.boot();
  EXPECT_EQ(d.write({0x1200, 1}, 0x606, 4), kReadOnly);  // channel 1 is fixed (§6.3)
  EXPECT_EQ(d.write({0x1202, 1}, 0x80000645U, 4), 0U);   // channel 3 off
  d.step();
  EXPECT_EQ(d.node.sdo(3), nullptr);
  EXPECT_EQ(d.write({0x1202, 1}, 0x645U, 4), 0U);
  d.step();
  EXPECT_NE(d.node.sdo(3), nullptr);
  d.send(nmt(NmtCommand::Start, 5));
  EXPECT_EQ(d.write({0x1203, 1}, 0x80000665U, 4), 0x08000022U);  // §5.4
}

// --- Kollmorgen AKD (akd-canopen-part1-communication.md, akd-canopen-part2-ds402.md) -------------

TEST(AkdPersona, AnswersDeviceTypeAndIdentity) {
  Drive d(akd(1));
  ASSERT_TRUE(is_frame(d.boot().at(0), 0x701, {0x00}));
  auto r = d.sdo(SdoBytes{0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0});
  EXPECT_TRUE(is_frame(r.frame, 0x581, {0x43, 0x00, 0x10, 0x00, 0x92, 0x01, 0x02, 0x00}));  // part 1 §13.1
  r = d.sdo(SdoBytes{0x40, 0x18, 0x10, 0x01, 0, 0, 0, 0});
  EXPECT_TRUE(is_frame(r.frame, 0x581, {0x43, 0x18, 0x10, 0x01, 0x6A, 0x00, 0x00, 0x00}));
  r = d.sdo(SdoBytes{0x40, 0x18, 0x10, 0x02, 0, 0, 0, 0});
  EXPECT_TRUE(is_frame(r.frame, 0x581, {0x43, 0x18, 0x10, 0x02, 'M', '0', '0', '6'}));  // quirk 12
}

TEST(AkdPersona, StoresFbusParameters) {
  Drive d(akd(1));
  d.boot();
  // FBUS.PARAM05 = 315h as the device profile writes it (part 1 §3).
  auto r = d.sdo(SdoBytes{0x23, 0xE9, 0x36, 0x00, 0x15, 0x03, 0x00, 0x00});
  EXPECT_TRUE(is_frame(r.frame, 0x581, {0x60, 0xE9, 0x36, 0x00, 0x00, 0x00, 0x00, 0x00}));
  EXPECT_EQ(d.value({0x36E9, 0}), 0x315U);
  for (std::uint16_t i = 0x36E5; i <= 0x36EE; ++i) EXPECT_EQ(d.read({i, 0}).abort, 0U) << std::hex << i;
  EXPECT_EQ(d.read({0x36E9, 1}).abort, kNoSubIndex);
  EXPECT_EQ(d.write({0x36E9, 0}, 1, 2), 0x06070010U);  // U32 written with two bytes
  // The factor group the profile writes exists (part 2 §4.3, §4.4).
  EXPECT_EQ(d.value({0x608F, 1}), 1048576U);
  EXPECT_EQ(d.write({0x204C, 1}, 1, 4), 0U);
}

TEST(AkdPersona, HasOneConsumerHeartbeatEntryAndNoEmcyInhibitOrSdoParameters) {
  Drive d(akd(1));
  d.boot();
  EXPECT_EQ(d.value({0x1016, 0}), 1U);  // quirk 11
  EXPECT_EQ(d.write({0x1016, 1}, (127U << 16) | 300U, 4), 0U);
  EXPECT_EQ(d.value({0x1016, 1}), (127U << 16) | 300U);
  EXPECT_EQ(d.read({0x1016, 2}).abort, kNoSubIndex);
  EXPECT_EQ(d.read({0x1015, 0}).abort, kNoObject);  // §13.1
  EXPECT_EQ(d.read({0x1200, 1}).abort, kNoObject);  // quirk 7
  EXPECT_EQ(d.value({0x1014, 0}), 0x81U);
  EXPECT_EQ(d.write({0x1014, 0}, 0x80000081U, 4), kReadOnly);
}

TEST(AkdPersona, ReportsE5hSupportedModesAndLacksOptionCodes) {
  Drive d(akd(1));
  d.boot();
  // pp, pv, tq, hm, ip, csp supported; 6502h omits tq (part 2 §15.9).
  const auto r = d.read({0x6502, 0});
  EXPECT_TRUE(is_frame(r.frame, 0x581, {0x43, 0x02, 0x65, 0x00, 0xE5, 0x00, 0x00, 0x00}));
  EXPECT_EQ(d.write({0x6060, 0}, 4, 1), 0U);  // tq is accepted nevertheless
  EXPECT_EQ(d.read({0x605D, 0}).abort, kNoObject);  // §15.4
  EXPECT_EQ(d.read({0x6042, 0}).abort, kNoObject);  // no vl (§15.9)
  EXPECT_EQ(d.read({0x605A, 0}).abort, 0U);
}

TEST(AkdPersona, HomingAttainedReads1637h) {
  Drive d(akd(1));
  d.boot();
  ASSERT_EQ(d.write({0x6060, 0}, 6, 1), 0U);
  ASSERT_EQ(d.write({0x6098, 0}, 35, 1), 0U);  // current position is home
  d.enable();
  ASSERT_EQ(d.statusword() & 0x6F, 0x27);
  d.controlword(0x1F, 20ms);
  EXPECT_EQ(d.statusword(), 0x1637);  // part 2 §15.15
}

TEST(AkdPersona, FactoryPdoMappingIsEventDriven) {
  Drive d(akd(1));
  d.boot();
  // part 1 §12.5: all eight valid, type 255.
  EXPECT_EQ(d.value({0x1A00, 0}), 1U);
  EXPECT_EQ(d.value({0x1A02, 2}), 0x60640020U);
  EXPECT_EQ(d.value({0x1602, 2}), 0x607A0020U);
  EXPECT_EQ(d.value({0x1802, 1}), 0x381U);
  EXPECT_EQ(d.value({0x1800, 2}), 255U);
  EXPECT_EQ(d.write({0x1800, 2}, 254, 1), kValueRange);  // not described for the AKD
  // Homing objects are not mappable (part 2 §15.15).
  ASSERT_EQ(d.write({0x1400, 1}, 0x80000201U, 4), 0U);
  ASSERT_EQ(d.write({0x1600, 0}, 0, 1), 0U);
  EXPECT_EQ(d.write({0x1600, 1}, 0x60980008U, 4), 0x06040041U);
  EXPECT_EQ(d.write({0x1600, 1}, 0x60C10120U, 4), 0U);
}

// An RPDO of type 3 applied at the third SYNC (AKD) or at the first (CiA 301).
std::vector<std::uint32_t> controlword_after_syncs(SlaveNodeConfig config) {
  Drive d(std::move(config));
  d.boot();
  EXPECT_EQ(d.write({0x1400, 2}, 3, 1), 0U);
  d.send(nmt(NmtCommand::Start, 1));
  d.send(make_frame(0x201, {0x06, 0x00}));
  std::vector<std::uint32_t> seen;
  for (int i = 0; i < 3; ++i) {
    d.send(sync_frame());
    seen.push_back(static_cast<std::uint32_t>(d.node.drive().dictionary().get({0x6040, 0}).value_or(-1)));
  }
  return seen;
}

TEST(AkdPersona, AppliesSynchronousRpdoAtEveryNthSync) {
  // part 1 §12.2, quirk 8.
  EXPECT_EQ(controlword_after_syncs(akd(1)), (std::vector<std::uint32_t>{0, 0, 6}));
  auto g = generic(1);
  g.rpdos[0].transmission_type = 255;
  g.rpdos[0].count = 1;
  g.rpdos[0].mapping = {0x60400010U};
  EXPECT_EQ(controlword_after_syncs(std::move(g)), (std::vector<std::uint32_t>{6, 6, 6}));
}

// --- NORD SK 500P (nord-sk500p-ds402.md) -------------------------------------------------------

TEST(NordPersona, DefaultPdoMapsAreTheEdsMaps) {
  Drive d(nord(0x20));
  d.boot();
  // §8.1
  EXPECT_EQ(d.value({0x1600, 0}), 3U);
  EXPECT_EQ(d.value({0x1600, 1}), 0x60400010U);
  EXPECT_EQ(d.value({0x1600, 2}), 0x60420010U);
  EXPECT_EQ(d.value({0x1600, 3}), 0x60600008U);
  EXPECT_EQ(d.value({0x1601, 2}), 0x60840020U);
  EXPECT_EQ(d.value({0x1602, 1}), 0x607A0020U);
  EXPECT_EQ(d.value({0x1603, 0}), 0U);
  EXPECT_EQ(d.value({0x1403, 1}) & cob::kInvalid, cob::kInvalid);
  EXPECT_EQ(d.value({0x1A00, 0}), 4U);
  EXPECT_EQ(d.value({0x1A00, 4}), 0x60770010U);
  EXPECT_EQ(d.value({0x1A01, 2}), 0x606C0020U);
  EXPECT_EQ(d.value({0x1802, 1}) & cob::kInvalid, cob::kInvalid);
  // TxPDO1 arrives with 7 bytes once the node runs.
  const auto frames = d.send(nmt(NmtCommand::Start, 0x20));
  const auto tpdo1 = on_id(frames, 0x1A0);
  ASSERT_EQ(tpdo1.size(), 1U);
  EXPECT_EQ(tpdo1[0].dlc, 7);
  EXPECT_EQ(tpdo1[0].data[4], 2);  // mode display: vl
}

TEST(NordPersona, LacksErrorCodeAndOptionObjects) {
  Drive d(nord(0x20));
  d.boot();
  const auto r = d.read({0x603F, 0});  // quirk 20
  EXPECT_TRUE(is_frame(r.frame, 0x5A0, {0x80, 0x3F, 0x60, 0x00, 0x00, 0x00, 0x02, 0x06}));
  EXPECT_EQ(d.read({0x605A, 0}).abort, kNoObject);
  EXPECT_EQ(d.read({0x6502, 0}).abort, kNoObject);
  EXPECT_EQ(d.read({0x60C2, 1}).abort, kNoObject);
  EXPECT_EQ(d.value({0x605D, 0}), 2U);  // halt on the quick-stop ramp by default (quirk 12)
  // The start-up writes of the device profile land on objects the drive has.
  EXPECT_EQ(d.write({0x6046, 1}, 0, 4), 0U);
  EXPECT_EQ(d.write({0x608A, 0}, 0, 1), 0U);
  EXPECT_EQ(d.write({0x608A, 0}, 2, 1), 0x06090031U);  // 0 rev or 1 m
  EXPECT_EQ(d.write({0x6091, 2}, 1, 4), 0U);
}

TEST(NordPersona, VlRunsFromTheBusOnlyWithControlword7Fh) {
  Drive d(nord(0x20));
  d.boot();
  EXPECT_EQ(d.value({0x6061, 0}), 2U);  // default mode vl (quirk 2)
  d.send(nmt(NmtCommand::Start, 0x20));
  // TV-B style RxPDO1: CW | 6042h | 6060h | padding, DLC 8.
  const auto rx = [&](std::uint16_t cw, std::int16_t rpm) {
    const auto v = static_cast<std::uint16_t>(rpm);
    d.send(make_frame(0x220, {static_cast<std::uint8_t>(cw), static_cast<std::uint8_t>(cw >> 8),
                              static_cast<std::uint8_t>(v), static_cast<std::uint8_t>(v >> 8), 0x02, 0, 0, 0}));
    d.run(5ms);
  };
  rx(0x06, 1500);
  rx(0x07, 1500);
  rx(0x0F, 1500);
  ASSERT_EQ(d.statusword() & 0x6F, 0x27);
  d.run(500ms);
  EXPECT_EQ(d.value({0x6044, 0}), 0U);  // CW 0x000F: no bus set-point (quirk 5)
  rx(0x7F, 1500);                       // TV-D
  d.run(1500ms);
  EXPECT_NEAR(static_cast<std::int16_t>(d.value({0x6044, 0})), 1500, 5);
  // Quick stop ends in Switch on disabled; there is no 605Ah to change that (quirk 13).
  rx(0x73, 1500);
  d.run(2s);
  EXPECT_EQ(d.statusword() & 0x4F, 0x40);
}

TEST(NordPersona, RefusesModeZero) {
  Drive d(nord(0x20));
  d.boot();
  d.send(nmt(NmtCommand::Start, 0x20));
  // RxPDO1 with the mode byte 0 (quirk 18): the controlword is taken, the mode is not.
  d.send(make_frame(0x220, {0x06, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}));
  d.run(5ms);
  EXPECT_EQ(d.value({0x6060, 0}), 2U);
  EXPECT_EQ(d.statusword() & 0x6F, 0x21);
  EXPECT_EQ(d.node.counters().refused_pdo_values, 1U);
  EXPECT_EQ(d.write({0x6060, 0}, 0, 1), kValueRange);
  EXPECT_EQ(d.write({0x6060, 0}, 1, 1), 0U);
}

// --- generic (CiA 301/402) -----------------------------------------------------------------------

TEST(GenericPersona, HasTheStandardCommunicationObjects) {
  Drive d(generic(1));
  d.boot();
  EXPECT_EQ(d.value({0x1200, 0}), 2U);
  EXPECT_EQ(d.value({0x1200, 1}), 0x601U);
  EXPECT_EQ(d.value({0x1200, 2}), 0x581U);
  EXPECT_EQ(d.read({0x1201, 1}).abort, kNoObject);
  EXPECT_EQ(d.value({0x1005, 0}), 0x80U);
  EXPECT_EQ(d.write({0x1005, 0}, 0x40000080U, 4), kValueRange);  // no SYNC producer
  EXPECT_EQ(d.write({0x1015, 0}, 10, 2), 0U);
  EXPECT_EQ(d.value({0x1015, 0}), 10U);
  EXPECT_EQ(d.write({0x1010, 1}, 0x65766173U, 4), 0U);  // "save"
  EXPECT_EQ(d.write({0x1010, 1}, 0x12345678U, 4), 0x08000020U);
  EXPECT_EQ(d.value({0x603F, 0}), 0U);
  EXPECT_EQ(d.read({0x2000, 0}).abort, kNoObject);
  EXPECT_EQ(d.read({0x1018, 9}).abort, kNoSubIndex);
}

TEST(GenericPersona, FollowsAMovedSyncCobId) {
  Drive d(generic(1));
  d.boot();
  d.send(nmt(NmtCommand::Start, 1));
  ASSERT_EQ(d.write({0x1005, 0}, 0x90, 4), 0U);
  EXPECT_TRUE(on_id(d.send(sync_frame()), 0x181).empty());
  EXPECT_EQ(on_id(d.send(make_frame(0x90, std::initializer_list<std::uint8_t>{})), 0x181).size(), 1U);
}

TEST(Personas, UnknownNameIsRefusedWithTheList) {
  EXPECT_EQ(find_persona("akd")->name, "akd");
  EXPECT_EQ(find_persona("kollmorgen"), nullptr);
  try {
    (void)persona_for("kollmorgen");
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("stoeber-sd6"), std::string::npos);
  }
}

TEST(Personas, RefuseProfileMapsTheDriveCannotHold) {
  // A type 255 TPDO on an SD6 cannot be commissioned (quirk 3).
  auto t = sd6_tpdos();
  t[0].transmission_type = 255;
  const auto r = sd6_rpdos();
  auto c = make_slave_config(5, persona_for("stoeber-sd6"), drive_with_modes({1, 3, 6}), r, t);
  EXPECT_THROW(SlaveNode{std::move(c)}, std::invalid_argument);
  EXPECT_THROW(make_slave_config(0, persona_for("generic"), {}), std::invalid_argument);
}

}  // namespace
}  // namespace drivegate::canopen::sim::test
