// The master's DC engines (adapters/ethercat/master/dc.hpp) against a simulated line: three DC
// slaves with known per-hop delays, clock offsets and drifts, and a slave without DC between the
// first two. Checks: the delays found are the configured ones, the offsets written make the system
// times agree, static drift compensation and the cyclic FRMW keep the system time differences
// small, SYNC0 registers as computed and pulses on the common grid, the non-DC slave skipped,
// failures with their texts, no allocation in the cycle.
#include <gtest/gtest.h>

#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "adapters/ethercat/master/dc.hpp"
#include "adapters/ethercat/master/transactions.hpp"
#include "core/clock.hpp"
#include "tests/ethercat_sim/harness.hpp"
#include "tests/support/alloc_counter.hpp"
#include "tests/ethercat_sim/line_exchange.hpp"

namespace drivegate::ethercat::sim {
namespace {

using namespace std::chrono_literals;
using test::Bus;

// A slave application that only records SYNC0 (no process data).
class Sync0Recorder final : public SlaveApplication {
 public:
  std::size_t output_size() const noexcept override { return 0; }
  std::size_t input_size() const noexcept override { return 0; }
  void exchange(std::span<const std::uint8_t>, std::span<std::uint8_t>, AlState, std::uint64_t) noexcept override {}
  void on_sync0(std::uint64_t pulse_ns, std::uint64_t /*now_ns*/) noexcept override {
    last = pulse_ns;
    ++calls;
  }
  std::uint64_t last = 0;
  std::uint64_t calls = 0;
};

// Position: hop into it (ns), DC?, clock offset (ns), drift (ppm).
struct SlaveSpec {
  std::uint32_t hop_ns;
  bool dc;
  std::int64_t offset_ns;
  double drift_ppm;
};
constexpr std::array<SlaveSpec, 4> kSpecs{{
    {250, true, 3'000'000, 20.0},      // reference clock
    {400, false, 0, 0.0},              // no DC
    {330, true, -1'500'000, -35.0},
    {510, true, 12'345'678, 60.0},
}};
constexpr std::uint32_t kCycleNs = 1'000'000;
// Nanoseconds since 2000 at the start of the line's time: about 2024.
constexpr std::int64_t kBase = 760'000'000'000'000'000;

struct DcLine {
  DcLine() {
    for (const SlaveSpec& spec : kSpecs) {
      ios.push_back(std::make_unique<GenericIoSlave>(1, 1, SiiIdentity{1, 2, 3, 4}));
      apps.push_back(std::make_unique<Sync0Recorder>());
      EscConfig cfg;
      cfg.dc_supported = spec.dc;
      cfg.clock_offset_ns = spec.offset_ns;
      cfg.drift_ppm = spec.drift_ppm;
      escs.push_back(std::make_unique<EscSlave>(cfg, ios.back()->sii(), apps.back().get()));
      bus.line().add(*escs.back(), spec.hop_ns);
    }
    bus.line().set_time(static_cast<std::uint64_t>(core::to_ns(now)));
    bus.assign_addresses(kSpecs.size());
  }
  // What the line start-up would have read: features 0008h and DL status 0110h per slave.
  std::vector<DcSlaveInfo> infos(std::uint32_t cycle = kCycleNs) const {
    std::vector<DcSlaveInfo> v;
    for (std::size_t k = 0; k < escs.size(); ++k) {
      const auto mem = escs[k]->memory();
      const auto features = get_u16(mem, reg::kEscFeatures);
      const bool dc = features_dc(features);
      v.push_back(DcSlaveInfo{Bus::station(k), dc, features_dc_64bit(features), open_ports(get_u16(mem, reg::kDlStatus)),
                              dc ? cycle : 0U, 0});
    }
    return v;
  }
  // One master cycle: the engines queue (DcCyclic first), the frames pass the line, the answers
  // come back; then 1 ms passes.
  void cycle() {
    if (cyclic.configured()) cyclic.poll(now, tx);
    if (setup) setup->poll(now, tx);
    drivegate::ethercat::test::exchange_over_line(tx, bus.link(), bus.line(), now);
    bus.line().advance(static_cast<std::uint64_t>(core::to_ns(now)));
  }
  void run_setup(int max_cycles = 5000) {
    setup->start(now);
    for (int i = 0; i < max_cycles && setup->status() == DcSetupStatus::Running; ++i) cycle();
  }
  // The system time of slave k minus the reference's at the same line time (ground truth).
  std::int64_t true_difference(std::size_t k) const {
    const auto t = static_cast<std::uint64_t>(core::to_ns(now));
    return static_cast<std::int64_t>(escs[k]->system_time(t) - escs[0]->system_time(t));
  }
  std::int32_t register_difference(std::size_t k) const {
    return decode_system_time_difference(get_u32(escs[k]->memory(), reg::kDcSystemTimeDifference));
  }

