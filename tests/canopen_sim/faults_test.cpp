// Fault injection: drive faults with the persona's EMCY bytes, communication losses, power loss and
// return, silence, injected SDO aborts and damaged frames.
#include <gtest/gtest.h>

#include "tests/canopen_sim/sim_test_support.hpp"

namespace drivegate::canopen::sim::test {
namespace {

// Fault reset: controlword bit 7 rising edge.
void fault_reset(Drive& d) {
  d.controlword(0x00);
  d.controlword(0x80);
}

TEST(Faults, AkdEmcyHasCategoryAndAStateFollowUp) {
  Drive d(akd(1));
  d.boot();
  d.node.inject_fault(0x4310);
  const auto emcy = on_id(d.run(5ms), 0x81);
  // part 2 §12.10 rows 71/72: category 01h, then 0000h with the error register.
  ASSERT_EQ(emcy.size(), 2U);
  EXPECT_TRUE(is_frame(emcy[0], 0x81, {0x10, 0x43, 0x09, 0x01, 0x00, 0x00, 0x00, 0x00}));
  EXPECT_TRUE(is_frame(emcy[1], 0x81, {0x00, 0x00, 0x09, 0x00, 0x00, 0x00, 0x00, 0x00}));
  EXPECT_EQ(d.statusword() & 0x4F, 0x08);
  EXPECT_EQ(d.value({0x603F, 0}), 0x4310U);
  EXPECT_NE(d.value({0x1002, 0}) & (1U << 15), 0U);  // manufacturer status: fault

  fault_reset(d);
  EXPECT_EQ(d.statusword() & 0x4F, 0x08);  // the cause persists
  d.node.clear_fault_cause();
  d.controlword(0x00);
  ASSERT_EQ(d.write({0x6040, 0}, 0x80, 2), 0U);
  const auto cleared = on_id(d.run(5ms), 0x81);
  ASSERT_EQ(cleared.size(), 1U);  // all clear: code 0000h, register 00h, no follow-up
  EXPECT_TRUE(is_frame(cleared[0], 0x81, {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}));
  EXPECT_EQ(d.statusword() & 0x4F, 0x40);
  EXPECT_EQ(d.node.emcy().counters().sent, 3U);
}

TEST(Faults, Sd6EmcyCarriesEventAndCause) {
  Drive d(sd6(5));
  d.boot();
  d.node.inject_fault(0x4310, 2);
  const auto emcy = on_id(d.run(5ms), 0x85);
  ASSERT_EQ(emcy.size(), 1U);
  // D-9: 4310h, register 08h (no generic bit, Tab. 17), E82 = 41 = 29h, E43 = the cause.
  EXPECT_TRUE(is_frame(emcy[0], 0x85, {0x10, 0x43, 0x08, 0x29, 0x02, 0x00, 0x00, 0x00}));
  EXPECT_EQ(d.value({0x1001, 0}), 0x08U);
  EXPECT_EQ(d.value({0x2852, 0}), 41U);  // E82
  EXPECT_EQ(d.value({0x282B, 0}), 2U);   // E43
  EXPECT_EQ(d.value({0x2830, 0}), 5U);   // E48: fault
  EXPECT_EQ(d.value({0x1002, 0}), 5U);

  d.node.clear_fault_cause();
  fault_reset(d);
  EXPECT_EQ(d.statusword() & 0x4F, 0x40);
  EXPECT_EQ(d.value({0x2852, 0}), 30U);
  EXPECT_EQ(d.value({0x1001, 0}), 0U);
  EXPECT_EQ(d.node.emcy().counters().sent, 2U);
}

TEST(Faults, Sd6LeavingFaultSends1Eh) {
  Drive d(sd6(5));
  d.boot();
  d.node.inject_fault(0x2310);
  d.run(5ms);
  d.node.clear_fault_cause();
  d.controlword(0x00);
  ASSERT_EQ(d.write({0x6040, 0}, 0x80, 2), 0U);
  const auto emcy = on_id(d.run(5ms), 0x85);
  ASSERT_EQ(emcy.size(), 1U);
  EXPECT_TRUE(is_frame(emcy[0], 0x85, {0x00, 0x00, 0x00, 0x1E, 0x00, 0x00, 0x00, 0x00}));  // TV-5
}

TEST(Faults, Sd6LifeGuardingFaultsOnlyInOperational) {
  Drive d(sd6(5));
  d.boot();
  // D-5: 1017h = 0, 100Ch = 100, 100Dh = 3.
  ASSERT_EQ(d.sdo(SdoBytes{0x2B, 0x17, 0x10, 0x00, 0, 0, 0, 0}).abort, 0U);
  ASSERT_EQ(d.sdo(SdoBytes{0x2B, 0x0C, 0x10, 0x00, 0x64, 0, 0, 0}).abort, 0U);
  ASSERT_EQ(d.sdo(SdoBytes{0x2F, 0x0D, 0x10, 0x00, 0x03, 0, 0, 0}).abort, 0U);
  auto reply = on_id(d.send(rtr(0x705)), 0x705);
  ASSERT_EQ(reply.size(), 1U);
  EXPECT_TRUE(is_frame(reply[0], 0x705, {0x7F}));
  // Pre-operational: the life time passes without a fault (quirk 8).
  EXPECT_TRUE(on_id(d.run(400ms), 0x85).empty());
  EXPECT_EQ(d.statusword() & 0x4F, 0x40);

  d.send(nmt(NmtCommand::Start, 5));
  reply = on_id(d.send(rtr(0x705)), 0x705);
  ASSERT_EQ(reply.size(), 1U);
  EXPECT_TRUE(is_frame(reply[0], 0x705, {0x85}));  // Operational, toggle 1
  const auto emcy = on_id(d.run(400ms), 0x85);
  ASSERT_EQ(emcy.size(), 1U);
  EXPECT_TRUE(is_frame(emcy[0], 0x85, {0x00, 0x75, 0x10, 0x34, 0x01, 0x00, 0x00, 0x00}));  // D-7
  EXPECT_EQ(d.statusword() & 0x4F, 0x08);
  EXPECT_EQ(d.node.counters().comm_losses, 1U);
  // The cause ends with the event: a fault reset works once the master guards again.
  fault_reset(d);
  EXPECT_EQ(d.statusword() & 0x4F, 0x40);
}

TEST(Faults, HeartbeatLossFaultsTheGenericDrive) {
  Drive d(generic(1));
  d.boot();
  ASSERT_EQ(d.write({0x1016, 1}, (127U << 16) | 300U, 4), 0U);
  d.send(make_frame(0x77F, {0x05}));  // the gateway's heartbeat starts the monitoring
  EXPECT_TRUE(on_id(d.run(250ms), 0x81).empty());
  const auto emcy = on_id(d.run(100ms), 0x81);
  ASSERT_EQ(emcy.size(), 1U);
  EXPECT_TRUE(is_frame(emcy[0], 0x81, {0x30, 0x81, 0x11, 0x00, 0x00, 0x00, 0x00, 0x00}));  // 8130h
  fault_reset(d);
  EXPECT_EQ(d.statusword() & 0x4F, 0x40);
}

TEST(Faults, NordEmcyIsCodeAndRegisterOnly) {
  Drive d(nord(0x20));
  d.boot();
  d.node.inject_fault(0x3210, 7);
  const auto emcy = on_id(d.run(5ms), 0xA0);
  ASSERT_EQ(emcy.size(), 1U);
  EXPECT_TRUE(is_frame(emcy[0], 0xA0, {0x10, 0x32, 0x05, 0x00, 0x00, 0x00, 0x00, 0x00}));  // §9
}

TEST(Faults, DisabledEmcyCobIdSendsNothing) {
  Drive d(generic(1));
  d.boot();
  ASSERT_EQ(d.write({0x1014, 0}, 0x80000081U, 4), 0U);
  EXPECT_EQ(d.write({0x1014, 0}, 0x82U, 4), 0x06090030U);  // the EMCY stays on 80h + node-ID
  d.node.inject_fault(0x2310);
  EXPECT_TRUE(on_id(d.run(5ms), 0x81).empty());
  EXPECT_EQ(d.node.emcy().counters().suppressed, 1U);
}

TEST(Faults, PowerLossSilencesAndPowerReturnBootsIntoSwitchOnDisabled) {
  Drive d(akd(1));
  d.boot();
  ASSERT_EQ(d.write({0x1017, 0}, 10, 2), 0U);
  ASSERT_EQ(d.write({0x1A00, 0}, 0, 1), 0x08000022U);  // TPDO1 valid: mapping locked
  ASSERT_EQ(d.write({0x1800, 1}, 0x80000181U, 4), 0U);
  ASSERT_EQ(d.write({0x1A00, 0}, 0, 1), 0U);
  d.send(nmt(NmtCommand::Start, 1));
  d.enable();
  ASSERT_EQ(d.statusword() & 0x6F, 0x27);

  d.node.power_off();
  EXPECT_TRUE(d.send(make_frame(0x601, sdo_upload_request({0x1000, 0}))).empty());
  EXPECT_TRUE(d.run(100ms).empty());  // no heartbeat, no TPDO
  EXPECT_GT(d.node.counters().ignored_off, 0U);

  d.node.power_on();
  const auto frames = d.step();
  ASSERT_FALSE(frames.empty());
  EXPECT_TRUE(is_frame(frames[0], 0x701, {0x00}));
  EXPECT_EQ(d.node.nmt_state(), NmtState::PreOperational);
  d.run(5ms);
  EXPECT_EQ(d.statusword(), 0x0240);  // Switch on disabled, remote
  EXPECT_EQ(d.value({0x1017, 0}), 0U);
  EXPECT_EQ(d.value({0x1A00, 0}), 1U);
  EXPECT_EQ(d.value({0x6040, 0}), 0U);
}

TEST(Faults, InjectedCauseOutlivesAPowerCycle) {
  Drive d(generic(1));
  d.boot();
  d.node.inject_fault(0x2310);
  d.run(5ms);
  d.node.power_off();
  d.node.power_on();
  d.step();
  const auto emcy = on_id(d.run(10ms), 0x81);
  ASSERT_EQ(emcy.size(), 1U);  // faulted again after the boot, reported in Pre-operational
  EXPECT_EQ(emcy[0].data[0], 0x10);
  EXPECT_EQ(emcy[0].data[1], 0x23);
  EXPECT_EQ(d.statusword() & 0x4F, 0x08);
}

TEST(Faults, SilentNodeHearsAndSaysNothingWhileItsTimersRun) {
  Drive d(generic(1));
  d.boot();
  ASSERT_EQ(d.write({0x1017, 0}, 0, 2), 0U);
  ASSERT_EQ(d.write({0x100C, 0}, 50, 2), 0U);
  ASSERT_EQ(d.write({0x100D, 0}, 2, 1), 0U);
  d.send(nmt(NmtCommand::Start, 1));
  ASSERT_EQ(on_id(d.send(rtr(0x701)), 0x701).size(), 1U);

  d.node.set_silent(true);
  std::vector<CanFrame> seen;
  for (int i = 0; i < 10; ++i) {  // the master keeps asking; the cable is cut
    const auto a = d.send(rtr(0x701));
    const auto b = d.send(make_frame(0x601, sdo_upload_request({0x1000, 0})));
    const auto c = d.run(20ms);
    seen.insert(seen.end(), a.begin(), a.end());
    seen.insert(seen.end(), b.begin(), b.end());
    seen.insert(seen.end(), c.begin(), c.end());
  }
  EXPECT_TRUE(seen.empty());
  EXPECT_EQ(d.node.counters().ignored_silent, 20U);
  EXPECT_GT(d.node.counters().discarded_silent, 0U);  // the life-guarding EMCY went nowhere
  EXPECT_EQ(d.node.drive().state(), core::AxisState::Fault);

  d.node.set_silent(false);
  EXPECT_EQ(d.read({0x1000, 0}).abort, 0U);
}

TEST(Faults, InjectedSdoAbortHitsOneRequest) {
  Drive d(generic(1));
  d.boot();
  d.node.inject_sdo_abort({0x1000, 0}, 0x08000000U);
  EXPECT_EQ(d.read({0x1018, 1}).abort, 0U);  // another object
  EXPECT_EQ(d.read({0x1000, 0}).abort, 0x08000000U);
  EXPECT_EQ(d.read({0x1000, 0}).abort, 0U);
}

TEST(Faults, DamagedFramesHaveAWrongLengthOrGarbage) {
  Drive d(generic(1));
  d.boot();
  d.node.damage_next(1, FrameDamage::WrongDlc);
  auto frames = on_id(d.send(make_frame(0x601, sdo_upload_request({0x1000, 0}))), 0x581);
  ASSERT_EQ(frames.size(), 1U);
  EXPECT_EQ(frames[0].dlc, 7);
  EXPECT_EQ(d.read({0x1000, 0}).frame.dlc, 8);  // one frame only

  d.node.damage_next(2, FrameDamage::Garbage);
  frames = on_id(d.send(make_frame(0x601, sdo_upload_request({0x1000, 0}))), 0x581);
  ASSERT_EQ(frames.size(), 1U);
  EXPECT_TRUE(is_frame(frames[0], 0x581, {0xBC, 0xFF, 0xEF, 0xFF, 0x6D, 0xFE, 0xFD, 0xFF}));  // ~43 00 10 00 92 01 02 00
  // The confirmation is spoiled too: ~60h has the abort specifier, with code FFFFFFFFh.
  EXPECT_EQ(d.write({0x1017, 0}, 0, 2), 0xFFFFFFFFU);
  EXPECT_EQ(d.node.counters().damaged, 3U);
}

}  // namespace
}  // namespace drivegate::canopen::sim::test
