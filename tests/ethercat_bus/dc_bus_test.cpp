// Distributed clocks in the EtherCAT bus (adapters/ethercat/bus_dc.hpp): generic CiA 402 drives
// with DC on the simulated line reach OP with SYNC0 running (1C32h:01 = 2, 0981h = 03h), follow
// csp set-points, keep the system time differences small; with distributed_clocks: false they run
// free; a power-cycled DC slave gets its offset, delay and SYNC0 again; nothing allocates per
// cycle with DC.
#include <gtest/gtest.h>

#include "tests/ethercat_bus/bus_harness.hpp"
#include "tests/support/alloc_counter.hpp"

namespace drivegate::ethercat::test {
namespace {

using core::AxisState;
using core::CommandKind;
using core::LinkState;
using core::Mode;
using core::ReplyStatus;

// Two generic drives (DC) around the I/O panel (no DC); 1 ms cycle.
const char* kDcLine = R"(gateway: { name: ecat-test }
buses:
  - name: ec0
    type: ethercat
    cycle_time: 1ms
    options: { transport: sim, lost_cycles: 3, boot_retry: 200ms, boot_retry_max: 1s, sync0_shift: 250us }
    io:
      - { name: panel, position: 2, vendor_id: 0x99, product_code: 0x1000, inputs: 2, outputs: 2 }
axes:
  - { name: a, bus: ec0, address: 1, device: generic-cia402, mechanics: { encoder_counts_per_rev: 4096 } }
  - { name: b, bus: ec0, address: 3, device: generic-cia402, mechanics: { encoder_counts_per_rev: 4096 } }
)";

// The line of kDcLine: generic drives at 1 and 3 whose clocks start apart and drift apart
// (EscConfig clock offset and ppm), hop delays of 300/450/520 ns.
struct DcHarness : EcatHarness {
  explicit DcHarness(const std::string& yaml = kDcLine, bool slave3_has_dc = true) : EcatHarness(yaml, false) {
    const auto& bp = plan.buses.at(0);
    for (const auto& ax : bp.axes) specs.push_back(ax.spec);
    auto memory = std::make_unique<MemoryLink>(64);
    link = memory.get();
    line = std::make_unique<sim::SimLine>(*link);
    esr.app = sim::make_cia402_slave("generic-cia402");  // slave 1 (the harness' "esr" slot)
    sim::EscConfig c1 = esr.app->esc_config();
    c1.clock_offset_ns = 4'000'000;
    c1.drift_ppm = 25.0;
    esr.esc = std::make_unique<sim::EscSlave>(c1, esr.app->sii(), esr.app.get());
    panel = std::make_unique<sim::GenericIoSlave>(2, 2, kPanelId);
    panel_esc = std::make_unique<sim::EscSlave>(sim::EscConfig{}, panel->sii(), panel.get());
    gen.app = sim::make_cia402_slave("generic-cia402");  // slave 3
    sim::EscConfig c3 = gen.app->esc_config();
    c3.clock_offset_ns = -7'500'000;
    c3.drift_ppm = -40.0;
    c3.dc_supported = slave3_has_dc;
    gen.esc = std::make_unique<sim::EscSlave>(c3, gen.app->sii(), gen.app.get());
    line->add(*esr.esc, 300);
    line->add(*panel_esc, 450);
    line->add(*gen.esc, 520);
    bus = std::make_unique<EthercatBus>(bp, std::move(memory), std::make_unique<LinePeer>(*line));
    runner = std::make_unique<core::BusRunner>(*bus, specs);
    bus->open(now);
    replies.reserve(4096);
    events.reserve(4096);
  }
  // Slave 3's system time minus slave 1's at the same line time (ground truth).
  std::int64_t true_difference() const {
    const auto t = static_cast<std::uint64_t>(core::to_ns(now));
    return static_cast<std::int64_t>(gen.esc->system_time(t) - esr.esc->system_time(t));
  }
};

void expect_completed(EcatHarness& h, core::CommandId id, core::Duration budget, const std::string& what) {
  ASSERT_EQ(h.wait_final(id, budget), ReplyStatus::Completed) << what << ": " << h.reason(id) << h.events_text()
                                                              << h.details();
}

TEST(EthercatBusDc, GenericDrivesReachOpWithSync0) {
  DcHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details() << h.events_text();
  EXPECT_EQ(h.bus->dc().line(), BusDcLine::Running);
  ASSERT_TRUE(h.bus->dc().reference().has_value());
  EXPECT_EQ(*h.bus->dc().reference(), 0U);
  EXPECT_EQ(h.bus->dc().verdict(0), BusDc::Verdict::Sync0);
  EXPECT_EQ(h.bus->dc().verdict(1), BusDc::Verdict::Free);  // the I/O panel: no DC asked for
  EXPECT_EQ(h.bus->dc().verdict(2), BusDc::Verdict::Sync0);
  // 1C32h:01 = 2 (DC SYNC0) written, SYNC0 running in both ESCs [ETG.1020].
  EXPECT_EQ(h.esr.app->sync_mode(), 2U);
  EXPECT_EQ(h.gen.app->sync_mode(), 2U);
  EXPECT_TRUE(h.esr.esc->sync0_running());
  EXPECT_TRUE(h.gen.esc->sync0_running());
  EXPECT_FALSE(h.panel_esc->sync0_running());
  // SYNC0 every cycle (1 ms) and 250 us after the grid: start = k * 1 ms + 250 us.
  const std::uint64_t start = h.bus->dc().sync0_start(2);
  EXPECT_EQ(start % 1'000'000U, 250'000U);
  EXPECT_EQ(h.bus->dc().sync0_start(0), start);
  EXPECT_EQ(core::get_u32(h.gen.esc->memory(), reg::kDcSync0CycleTime), 1'000'000U);
  EXPECT_NE(h.events_text().find("info: bus ec0: distributed clocks: reference clock slave 1 (0x1001), SYNC0 every "
                                 "1000000 ns (shift 250000 ns) on 2 slaves"),
            std::string::npos)
      << h.events_text();
  // Pulses come once the start time (100 ms lead) has passed, one per cycle.
  h.run_until([] { return false; }, 150ms);
  const auto pulses = h.gen.esc->sync0_pulses();
  h.run_until([] { return false; }, 100ms);
  EXPECT_NEAR(static_cast<double>(h.gen.esc->sync0_pulses() - pulses), 100.0, 1.0);
  EXPECT_EQ((h.gen.esc->last_sync0() - start) % 1'000'000U, 0U);
}

TEST(EthercatBusDc, SystemTimeDifferenceStaysSmallAndIsPublished) {
  DcHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details() << h.events_text();
  h.run_until([] { return false; }, 3s);
  // The clocks started 11.5 ms apart and drift 65 ppm apart; the offsets, the static drift
  // compensation and the cyclic FRMW keep them within a microsecond.
  EXPECT_LT(std::llabs(h.true_difference()), 1000) << h.true_difference();
  const std::int64_t d = h.bus->dc_max_difference_ns();
  EXPECT_GE(d, 0);
  EXPECT_LT(d, 1000);
  EXPECT_GE(h.bus->dc().cyclic().counters().difference_rounds, 2U);
  EXPECT_EQ(h.bus->dc().cyclic().counters().lost, 0U);
  EXPECT_GT(h.bus->dc().cyclic().counters().answered, 2000U);
  // The master's clock (virtual time + the base from open()) is the reference's within a cycle.
  EXPECT_LT(std::llabs(h.bus->dc_master_minus_reference_ns()), 1'000'000);
  // The same figures for the bus status (core::Bus::clock_sync, any thread).
  const core::ClockSync cs = h.bus->clock_sync();
  EXPECT_TRUE(cs.valid);
  EXPECT_EQ(cs.max_difference_ns, h.bus->dc_max_difference_ns());
  EXPECT_EQ(cs.master_minus_reference_ns, h.bus->dc_master_minus_reference_ns());
}

TEST(EthercatBusDc, CspSetpointsOnSync0) {
  DcHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details() << h.events_text();
  expect_completed(h, h.push("b", CommandKind::Enable), 3s, "enable");
  expect_completed(h, h.set_mode("b", Mode::CyclicPosition), 3s, "csp");
  double target = h.snap("b").position;
  for (int i = 0; i < 300; ++i) {
    target += 0.002;
    core::Setpoint sp;
    sp.axis = h.axis("b");
    sp.position = target;
    ASSERT_TRUE(h.runner->push_setpoint(sp));
    h.cycle();
  }
  h.run_until([] { return false; }, 50ms);
  EXPECT_NEAR(h.snap("b").position, target, 0.05);
  EXPECT_TRUE(h.gen.esc->sync0_running());
  expect_completed(h, h.push("b", CommandKind::Disable), 3s, "disable");
}

TEST(EthercatBusDc, DistributedClocksOffRunsFree) {
  std::string yaml = kDcLine;
  yaml.replace(yaml.find("sync0_shift: 250us"), std::string("sync0_shift: 250us").size(), "distributed_clocks: false");
  DcHarness h(yaml);
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details() << h.events_text();
  EXPECT_EQ(h.bus->dc().line(), BusDcLine::Off);
  EXPECT_EQ(h.bus->dc().verdict(0), BusDc::Verdict::Free);
  EXPECT_EQ(h.esr.app->sync_mode(), 0U);
  EXPECT_EQ(h.gen.app->sync_mode(), 0U);
  EXPECT_FALSE(h.esr.esc->sync0_running());
  EXPECT_FALSE(h.gen.esc->sync0_running());
  EXPECT_EQ(h.bus->dc_max_difference_ns(), -1);
  EXPECT_FALSE(h.bus->clock_sync().valid);  // the bus status shows no figure
  expect_completed(h, h.push("b", CommandKind::Enable), 3s, "enable");
}

// The ESR (no DC unit, distributed_clocks: false in its profile) next to a DC drive: the ESR runs
// free, the generic drive is the reference clock.
TEST(EthercatBusDc, EsrRunsFreeNextToADcDrive) {
  EcatHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details() << h.events_text();
  EXPECT_EQ(h.bus->dc().verdict(0), BusDc::Verdict::Free);
  EXPECT_EQ(h.bus->dc().verdict(2), BusDc::Verdict::Sync0);
  EXPECT_EQ(*h.bus->dc().reference(), 2U);
  EXPECT_FALSE(h.esr.esc->sync0_running());
  EXPECT_TRUE(h.gen.esc->sync0_running());
  EXPECT_EQ(h.gen.app->sync_mode(), 2U);
  // The reference clock is the only DC slave: no 092Ch to read, nothing differs once its time
  // comes back.
  EXPECT_EQ(h.bus->dc_max_difference_ns(), 0);
  EXPECT_TRUE(h.bus->clock_sync().valid);
}

// Slave 3 (not the reference) power-cycled: its DC registers are zero when it comes back; it gets
// offset, delay and SYNC0 again before SAFE-OP, on the common grid, while slave 1 keeps running.
TEST(EthercatBusDc, PowerCycledDcSlaveGetsSync0Again) {
  DcHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details() << h.events_text();
  const std::uint64_t start = h.bus->dc().sync0_start(2);
  h.line->power_off(2);
  ASSERT_TRUE(h.run_until([&] { return h.bus->link_state(h.axis("b")) == LinkState::Lost; }, 100ms)) << h.details();
  h.gen.app->power_cycle();
  h.line->power_on(2);
  EXPECT_FALSE(h.gen.esc->sync0_running());
  ASSERT_TRUE(h.run_until([&] { return h.up("b"); }, 5s)) << h.details() << h.events_text();
  EXPECT_EQ(h.bus->dc().rejoins(), 1U);
  EXPECT_TRUE(h.gen.esc->sync0_running());
  EXPECT_EQ(h.gen.app->sync_mode(), 2U);
  EXPECT_TRUE(h.esr.esc->sync0_running());
  // On the same grid: the new start time is the old one + k cycles.
  EXPECT_EQ((h.bus->dc().sync0_start(2) - start) % 1'000'000U, 0U);
  h.run_until([] { return false; }, 2s);
  EXPECT_LT(std::llabs(h.true_difference()), 1000) << h.true_difference();
  expect_completed(h, h.push("b", CommandKind::Enable), 3s, "enable after the restart");
}

// The reference clock (slave 1) power-cycled: its offset from the master's time, the others follow.
TEST(EthercatBusDc, PowerCycledReferenceClockGetsSync0Again) {
  DcHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details() << h.events_text();
  h.line->power_off(0);
  ASSERT_TRUE(h.run_until([&] { return h.bus->link_state(h.axis("a")) == LinkState::Lost; }, 100ms)) << h.details();
  h.esr.app->power_cycle();
  h.line->power_on(0);
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details() << h.events_text();
  EXPECT_TRUE(h.esr.esc->sync0_running());
  EXPECT_TRUE(h.gen.esc->sync0_running());
  h.run_until([] { return false; }, 2s);
  EXPECT_LT(std::llabs(h.true_difference()), 2000) << h.true_difference();
}

// Slave 3's ESC has no DC unit (0008h bit 2 clear) although its profile asks for SYNC0: one
// warning, it runs free (1C32h left at free run), slave 1 alone is synchronized.
TEST(EthercatBusDc, DcDriveWithoutDcUnitRunsFree) {
  DcHarness h(kDcLine, false);
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details() << h.events_text();
  EXPECT_EQ(h.bus->dc().verdict(0), BusDc::Verdict::Sync0);
  EXPECT_EQ(h.bus->dc().verdict(2), BusDc::Verdict::Free);
  EXPECT_TRUE(h.esr.esc->sync0_running());
  EXPECT_FALSE(h.gen.esc->sync0_running());
  EXPECT_EQ(h.gen.app->sync_mode(), 0U);
  EXPECT_NE(h.events_text().find("warning: bus ec0: slave 3 (0x1003): its device profile asks for distributed clocks, "
                                 "its ESC has none (0008h bit 2): it runs free"),
            std::string::npos)
      << h.events_text();
  EXPECT_NE(h.events_text().find("SYNC0 every 1000000 ns (shift 250000 ns) on 1 slave\n"), std::string::npos)
      << h.events_text();
}

// Records the first datagram of the first frame sent in each cycle, and passes every frame on to
// the line.
class FirstDatagramTap final : public FrameSink {
 public:
  explicit FirstDatagramTap(FrameSink& next) : next_(next) {}
  void on_frame(FrameView frame) noexcept override {
    // Ethernet header (14 bytes), EtherCAT header (2), then the first datagram: command, index,
    // ADP (u16), ADO (u16) [ETG.1000.4 §5.3 frame structure, §5.4 datagram].
    if (first_of_cycle && frame.size() >= 22) {
      command = frame[16];
      adp = core::get_u16(frame, 18);
      ado = core::get_u16(frame, 20);
      first_of_cycle = false;
    }
    next_.on_frame(frame);
  }
  bool first_of_cycle = false;
  std::uint8_t command = 0;
  std::uint16_t adp = 0, ado = 0;

 private:
  FrameSink& next_;
};

// Every cycle's first frame starts with the FRMW of the reference clock's system time (0910h at
// 0x1001; FRMW = 14 [ETG.1000.4 Table 12]), the slot bus_image_options() keeps for it.
TEST(EthercatBusDc, FrmwIsTheFirstDatagramOfEveryCycle) {
  DcHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details();
  FirstDatagramTap tap(*h.line);
  h.link->set_sink(&tap);
  for (int i = 0; i < 100; ++i) {
    tap.first_of_cycle = true;
    tap.command = 0;
    h.cycle();
    ASSERT_EQ(tap.command, static_cast<std::uint8_t>(Command::FRMW)) << "cycle " << i;
    ASSERT_EQ(tap.adp, 0x1001U);
    ASSERT_EQ(tap.ado, 0x0910U);
  }
  h.link->set_sink(h.line.get());
  EXPECT_TRUE(h.up("b"));
}

// With DC: the FRMW first in the frame and the 092Ch rounds, and still nothing allocates.
TEST(EthercatBusDc, NoAllocationPerCycleWithDc) {
  DcHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details();
  h.run_until([] { return false; }, 50ms);
  const auto answered = h.bus->dc().cyclic().counters().answered;
  const auto rounds = h.bus->dc().cyclic().counters().difference_rounds;
  {
    const drivegate::test::AllocationScope scope;
    for (int i = 0; i < 1200; ++i) {  // over a 092Ch round (every 1000 cycles)
      h.now += 1ms;
      h.runner->cycle(h.now);
    }
    EXPECT_EQ(scope.count(), 0U);
  }
  EXPECT_EQ(h.bus->dc().cyclic().counters().answered - answered, 1200U);
  EXPECT_GE(h.bus->dc().cyclic().counters().difference_rounds - rounds, 1U);
  EXPECT_EQ(h.bus->counters().errors, 0U);
}

}  // namespace
}  // namespace drivegate::ethercat::test