  Bus bus;
  std::vector<std::unique_ptr<GenericIoSlave>> ios;
  std::vector<std::unique_ptr<Sync0Recorder>> apps;
  std::vector<std::unique_ptr<EscSlave>> escs;
  Transactions tx;
  std::unique_ptr<DcSetup> setup;
  DcCyclic cyclic;
  core::TimePoint now{10s};
};

DcConfig config() {
  DcConfig c;
  c.system_time_base_ns = kBase;
  return c;
}

TEST(EthercatSimDcMaster, SetupSynchronizesALineWithANonDcSlaveInTheMiddle) {
  DcLine l;
  const auto infos = l.infos();
  EXPECT_FALSE(infos[1].dc);
  EXPECT_EQ(infos[0].open_ports, 0x03);
  EXPECT_EQ(infos[3].open_ports, 0x01);
  l.setup = std::make_unique<DcSetup>(infos, config());
  l.setup->start(l.now);
  // Run to the static drift step: the offsets are written; the system times already agree to
  // within what the drift added since the latch (a few ms at most 95 ppm apart).
  for (int i = 0; i < 100 && l.setup->step() != DcStep::StaticDrift; ++i) l.cycle();
  ASSERT_EQ(l.setup->step(), DcStep::StaticDrift) << l.setup->line_text();
  EXPECT_LT(std::llabs(l.true_difference(2)), 1'000);
  EXPECT_LT(std::llabs(l.true_difference(3)), 1'000);
  for (int i = 0; i < 5000 && l.setup->status() == DcSetupStatus::Running; ++i) l.cycle();
  ASSERT_EQ(l.setup->status(), DcSetupStatus::Done) << l.setup->line_text();
  for (std::size_t k = 0; k < 4; ++k) EXPECT_TRUE(l.setup->slave(k).text.empty()) << l.setup->slave(k).text.view();
  EXPECT_TRUE(l.setup->ok());
  ASSERT_EQ(l.setup->reference(), std::optional<std::size_t>(0));
  EXPECT_EQ(l.setup->reference_station(), 0x1001);
  EXPECT_EQ(l.setup->drift_answered(), 15000U);
  EXPECT_EQ(l.setup->drift_lost(), 0U);

  // The non-DC slave is skipped: nothing was written to it.
  EXPECT_EQ(l.setup->slave(1).status, DcSlaveStatus::NotDc);
  EXPECT_EQ(get_u64(l.escs[1]->memory(), reg::kDcSystemTimeOffset), 0U);

  // Delays from the reference: 400 + 330 = 730 ns to position 2, + 510 = 1240 ns to position 3
  // (round trips behind each slave are 2·(sum of the hops after it), measured on drifting clocks:
  // a ns of tolerance).
  EXPECT_EQ(l.setup->slave(0).delay_ns, 0U);
  EXPECT_NEAR(l.setup->slave(2).delay_ns, 730, 1);
  EXPECT_NEAR(l.setup->slave(3).delay_ns, 1240, 1);
  EXPECT_NEAR(l.setup->slave(0).round_trip_ns, 2 * (400 + 330 + 510), 1);
  EXPECT_EQ(l.setup->slave(3).round_trip_ns, 0U);
  for (const std::size_t k : {0U, 2U, 3U}) {
    const DcSlaveReport& r = l.setup->slave(k);
    EXPECT_EQ(r.status, DcSlaveStatus::Synchronized) << k;
    // Offset and delay as written, byte for byte in 0920h..092Bh.
    EXPECT_EQ(get_u64(l.escs[k]->memory(), reg::kDcSystemTimeOffset), r.offset_ns) << k;
    EXPECT_EQ(get_u32(l.escs[k]->memory(), reg::kDcSystemTimeDelay), r.delay_ns) << k;
  }

  // After static drift compensation: the slaves follow the reference within 100 ns, by their
  // own 092Ch and by the simulation's ground truth.
  for (const std::size_t k : {2U, 3U}) {
    EXPECT_LT(std::abs(l.register_difference(k)), 100) << k;
    EXPECT_LT(std::llabs(l.true_difference(k)), 100) << k;
    // The loop found the drift to the reference (+20 ppm): -35 - 20 and 60 - 20 ppm, corrected.
    const double expected = -(kSpecs[k].drift_ppm - kSpecs[0].drift_ppm);
    EXPECT_NEAR(l.escs[k]->dc_clock().frequency_ppm(), expected, 1.0) << k;
  }

  // SYNC0: start = reference time read + 100 ms rounded up to the 1 ms cycle; the registers as the
  // slave holds them: 0981h = 03h, 09A0h = 1 000 000 = 40 42 0F 00, 0990h = the start time (no
  // pulse yet: the next pulse is the first).
  const std::uint64_t start = l.setup->slave(0).sync0_start;
  EXPECT_EQ(start, (l.setup->reference_time() + 100'000'000 + kCycleNs - 1) / kCycleNs * kCycleNs);
  EXPECT_EQ(start % kCycleNs, 0U);
  for (const std::size_t k : {0U, 2U, 3U}) {
    const auto mem = l.escs[k]->memory();
    EXPECT_EQ(l.setup->slave(k).sync0_start, start) << k;
    EXPECT_EQ(mem[reg::kDcCyclicUnitControl], 0x00) << k;
    EXPECT_EQ(mem[reg::kDcActivation], 0x03) << k;
    EXPECT_EQ(mem[reg::kDcActivationStatus], 0x01) << k;  // first pulse pending
    const std::array<std::uint8_t, 4> cycle{0x40, 0x42, 0x0F, 0x00};
    EXPECT_TRUE(std::equal(cycle.begin(), cycle.end(), mem.begin() + reg::kDcSync0CycleTime)) << k;
    std::array<std::uint8_t, 8> start_bytes{};
    put_u64(start_bytes, 0, start);
    EXPECT_TRUE(std::equal(start_bytes.begin(), start_bytes.end(), mem.begin() + reg::kDcSync0StartTime)) << k;
    EXPECT_TRUE(l.escs[k]->sync0_running()) << k;
  }
  EXPECT_FALSE(l.escs[1]->sync0_running());
}

TEST(EthercatSimDcMaster, CyclicDriftCompensationConvergesAndSync0RunsOnOneGrid) {
  DcLine l;
  l.setup = std::make_unique<DcSetup>(l.infos(), config());
  l.run_setup();
  ASSERT_TRUE(l.setup->ok()) << l.setup->line_text();
  DcCyclicConfig cc;
  cc.system_time_base_ns = kBase;
  cc.difference_every = 50;
  ASSERT_TRUE(l.cyclic.configure(*l.setup, cc));
  EXPECT_EQ(l.cyclic.station_count(), 3U);  // the non-DC slave is not read

  std::uint64_t previous = 0;
  std::uint32_t worst_late = 0;
  for (int i = 0; i < 3000; ++i) {
    l.cycle();
    ASSERT_TRUE(l.cyclic.has_reference_time());
    if (previous != 0) {
      // The reference time advances one cycle per cycle, at the reference's rate (+20 ppm).
      EXPECT_NEAR(static_cast<double>(l.cyclic.reference_time() - previous), 1'000'020.0, 2.0);
    }
    previous = l.cyclic.reference_time();
    if (i >= 1000) {
      worst_late = std::max(worst_late, l.cyclic.max_abs_difference_ns());
      for (const std::size_t k : {2U, 3U}) ASSERT_LT(std::llabs(l.true_difference(k)), 20) << k << " cycle " << i;
    }
  }
  EXPECT_EQ(l.cyclic.counters().answered, 3000U);
  EXPECT_EQ(l.cyclic.counters().lost, 0U);
  EXPECT_EQ(l.cyclic.last_wkc(), 4);  // reference reads, the three others write (the non-DC one too)
  EXPECT_EQ(l.cyclic.counters().difference_rounds, 60U);
  EXPECT_TRUE(l.cyclic.difference_valid());
  EXPECT_LT(worst_late, 20U);
  EXPECT_EQ(l.cyclic.difference_ns(0), 0);  // the reference compares with nobody
  // The master's clock against the reference's: the reference runs 20 ppm fast, so after 3 s of
  // cycles plus the setup the reference is ahead by about 20 ppm of the time since the latch.
  EXPECT_LT(l.cyclic.master_minus_reference_ns(), 0);

  // SYNC0 pulses ran on every DC slave on the same grid (start + k·cycle) and reached the
  // application hook; the last pulse is the same system time everywhere.
  const std::uint64_t start = l.setup->slave(0).sync0_start;
  const std::uint64_t last = l.escs[0]->last_sync0();
  EXPECT_GT(l.escs[0]->sync0_pulses(), 2800U);
  EXPECT_EQ((last - start) % kCycleNs, 0U);
  for (const std::size_t k : {0U, 2U, 3U}) {
    EXPECT_EQ(l.escs[k]->last_sync0(), last) << k;
    EXPECT_EQ(l.apps[k]->last, last) << k;
    EXPECT_GT(l.apps[k]->calls, 2800U) << k;
    // 0990h reads the next pulse.
    EXPECT_EQ(get_u64(l.escs[k]->memory(), reg::kDcSync0StartTime), last + kCycleNs) << k;
  }
  EXPECT_EQ(l.apps[1]->calls, 0U);
  // The reference time lies in the SYNC0 cycle where the cyclic frame passes: fixed here (cycles
  // start on the line's whole ms).
  EXPECT_LT(DcCyclic::sync0_phase(l.cyclic.reference_time(), start, kCycleNs), kCycleNs);

  // Zero allocation in the cycle (DcCyclic + Transactions + the simulated line).
  drivegate::test::AllocationScope scope;
  for (int i = 0; i < 200; ++i) l.cycle();
  EXPECT_EQ(scope.count(), 0U);
}

TEST(EthercatSimDcMaster, ThirtyTwoBitReferenceIsExtended) {
  // A 32-bit DC reference: FRMW of 4 bytes, the master extends the time across the 4.29 s wrap.
  Bus bus;
  GenericIoSlave io(1, 1, SiiIdentity{1, 2, 3, 4});
  EscConfig cfg;
  cfg.dc_supported = true;
  cfg.dc_64bit = false;
  EscSlave esc(cfg, io.sii(), &io);
  EscConfig cfg2;
  cfg2.dc_supported = true;
  EscSlave esc2(cfg2, io.sii(), &io);
  bus.line().add(esc);
  bus.line().add(esc2);
  bus.assign_addresses(2);
  const std::array<DcSlaveInfo, 2> infos{{{0x1001, true, false, 0x03, kCycleNs, 0}, {0x1002, true, true, 0x01, 0, 0}}};
  DcConfig c = config();
  c.static_drift_datagrams = 300;
  DcSetup setup(infos, c);
  Transactions tx;
  DcCyclic cyclic;
  core::TimePoint now{1s};
  const auto cycle = [&] {
    if (cyclic.configured()) cyclic.poll(now, tx);
    setup.poll(now, tx);
    drivegate::ethercat::test::exchange_over_line(tx, bus.link(), bus.line(), now);
    bus.line().advance(static_cast<std::uint64_t>(core::to_ns(now)));
  };
  setup.start(now);
  for (int i = 0; i < 1000 && setup.status() == DcSetupStatus::Running; ++i) cycle();
  ASSERT_TRUE(setup.ok()) << setup.line_text() << " / " << setup.slave(0).text.view();
  EXPECT_FALSE(setup.reference_64bit());
  // The start time's low 32 bits in the 32-bit slave; the master's value is the full one.
  EXPECT_EQ(get_u32(esc.memory(), reg::kDcSync0StartTime), static_cast<std::uint32_t>(setup.slave(0).sync0_start));
  DcCyclicConfig cc;
  cc.system_time_base_ns = kBase;
  ASSERT_TRUE(cyclic.configure(setup, cc));
  std::uint64_t previous = 0;
  for (int i = 0; i < 5000; ++i) {  // 5 s: the 32-bit time wraps at least once
    cycle();
    if (previous != 0) {
      EXPECT_EQ(cyclic.reference_time() - previous, 1'000'000U) << i;
    }
    previous = cyclic.reference_time();
  }
  // The extended time follows the master's (offsets made them equal; both run at the same rate).
  EXPECT_LT(std::llabs(cyclic.master_minus_reference_ns()), 2'000);
  EXPECT_LT(std::abs(decode_system_time_difference(get_u32(esc2.memory(), reg::kDcSystemTimeDifference))), 100);
}

// A peer that answers only the first frame of each cycle (a slow simulator process, a loaded
// veth): the static drift compensation's burst of four frames loses three every cycle, which once
// failed the setup after 10 % losses; the window shrinks to what gets through and the setup ends.
TEST(EthercatSimDcMaster, StaticDriftShrinksItsBurstToWhatThePeerAnswers) {
  DcLine l;
  DcConfig c = config();
  c.static_drift_datagrams = 3000;
  l.setup = std::make_unique<DcSetup>(l.infos(), c);
  DcSetup& setup = *l.setup;
  std::uint32_t smallest_window = c.static_drift_per_poll;
  setup.start(l.now);
  for (int i = 0; i < 5000 && setup.status() == DcSetupStatus::Running; ++i) {
    setup.poll(l.now, l.tx);
    l.bus.line().set_time(static_cast<std::uint64_t>(core::to_ns(l.now)));
    bool first = true;
    for (const auto& f : l.tx.take_frames(l.now + 1ms)) {
      if (!first) continue;  // lost on the way: never answered
      first = false;
      l.bus.link().send(FrameView(f.data(), f.size()));
      std::array<FrameBuffer, 1> rx;
      if (l.bus.link().receive(rx) == 1) l.tx.on_frame(rx[0].view());
    }
    l.now += 1ms;
    l.tx.expire(l.now);
    l.bus.line().advance(static_cast<std::uint64_t>(core::to_ns(l.now)));
    if (setup.drift_window() != 0) smallest_window = std::min(smallest_window, setup.drift_window());
  }
  ASSERT_TRUE(setup.ok()) << setup.line_text();
  EXPECT_GT(setup.drift_lost(), 0U);
  // One frame's worth: the reference's 64-bit system time, 12 + 8 bytes a FRMW, 74 in a frame
  // (fewer than the 128 of a poll).
  constexpr std::size_t kPerFrame = (kMaxFrameSize - kEthernetHeaderSize - kEcatHeaderSize) / (kDatagramOverhead + 8);
  static_assert(kPerFrame == 74);
  ASSERT_TRUE(l.infos()[0].dc_64bit);
  EXPECT_LE(smallest_window, kPerFrame);
  EXPECT_GE(setup.drift_answered(), c.static_drift_datagrams);
}

TEST(EthercatSimDcMaster, FailuresAreReportedWithText) {
  {
    // A station that is not on the line: its reads are not executed; the others carry on.
    DcLine l;
    auto infos = l.infos();
    infos[3].station = 0x1009;
    DcConfig c = config();
    c.static_drift_datagrams = 100;
    l.setup = std::make_unique<DcSetup>(infos, c);
    l.run_setup();
    ASSERT_EQ(l.setup->status(), DcSetupStatus::Done) << l.setup->line_text();
    EXPECT_FALSE(l.setup->ok());
    EXPECT_EQ(l.setup->slave(3).status, DcSlaveStatus::Failed);
    EXPECT_EQ(l.setup->slave(3).step, DcStep::ReceiveTimes);
    EXPECT_EQ(l.setup->slave(3).text.view(), "slave 4 (0x1009): DC: FPRD 0x0900 not executed (WKC 0)");
    EXPECT_EQ(l.setup->slave(2).status, DcSlaveStatus::Synchronized);
    std::array<std::uint16_t, 4> st{};
    EXPECT_EQ(l.setup->synchronized_stations(st), 2U);
    EXPECT_EQ(st[1], 0x1003);
  }
  {
    // Frames stop coming back while the receive times are read: every slave fails, the reference
    // with it, and the setup says so.
    DcLine l;
    l.setup = std::make_unique<DcSetup>(l.infos(), config());
    l.setup->start(l.now);
    for (int i = 0; i < 100 && l.setup->step() != DcStep::ReceiveTimes; ++i) l.cycle();
    l.bus.line().drop_next(1000);
    for (int i = 0; i < 100 && l.setup->status() == DcSetupStatus::Running; ++i) l.cycle();
    ASSERT_EQ(l.setup->status(), DcSetupStatus::Failed);
    EXPECT_EQ(l.setup->slave(2).text.view(),
              "slave 3 (0x1003): DC: no answer to the port receive times (FPRD 0900h), frame lost 4 times");
    EXPECT_EQ(l.setup->line_text(),
              "DC: reference clock failed: slave 1 (0x1001): DC: no answer to the port receive times (FPRD 0900h), "
              "frame lost 4 times");
  }
  {
    // A branch (ports 1 and 3 open on the first slave) is refused with its reason.
    DcLine l;
    auto infos = l.infos();
    infos[0].open_ports = 0x0B;
    l.setup = std::make_unique<DcSetup>(infos, config());
    l.run_setup();
    ASSERT_EQ(l.setup->status(), DcSetupStatus::Failed);
    EXPECT_EQ(l.setup->line_text(),
              "DC: slave 1 (0x1001): ports 1 and 3 open: a branch; propagation delays are computed for a line "
              "topology only");
  }
  {
    // No lead: the start time is past before the activation arrives; the read-back catches it.
    DcLine l;
    DcConfig c = config();
    c.static_drift_datagrams = 100;
    c.sync0_lead = 0ms;
    l.setup = std::make_unique<DcSetup>(l.infos(), c);
    l.run_setup();
    ASSERT_EQ(l.setup->status(), DcSetupStatus::Failed);
    const std::string text(l.setup->line_text());
    EXPECT_NE(text.find("reference clock failed: slave 1 (0x1001): DC: SYNC0 start time"), std::string::npos) << text;
    EXPECT_NE(text.find("was already past when activated (0984h 0x04)"), std::string::npos) << text;
    EXPECT_EQ(l.setup->slave(0).step, DcStep::Sync0Check);
  }
}

}  // namespace
}  // namespace drivegate::ethercat::sim
