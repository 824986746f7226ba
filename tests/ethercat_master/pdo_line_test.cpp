// The whole process data path on a simulated line (two CoE drives and a generic I/O slave without
// mailbox): LineBoot to PRE-OP -> PdoSetup (mapping, SM2/SM3, FMMUs, SM watchdog) -> SAFE-OP ->
// cyclic LRW frames -> OP, outputs reaching the slaves and inputs coming back with the expected
// working counter; then a slave powered off, counted as working counter errors and found missing.
// Zero allocations per cycle.
#include <gtest/gtest.h>

#include <array>
#include <vector>

#include "adapters/ethercat/master/cyclic_exchange.hpp"
#include "adapters/ethercat/master/pdo_setup.hpp"
#include "adapters/ethercat/master/process_image.hpp"
#include "tests/ethercat_master/pdo_sim.hpp"
#include "tests/support/alloc_counter.hpp"

namespace drivegate::ethercat {
namespace {

using namespace std::chrono_literals;
using pdo_test::PdoLine;

// IP-mode image of the digest (TV-6): controlword + 60C1h:01 out, statusword + 6063h in.
constexpr std::array<PdoEntryConfig, 2> kRxEntries{PdoEntryConfig{0x6040, 0, 16}, PdoEntryConfig{0x60C1, 1, 32}};
constexpr std::array<PdoEntryConfig, 2> kTxEntries{PdoEntryConfig{0x6041, 0, 16}, PdoEntryConfig{0x6063, 0, 32}};
const std::array<PdoConfig, 1> kRx{PdoConfig{0x1600, kRxEntries}};
const std::array<PdoConfig, 1> kTx{PdoConfig{0x1A00, kTxEntries}};
constexpr std::array<CoeStartupWrite, 1> kStartup{CoeStartupWrite{0x6007, 0, 1, 2}};

struct Bring {
  PdoLine t{2, 1};
  ProcessImage img;
  std::array<PdoSetup, 3> setups{};

  // PRE-OP, the image, and every slave's set-up done.
  void configure(const ImageOptions& options = {}) {
    t.preop();
    const std::array<ImageSlave, 3> slaves{image_slave_from_sii(t.boot->sii(0), 0x1001, 48, 48),
                                           image_slave_from_sii(t.boot->sii(1), 0x1002, 48, 48),
                                           image_slave_from_sii(t.boot->sii(2), 0x1003, 16, 16)};
    ASSERT_TRUE(img.build(slaves, options)) << img.text();
    for (std::size_t k = 0; k < 3; ++k) {
      PdoSetupConfig cfg;
      cfg.position = static_cast<std::uint16_t>(k);
      cfg.sm_watchdog = 100ms;
      if (k < 2) {
        cfg.startup_writes = kStartup;
        cfg.rx_pdos = kRx;
        cfg.tx_pdos = kTx;
      } else {
        cfg.map_pdos = false;  // plain I/O: no mailbox, registers only
      }
      ASSERT_TRUE(setups[k].start(k < 2 ? t.clients[k].get() : nullptr, cfg, img.slave(k), t.now)) << setups[k].text();
    }
    auto running = [&] {
      return std::any_of(setups.begin(), setups.end(), [](const PdoSetup& s) { return s.status() == PdoSetupStatus::Running; });
    };
    for (int i = 0; i < 5000 && running(); ++i) {
      t.cycle([&](core::TimePoint now) {
        for (auto& s : setups) s.poll(now, t.tx);
      });
    }
    for (auto& s : setups) ASSERT_EQ(s.status(), PdoSetupStatus::Done) << s.text();
  }

