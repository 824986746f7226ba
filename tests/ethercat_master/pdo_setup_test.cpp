// PdoSetup against simulated CoE drives (tests/ethercat_master/pdo_sim.hpp): the write sequence of
// the digest (§7.2, §7.4, TV-6), read-back, fixed mappings, ignored writes, a drive that ignores a
// mapping write, and the SM/FMMU/watchdog registers in the ESC afterwards.
#include <gtest/gtest.h>

#include <array>
#include <vector>

#include "adapters/ethercat/master/pdo_setup.hpp"
#include "adapters/ethercat/master/process_image.hpp"
#include "tests/ethercat_master/pdo_sim.hpp"

namespace drivegate::ethercat {
namespace {

using namespace std::chrono_literals;
using pdo_test::PdoLine;
using pdo_test::WriteLog;

// RxPDO 1600h: controlword, target position; TxPDO 1A00h: statusword, position actual (TV-1).
constexpr std::array<PdoEntryConfig, 2> kRxEntries{PdoEntryConfig{0x6040, 0, 16}, PdoEntryConfig{0x607A, 0, 32}};
constexpr std::array<PdoEntryConfig, 2> kTxEntries{PdoEntryConfig{0x6041, 0, 16}, PdoEntryConfig{0x6064, 0, 32}};
const std::array<PdoConfig, 1> kRx{PdoConfig{0x1600, kRxEntries}};
const std::array<PdoConfig, 1> kTx{PdoConfig{0x1A00, kTxEntries}};
// 6007h := 1 (digest quirk 6: fault on a lost master).
constexpr std::array<CoeStartupWrite, 1> kStartup{CoeStartupWrite{0x6007, 0, 1, 2}};

// Runs the set-up of drive `k` until it ends.
void run(PdoLine& t, PdoSetup& setup, std::size_t k, const PdoSetupConfig& cfg, const SlaveImage& image) {
  ASSERT_TRUE(setup.start(t.clients[k].get(), cfg, image, t.now)) << setup.text();
  for (int i = 0; i < 5000 && setup.status() == PdoSetupStatus::Running; ++i) {
    t.cycle([&](core::TimePoint now) { setup.poll(now, t.tx); });
  }
}

ProcessImage image_of(PdoLine& t, std::size_t drives, std::uint32_t out_bits, std::uint32_t in_bits) {
  std::vector<ImageSlave> s;
  for (std::size_t k = 0; k < drives; ++k) {
    s.push_back(image_slave_from_sii(t.boot->sii(k), static_cast<std::uint16_t>(0x1001 + k), out_bits, in_bits));
  }
  ProcessImage img;
  EXPECT_TRUE(img.build(s)) << img.text();
  return img;
}

TEST(PdoSetup, WritesTheMappingInTheDigestsOrderAndVerifiesIt) {
  PdoLine t(1, 0);
  t.preop();
  const ProcessImage img = image_of(t, 1, 48, 48);
  PdoSetup setup;
  PdoSetupConfig cfg;
  cfg.startup_writes = kStartup;
  cfg.rx_pdos = kRx;
  cfg.tx_pdos = kTx;
  cfg.sm_watchdog = 100ms;
  t.apps[0]->quirky.log.clear();
  run(t, setup, 0, cfg, img.slave(0));
  ASSERT_EQ(setup.status(), PdoSetupStatus::Done) << setup.text();
  EXPECT_EQ(setup.step(), PdoSetupStep::Finished);
  EXPECT_EQ(setup.warning_count(), 0U);

  // The writes as the drive saw them: TV-6 steps 1-14 with these entries, 6007h first.
  const std::vector<WriteLog> expected{
      {0x6007, 0, 1},
      {0x1C12, 0, 0}, {0x1600, 0, 0}, {0x1600, 1, 0x60400010}, {0x1600, 2, 0x607A0020}, {0x1600, 0, 2},
      {0x1C12, 1, 0x1600}, {0x1C12, 0, 1},
      {0x1C13, 0, 0}, {0x1A00, 0, 0}, {0x1A00, 1, 0x60410010}, {0x1A00, 2, 0x60640020}, {0x1A00, 0, 2},
      {0x1C13, 1, 0x1A00}, {0x1C13, 0, 1},
  };
  EXPECT_EQ(t.apps[0]->quirky.log, expected);
  EXPECT_EQ(setup.counters().sdo_writes, 15U);
  EXPECT_EQ(setup.counters().sdo_reads, 15U);
  EXPECT_EQ(setup.mapped_bits(2), 48U);
  EXPECT_EQ(setup.mapped_bits(3), 48U);
  EXPECT_EQ(t.apps[0]->output_size(), 6U);
  EXPECT_EQ(t.apps[0]->input_size(), 6U);

  // The registers in the ESC: SM2/SM3 (status and PDI control bytes are the slave's), FMMU0/1,
  // watchdog divider 2498 = 09C2h and 100 ms = 1000 ticks = 03E8h [digest §8.2].
  const auto mem = t.escs[0]->memory();
  const auto sm2 = encode_sm(img.slave(0).sm2);
  EXPECT_TRUE(std::equal(sm2.begin(), sm2.begin() + 5, mem.begin() + 0x0810));
  EXPECT_EQ(mem[0x0816], 0x01);
  const auto sm3 = encode_sm(img.slave(0).sm3);
  EXPECT_TRUE(std::equal(sm3.begin(), sm3.begin() + 5, mem.begin() + 0x0818));
  const auto f0 = encode_fmmu(img.slave(0).fmmu_outputs);
  EXPECT_TRUE(std::equal(f0.begin(), f0.begin() + 13, mem.begin() + 0x0600));
  const auto f1 = encode_fmmu(img.slave(0).fmmu_inputs);
  EXPECT_TRUE(std::equal(f1.begin(), f1.begin() + 13, mem.begin() + 0x0610));
  EXPECT_EQ(mem[0x0400], 0xC2);
  EXPECT_EQ(mem[0x0401], 0x09);
  EXPECT_EQ(mem[0x0420], 0xE8);
  EXPECT_EQ(mem[0x0421], 0x03);
  EXPECT_EQ(setup.counters().register_writes, 6U);
}

TEST(PdoSetup, AnIgnoredObjectThatReadsDifferentIsAWarning) {
  PdoLine t(1, 0);
  t.preop();
  const ProcessImage img = image_of(t, 1, 16, 16);  // default mapping kept
  const std::array<CoeStartupWrite, 2> writes{CoeStartupWrite{0x60C2, 1, 4, 1}, CoeStartupWrite{0x60C2, 2, 0xFE, 1}};
  const std::array<CoeObjectId, 1> ignored{CoeObjectId{0x60C2, 2}};
  PdoSetup setup;
  PdoSetupConfig cfg;
  cfg.startup_writes = writes;
  cfg.ignored_writes = ignored;
  cfg.map_pdos = false;
  run(t, setup, 0, cfg, img.slave(0));
  ASSERT_EQ(setup.status(), PdoSetupStatus::Done) << setup.text();
  ASSERT_EQ(setup.warning_count(), 1U);
  EXPECT_EQ(setup.warning(0),
            "slave 1 (0x1001): start-up write: 60C2h:02 reads 0xFD after writing 0xFE (listed as ignored by the drive)");

  // The same write, not listed as ignored: the set-up fails.
  PdoSetup strict;
  cfg.ignored_writes = {};
  run(t, strict, 0, cfg, img.slave(0));
  EXPECT_EQ(strict.status(), PdoSetupStatus::Failed);
  EXPECT_EQ(strict.step(), PdoSetupStep::StartupWrites);
  EXPECT_EQ(strict.text(),
            "slave 1 (0x1001): start-up write: 60C2h:02 reads 0xFD after writing 0xFE (the drive ignored the write)");
}

TEST(PdoSetup, ARefusedWriteThatAlreadyHoldsTheValueIsAccepted) {
  PdoLine t(1, 0);
  t.preop();
  // TxPDO 1A01h is fixed (read-only, 6041h:00/16); 1C13h:01 names it.
  auto& od = t.apps[0]->od;
  core::put_u16(od.value(0x1C13, 1), 0, 0x1A01);
  constexpr std::array<PdoEntryConfig, 1> fixed{PdoEntryConfig{0x6041, 0, 16}};
  const std::array<PdoConfig, 1> tx{PdoConfig{0x1A01, fixed}};
  const std::array<PdoConfig, 1> rx{PdoConfig{0x1600, std::span<const PdoEntryConfig>(kRxEntries).first(1)}};
  const ProcessImage img = image_of(t, 1, 16, 16);
  PdoSetup setup;
  PdoSetupConfig cfg;
  cfg.rx_pdos = rx;
  cfg.tx_pdos = tx;
  run(t, setup, 0, cfg, img.slave(0));
  ASSERT_EQ(setup.status(), PdoSetupStatus::Done) << setup.text();
  // 1A01h:00 := 0 (reads 1, the count the sequence ends with), 1A01h:01, 1A01h:00 := 1.
  EXPECT_EQ(setup.counters().refused_but_set, 3U);
  EXPECT_EQ(setup.warning_count(), 0U);

  // A refused write whose read-back differs fails with both values and the abort.
  constexpr std::array<PdoEntryConfig, 1> other{PdoEntryConfig{0x6064, 0, 32}};
  const std::array<PdoConfig, 1> tx2{PdoConfig{0x1A01, other}};
  cfg.tx_pdos = tx2;
  const ProcessImage img2 = image_of(t, 1, 16, 32);
  PdoSetup wrong;
  run(t, wrong, 0, cfg, img2.slave(0));
  EXPECT_EQ(wrong.status(), PdoSetupStatus::Failed);
  EXPECT_EQ(wrong.text(),
            "slave 1 (0x1001): PDO mapping: 1A01h:01 := 0x60640020 refused (0x06010002 attempt to write a read-only "
            "object); it reads 0x60410010");
}

TEST(PdoSetup, AMappingWriteTheDriveIgnoresFailsWithOneSentence) {
  PdoLine t(2, 0);
  t.preop();
  // Slave 2 takes writes to 1600h:03 without storing them; it holds 60710010h from before.
  t.apps[1]->quirky.ignored.push_back(WriteLog{0x1600, 3, 0});
  constexpr std::array<PdoEntryConfig, 3> entries{PdoEntryConfig{0x6040, 0, 16}, PdoEntryConfig{0x6060, 0, 16},
                                                  PdoEntryConfig{0x607A, 0, 32}};
  const std::array<PdoConfig, 1> rx{PdoConfig{0x1600, entries}};
  const ProcessImage img = image_of(t, 2, 64, 48);
  PdoSetup setup;
  PdoSetupConfig cfg;
  cfg.position = 1;
  cfg.rx_pdos = rx;
  cfg.tx_pdos = kTx;
  run(t, setup, 1, cfg, img.slave(1));
  EXPECT_EQ(setup.status(), PdoSetupStatus::Failed);
  EXPECT_EQ(setup.step(), PdoSetupStep::Assignment);
  EXPECT_EQ(setup.text(),
            "slave 2 (0x1002): PDO mapping: 1600h:03 reads 0x60710010 after writing 0x607A0020 (the drive ignored the write)");
  EXPECT_EQ(setup.counters().register_writes, 0U);  // nothing written to the ESC
}

TEST(PdoSetup, APlannedSizeThatDiffersFromTheMappingFails) {
  PdoLine t(1, 0);
  t.preop();
  const ProcessImage img = image_of(t, 1, 32, 48);  // the plan says 4 output bytes, the PDOs carry 6
  PdoSetup setup;
  PdoSetupConfig cfg;
  cfg.rx_pdos = kRx;
  cfg.tx_pdos = kTx;
  run(t, setup, 0, cfg, img.slave(0));
  EXPECT_EQ(setup.status(), PdoSetupStatus::Failed);
  EXPECT_EQ(setup.step(), PdoSetupStep::Verify);
  EXPECT_EQ(setup.text(),
            "slave 1 (0x1001): PDO mapping: SM2 carries 48 bits (6 bytes) after the mapping, the process image plans 4 bytes");
}

TEST(PdoSetup, ARestartFreesTheRequestItLeftRunning) {
  PdoLine t(1, 0);
  t.preop();
  const ProcessImage img = image_of(t, 1, 48, 48);
  PdoSetup setup;
  PdoSetupConfig cfg;
  cfg.rx_pdos = kRx;
  cfg.tx_pdos = kTx;
  ASSERT_TRUE(setup.start(t.clients[0].get(), cfg, img.slave(0), t.now));
  t.cycle([&](core::TimePoint now) { setup.poll(now, t.tx); });  // a download in flight
  ASSERT_FALSE(t.clients[0]->idle());
  run(t, setup, 0, cfg, img.slave(0));
  ASSERT_EQ(setup.status(), PdoSetupStatus::Done) << setup.text();
  for (int i = 0; i < 100 && !t.clients[0]->idle(); ++i) t.cycle([&](core::TimePoint now) { setup.poll(now, t.tx); });
  // Every request slot of the client is free again.
  std::array<CoeSdoId, CoeSdoClient::kQueueDepth> ids{};
  for (auto& id : ids) id = t.clients[0]->upload_value(0x6007, 0);
  EXPECT_TRUE(std::all_of(ids.begin(), ids.end(), [](CoeSdoId id) { return id != 0; }));
}

TEST(PdoSetup, ConfigurationErrorsAreRefusedAtStart) {
  PdoSetup setup;
  const SlaveImage image{};
  PdoSetupConfig cfg;
  cfg.startup_writes = kStartup;
  EXPECT_FALSE(setup.start(nullptr, cfg, image, core::TimePoint{}));
  EXPECT_EQ(setup.status(), PdoSetupStatus::Failed);
  EXPECT_EQ(setup.text(), "slave 1 (0x0000): process data set-up: CoE writes configured, but the slave has no mailbox");
  const std::array<CoeStartupWrite, 1> wide{CoeStartupWrite{0x2000, 0, 0, 8}};
  cfg.startup_writes = wide;
  PdoLine t(1, 0);
  t.preop();
  EXPECT_FALSE(setup.start(t.clients[0].get(), cfg, image, t.now));
  EXPECT_EQ(setup.text(), "slave 1 (0x0000): start-up write 2000h:00 has 8 bytes (1..4 supported)");
}

}  // namespace
}  // namespace drivegate::ethercat
