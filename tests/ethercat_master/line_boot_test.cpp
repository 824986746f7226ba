// LineBoot against a scripted fake line (fake_line.hpp): count, reset, station addresses, SII read
// through the EEPROM interface (build_sii images), identity check, SM0/SM1 from the SII, PRE-OP,
// a refused SAFE-OP with AL status code 001Dh, identity mismatch, extra and missing slaves, a
// transition timeout and lost frames.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <vector>

#include "adapters/ethercat/master/line_boot.hpp"
#include "tests/ethercat_master/fake_line.hpp"

namespace drivegate::ethercat {
namespace {

using namespace std::chrono_literals;
using test::FakeEsc;
using test::FakeLine;

constexpr std::uint32_t kVendor = 0x0000000F;  // dunker-ethercat-coe.md §1: vendor "15"
constexpr std::uint32_t kProduct = 6755;

std::vector<std::uint8_t> image(std::uint32_t product, std::uint32_t revision, std::string_view name) {
  static const std::array<SiiSyncManager, 4> sms{{
      {0x1000, 128, 0x26, 0, 1, sii_sm_type::kMailboxOut},
      {0x1080, 128, 0x22, 0, 1, sii_sm_type::kMailboxIn},
      {0x1100, 0, 0x64, 0, 1, sii_sm_type::kOutputs},
      {0x1180, 0, 0x20, 0, 1, sii_sm_type::kInputs},
  }};
  SiiProfile p;
  p.header.identity = SiiIdentity{kVendor, product, revision, 1234};
  p.header.standard_mailbox = SiiMailbox{0x1000, 128, 0x1080, 128};
  p.header.mailbox_protocols = mailbox_protocol::kCoE;
  p.name = name;
  p.group = "Drive";
  p.sync_managers = sms;
  std::vector<std::uint8_t> out(2048);
  const auto r = build_sii(p, out);
  EXPECT_TRUE(r.ok()) << to_string(r.error);
  return out;
}

FakeLine line_of(std::size_t n) {
  FakeLine line;
  for (std::size_t i = 0; i < n; ++i) {
    FakeEsc esc;
    esc.sii = image(kProduct, 0x00010000, "ESR TrioDrive");
    line.slaves.push_back(std::move(esc));
  }
  return line;
}

const std::vector<ExpectedSlave> kThree{
    {kVendor, kProduct, 0x00010000, "ESR TrioDrive"},
    {kVendor, kProduct, 0x00010000, "ESR TrioDrive"},
    {kVendor, kProduct, 0, "ESR TrioDrive"},
};

struct Harness {
  FakeLine line;
  Transactions tx;
  std::unique_ptr<LineBoot> boot;
  core::TimePoint now{};
  std::function<bool(std::size_t)> drop;  // frame number -> lose it
  std::size_t frames = 0;

  Harness(FakeLine l, std::span<const ExpectedSlave> expected, LineBootConfig cfg = {})
      : line(std::move(l)), boot(std::make_unique<LineBoot>(expected, cfg)) {}