  // Requests `state` of every slave and cycles (with the exchange) until they are there.
  void go(AlState state, CyclicExchange& cx) {
    for (std::size_t k = 0; k < 3; ++k) ASSERT_TRUE(t.boot->request_state(k, state, t.now)) << k;
    auto busy = [&] {
      for (std::size_t k = 0; k < 3; ++k) {
        if (t.boot->slave(k).status == SlaveStatus::Busy) return true;
      }
      return false;
    };
    for (int i = 0; i < 2000 && busy(); ++i) {
      t.cycle([&](core::TimePoint) { cx.queue(t.tx); });
    }
    for (std::size_t k = 0; k < 3; ++k) {
      ASSERT_EQ(t.boot->slave(k).status, SlaveStatus::Ready) << t.boot->slave(k).text.view();
      ASSERT_EQ(t.escs[k]->state(), state) << k;
    }
  }
  void cycles(CyclicExchange& cx, int n) {
    for (int i = 0; i < n; ++i) t.cycle([&](core::TimePoint) { cx.queue(t.tx); });
  }
};

TEST(PdoLine, BootMapSafeOpCyclicOpAndAPoweredOffSlave) {
  Bring b;
  b.configure();
  if (HasFatalFailure()) return;
  EXPECT_EQ(b.img.size(), 28U);        // 6 + 6 | 6 + 6 | 2 + 2
  EXPECT_EQ(b.img.expected_wkc(), 9);  // 3 per slave

  // Inputs the slaves publish: TV-7 (statusword 0027h, 6063h = 100000), and two I/O bytes.
  const std::array<std::uint8_t, 6> drive_in{0x27, 0x00, 0xA0, 0x86, 0x01, 0x00};
  std::copy(drive_in.begin(), drive_in.end(), b.t.apps[0]->inputs.begin());
  b.t.apps[1]->inputs[0] = 0x37;
  b.t.ios_[0]->inputs()[0] = 0xA5;
  b.t.ios_[0]->inputs()[1] = 0x5A;

  CyclicExchange cx(b.img);
  b.go(AlState::SafeOp, cx);
  if (HasFatalFailure()) return;
  // SAFE-OP: inputs valid, outputs ignored by the slaves (digest §5).
  const std::uint64_t before = cx.counters().wkc_errors + cx.counters().lost;
  b.cycles(cx, 5);
  EXPECT_EQ(cx.counters().wkc_errors + cx.counters().lost, before);  // none since every slave reached SAFE-OP
  EXPECT_TRUE(cx.last_cycle_good());
  EXPECT_EQ(cx.counters().last_wkc, 9);
  EXPECT_TRUE(std::equal(drive_in.begin(), drive_in.end(), cx.inputs(0).begin()));
  EXPECT_EQ(cx.inputs(1)[0], 0x37);
  EXPECT_EQ(cx.inputs(2)[0], 0xA5);
  EXPECT_EQ(cx.inputs(2)[1], 0x5A);

  // Outputs primed before OP (digest step 7): TV-7 "1F 00 45 23 01 00", and two I/O bytes.
  const std::array<std::uint8_t, 6> drive_out{0x1F, 0x00, 0x45, 0x23, 0x01, 0x00};
  std::copy(drive_out.begin(), drive_out.end(), cx.outputs(0).begin());
  cx.outputs(1)[0] = 0x06;
  cx.outputs(2)[0] = 0x12;
  cx.outputs(2)[1] = 0x34;
  b.cycles(cx, 3);
  EXPECT_EQ(b.t.apps[0]->outputs[0], 0);  // SAFE-OP: not applied
  b.go(AlState::Op, cx);
  if (HasFatalFailure()) return;
  b.cycles(cx, 5);
  EXPECT_TRUE(std::equal(drive_out.begin(), drive_out.end(), b.t.apps[0]->outputs.begin()));
  EXPECT_EQ(b.t.apps[1]->outputs[0], 0x06);
  EXPECT_EQ(b.t.ios_[0]->outputs()[0], 0x12);
  EXPECT_EQ(b.t.ios_[0]->outputs()[1], 0x34);
  EXPECT_EQ(cx.counters().wkc_errors + cx.counters().lost, before);
  EXPECT_EQ(cx.counters().last_wkc, 9);
  for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ(cx.answered(k), SlaveAnswer::Answered) << k;

  // Zero allocations per cycle: the exchange, Transactions, the link and the simulated line.
  {
    const drivegate::test::AllocationScope scope;
    b.cycles(cx, 100);
    EXPECT_EQ(scope.count(), 0U);
  }
  EXPECT_EQ(cx.counters().wkc_errors + cx.counters().lost, before);

  // The I/O slave loses power: the LRW comes back 3 short every cycle; its AL status check gets
  // no answer, so it is Missing while the drives answer theirs.
  b.t.line.power_off(2);
  const std::uint64_t errors = cx.counters().wkc_errors;
  const std::uint64_t cycles = cx.counters().completed;
  b.cycles(cx, 10);
  EXPECT_EQ(cx.counters().wkc_errors - errors, cx.counters().completed - cycles);
  EXPECT_EQ(cx.counters().wkc_errors - errors, 10U);
  EXPECT_EQ(cx.counters().last_wkc, 6);
  EXPECT_FALSE(cx.last_cycle_good());
  EXPECT_EQ(cx.answered(2), SlaveAnswer::Missing);
  EXPECT_EQ(cx.answered(0), SlaveAnswer::Answered);
  EXPECT_EQ(cx.answered(1), SlaveAnswer::Answered);
  EXPECT_GT(cx.counters().al_missing, 0U);
  // The I/O inputs stay the last good ones.
  EXPECT_EQ(cx.inputs(2)[0], 0xA5);
  EXPECT_EQ(b.t.escs[0]->state(), AlState::Op);
}

TEST(PdoLine, PerSlaveDatagramsTellWhichSlaveIsMissing) {
  Bring b;
  b.configure(ImageOptions{0, CyclicDatagrams::PerSlave, 1, 2});
  if (HasFatalFailure()) return;
  ASSERT_EQ(b.img.datagrams().size(), 3U);
  CyclicExchange cx(b.img, CyclicOptions{false});
  b.go(AlState::SafeOp, cx);
  if (HasFatalFailure()) return;
  b.go(AlState::Op, cx);
  if (HasFatalFailure()) return;
  b.cycles(cx, 3);
  EXPECT_TRUE(cx.last_cycle_good());
  // Two frames dropped on the line: two lost cycles, not working counter errors; the inputs stay.
  const CyclicCounters c0 = cx.counters();
  b.t.line.drop_next(2);
  b.cycles(cx, 4);
  EXPECT_EQ(cx.counters().lost - c0.lost, 2U);
  EXPECT_EQ(cx.counters().wkc_errors, c0.wkc_errors);
  EXPECT_EQ(cx.counters().good - c0.good, 2U);
  EXPECT_TRUE(cx.last_cycle_good());
  b.t.line.power_off(1);  // slave 2 and everything behind it
  b.cycles(cx, 3);
  EXPECT_EQ(cx.answered(0), SlaveAnswer::Answered);
  EXPECT_EQ(cx.answered(1), SlaveAnswer::Missing);
  EXPECT_EQ(cx.answered(2), SlaveAnswer::Missing);
  EXPECT_EQ(cx.counters().last_wkc, 3);
  EXPECT_EQ(cx.counters().al_checks, 0U);
}

// An AL status check whose answer comes a cycle late (a loaded machine, a slow line) is not
// taken for its slave's status: until it is back, each slave's record is the check before it,
// cycle and status together. A record with the new cycle and the old check's SAFE-OP made the
// bus take a slave that had just gone to OP for one that left it.
TEST(PdoLine, AnAlCheckInFlightLeavesTheLastAnsweredOne) {
  Bring b;
  b.configure();
  if (HasFatalFailure()) return;
  CyclicExchange cx(b.img);
  b.go(AlState::SafeOp, cx);
  if (HasFatalFailure()) return;
  b.cycles(cx, 3);  // every slave checked in SAFE-OP
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_TRUE(cx.al_check(k).answered) << k;
    EXPECT_EQ(cx.al_check(k).status().state(), AlState::SafeOp) << k;
  }
  b.go(AlState::Op, cx);
  if (HasFatalFailure()) return;

  // This cycle's frame is queued, not yet back.
  ASSERT_TRUE(cx.queue(b.t.tx));
  const std::uint64_t in_flight = cx.counters().cycles;
  for (std::size_t k = 0; k < 3; ++k) EXPECT_LT(cx.al_check(k).cycle, in_flight) << k;

  b.t.cycle();  // the frame passes the line and comes back
  std::size_t checked = 0;
  for (std::size_t k = 0; k < 3; ++k) {
    const SlaveAlCheck& c = cx.al_check(k);
    if (c.cycle != in_flight) continue;
    ++checked;
    EXPECT_TRUE(c.answered) << k;
    EXPECT_EQ(c.status().state(), AlState::Op) << k;
  }
  EXPECT_EQ(checked, 1U);  // one slave per cycle, round robin
}

}  // namespace
}  // namespace drivegate::ethercat
