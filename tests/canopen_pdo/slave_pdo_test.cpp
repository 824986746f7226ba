// SlavePdos: the PDO parameter objects as the slave's SDO server sees them (CiA 301 rules, the AKD
// remap vectors, the SD6 fixed-mapping persona) and the slave's side of the exchange.
#include <stdexcept>

#include "tests/canopen_pdo/pdo_harness.hpp"
#include "tests/support/alloc_counter.hpp"

namespace drivegate::canopen::test {
namespace {

// AKD default mappings (akd-canopen-part1-communication.md §12.5): all valid, type 255.
struct AkdDefaults {
  std::array<sim::SlavePdoConfig, 4> rpdos;
  std::array<sim::SlavePdoConfig, 4> tpdos;
  explicit AkdDefaults(NodeId n) {
    rpdos = {slave_pdo(cob::rpdo(0, n), 255, {obj::kControlword}),
             slave_pdo(cob::rpdo(1, n), 255, {obj::kControlword, obj::kModesOfOperation}),
             slave_pdo(cob::rpdo(2, n), 255, {obj::kControlword, obj::kTargetPosition}),
             slave_pdo(cob::rpdo(3, n), 255, {obj::kControlword, obj::kTargetVelocity})};
    tpdos = {slave_pdo(cob::tpdo(0, n), 255, {obj::kStatusword}),
             slave_pdo(cob::tpdo(1, n), 255, {obj::kStatusword, obj::kModesOfOperationDisplay}),
             slave_pdo(cob::tpdo(2, n), 255, {obj::kStatusword, obj::kPositionActual}),
             slave_pdo(cob::tpdo(3, n), 255, {obj::kStatusword, obj::kVelocityActual})};
  }
};

sim::SlavePdoOptions akd_options() {
  sim::SlavePdoOptions o;
  o.rpdo_every_nth_sync = true;  // AKD part 1 §12.2, quirk 8
  return o;
}

// STÖBER SD6 (stoeber-sd6-canopen.md §6.2, quirks 3-5): six fixed entries, types 1..240 and 254,
// type 254 TPDOs sent on RPDO reception.
sim::SlavePdoOptions sd6_options() {
  sim::SlavePdoOptions o;
  o.max_entries = 6;
  o.fixed_count = 6;
  o.transmission_types = {1, 240, true, false};
  o.tpdo_254_on_rpdo = true;
  return o;
}

struct AkdSlave {
  FakeObjects objects;
  AkdDefaults defaults{1};
  sim::SlavePdos slave{objects, akd_options(), defaults.rpdos, defaults.tpdos};
  TxQueue tx;
};

std::uint32_t value_of(const sim::SlavePdos& s, cia402::ObjectId id) {
  const auto r = s.read(id);
  EXPECT_EQ(r.abort_code, 0U) << std::hex << id.index << ":" << int{id.sub};
  return r.value;
}

// AKD part 1 §12.6 and §14 vectors 3-8: free mapping of TPDO1 = SW + 1002h, node 1.
TEST(SlavePdoObjects, AkdTpdo1RemapSequence) {
  AkdSlave a;
  EXPECT_EQ(value_of(a.slave, {0x1A00, 0}), 1U);
  EXPECT_EQ(value_of(a.slave, {0x1A00, 1}), 0x60410010U);
  // While the PDO is valid its mapping cannot change [CiA 301]: 08000022h.
  EXPECT_EQ(sdo(a.slave, {0x2F, 0x00, 0x1A, 0x00, 0x00, 0, 0, 0}), (Bytes{0x80, 0x00, 0x1A, 0x00, 0x22, 0x00, 0x00, 0x08}));
  EXPECT_EQ(sdo(a.slave, {0x23, 0x00, 0x18, 0x01, 0x81, 0x01, 0x00, 0xC0}), confirm(0x1800, 1));  // 3
  EXPECT_EQ(sdo(a.slave, {0x2F, 0x00, 0x1A, 0x00, 0x00, 0x00, 0x00, 0x00}), confirm(0x1A00, 0));  // 4
  EXPECT_EQ(sdo(a.slave, {0x23, 0x00, 0x1A, 0x01, 0x10, 0x00, 0x41, 0x60}), confirm(0x1A00, 1));  // 5
  EXPECT_EQ(sdo(a.slave, {0x23, 0x00, 0x1A, 0x02, 0x20, 0x00, 0x02, 0x10}), confirm(0x1A00, 2));  // 6
  EXPECT_EQ(sdo(a.slave, {0x2F, 0x00, 0x1A, 0x00, 0x02, 0x00, 0x00, 0x00}), confirm(0x1A00, 0));  // 7
  EXPECT_EQ(sdo(a.slave, {0x23, 0x00, 0x18, 0x01, 0x81, 0x01, 0x00, 0x40}), confirm(0x1800, 1));  // 8
  EXPECT_EQ(value_of(a.slave, {0x1800, 1}), 0x40000181U);
  EXPECT_EQ(value_of(a.slave, {0x1A00, 0}), 2U);
  EXPECT_EQ(value_of(a.slave, {0x1A00, 2}), 0x10020020U);

  // The resulting TPDO1: statusword (bytes 0-1) + 1002h (bytes 2-5).
  a.objects.set(obj::kStatusword.id, 0x0237);
  a.objects.set(kManufacturerStatus.id, 0x44030000);
  a.slave.set_operational(true);
  a.slave.poll(kT0, a.tx);
  const auto frames = drain(a.tx);
  ASSERT_EQ(frames.size(), 4U);  // every event-driven TPDO goes out once on entering Operational
  EXPECT_EQ(frames[0].id, 0x181U);
  EXPECT_EQ(payload(frames[0]), (Bytes{0x37, 0x02, 0x00, 0x00, 0x03, 0x44}));
}

// AKD part 1 §14 vector 17: a mapping longer than 8 bytes is refused on sub 0 with 06040042h.
TEST(SlavePdoObjects, MappingLongerThanEightBytes) {
  AkdSlave a;
  ASSERT_EQ(a.slave.write({0x1800, 1}, 0xC0000181), 0U);
  ASSERT_EQ(a.slave.write({0x1A00, 0}, 0), 0U);
  ASSERT_EQ(a.slave.write({0x1A00, 1}, entry(obj::kPositionActual)), 0U);
  ASSERT_EQ(a.slave.write({0x1A00, 2}, entry(obj::kVelocityActual)), 0U);
  ASSERT_EQ(a.slave.write({0x1A00, 3}, entry(kManufacturerStatus)), 0U);
  EXPECT_EQ(sdo(a.slave, {0x2F, 0x00, 0x1A, 0x00, 0x03, 0, 0, 0}), (Bytes{0x80, 0x00, 0x1A, 0x00, 0x42, 0x00, 0x04, 0x06}));
  EXPECT_EQ(value_of(a.slave, {0x1A00, 0}), 0U);  // unchanged
  EXPECT_EQ(a.slave.write({0x1A00, 0}, 2), 0U);   // 8 bytes exactly
}

// AKD part 1 §14 vectors 27-29: TPDO3 inhibit 10 ms, TPDO4 event timer 50 ms, RPDO1 type 1.
TEST(SlavePdoObjects, AkdCommunicationParameterVectors) {
  AkdSlave a;
  EXPECT_EQ(sdo(a.slave, {0x2B, 0x02, 0x18, 0x03, 0x64, 0x00, 0x00, 0x00}), confirm(0x1802, 3));
  EXPECT_EQ(sdo(a.slave, {0x2B, 0x03, 0x18, 0x05, 0x32, 0x00, 0x00, 0x00}), confirm(0x1803, 5));
  EXPECT_EQ(sdo(a.slave, {0x2F, 0x00, 0x14, 0x02, 0x01, 0x00, 0x00, 0x00}), confirm(0x1400, 2));
  EXPECT_EQ(value_of(a.slave, {0x1802, 3}), 100U);
  EXPECT_EQ(value_of(a.slave, {0x1803, 5}), 50U);
  EXPECT_EQ(value_of(a.slave, {0x1400, 2}), 1U);
  const auto r = a.slave.read({0x1802, 3});
  EXPECT_EQ(r.size, 2);
  EXPECT_EQ(a.slave.read({0x1800, 1}).size, 4);
  EXPECT_EQ(a.slave.read({0x1800, 0}).value, 5U);
  EXPECT_EQ(a.slave.read({0x1400, 0}).value, 2U);
  EXPECT_EQ(a.slave.read({0x1600, 0}).size, 1);
}

TEST(SlavePdoObjects, MappingRules) {
  AkdSlave a;
  auto& s = a.slave;
  ASSERT_EQ(s.write({0x1401, 1}, 0x80000301), 0U);  // RPDO2 invalid
  ASSERT_EQ(s.write({0x1601, 0}, 0), 0U);
  // Entries: objects that exist and may go this way, with their exact length.
  EXPECT_EQ(s.write({0x1601, 1}, entry(obj::kStatusword)), cia402::sdo_abort_code::kNotMappable);  // TPDO-only object
  EXPECT_EQ(s.write({0x1601, 1}, entry(obj::kSupportedDriveModes)), cia402::sdo_abort_code::kNotMappable);
  EXPECT_EQ(s.write({0x1601, 1}, 0x22220010), cia402::sdo_abort_code::kNotMappable);  // does not exist
  EXPECT_EQ(s.write({0x1601, 1}, 0x60400020), cia402::sdo_abort_code::kNotMappable);  // CW as 32 bit
  EXPECT_EQ(s.write({0x1601, 1}, 0x60400008), cia402::sdo_abort_code::kNotMappable);  // part of CW
  EXPECT_EQ(s.write({0x1601, 9}, entry(obj::kControlword)), cia402::sdo_abort_code::kNoSubIndex);
  EXPECT_EQ(s.write({0x1601, 1}, entry(obj::kControlword), 2), cia402::sdo_abort_code::kTypeMismatch);
  ASSERT_EQ(s.write({0x1601, 1}, entry(obj::kControlword), 4), 0U);
  // Count: <= 8 and only over entries that are set.
  EXPECT_EQ(s.write({0x1601, 0}, 9), cia402::sdo_abort_code::kValueRange);
  EXPECT_EQ(s.write({0x1601, 0}, 2), 0U);  // entry 2 still holds the default 6060h
  ASSERT_EQ(s.write({0x1601, 0}, 0), 0U);
  ASSERT_EQ(s.write({0x1601, 2}, 0), 0U);
  EXPECT_EQ(s.write({0x1601, 0}, 2), cia402::sdo_abort_code::kNotMappable);  // entry 2 is empty now
  EXPECT_EQ(s.write({0x1601, 0}, 1, 4), cia402::sdo_abort_code::kTypeMismatch);
  EXPECT_EQ(s.write({0x1601, 0}, 1, 1), 0U);
  EXPECT_EQ(s.write({0x1601, 1}, 0), 0U);  // clearing an entry is allowed while invalid
  EXPECT_EQ(s.read({0x1601, 9}).abort_code, cia402::sdo_abort_code::kNoSubIndex);
}

TEST(SlavePdoObjects, CommunicationParameterRules) {
  AkdSlave a;
  auto& s = a.slave;
  EXPECT_EQ(s.write({0x1800, 0}, 5), cia402::sdo_abort_code::kReadOnly);
  EXPECT_EQ(s.write({0x1400, 3}, 10), cia402::sdo_abort_code::kNoSubIndex);  // RPDOs: no inhibit time
  EXPECT_EQ(s.write({0x1400, 5}, 10), cia402::sdo_abort_code::kNoSubIndex);  // ... and no event timer
  EXPECT_EQ(s.read({0x1400, 5}).abort_code, cia402::sdo_abort_code::kNoSubIndex);
  EXPECT_EQ(s.write({0x1800, 4}, 0), cia402::sdo_abort_code::kNoSubIndex);
  EXPECT_EQ(s.write({0x1800, 6}, 0), cia402::sdo_abort_code::kNoSubIndex);
  EXPECT_EQ(s.write({0x1404, 1}, 0x205), cia402::sdo_abort_code::kNoObject);
  EXPECT_EQ(s.read({0x1C00, 0}).abort_code, cia402::sdo_abort_code::kNoObject);
  EXPECT_FALSE(sim::SlavePdos::owns(0x1404));
  EXPECT_TRUE(sim::SlavePdos::owns(0x1A03));
  // COB-ID: the id only changes while invalid; no 29-bit ids; a valid PDO needs an id.
  EXPECT_EQ(s.write({0x1800, 1}, 0x00000191), cia402::sdo_abort_code::kValueRange);
  EXPECT_EQ(s.write({0x1800, 1}, 0x40000181), 0U);  // same id, bit 30 only
  EXPECT_EQ(s.write({0x1800, 1}, 0x20000181), cia402::sdo_abort_code::kValueRange);
  EXPECT_EQ(s.write({0x1800, 1}, 0x00010181), cia402::sdo_abort_code::kValueRange);
  EXPECT_EQ(s.write({0x1800, 1}, 0x80000191), 0U);
  EXPECT_EQ(s.write({0x1800, 1}, 0x00000000), cia402::sdo_abort_code::kValueRange);
  EXPECT_EQ(s.write({0x1800, 1}, 0x00000191), 0U);
  EXPECT_EQ(s.write({0x1800, 1}, 0x191, 2), cia402::sdo_abort_code::kTypeMismatch);
  // Transmission type: 0..240, 254, 255 by default; values past the type's width are range errors.
  for (const std::uint32_t t : {241U, 252U, 253U}) {
    EXPECT_EQ(s.write({0x1800, 2}, t), cia402::sdo_abort_code::kValueRange);
  }
  for (const std::uint32_t t : {0U, 1U, 240U, 254U, 255U}) EXPECT_EQ(s.write({0x1800, 2}, t), 0U);
  EXPECT_EQ(s.write({0x1800, 2}, 0x101), cia402::sdo_abort_code::kValueRange);
  EXPECT_EQ(s.write({0x1800, 3}, 0x10000), cia402::sdo_abort_code::kValueRange);
  EXPECT_EQ(s.write({0x1800, 3}, 0xFFFF, 2), 0U);
}

TEST(SlavePdoObjects, Sd6FixedMappingPersonaRefusesMappingWrites) {
  FakeObjects objects;
  auto rx1 = slave_pdo(cob::rpdo(0, 5), 1, {obj::kControlword});
  rx1.mapping[2] = entry(obj::kTargetVelocity);  // slots 2 and 4..6 unused
  const std::array<sim::SlavePdoConfig, 1> rpdos{rx1};
  const std::array<sim::SlavePdoConfig, 1> tpdos{slave_pdo(cob::tpdo(0, 5), 254, {obj::kStatusword, obj::kPositionActual})};
  sim::SlavePdos s{objects, sd6_options(), rpdos, tpdos};
  EXPECT_EQ(s.read({0x1600, 0}).value, 6U);
  EXPECT_EQ(s.read({0x1A03, 0}).value, 6U);
  EXPECT_EQ(s.read({0x1600, 3}).value, 0x60FF0020U);
  EXPECT_EQ(s.read({0x1600, 7}).abort_code, cia402::sdo_abort_code::kNoSubIndex);
  ASSERT_EQ(s.write({0x1400, 1}, 0x80000205), 0U);  // even while invalid
  EXPECT_EQ(s.write({0x1600, 0}, 0), cia402::sdo_abort_code::kReadOnly);
  EXPECT_EQ(s.write({0x1600, 1}, entry(obj::kControlword)), cia402::sdo_abort_code::kReadOnly);
  EXPECT_EQ(s.write({0x1600, 7}, 0), cia402::sdo_abort_code::kNoSubIndex);
  EXPECT_EQ(s.read({0x1600, 1}).value, 0x60400010U);
  // Transmission types 1..240 and 254 only (quirk 3).
  EXPECT_EQ(s.write({0x1800, 2}, 255), cia402::sdo_abort_code::kValueRange);
  EXPECT_EQ(s.write({0x1800, 2}, 0), cia402::sdo_abort_code::kValueRange);
  EXPECT_EQ(s.write({0x1400, 2}, 241), cia402::sdo_abort_code::kValueRange);
  EXPECT_EQ(s.write({0x1800, 2}, 240), 0U);
  EXPECT_EQ(s.write({0x1800, 2}, 254), 0U);
  // The fixed RPDO1 maps CW and 60FFh (6 bytes); empty slots map nothing.
  ASSERT_EQ(s.write({0x1400, 1}, 0x205), 0U);
  s.set_operational(true);
  TxQueue tx;
  EXPECT_TRUE(s.on_frame(make_frame(0x205, {0x0F, 0x00, 0x10, 0x27, 0x00, 0x00}), kT0));
  s.on_sync(kT0, tx);
  EXPECT_EQ(objects.get(obj::kControlword.id), 0x0F);
  EXPECT_EQ(objects.get(obj::kTargetVelocity.id), 10000);
  EXPECT_EQ(s.counters().short_rpdos, 0U);
}

TEST(SlavePdoObjects, DefaultsThePersonaRefusesDoNotConstruct) {
  FakeObjects objects;
  const std::array<sim::SlavePdoConfig, 1> type_255{slave_pdo(cob::tpdo(0, 5), 255, {obj::kStatusword})};
  EXPECT_THROW((sim::SlavePdos{objects, sd6_options(), {}, type_255}), std::invalid_argument);
  const std::array<sim::SlavePdoConfig, 1> rx_in_tx{slave_pdo(cob::tpdo(0, 5), 1, {obj::kControlword})};
  EXPECT_THROW((sim::SlavePdos{objects, {}, {}, rx_in_tx}), std::invalid_argument);
  auto seven = slave_pdo(cob::tpdo(0, 5), 1, {});
  seven.mapping[6] = entry(obj::kStatusword);
  seven.count = 7;
  EXPECT_THROW((sim::SlavePdos{objects, sd6_options(), {}, std::array{seven}}), std::invalid_argument);
  const std::array<sim::SlavePdoConfig, 1> too_long{
      slave_pdo(cob::tpdo(0, 5), 1, {obj::kPositionActual, obj::kVelocityActual, obj::kStatusword})};
  EXPECT_THROW((sim::SlavePdos{objects, {}, {}, too_long}), std::invalid_argument);
  const std::array<sim::SlavePdoConfig, 5> five{};
  EXPECT_THROW((sim::SlavePdos{objects, {}, five, {}}), std::invalid_argument);
  sim::SlavePdoOptions bad;
  bad.fixed_count = 9;
  EXPECT_THROW((sim::SlavePdos{objects, bad, {}, {}}), std::invalid_argument);
  // Missing PDOs are invalid and empty.
  sim::SlavePdos none{objects, {}, {}, {}};
  EXPECT_EQ(none.read({0x1803, 1}).value, cob::kInvalid);
  EXPECT_EQ(none.read({0x1A03, 0}).value, 0U);
}

TEST(SlavePdoObjects, RestoreDefaultsUndoesARemap) {
  AkdSlave a;
  ASSERT_EQ(a.slave.write({0x1800, 1}, 0xC0000181), 0U);
  ASSERT_EQ(a.slave.write({0x1A00, 0}, 0), 0U);
  a.slave.restore_defaults();
  EXPECT_EQ(value_of(a.slave, {0x1800, 1}), 0x181U);
  EXPECT_EQ(value_of(a.slave, {0x1A00, 0}), 1U);
}

TEST(SlaveRpdos, EventDrivenAppliedAtOnceSynchronousAtTheNextSync) {
  AkdSlave a;
  ASSERT_EQ(a.slave.write({0x1400, 2}, 1), 0U);  // RPDO1 (CW) synchronous; RPDO3 stays 255
  a.slave.set_operational(true);
  // AKD vector 30: default RPDO3 401h.
  EXPECT_TRUE(a.slave.on_frame(make_frame(0x401, {0x1F, 0x00, 0xA0, 0x86, 0x01, 0x00}), kT0));
  EXPECT_EQ(a.objects.get(obj::kControlword.id), 0x1F);
  EXPECT_EQ(a.objects.get(obj::kTargetPosition.id), 100000);
  EXPECT_TRUE(a.slave.on_frame(make_frame(0x201, {0x0F, 0x00}), kT0 + 100us));
  EXPECT_EQ(a.objects.get(obj::kControlword.id), 0x1F);  // waits for the SYNC
  EXPECT_TRUE(a.slave.on_frame(make_frame(0x201, {0x2F, 0x00}), kT0 + 200us));  // the newest counts
  a.slave.on_sync(kT0 + 1ms, a.tx);
  EXPECT_EQ(a.objects.get(obj::kControlword.id), 0x2F);
  a.objects.set(obj::kControlword.id, 0);
  a.slave.on_sync(kT0 + 2ms, a.tx);  // nothing new: nothing applied
  EXPECT_EQ(a.objects.get(obj::kControlword.id), 0);
  EXPECT_EQ(a.slave.counters().rpdos_received, 3U);
  EXPECT_EQ(a.slave.counters().rpdos_applied, 2U);
}

TEST(SlaveRpdos, AkdAppliesTypeNAtEveryNthSyncCiaAtTheNext) {
  for (const bool akd : {true, false}) {
    FakeObjects objects;
    const std::array<sim::SlavePdoConfig, 1> rpdos{slave_pdo(0x201, 3, {obj::kTargetPosition})};
    sim::SlavePdoOptions options;
    options.rpdo_every_nth_sync = akd;
    sim::SlavePdos s{objects, options, rpdos, {}};
    s.set_operational(true);
    TxQueue tx;
    std::vector<int> applied_at;
    for (int sync = 1; sync <= 6; ++sync) {
      s.on_frame(make_frame(0x201, {static_cast<std::uint8_t>(sync), 0, 0, 0}), kT0 + sync * 1ms);
      const auto before = objects.writes();
      s.on_sync(kT0 + sync * 1ms + 500us, tx);
      if (objects.writes() != before) applied_at.push_back(sync);
    }
    if (akd) {
      EXPECT_EQ(applied_at, (std::vector<int>{3, 6}));  // "0 to 239 SYNCs ignored before one is interpreted"
      EXPECT_EQ(objects.get(obj::kTargetPosition.id), 6);
    } else {
      EXPECT_EQ(applied_at, (std::vector<int>{1, 2, 3, 4, 5, 6}));
    }
  }
}

TEST(SlaveRpdos, LengthRulesAndWhatIsIgnored) {
  AkdSlave a;
  EXPECT_TRUE(a.slave.on_frame(make_frame(0x401, {0x1F, 0x00, 0xA0, 0x86, 0x01, 0x00}), kT0));  // pre-operational
  EXPECT_EQ(a.slave.counters().ignored, 1U);
  EXPECT_EQ(a.objects.writes(), 0U);
  a.slave.set_operational(true);
  EXPECT_TRUE(a.slave.on_frame(make_frame(0x401, {0x1F, 0x00, 0xA0, 0x86, 0x01}), kT0));  // 5 of 6 bytes
  EXPECT_EQ(a.objects.writes(), 0U);
  EXPECT_EQ(a.slave.counters().short_rpdos, 1U);
  EXPECT_TRUE(a.slave.take_length_error());   // the owner sends EMCY 8210h
  EXPECT_FALSE(a.slave.take_length_error());  // once
  EXPECT_TRUE(a.slave.on_frame(make_frame(0x401, {0x1F, 0x00, 0xA0, 0x86, 0x01, 0x00, 0xAA, 0xBB}), kT0));
  EXPECT_EQ(a.objects.get(obj::kTargetPosition.id), 100000);
  EXPECT_EQ(a.slave.counters().long_rpdos, 1U);
  EXPECT_FALSE(a.slave.take_length_error());
  auto rtr = make_frame(0x201, {});
  rtr.remote = true;
  EXPECT_TRUE(a.slave.on_frame(rtr, kT0));
  auto bad = make_frame(0x201, {0x0F, 0x00});
  bad.dlc = 12;
  EXPECT_TRUE(a.slave.on_frame(bad, kT0));
  EXPECT_EQ(a.slave.counters().ignored, 3U);
  EXPECT_FALSE(a.slave.on_frame(make_frame(0x202, {0x0F, 0x00}), kT0));  // another node
  EXPECT_FALSE(a.slave.on_frame(make_frame(0x181, {0x0F, 0x00}), kT0));  // its own TPDO
  ASSERT_EQ(a.slave.write({0x1400, 1}, 0x80000201), 0U);
  EXPECT_FALSE(a.slave.on_frame(make_frame(0x201, {0x0F, 0x00}), kT0));  // invalid RPDO
}

TEST(SlaveRpdos, LeavingOperationalDropsDataWaitingForSync) {
  AkdSlave a;
  ASSERT_EQ(a.slave.write({0x1400, 2}, 0), 0U);
  a.slave.set_operational(true);
  a.slave.on_frame(make_frame(0x201, {0x0F, 0x00}), kT0);
  a.slave.set_operational(false);
  a.slave.on_sync(kT0 + 1ms, a.tx);
  a.slave.set_operational(true);
  a.slave.on_sync(kT0 + 2ms, a.tx);
  EXPECT_EQ(a.objects.writes(), 0U);
}

// AKD part 2 §12.10 (corrected): node 3, TPDO1 = 6064h type 2, TPDO2 = SW + 1002h type 3.
TEST(SlaveTpdos, SynchronousEveryNthSync) {
  FakeObjects objects;
  const std::array<sim::SlavePdoConfig, 2> tpdos{slave_pdo(0x183, 2, {obj::kPositionActual}),
                                                 slave_pdo(0x283, 3, {obj::kStatusword, kManufacturerStatus})};
  sim::SlavePdos s{objects, akd_options(), {}, tpdos};
  TxQueue tx;
  s.on_sync(kT0, tx);  // not operational: nothing
  EXPECT_TRUE(tx.empty());
  s.set_operational(true);
  objects.set(obj::kPositionActual.id, 83454);
  std::vector<std::pair<int, std::uint32_t>> seen;
  for (int sync = 1; sync <= 6; ++sync) {
    s.on_sync(kT0 + sync * 1ms, tx);
    s.poll(kT0 + sync * 1ms, tx);  // synchronous TPDOs ignore polls
    for (const auto& f : drain(tx)) seen.emplace_back(sync, f.id);
  }
  const std::vector<std::pair<int, std::uint32_t>> expected{{2, 0x183}, {3, 0x283}, {4, 0x183}, {6, 0x183}, {6, 0x283}};
  EXPECT_EQ(seen, expected);
  objects.set(obj::kPositionActual.id, -2);
  for (int sync = 7; sync <= 8; ++sync) s.on_sync(kT0 + sync * 1ms, tx);
  const auto frames = drain(tx);
  ASSERT_EQ(frames.size(), 1U);
  EXPECT_EQ(payload(frames[0]), (Bytes{0xFE, 0xFF, 0xFF, 0xFF}));
}

TEST(SlaveTpdos, TypeZeroAtSyncOnlyWhenChanged) {
  FakeObjects objects;
  const std::array<sim::SlavePdoConfig, 1> tpdos{slave_pdo(0x181, 0, {obj::kStatusword})};
  sim::SlavePdos s{objects, {}, {}, tpdos};
  s.set_operational(true);
  TxQueue tx;
  objects.set(obj::kStatusword.id, 0x0231);
  s.poll(kT0, tx);
  EXPECT_TRUE(tx.empty());  // only at a SYNC
  s.on_sync(kT0, tx);
  EXPECT_EQ(drain(tx).size(), 1U);  // first one
  s.on_sync(kT0 + 1ms, tx);
  EXPECT_TRUE(tx.empty());
  objects.set(obj::kStatusword.id, 0x0233);
  s.on_sync(kT0 + 2ms, tx);
  const auto frames = drain(tx);
  ASSERT_EQ(frames.size(), 1U);
  EXPECT_EQ(payload(frames[0]), (Bytes{0x33, 0x02}));
}

// Event-driven TPDO with inhibit time 10 ms (100 x 100 us, AKD vector 27) and event timer 50 ms
// (vector 28): the mapped value changes every millisecond up to 35 ms, then stays.
TEST(SlaveTpdos, EventDrivenInhibitAndEventTimerExact) {
  FakeObjects objects;
  auto t = slave_pdo(0x381, 255, {obj::kStatusword, obj::kPositionActual});
  t.inhibit_time = 100;
  t.event_timer = 50;
  const std::array<sim::SlavePdoConfig, 1> tpdos{t};
  sim::SlavePdos s{objects, {}, {}, tpdos};
  s.set_operational(true);
  TxQueue tx;
  EXPECT_EQ(s.next_deadline(), core::TimePoint::min());  // the first send is due at once
  std::vector<core::Duration> sent;
  for (auto at = 0us; at <= 150ms; at += 100us) {
    objects.set(obj::kPositionActual.id, std::min<std::int64_t>(at / 1ms, 35));
    s.poll(kT0 + at, tx);
    for (const auto& f : drain(tx)) {
      EXPECT_EQ(f.dlc, 6);
      sent.push_back(at);
    }
    if (at == 35ms) {  // a change is held by the inhibit time
      EXPECT_EQ(s.next_deadline(), kT0 + 40ms);
    }
    if (at == 45ms) {  // only the event timer runs
      EXPECT_EQ(s.next_deadline(), kT0 + 90ms);
    }
  }
  const std::vector<core::Duration> expected{0ms, 10ms, 20ms, 30ms, 40ms, 90ms, 140ms};
  EXPECT_EQ(sent, expected);
  EXPECT_EQ(s.counters().tpdos_sent, expected.size());
}

TEST(SlaveTpdos, Sd6Type254IsSentOnRpdoReceptionWithTheEventTimerAsFallback) {
  FakeObjects objects;
  const std::array<sim::SlavePdoConfig, 1> rpdos{slave_pdo(0x205, 254, {obj::kControlword})};
  auto t = slave_pdo(0x185, 254, {obj::kStatusword});
  t.event_timer = 20;
  const std::array<sim::SlavePdoConfig, 1> tpdos{t};
  sim::SlavePdos s{objects, sd6_options(), rpdos, tpdos};
  s.set_operational(true);
  TxQueue tx;
  s.poll(kT0, tx);
  EXPECT_EQ(drain(tx).size(), 1U);  // the first one on entering Operational
  objects.set(obj::kStatusword.id, 0x0237);
  s.poll(kT0 + 5ms, tx);
  EXPECT_TRUE(tx.empty());  // a change alone does not send it
  s.on_frame(make_frame(0x205, {0x0F, 0x00}), kT0 + 6ms);
  s.poll(kT0 + 6ms, tx);
  auto frames = drain(tx);
  ASSERT_EQ(frames.size(), 1U);
  EXPECT_EQ(payload(frames[0]), (Bytes{0x37, 0x02}));
  s.poll(kT0 + 7ms, tx);
  EXPECT_TRUE(tx.empty());  // one per reception
  EXPECT_EQ(s.next_deadline(), kT0 + 26ms);
  s.poll(kT0 + 26ms, tx);  // no RPDO for 20 ms: the event timer sends it
  EXPECT_EQ(drain(tx).size(), 1U);
}

TEST(SlaveTpdos, RefusedFramesAreCountedAndRetried) {
  AkdSlave a;
  a.slave.set_operational(true);
  TxQueue full;
  for (std::size_t i = 0; i < 1024; ++i) ASSERT_TRUE(full.push(sync_frame()));
  a.slave.poll(kT0, full);
  EXPECT_EQ(a.slave.counters().tx_full, 4U);
  a.slave.poll(kT0 + 1ms, a.tx);
  EXPECT_EQ(drain(a.tx).size(), 4U);
}

TEST(SlavePdos, CyclicCallsAndSdoAccessDoNotAllocate) {
  AkdSlave a;
  ASSERT_EQ(a.slave.write({0x1400, 2}, 1), 0U);
  ASSERT_EQ(a.slave.write({0x1800, 2}, 1), 0U);
  ASSERT_EQ(a.slave.write({0x1802, 3}, 10), 0U);
  const auto rpdo1 = make_frame(0x201, {0x0F, 0x00});
  const auto rpdo3 = make_frame(0x401, {0x1F, 0x00, 0xA0, 0x86});  // short
  drivegate::test::AllocationScope scope;
  a.slave.set_operational(true);
  for (int c = 0; c < 50; ++c) {
    const auto now = kT0 + c * 1ms;
    a.objects.set(obj::kPositionActual.id, c);
    a.slave.on_sync(now, a.tx);
    a.slave.on_frame(rpdo1, now + 100us);
    a.slave.on_frame(rpdo3, now + 200us);
    a.slave.poll(now + 300us, a.tx);
    static_cast<void>(a.slave.next_deadline());
    static_cast<void>(a.slave.take_length_error());
    static_cast<void>(a.slave.read({0x1A00, 1}));
    static_cast<void>(a.slave.write({0x1803, 5}, 100, 2));
    a.tx.clear();
  }
  EXPECT_EQ(scope.count(), 0U);
  EXPECT_EQ(a.slave.counters().short_rpdos, 50U);
  EXPECT_GE(a.slave.counters().tpdos_sent, 50U + 5U);
}

}  // namespace
}  // namespace drivegate::canopen::test
