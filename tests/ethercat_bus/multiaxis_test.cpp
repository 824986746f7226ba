// A multi-axis slave on the EtherCAT bus [ETG.6010 §4 modular device profile: axis n's objects at
// 6000h + n x 800h]: a line of a generic I/O panel, a two-axis drive (generic-cia402-2axis, axes
// "left" = slave axis 0 and "right" = slave axis 1) and a single-axis generic drive. The axes of
// the one slave are enabled, moved, parameterised and faulted independently; the slave's power
// loss takes both.
#include <gtest/gtest.h>

#include <cmath>

#include "config/describe.hpp"
#include "tests/ethercat_bus/bus_harness.hpp"

namespace drivegate::ethercat::test {
namespace {

using core::AxisState;
using core::CommandKind;
using core::LinkState;
using core::Mode;
using core::ReplyStatus;

const char* kMultiLine = R"(gateway: { name: ecat-multi }
buses:
  - name: ec0
    type: ethercat
    cycle_time: 1ms
    options: { transport: sim, lost_cycles: 3, boot_retry: 200ms, boot_retry_max: 1s }
    io:
      - { name: panel, position: 1, vendor_id: 0x99, product_code: 0x1000, inputs: 2, outputs: 2 }
axes:
  - { name: left, bus: ec0, address: 2, device: generic-cia402-2axis, ethercat: { axis: 0 }, mechanics: { encoder_counts_per_rev: 4096 } }
  - { name: right, bus: ec0, address: 2, device: generic-cia402-2axis, ethercat: { axis: 1 }, mechanics: { encoder_counts_per_rev: 4096 } }
  - { name: gen, bus: ec0, address: 3, device: generic-cia402, mechanics: { encoder_counts_per_rev: 4096 } }
)";

// The harness' bus and runner over this line: the panel (EcatHarness::panel), the two-axis drive
// (duo) and the generic drive (EcatHarness::gen).
struct MultiHarness : EcatHarness {
  MultiHarness() : EcatHarness(kMultiLine, false) {
    const auto& bp = plan.buses.at(0);
    for (const auto& a : bp.axes) specs.push_back(a.spec);
    auto memory = std::make_unique<MemoryLink>(64);
    link = memory.get();
    line = std::make_unique<sim::SimLine>(*link);
    panel = std::make_unique<sim::GenericIoSlave>(2, 2, kPanelId);
    panel_esc = std::make_unique<sim::EscSlave>(sim::EscConfig{}, panel->sii(), panel.get());
    duo = sim::make_cia402_device("generic-cia402-2axis");
    gen = sim::make_cia402_device("generic-cia402");
    line->add(*panel_esc);
    line->add(*duo.esc);
    line->add(*gen.esc);
    bus = std::make_unique<EthercatBus>(bp, std::move(memory), std::make_unique<LinePeer>(*line));
    runner = std::make_unique<core::BusRunner>(*bus, specs);
    bus->open(now);
    replies.reserve(4096);
    events.reserve(4096);
  }
  ~MultiHarness() {
    // The runner, line and bus go before the drive they refer to.
    runner.reset();
    line.reset();
    bus.reset();
  }
  const cia402::sim::DriveModel& model(std::size_t axis) const { return duo.app->drive(axis); }

