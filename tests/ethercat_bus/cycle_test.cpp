// The EtherCAT bus' cycle: no allocation once in OP, a slave that leaves OP (the AL status code in
// the sentence) and its recovery, and the --check-config rows and the frame-fit refusal.
#include <gtest/gtest.h>

#include "config/describe.hpp"
#include "tests/ethercat_bus/bus_harness.hpp"
#include "tests/support/alloc_counter.hpp"

namespace drivegate::ethercat::test {
namespace {

using core::AxisState;
using core::LinkState;

// The bus' receive() and transmit() with the profile and runner between them, the link, the
// engines and the simulated line: nothing allocates once the line is in OP.
TEST(EthercatBusCycle, NoAllocationPerCycleInOp) {
  EcatHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details();
  h.run_until([] { return false; }, 50ms);  // the default modes settle
  const auto good = h.cx().counters().good;
  {
    const drivegate::test::AllocationScope scope;
    for (int i = 0; i < 200; ++i) {
      h.now += 1ms;
      h.runner->cycle(h.now);
    }
    EXPECT_EQ(scope.count(), 0U);
  }
  EXPECT_EQ(h.cx().counters().good - good, 200U);
  EXPECT_EQ(h.bus->counters().errors, 0U);
  EXPECT_GT(h.bus->counters().frames_sent, 200U);
  EXPECT_EQ(h.bus->counters().frames_lost, 0U);
}

// The ESR drops to SAFE-OP with the SM watchdog error: its axis is Lost with the AL status code
// in words [ETG.1000.6 Table 11: 001Bh sync manager watchdog]; once it takes OP again it is
// restarted (INIT, SII, identity, mapping) and comes back disabled.
TEST(EthercatBusRecovery, SlaveLeavingOpIsLostWithItsAlStatusCode) {
  EcatHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details();
  h.line->stick(0, AlState::SafeOp, 0x001B);
  ASSERT_TRUE(h.run_until([&] { return h.bus->link_state(h.axis("esr")) == LinkState::Lost; }, 100ms)) << h.details();
  EXPECT_EQ(h.bus->link_detail(h.axis("esr")),
            "slave 1 (0x1001, ESR TrioDrive D/ES): left OP: SAFE-OP + error 0x001B sync manager watchdog");
  EXPECT_EQ(h.bus->link_state(h.axis("gen")), LinkState::Operational);
  // Stuck: the restart is refused at SAFE-OP -> OP, and tried again with the back-off.
  h.run_until([] { return false; }, 600ms);
  EXPECT_NE(h.bus->link_state(h.axis("esr")), LinkState::Operational);
  h.line->stick(0, AlState::Op, 0);
  ASSERT_TRUE(h.run_until([&] { return h.up("esr"); }, 5s)) << h.details() << h.events_text();
  EXPECT_GE(h.bus->restarts(0), 1U);
  EXPECT_EQ(h.snap("esr").state, AxisState::SwitchOnDisabled);
  EXPECT_EQ(h.esr.esc->state(), AlState::Op);
}

// --check-config: the image and frame rows of the bus, the slave row of each axis.
TEST(EthercatBusConfig, PrintoutRows) {
  const config::Plan plan = config::load_plan_from_string(kLine, "ecat-test.yaml", load_options());
  const std::string out = config::describe_plan(plan);
  // ESR: 2+2+4+4+4+2+2 = 20 bytes out, 2+2+4+4+4+2+2 = 20 in; panel 2/2; generic 2+1+2+4+4+4 = 17
  // out, 2+1+2+2+4+4 = 15 in (profiles/devices/*.yaml).
  EXPECT_EQ(row(out, "image"), "76 bytes (39 out, 37 in) over 3 slaves, 3 datagrams, working counter 9") << out;
  // 16 bytes of headers, the three LRWs (12 + 40, 12 + 4, 12 + 32), the AL status check and DC
  // slots (24 + 10): 162 bytes; with preamble, FCS and gap 186 bytes at 80 ns (IEEE 802.3).
  EXPECT_EQ(row(out, "frame"), "1 frame, 162 bytes, 14.9 us on the wire at 100 Mbit/s (round trip 17.9 us)") << out;
  EXPECT_EQ(row(out, "slave"), "position 1, station 0x1001, axis 0, outputs at 0 (20 bytes), inputs at 20 (20 bytes)")
      << out;
  EXPECT_EQ(row(out, "slave", 1), "position 3, station 0x1003, axis 0, outputs at 44 (17 bytes), inputs at 61 (15 bytes)")
      << out;
}

// A frame that is not back within half the cycle is refused with the numbers.
TEST(EthercatBusConfig, FrameThatDoesNotFitTheCycleIsRefused) {
  const std::string yaml = R"(gateway: { name: ecat-test }
buses:
  - name: ec0
    type: ethercat
    cycle_time: 125us
    options: { transport: sim, sm_watchdog: 0 }
    io:
      - { name: big, position: 1, inputs: 400, outputs: 400 }
)";
  try {
    config::load_plan_from_string(yaml, "fit.yaml", load_options());
    FAIL() << "loaded";
  } catch (const config::ConfigError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("does not fit in half the cycle_time of 125.0 us: lengthen cycle_time or map fewer objects"),
              std::string::npos)
        << what;
    EXPECT_NE(what.find("the cyclic frame (8"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace drivegate::ethercat::test

namespace drivegate::ethercat::test {
namespace {

// Mapped objects in the image: little-endian at their PDO entry offsets, sign-extended per type;
// the I/O slave's sizes taken from its SII when the plan leaves them open.
TEST(EthercatBusImage, MappedObjectsAndIoSizesFromTheSii) {
  std::string yaml = kLine;
  yaml.replace(yaml.find(", inputs: 2, outputs: 2"), std::string(", inputs: 2, outputs: 2").size(), "");
  EcatHarness h(yaml);
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details();
  EXPECT_EQ(h.bus->image().slave(1).output_bytes, 2);
  EXPECT_EQ(h.bus->image().slave(1).input_bytes, 2);
  SlaveAccess& gen = h.bus->access(h.axis("gen"));
  // 6071h (INTEGER16) sits after 6040h (2 bytes) and 6060h (1 byte): offset 3 of the outputs.
  gen.write({0x6071, 0}, -100);
  EXPECT_EQ(gen.read({0x6071, 0}), -100);
  const auto out = h.cx().inputs(2);  // inputs; the outputs are read back through the access
  EXPECT_EQ(out.size(), 15U);
  EXPECT_TRUE(gen.mapped({0x6064, 0}));
  EXPECT_FALSE(gen.mapped({0x6081, 0}));
  // The drive's position (6064h, INTEGER32 at input offset 7) as the model has it.
  h.cycle();
  EXPECT_EQ(gen.read({0x6064, 0}), h.gen.app->drive().read_object({0x6064, 0}).value);
  EXPECT_TRUE(gen.inputs_fresh());
}

// SlaveAccess finds its objects through a hash table: every mapped object is found (also with
// more objects than the table's first size, so that probes collide, and with one mapped twice),
// unmapped ones are not, and the second axis of a multi-axis slave finds the profile objects at
// its own offset.
TEST(EthercatSlaveAccess, FindsEveryMappedObject) {
  std::vector<MappedObject> objects;
  for (std::uint16_t i = 0; i < 40; ++i)
    objects.push_back(MappedObject{{static_cast<std::uint16_t>(0x6000 + i), 0}, cia402::DataType::U16, true,
                                   static_cast<std::uint16_t>(2 * i)});
  objects.push_back(MappedObject{{0x6005, 0}, cia402::DataType::U8, false, 99});  // 6005h again
  objects.push_back(MappedObject{{0x2000, 7}, cia402::DataType::U8, false, 100});
  const SlaveAccess a(0, objects, 0, 0x800, nullptr, {}, {});
  for (std::uint16_t i = 0; i < 40; ++i) EXPECT_TRUE(a.mapped({static_cast<std::uint16_t>(0x6000 + i), 0})) << i;
  EXPECT_TRUE(a.mapped({0x2000, 7}));
  EXPECT_FALSE(a.mapped({0x2000, 6}));
  EXPECT_FALSE(a.mapped({0x6000, 1}));
  EXPECT_FALSE(a.mapped({0x6028, 0}));
  EXPECT_FALSE(a.mapped({0x6805, 0}));

  const std::vector<MappedObject> second{{{0x6840, 0}, cia402::DataType::U16, true, 0},
                                         {{0x2000, 7}, cia402::DataType::U8, false, 0}};
  const SlaveAccess b(0, second, 1, 0x800, nullptr, {}, {});
  EXPECT_TRUE(b.mapped({0x6040, 0}));  // axis 1: 6040h + 800h
  EXPECT_TRUE(b.mapped({0x2000, 7}));  // outside the profile area: not offset
  EXPECT_EQ(b.resolve({0x6040, 0}).slot(), b.resolve({0x6840, 0}).slot());
  // A reference that is not mapped (or out of the table) reads 0 and writes nothing.
  EXPECT_EQ(b.read(cia402::ImageRef{}), 0);
  EXPECT_EQ(b.read(cia402::ImageRef::at(0x7FFF, b.mapping_generation())), 0);
}

// The references the CiA 402 profile resolves once stay valid through a slave's loss and
// restart: the mapping comes from the plan and the offsets never move, so the same reference reads
// the drive's inputs and writes its outputs after the slave is back in OP.
TEST(EthercatSlaveAccess, ReferencesStayValidThroughASlaveRestart) {
  EcatHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details();
  SlaveAccess& gen = h.bus->access(h.axis("gen"));
  const cia402::ImageRef position = gen.resolve({0x6064, 0});
  const cia402::ImageRef torque = gen.resolve({0x6071, 0});
  ASSERT_TRUE(position.mapped());
  ASSERT_TRUE(torque.mapped());
  const std::uint32_t generation = gen.mapping_generation();

  h.line->stick(2, AlState::SafeOp, 0x001B);
  ASSERT_TRUE(h.run_until([&] { return h.bus->link_state(h.axis("gen")) == LinkState::Lost; }, 100ms)) << h.details();
  h.line->stick(2, AlState::Op, 0);
  ASSERT_TRUE(h.run_until([&] { return h.up("gen"); }, 5s)) << h.details() << h.events_text();
  EXPECT_GE(h.bus->restarts(2), 1U);

  EXPECT_EQ(gen.mapping_generation(), generation);
  EXPECT_TRUE(position.current(gen.mapping_generation()));
  h.cycle();
  EXPECT_EQ(gen.read(position), h.gen.app->drive().read_object({0x6064, 0}).value);
  gen.write(torque, -100);
  EXPECT_EQ(gen.read({0x6071, 0}), -100);
}

// A reference carries the object's place (direction, type, offset): each type reads back as the
// type holds it, an input cannot be written, and while the bus holds the controlword for a safe
// stop the profile's writes to 6040h are dropped and its other outputs still go out.
TEST(EthercatSlaveAccess, ReferencesKeepTheTypeAndTheSafeStopHoldsTheControlword) {
  EcatHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details();
  SlaveAccess& gen = h.bus->access(h.axis("gen"));
  const cia402::ImageRef modes = gen.resolve({0x6060, 0});   // INTEGER8 output
  const cia402::ImageRef torque = gen.resolve({0x6071, 0});  // INTEGER16 output
  const cia402::ImageRef cw = gen.resolve({0x6040, 0});      // UNSIGNED16 output
  const cia402::ImageRef sw = gen.resolve({0x6041, 0});      // UNSIGNED16 input
  ASSERT_TRUE(modes.mapped() && torque.mapped() && cw.mapped() && sw.mapped());
  gen.write(modes, -1);
  EXPECT_EQ(gen.read(modes), -1);
  gen.write(modes, 0x1FF);  // truncated to the type
  EXPECT_EQ(gen.read(modes), -1);
  gen.write(cw, 0xFFFF);
  EXPECT_EQ(gen.read(cw), 0xFFFF);
  const std::int64_t status = gen.read(sw);
  gen.write(sw, status ^ 0xFF);
  EXPECT_EQ(gen.read(sw), status);

  gen.override_controlword(true, 0x0002);
  EXPECT_EQ(gen.read(cw), 0x0002);
  gen.write(cw, 0x000F);
  gen.write({0x6040, 0}, 0x000F);
  gen.write(torque, 123);
  EXPECT_EQ(gen.read(cw), 0x0002);
  EXPECT_EQ(gen.read(torque), 123);
  gen.override_controlword(false);
  gen.write(cw, 0x0006);
  EXPECT_EQ(gen.read(cw), 0x0006);
}

}  // namespace
}  // namespace drivegate::ethercat::test