  void cycle() {
    boot->poll(now, tx);
    std::vector<std::vector<std::uint8_t>> out;
    for (const auto& f : tx.take_frames(now + 1ms)) out.emplace_back(f.begin(), f.end());
    for (auto& f : out) {
      line.process(f);
      if (!(drop && drop(frames++))) tx.on_frame(f);
    }
    now += 1ms;
    tx.expire(now);
  }
  // Runs until the boot is no longer running (or the slave transition finished).
  void run(int max_cycles = 20000) {
    for (int i = 0; i < max_cycles && boot->status() != LineStatus::Done && boot->status() != LineStatus::Failed;
         ++i) {
      cycle();
    }
  }
};

TEST(EthercatLineBoot, ThreeSlavesReachPreOp) {
  FakeLine line = line_of(3);
  line.slaves[1].sii_eight_bytes = true;  // 8-byte EEPROM reads
  line.slaves[2].sii_busy_reads = 2;      // busy twice after every read command
  line.slaves[0].al_delay_reads = 3;      // PRE-OP reached after a few status reads
  Harness h(std::move(line), kThree);
  h.boot->start(h.now);
  h.run();
  ASSERT_EQ(h.boot->status(), LineStatus::Done) << h.boot->line_text();
  EXPECT_TRUE(h.boot->ok());
  EXPECT_EQ(h.boot->slave_count(), 3U);
  EXPECT_TRUE(h.boot->line_text().empty()) << h.boot->line_text();
  for (std::size_t i = 0; i < 3; ++i) {
    const SlaveReport& r = h.boot->slave(i);
    EXPECT_EQ(r.status, SlaveStatus::Ready) << r.text.view();
    EXPECT_EQ(r.state, AlState::PreOp);
    EXPECT_EQ(r.station, 0x1001 + i);
    EXPECT_EQ(h.line.slaves[i].station(), 0x1001 + i);       // APWR 0010h = 1001h + position
    EXPECT_EQ(h.line.slaves[i].al_state(), 2);               // the ESC is in PRE-OP
    EXPECT_EQ(h.boot->sii(i).header.identity, (SiiIdentity{kVendor, kProduct, 0x00010000, 1234}));
    EXPECT_EQ(h.boot->sii(i).string(h.boot->sii(i).general.name_index), "ESR TrioDrive");
    // SM0/SM1 as the SII standard mailbox says, with the SyncM category's control bytes
    // [ETG.1000.4 Table 59: start, length, control, status, activate, PDI control].
    const std::vector<std::uint8_t> sms(h.line.slaves[i].mem.begin() + 0x0800, h.line.slaves[i].mem.begin() + 0x0810);
    EXPECT_EQ(sms, (std::vector<std::uint8_t>{0x00, 0x10, 0x80, 0x00, 0x26, 0x00, 0x01, 0x00,  //
                                              0x80, 0x10, 0x80, 0x00, 0x22, 0x00, 0x01, 0x00}));
    // The reset acknowledged INIT first, then PRE-OP was requested.
    ASSERT_GE(h.line.slaves[i].al_control_writes.size(), 2U);
    EXPECT_EQ(h.line.slaves[i].al_control_writes.front(), 0x0011);
    EXPECT_EQ(h.line.slaves[i].al_control_writes.back(), 0x0002);
  }
  // The reset also put the DC filter registers at their reset values.
  EXPECT_EQ(get_u16(h.line.slaves[0].mem, reg::kDcSpeedCounterStart), 0x1000);
  EXPECT_EQ(h.tx.counters().datagrams_lost, 0U);
}

TEST(EthercatLineBoot, ResetClearsSmsAndFmmusBeforeInitAndTakesTheEeprom) {
  FakeLine line = line_of(1);
  line.slaves[0].mem[0x0103] = 0x01;  // station alias enabled (DL control bit 24)
  line.slaves[0].mem[0x0500] = 0x01;  // EEPROM offered to the PDI
  Harness h(std::move(line), std::span<const ExpectedSlave>(kThree).first(1));
  h.boot->start(h.now);
  h.run();
  ASSERT_TRUE(h.boot->ok()) << h.boot->line_text();
  const FakeEsc& esc = h.line.slaves[0];
  // The reset frame's broadcast writes in order [ETG.1000.4 Tables 31, 47, 56, 59; §6 DC
  // registers; ETG.1000.6 §5.3.2], first two bytes of each (little-endian).
  const std::vector<std::pair<std::uint16_t, std::uint16_t>> reset(esc.writes.begin(), esc.writes.begin() + 12);
  EXPECT_EQ(reset, (std::vector<std::pair<std::uint16_t, std::uint16_t>>{
                       {0x0600, 0x0000}, {0x0800, 0x0000}, {0x0981, 0x00}, {0x0910, 0x0000}, {0x0920, 0x0000},
                       {0x0928, 0x0000}, {0x0930, 0x1000}, {0x0934, 0x0C00}, {0x0103, 0x00}, {0x0120, 0x0011},
                       {0x0500, 0x02}, {0x0500, 0x00}}));
  EXPECT_EQ(esc.mem[0x0934], 0x00);  // system time difference filter depth (SOEM: u16 0C00h)
  EXPECT_EQ(esc.mem[0x0935], 0x0C);  // speed counter filter depth
  EXPECT_EQ(esc.mem[0x0103], 0x00);
  EXPECT_EQ(esc.mem[0x0500], 0x00);
}

TEST(EthercatLineBoot, ResetWaitsUntilEverySlaveIsInInit) {
  // Slave 2 was left in SAFE-OP and takes a few status reads to get to INIT: nothing else may
  // start before it is there.
  FakeLine line = line_of(3);
  put_u16(line.slaves[1].mem, reg::kAlStatus, 0x0004);
  line.slaves[1].al_delay_reads = 5;
  Harness h(std::move(line), kThree);
  h.boot->start(h.now);
  h.run();
  ASSERT_EQ(h.boot->status(), LineStatus::Done) << h.boot->line_text();
  EXPECT_TRUE(h.boot->ok()) << h.boot->slave(1).text.view();
  for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(h.line.slaves[i].al_state(), 2);
  // The station addresses were written after every slave reported INIT.
  for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(h.line.slaves[i].state_when_addressed, 1) << i;
  EXPECT_EQ(h.line.slaves[1].al_control_writes, (std::vector<std::uint16_t>{0x0011, 0x0002}));
}

TEST(EthercatLineBoot, SlaveNotInInitAfterTheResetFailsTheLine) {
  FakeLine line = line_of(2);
  put_u16(line.slaves[1].mem, reg::kAlStatus, 0x0002);
  line.slaves[1].never_reach = true;
  LineBootConfig cfg;
  cfg.to_lower_state = 50ms;
  Harness h(std::move(line), std::span<const ExpectedSlave>(kThree).first(2), cfg);
  h.boot->start(h.now);
  const auto t0 = h.now;
  h.run();
  EXPECT_EQ(h.boot->status(), LineStatus::Failed);
  EXPECT_EQ(h.boot->line_text(),
            "reset: not every slave in INIT after 50 ms (BRD 0x0130: AL status 0x0003 OR-ed over 2 of 2 slaves)");
  EXPECT_LT(h.now - t0, 100ms);
  EXPECT_EQ(h.line.slaves[0].station(), 0);  // no station address written
}

TEST(EthercatLineBoot, EepromNackIsClearedAndTheReadGivenAgain) {
  FakeLine line = line_of(2);
  line.slaves[0].sii_nacks = 2;  // two reads not acknowledged, the third is
  line.slaves[1].sii_nacks = 1000;
  LineBootConfig cfg;
  Harness h(std::move(line), std::span<const ExpectedSlave>(kThree).first(2), cfg);
  h.boot->start(h.now);
  h.run();
  ASSERT_EQ(h.boot->status(), LineStatus::Done) << h.boot->line_text();
  EXPECT_EQ(h.boot->slave(0).status, SlaveStatus::Ready) << h.boot->slave(0).text.view();
  EXPECT_EQ(h.boot->slave(0).state, AlState::PreOp);
  // Each error cleared with a NOP (0502h = 0000h) before the read command again.
  const auto& w = h.line.slaves[0].writes;
  EXPECT_EQ(std::count(w.begin(), w.end(), std::pair<std::uint16_t, std::uint16_t>{0x0502, 0x0000}), 2);
  const SlaveReport& r = h.boot->slave(1);
  EXPECT_EQ(r.status, SlaveStatus::Failed);
  EXPECT_EQ(r.step, BootStep::Sii);
  EXPECT_EQ(r.text.view(),
            "slave 2 (0x1002, ESR TrioDrive): SII read of word 0x0000 failed 4 times (control 0x2000: the EEPROM did "
            "not acknowledge)");
}

TEST(EthercatLineBoot, RefusedSafeOpReportsTheAlStatusCodeAndAcknowledges) {
  FakeLine line = line_of(3);
  line.slaves[1].refuse[4] = 0x001D;
  Harness h(std::move(line), kThree);
  h.boot->start(h.now);
  h.run();
  ASSERT_TRUE(h.boot->ok());
  ASSERT_TRUE(h.boot->request_state(1, AlState::SafeOp, h.now));
  ASSERT_TRUE(h.boot->request_state(2, AlState::SafeOp, h.now));
  EXPECT_FALSE(h.boot->request_state(1, AlState::SafeOp, h.now));  // already busy
  h.run();
  const SlaveReport& r = h.boot->slave(1);
  EXPECT_EQ(r.status, SlaveStatus::Failed);
  EXPECT_EQ(r.step, BootStep::Transition);
  EXPECT_EQ(r.al_code, 0x001D);
  EXPECT_EQ(r.text.view(), "slave 2 (0x1002, ESR TrioDrive): PRE-OP -> SAFE-OP refused: 0x001D invalid output configuration");
  // Error acknowledged in the state the slave stayed in: AL control = PRE-OP | ack (0012h).
  EXPECT_EQ(h.line.slaves[1].al_control_writes.back(), 0x0012);
  EXPECT_EQ(h.line.slaves[1].mem[reg::kAlStatus], 0x02);
  EXPECT_EQ(h.boot->slave(2).status, SlaveStatus::Ready);
  EXPECT_EQ(h.boot->slave(2).state, AlState::SafeOp);
  EXPECT_EQ(h.line.slaves[2].al_state(), 4);
}

TEST(EthercatLineBoot, RefusedTransitionCanBeAskedAgain) {
  // After the refusal was acknowledged the slave can be asked again without a new start().
  FakeLine line = line_of(3);
  line.slaves[1].refuse[4] = 0x001D;
  Harness h(std::move(line), kThree);
  h.boot->start(h.now);
  h.run();
  ASSERT_TRUE(h.boot->ok());
  ASSERT_TRUE(h.boot->request_state(1, AlState::SafeOp, h.now));
  h.run();
  ASSERT_EQ(h.boot->slave(1).status, SlaveStatus::Failed);
  EXPECT_EQ(h.boot->slave(1).state, AlState::PreOp);
  EXPECT_EQ(h.boot->slave(1).al_code, 0x001D);  // kept in the report
  h.line.slaves[1].refuse.clear();              // the cause is mended
  ASSERT_TRUE(h.boot->request_state(1, AlState::SafeOp, h.now));
  h.run();
  const SlaveReport& r = h.boot->slave(1);
  EXPECT_EQ(r.status, SlaveStatus::Ready) << r.text.view();
  EXPECT_EQ(r.state, AlState::SafeOp);
  EXPECT_EQ(r.al_code, 0);
  EXPECT_TRUE(r.text.empty());
  EXPECT_EQ(h.line.slaves[1].al_state(), 4);
}

TEST(EthercatLineBoot, DownwardRequestFromAnErrorStateSucceeds) {
  // SAFE-OP with the error indication set (e.g. after an SM watchdog, AL status code 001Bh): a
  // request for INIT acknowledges with INIT | 10h [ETG.1000.6 §5.3.2] and reaches INIT.
  Harness h(line_of(1), std::span<const ExpectedSlave>(kThree).first(1));
  h.boot->start(h.now);
  h.run();
  ASSERT_TRUE(h.boot->ok());
  ASSERT_TRUE(h.boot->request_state(0, AlState::SafeOp, h.now));
  h.run();
  ASSERT_EQ(h.boot->slave(0).state, AlState::SafeOp);
  FakeEsc& esc = h.line.slaves[0];
  put_u16(esc.mem, reg::kAlStatus, 0x0014);      // SAFE-OP + error
  put_u16(esc.mem, reg::kAlStatusCode, 0x001B);  // sync manager watchdog
  const std::size_t writes = esc.al_control_writes.size();
  ASSERT_TRUE(h.boot->request_state(0, AlState::Init, h.now));
  h.run();
  const SlaveReport& r = h.boot->slave(0);
  EXPECT_EQ(r.status, SlaveStatus::Ready) << r.text.view();
  EXPECT_EQ(r.state, AlState::Init);
  EXPECT_EQ(esc.mem[reg::kAlStatus], 0x01);  // INIT, error cleared
  ASSERT_GT(esc.al_control_writes.size(), writes);
  EXPECT_EQ(esc.al_control_writes[writes], 0x0011);  // INIT + acknowledge
}

TEST(EthercatLineBoot, IdentityMismatchIsReportedWithBothIdentities) {
  FakeLine line = line_of(3);
  line.slaves[1].sii = image(6745, 0x00020000, "ESR MidiDrive");
  Harness h(std::move(line), kThree);
  h.boot->start(h.now);
  h.run();
  ASSERT_EQ(h.boot->status(), LineStatus::Done);
  EXPECT_FALSE(h.boot->ok());
  const SlaveReport& r = h.boot->slave(1);
  EXPECT_EQ(r.status, SlaveStatus::Failed);
  EXPECT_EQ(r.step, BootStep::Identity);
  EXPECT_TRUE(r.identity_mismatch());
  EXPECT_EQ(r.found.product_code, 6745U);
  EXPECT_EQ(r.text.view(),
            "slave 2 (0x1002, ESR TrioDrive): identity mismatch: expected vendor 0x0000000F product 0x00001A63 "
            "revision 0x00010000, found vendor 0x0000000F product 0x00001A59 revision 0x00020000");
  EXPECT_EQ(h.line.slaves[1].al_state(), 1);  // left in INIT
  EXPECT_EQ(h.boot->slave(0).state, AlState::PreOp);
  EXPECT_EQ(h.boot->slave(2).state, AlState::PreOp);
}

TEST(EthercatLineBoot, ExtraSlaveIsReportedAndLeftInInit) {
  FakeLine line = line_of(4);
  line.slaves[3].sii = image(0x44, 1, "EK1100");
  Harness h(std::move(line), kThree);
  h.boot->start(h.now);
  h.run();
  ASSERT_EQ(h.boot->status(), LineStatus::Done);
  EXPECT_FALSE(h.boot->ok());
  EXPECT_EQ(h.boot->slave_count(), 4U);
  const SlaveReport& r = h.boot->slave(3);
  EXPECT_EQ(r.status, SlaveStatus::Extra);
  EXPECT_EQ(r.text.view(),
            "slave 4 (0x1004, EK1100): not configured (vendor 0x0000000F product 0x00000044 revision 0x00000001), "
            "left in INIT");
  EXPECT_EQ(h.line.slaves[3].al_state(), 1);
  EXPECT_EQ(h.line.slaves[3].al_control_writes, (std::vector<std::uint16_t>{0x0011}));  // only the reset
  for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(h.boot->slave(i).state, AlState::PreOp);
}

TEST(EthercatLineBoot, MissingSlaveIsReported) {
  Harness h(line_of(2), kThree);
  h.boot->start(h.now);
  h.run();
  ASSERT_EQ(h.boot->status(), LineStatus::Done);
  EXPECT_FALSE(h.boot->ok());
  EXPECT_EQ(h.boot->missing(), 1U);
  EXPECT_EQ(h.boot->line_text(), "3 slave(s) configured, 2 found: position 2 and after missing");
}

TEST(EthercatLineBoot, TransitionTimeoutNamesTheStateTheSlaveStayedIn) {
  FakeLine line = line_of(1);
  line.slaves[0].never_reach = true;
  LineBootConfig cfg;
  cfg.init_to_preop = 50ms;
  Harness h(std::move(line), std::span<const ExpectedSlave>(kThree).first(1), cfg);
  h.boot->start(h.now);
  const auto t0 = h.now;
  h.run();
  const SlaveReport& r = h.boot->slave(0);
  EXPECT_EQ(r.status, SlaveStatus::Failed);
  EXPECT_EQ(r.text.view(), "slave 1 (0x1001, ESR TrioDrive): INIT -> PRE-OP timed out (AL status 0x0001 INIT)");
  EXPECT_LT(h.now - t0, 1s);
}

TEST(EthercatLineBoot, LostFramesAreRetried) {
  Harness h(line_of(3), kThree);
  h.drop = [](std::size_t n) { return n % 7 == 3; };
  h.boot->start(h.now);
  h.run();
  ASSERT_EQ(h.boot->status(), LineStatus::Done) << h.boot->line_text();
  EXPECT_TRUE(h.boot->ok()) << h.boot->slave(0).text.view() << h.boot->slave(1).text.view();
  EXPECT_GT(h.tx.counters().frames_lost, 0U);
}

TEST(EthercatLineBoot, RestartIgnoresAnswersOfTheEarlierRun) {
  // start() while the count of the first run is in flight; its answer (two slaves, the line has
  // changed since) comes back after the new run queued its own count.
  Harness h(line_of(3), kThree);
  h.boot->start(h.now);
  h.boot->poll(h.now, h.tx);
  std::vector<std::vector<std::uint8_t>> old;
  for (const auto& f : h.tx.take_frames(h.now + 10ms)) old.emplace_back(f.begin(), f.end());
  ASSERT_EQ(old.size(), 1U);
  h.boot->start(h.now);
  h.boot->poll(h.now, h.tx);
  std::vector<std::vector<std::uint8_t>> fresh;
  for (const auto& f : h.tx.take_frames(h.now + 10ms)) fresh.emplace_back(f.begin(), f.end());
  ASSERT_EQ(fresh.size(), 1U);
  FakeLine two = line_of(2);
  two.process(old[0]);
  h.line.process(fresh[0]);
  h.tx.on_frame(old[0]);
  h.tx.on_frame(fresh[0]);
  h.now += 1ms;
  h.run();
  ASSERT_EQ(h.boot->status(), LineStatus::Done) << h.boot->line_text();
  EXPECT_EQ(h.boot->slave_count(), 3U);
  EXPECT_TRUE(h.boot->ok());
}

TEST(EthercatLineBoot, EmptyLineFailsTheCount) {
  Harness h(line_of(0), kThree);
  h.boot->start(h.now);
  h.run();
  EXPECT_EQ(h.boot->status(), LineStatus::Failed);
  EXPECT_EQ(h.boot->line_text(), "count: no slave answered BRD 0x0000 (WKC 0)");
}

TEST(EthercatLineBoot, DisconnectedLineFailsAfterRetries) {
  Harness h(line_of(1), kThree);
  h.drop = [](std::size_t) { return true; };
  h.boot->start(h.now);
  h.run();
  EXPECT_EQ(h.boot->status(), LineStatus::Failed);
  EXPECT_EQ(h.boot->line_text(), "count: no answer to BRD 0x0000 (frame lost 4 times): is the line connected?");
}

// A line of 64 slaves (LineBoot::kMaxSlaves) boots: the per-slave records are allocated for the
// configured slaves by the constructor; stations 1001h..1040h [APWR 0010h = 1001h + position].
TEST(EthercatLineBoot, SixtyFourSlavesReachPreOp) {
  const std::vector<ExpectedSlave> expected(LineBoot::kMaxSlaves, ExpectedSlave{kVendor, kProduct, 0, "ESR TrioDrive"});
  Harness h(line_of(LineBoot::kMaxSlaves), expected);
  EXPECT_EQ(h.boot->capacity(), 64U);
  h.boot->start(h.now);
  h.run();
  ASSERT_EQ(h.boot->status(), LineStatus::Done) << h.boot->line_text();
  EXPECT_TRUE(h.boot->ok()) << h.boot->slave(0).text.view();
  EXPECT_EQ(h.boot->slave_count(), 64U);
  for (std::size_t i = 0; i < 64; ++i) {
    EXPECT_EQ(h.boot->slave(i).status, SlaveStatus::Ready) << i;
    EXPECT_EQ(h.line.slaves[i].station(), 0x1001 + i);
    EXPECT_EQ(h.line.slaves[i].al_state(), 2);
  }
  EXPECT_EQ(h.tx.counters().datagrams_lost, 0U);
}

// Capacity: the configured slaves + 8 extra, at least 16, at most 64. Extra slaves within it are
// reported and left in INIT; a line longer than it fails the count with the numbers.
TEST(EthercatLineBoot, CapacityIsTheConfiguredSlavesPlusSpare) {
  {
    Harness h(line_of(11), kThree);  // 3 configured: capacity 16, 8 extra slaves fit
    EXPECT_EQ(h.boot->capacity(), 16U);
    h.boot->start(h.now);
    h.run();
    ASSERT_EQ(h.boot->status(), LineStatus::Done) << h.boot->line_text();
    EXPECT_FALSE(h.boot->ok());
    EXPECT_EQ(h.boot->slave_count(), 11U);
    EXPECT_EQ(h.boot->slave(10).status, SlaveStatus::Extra);
  }
  {
    Harness h(line_of(17), kThree);
    h.boot->start(h.now);
    h.run();
    ASSERT_EQ(h.boot->status(), LineStatus::Failed);
    EXPECT_EQ(h.boot->line_text(), "count: 17 slaves on the line, at most 16 supported with 3 configured");
  }
  const std::vector<ExpectedSlave> forty(40, ExpectedSlave{kVendor, kProduct, 0, "ESR TrioDrive"});
  EXPECT_EQ(LineBoot(forty, {}).capacity(), 48U);
  const std::vector<ExpectedSlave> sixty(60, ExpectedSlave{kVendor, kProduct, 0, "ESR TrioDrive"});
  EXPECT_EQ(LineBoot(sixty, {}).capacity(), 64U);
}

}  // namespace
}  // namespace drivegate::ethercat