  sim::Cia402Device duo;
};

void expect_completed(EcatHarness& h, core::CommandId id, core::Duration budget, const std::string& what) {
  ASSERT_EQ(h.wait_final(id, budget), ReplyStatus::Completed) << what << ": " << h.reason(id) << h.events_text()
                                                              << h.details();
}

void up(EcatHarness& h) { ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details() << h.events_text(); }

// csp set-points for `axis` from where it is, `step` per cycle for `cycles` cycles; the target.
double move(EcatHarness& h, const std::string& axis, double step, int cycles) {
  double target = h.snap(axis).position;
  for (int i = 0; i < cycles; ++i) {
    target += step;
    core::Setpoint sp;
    sp.axis = h.axis(axis);
    sp.position = target;
    EXPECT_TRUE(h.runner->push_setpoint(sp));
    h.cycle();
  }
  h.run_until([] { return false; }, 50ms);
  return target;
}

TEST(EthercatMultiAxis, BothAxesOfTheSlaveReachOpDisabled) {
  MultiHarness h;
  up(h);
  if (HasFatalFailure()) return;
  EXPECT_EQ(h.bus->slave_count(), 3U);
  EXPECT_EQ(h.duo.esc->state(), AlState::Op);
  EXPECT_EQ(h.panel_esc->state(), AlState::Op);
  EXPECT_EQ(h.gen.esc->state(), AlState::Op);
  for (const char* a : {"left", "right", "gen"}) EXPECT_EQ(h.snap(a).state, AxisState::SwitchOnDisabled) << a;
  EXPECT_EQ(h.bus->link_detail(h.axis("left")), "slave 2 (0x1002, drivegate simulated two-axis CiA 402 drive): in OP");
  EXPECT_EQ(h.bus->link_detail(h.axis("right")), h.bus->link_detail(h.axis("left")));
  // Both axes' PDOs assigned (1C12h/1C13h: 1600h/1601h, 1A00h/1A01h): 2 x 17 output bytes and
  // 2 x 15 input bytes in the slave's image.
  EXPECT_EQ(h.bus->image().slave(1).output_bytes, 34);
  EXPECT_EQ(h.bus->image().slave(1).input_bytes, 30);
  EXPECT_EQ(h.duo.app->output_size(), 34U);
  EXPECT_EQ(h.duo.app->input_size(), 30U);
}

// --check-config: both axes on the one slave at position 2, with its whole image each.
TEST(EthercatMultiAxis, PrintoutShowsBothAxesOnOneSlave) {
  const config::Plan plan = config::load_plan_from_string(kMultiLine, "ecat-multi.yaml", load_options());
  const std::string out = config::describe_plan(plan);
  // panel 2/2; two-axis drive 2 x 17 out, 2 x 15 in; generic 17/15.
  EXPECT_EQ(row(out, "image"), "100 bytes (53 out, 47 in) over 3 slaves, 3 datagrams, working counter 9") << out;
  EXPECT_EQ(row(out, "slave", 0), "position 2, station 0x1002, axis 0, outputs at 4 (34 bytes), inputs at 38 (30 bytes)")
      << out;
  EXPECT_EQ(row(out, "slave", 1),
            "position 2, station 0x1002, axis 1 (objects + 800h), outputs at 4 (34 bytes), inputs at 38 (30 bytes)")
      << out;
  EXPECT_EQ(row(out, "slave", 2), "position 3, station 0x1003, axis 0, outputs at 68 (17 bytes), inputs at 85 (15 bytes)")
      << out;
}

// Axis 0 enabled and moved while axis 1 stays disabled and still; then the reverse.
TEST(EthercatMultiAxis, AxesEnableAndMoveIndependently) {
  MultiHarness h;
  up(h);
  if (HasFatalFailure()) return;
  expect_completed(h, h.push("left", CommandKind::Enable), 3s, "enable left");
  EXPECT_EQ(h.model(0).state(), AxisState::OperationEnabled);
  EXPECT_EQ(h.model(1).state(), AxisState::SwitchOnDisabled);
  EXPECT_EQ(h.snap("right").state, AxisState::SwitchOnDisabled);
  expect_completed(h, h.set_mode("left", Mode::CyclicPosition), 3s, "csp left");
  const double right_before = h.model(1).position();
  const double left_before = h.model(0).position();
  const double left_target = move(h, "left", 0.002, 300);
  EXPECT_NEAR(h.snap("left").position, left_target, 0.05);
  EXPECT_NEAR(h.model(0).position() - left_before, 0.6 * 4096, 0.05 * 4096);  // counts
  EXPECT_EQ(h.model(1).position(), right_before);
  EXPECT_EQ(h.model(1).active_mode(), 0);  // its 6860h untouched

  expect_completed(h, h.push("left", CommandKind::Disable), 3s, "disable left");
  expect_completed(h, h.push("right", CommandKind::Enable), 3s, "enable right");
  EXPECT_EQ(h.model(1).state(), AxisState::OperationEnabled);
  EXPECT_NE(h.model(0).state(), AxisState::OperationEnabled);
  expect_completed(h, h.set_mode("right", Mode::CyclicPosition), 3s, "csp right");
  const double left_after = h.model(0).position();
  const double right_start = h.model(1).position();
  const double right_target = move(h, "right", -0.002, 300);
  EXPECT_NEAR(h.snap("right").position, right_target, 0.05);
  EXPECT_NEAR(h.model(1).position() - right_start, -0.6 * 4096, 0.05 * 4096);
  EXPECT_NEAR(h.model(0).position(), left_after, 1.0);  // disabled: it stays where it came to rest
  EXPECT_NEAR(h.snap("left").position, left_target, 0.05);
  expect_completed(h, h.push("right", CommandKind::Disable), 3s, "disable right");
}

// A parameter of axis 1 over CoE is its object + 800h on the slave: 6881h, not 6081h.
TEST(EthercatMultiAxis, ParameterOfAxisOneIsItsOffsetObject) {
  MultiHarness h;
  up(h);
  if (HasFatalFailure()) return;
  const std::int64_t left_before = h.model(0).read_object({0x6081, 0}).value;
  const core::ParamReply w = h.param("right", true, 0x6081, 0, core::ParamType::U32, "4321");
  ASSERT_TRUE(w.ok) << w.error.view();
  EXPECT_EQ(h.model(1).read_object({0x6081, 0}).value, 4321);
  EXPECT_EQ(h.model(0).read_object({0x6081, 0}).value, left_before);
  EXPECT_NE(left_before, 4321);
  const core::ParamReply r = h.param("right", false, 0x6081, 0, core::ParamType::U32);
  ASSERT_TRUE(r.ok) << r.error.view();
  EXPECT_EQ(core::get_u32(r.data, 0), 4321U);
  const core::ParamReply l = h.param("left", false, 0x6081, 0, core::ParamType::U32);
  ASSERT_TRUE(l.ok) << l.error.view();
  EXPECT_EQ(static_cast<std::int64_t>(core::get_u32(l.data, 0)), left_before);
  // Below 6000h the slave's objects are one: 1018h:02 is the same for both axes.
  const core::ParamReply p0 = h.param("left", false, 0x1018, 2, core::ParamType::U32);
  const core::ParamReply p1 = h.param("right", false, 0x1018, 2, core::ParamType::U32);
  ASSERT_TRUE(p0.ok && p1.ok);
  EXPECT_EQ(core::get_u32(p0.data, 0), 0x00020192U);
  EXPECT_EQ(core::get_u32(p1.data, 0), 0x00020192U);
}

// Names read over SDO Information: the slave names 6040h and 6840h both "Controlword"; each axis
// finds its own (in its own numbering, as a parameter request gives it), shared objects on both.
TEST(EthercatMultiAxis, NamesOfEachAxisComeFromItsOwnObjects) {
  MultiHarness h;
  up(h);
  if (HasFatalFailure()) return;
  ASSERT_TRUE(h.run_until([&] { return h.bus->dictionary(1)->state() == SlaveDictionary::State::Done; }, 60s));
  for (const char* axis : {"left", "right"}) {
    const core::NamedObject cw = h.bus->find_object(h.axis(axis), "Controlword");
    ASSERT_TRUE(cw.found) << axis << ": " << cw.error;
    EXPECT_EQ(cw.index, 0x6040) << axis;
    const core::NamedObject id = h.bus->find_object(h.axis(axis), "Identity:Product code");
    ASSERT_TRUE(id.found) << axis << ": " << id.error;
    EXPECT_EQ(id.index, 0x1018) << axis;
    EXPECT_EQ(id.sub, 2) << axis;
  }
}

// A fault on axis 1: that axis goes to Fault, with its EMCY event and fault report; axis 0 and the
// other drive stay as they were. The fault is reset on axis 1 alone.
TEST(EthercatMultiAxis, FaultOnOneAxisIsReportedOnThatAxisOnly) {
  MultiHarness h;
  up(h);
  if (HasFatalFailure()) return;
  expect_completed(h, h.push("left", CommandKind::Enable), 3s, "enable left");
  h.events.clear();
  h.duo.app->inject_fault(0x2310, 1);
  ASSERT_TRUE(h.run_until([&] { return h.snap("right").state == AxisState::Fault; }, 500ms)) << h.events_text();
  const auto emcy_of = [&](const std::string& axis) {
    for (const auto& e : h.events)
      if (e.kind == core::EventKind::Emcy && e.axis == h.axis(axis) && e.code == 0x2310) return true;
    return false;
  };
  ASSERT_TRUE(h.run_until([&] { return emcy_of("right"); }, 500ms)) << h.events_text();
  h.run_until([] { return false; }, 50ms);
  EXPECT_FALSE(emcy_of("left")) << h.events_text();
  EXPECT_EQ(h.snap("left").state, AxisState::OperationEnabled);
  EXPECT_EQ(h.model(0).state(), AxisState::OperationEnabled);
  EXPECT_EQ(h.snap("gen").state, AxisState::SwitchOnDisabled);
  const cia402::DriveFaultReport right = h.bus->access(h.axis("right")).fault_report();
  EXPECT_TRUE(right.valid);
  EXPECT_EQ(right.code, 0x2310);
  EXPECT_FALSE(h.bus->access(h.axis("left")).fault_report().valid);
  EXPECT_EQ(h.bus->link_state(h.axis("right")), LinkState::Operational);

  h.duo.app->clear_fault_cause(1);
  expect_completed(h, h.push("right", CommandKind::FaultReset), 3s, "reset right");
  EXPECT_NE(h.snap("right").state, AxisState::Fault);
  EXPECT_EQ(h.snap("left").state, AxisState::OperationEnabled);
}

// The two-axis slave loses its power: both its axes Lost with the sentence; the panel in front
// keeps cycling, the drive behind is cut off with it (an ESC without power passes no frame,
// ETG.1000.4 §5.2). Powered again, it is configured from scratch and both axes come back disabled.
TEST(EthercatMultiAxis, PowerLossTakesBothAxesAndTheyComeBackDisabled) {
  MultiHarness h;
  up(h);
  if (HasFatalFailure()) return;
  expect_completed(h, h.push("left", CommandKind::Enable), 3s, "enable left");
  expect_completed(h, h.push("right", CommandKind::Enable), 3s, "enable right");
  h.line->power_off(1);
  ASSERT_TRUE(h.run_until([&] {
    return h.bus->link_state(h.axis("left")) == LinkState::Lost && h.bus->link_state(h.axis("right")) == LinkState::Lost;
  }, 100ms)) << h.details();
  EXPECT_EQ(h.bus->link_detail(h.axis("right")),
            "slave 2 (0x1002, drivegate simulated two-axis CiA 402 drive): no answer for 3 cycles");
  h.run_until([] { return false; }, 20ms);
  EXPECT_EQ(h.cx().answered(0), SlaveAnswer::Answered);
  EXPECT_EQ(h.cx().answered(1), SlaveAnswer::Missing);
  EXPECT_EQ(h.panel_esc->state(), AlState::Op);

  h.duo.app->power_cycle();
  h.line->power_on(1);
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details() << h.events_text();
  EXPECT_EQ(h.bus->restarts(0), 0U);
  EXPECT_EQ(h.bus->restarts(1), 1U);
  EXPECT_EQ(h.duo.esc->state(), AlState::Op);
  EXPECT_EQ(h.snap("left").state, AxisState::SwitchOnDisabled);
  EXPECT_EQ(h.snap("right").state, AxisState::SwitchOnDisabled);
  EXPECT_EQ(h.model(0).state(), AxisState::SwitchOnDisabled);
  EXPECT_EQ(h.model(1).state(), AxisState::SwitchOnDisabled);
  expect_completed(h, h.push("right", CommandKind::Enable), 3s, "enable right after the restart");
  EXPECT_EQ(h.model(0).state(), AxisState::SwitchOnDisabled);
}

// The SM watchdog of the two-axis slave (the master stops sending): every axis' 6007h reaction
// (1 = fault 8100h on both).
TEST(EthercatMultiAxis, SmWatchdogFaultsBothAxes) {
  MultiHarness h;
  up(h);
  if (HasFatalFailure()) return;
  expect_completed(h, h.push("left", CommandKind::Enable), 3s, "enable left");
  EXPECT_EQ(h.duo.app->abort_option(0), 1);
  EXPECT_EQ(h.duo.app->abort_option(1), 1);
  // No more frames: only the PDI runs, 200 ms past the 100 ms SM watchdog.
  for (int i = 0; i < 200; ++i) {
    h.now += 1ms;
    h.line->advance(static_cast<std::uint64_t>(core::to_ns(h.now)));
  }
  EXPECT_EQ(h.duo.esc->state(), AlState::SafeOp);
  EXPECT_EQ(h.duo.app->counters().comm_losses, 1U);
  EXPECT_EQ(h.model(0).state(), AxisState::Fault);
  EXPECT_EQ(h.model(1).state(), AxisState::Fault);
}

// transport: sim as the daemon makes it: the line builder puts both axes on one simulated
// two-axis slave (its persona from the profile); both come up and enable independently.
TEST(EthercatMultiAxis, TransportSimBuildsTheTwoAxisSlave) {
  EcatHarness h(kMultiLine, false);
  h.make_from_factory();
  up(h);
  if (HasFatalFailure()) return;
  expect_completed(h, h.push("right", CommandKind::Enable), 3s, "enable right");
  EXPECT_EQ(h.snap("right").state, AxisState::OperationEnabled);
  EXPECT_EQ(h.snap("left").state, AxisState::SwitchOnDisabled);
}

}  // namespace
}  // namespace drivegate::ethercat::test
