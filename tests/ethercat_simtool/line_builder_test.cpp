// The line builder (a SimLine from a config's ethercat bus, persona factories) and the fault
// console, in memory: frames built with FrameBuilder pass BuiltLine::pass(). Working counters
// follow ETG.1000.4 §5.4 (a BRD is counted once by every slave it reaches).
#include <gtest/gtest.h>

#include "adapters/ethercat/sim/cia402_slave.hpp"
#include "adapters/ethercat/sim/generic_io.hpp"
#include "adapters/ethercat/sim/line_builder.hpp"
#include "adapters/ethercat/sim/line_console.hpp"
#include "tests/ethercat_simtool/support.hpp"

namespace drivegate::ethercat::sim {
namespace {

using test::count;
using test::plan_of;
using test::through;

TEST(EthercatLineBuilder, SlavesInPositionOrderEachWithItsSii) {
  const config::Plan plan = plan_of(test::three_io_config("eth1"));
  const auto line = build_line(plan.buses.at(0));
  ASSERT_EQ(line->size(), 3U);
  EXPECT_EQ(line->bus(), "ec0");
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(line->slave(k).position, k + 1);
    EXPECT_EQ(line->slave(k).persona, "generic-io");
    EXPECT_EQ(line->slave(k).esc->state(), AlState::Init);
  }
  EXPECT_EQ(line->slave(0).name, "io a");
  // Identity from the io: entry, or the simulator's own when it names none; serials 1, 2, 3.
  EXPECT_EQ(line->slave(0).identity, (SiiIdentity{kSimIoVendorId, kSimIoProductCode, 1, 1}));
  EXPECT_EQ(line->slave(2).identity, (SiiIdentity{0x99, 0x1000, 1, 3}));
  // Sizes from the io: entry (inputs = SM3, outputs = SM2).
  EXPECT_EQ(line->slave(0).parts.app->input_size(), 2U);
  EXPECT_EQ(line->slave(1).parts.app->output_size(), 1U);
  EXPECT_EQ(line->slave(2).parts.app->input_size(), 4U);
  EXPECT_EQ(line->slave(2).parts.app->output_size(), 0U);
  EXPECT_EQ(count(*line), 3);
}

TEST(EthercatLineBuilder, AGapInThePositionsIsRefused) {
  const config::Plan plan = plan_of(R"(gateway: { name: t }
buses:
  - name: ec0
    type: ethercat
    cycle_time: 1ms
    options: { transport: sim }
    io: [{ name: a, position: 1 }, { name: c, position: 3 }]
)");
  try {
    build_line(plan.buses.at(0));
    FAIL() << "built";
  } catch (const LineBuildError& e) {
    EXPECT_STREQ(e.what(),
                 "bus ec0: no slave at position 2 (the next is at 3); a simulated line has a slave at every position "
                 "from 1 on");
  }
}

const std::string kDriveAndIo = R"(gateway: { name: t }
buses:
  - name: ec0
    type: ethercat
    cycle_time: 1ms
    options: { transport: sim }
    io: [{ name: panel, position: 2 }]
axes:
  - { name: x, bus: ec0, address: 1, device: generic-cia402, mechanics: { encoder_counts_per_rev: 4096 } }
)";

TEST(EthercatLineBuilder, AnUnknownPersonaIsRefusedWithTheKnownOnes) {
  PersonaRegistry only_io;
  only_io.add("generic-io", make_generic_io);
  const config::Plan plan = plan_of(kDriveAndIo);
  try {
    build_line(plan.buses.at(0), only_io);
    FAIL() << "built";
  } catch (const LineBuildError& e) {
    EXPECT_STREQ(e.what(), "bus ec0 position 1 (axis x): no simulated persona \"generic-cia402\" in this build "
                           "(known: generic-io)");
  }
}

TEST(EthercatLineBuilder, APersonaFactoryGetsItsPositionAndRunsAtPowerOn) {
  // The seam the CiA 402 personas plug into: a factory by the profile's ethercat.persona.
  PersonaRegistry personas = PersonaRegistry::builtin();
  int power_ons = 0;
  std::vector<std::string> seen;
  personas.add("generic-cia402", [&](const SlaveRequest& q) {
    seen.push_back(q.bus + " " + std::to_string(q.position) + " " + q.persona + " " + q.name + " " +
                   (q.device != nullptr ? q.device->name : "-") + " " + std::to_string(q.axes.size()));
    auto app = std::make_unique<GenericIoSlave>(1, 1, SiiIdentity{0x42, 0x43, 7, q.serial});
    SimSlaveParts parts;
    parts.sii.assign(app->sii().begin(), app->sii().end());
    parts.app = std::move(app);
    parts.power_on = [&power_ons] { ++power_ons; };
    return parts;
  });
  const config::Plan plan = plan_of(kDriveAndIo);
  const auto line = build_line(plan.buses.at(0), personas);
  ASSERT_EQ(line->size(), 2U);
  EXPECT_EQ(seen, std::vector<std::string>{"ec0 1 generic-cia402 axis x generic-cia402 1"});
  EXPECT_EQ(line->slave(0).identity, (SiiIdentity{0x42, 0x43, 7, 1}));
  EXPECT_EQ(line->slave(1).persona, "generic-io");
  EXPECT_EQ(line->slave(1).name, "io panel");
  line->power_off(0);
  EXPECT_EQ(power_ons, 0);
  line->power_on(0);
  line->power_on(0);  // already on: nothing
  EXPECT_EQ(power_ons, 1);
}

// Both axes of a two-axis drive on one simulated slave (generic-cia402-2axis), each model with its
// own config axis' mechanics, whatever order the config lists them in.
TEST(EthercatLineBuilder, TheAxesOfATwoAxisDriveShareOneSlave) {
  const config::Plan plan = plan_of(R"(gateway: { name: t }
buses:
  - name: ec0
    type: ethercat
    cycle_time: 1ms
    options: { transport: sim }
    io: [{ name: panel, position: 1 }]
axes:
  - { name: r, bus: ec0, address: 2, device: generic-cia402-2axis, mechanics: { encoder_counts_per_rev: 8192 }, ethercat: { axis: 1 } }
  - { name: l, bus: ec0, address: 2, device: generic-cia402-2axis, mechanics: { encoder_counts_per_rev: 4096 }, ethercat: { axis: 0 } }
  - { name: g, bus: ec0, address: 3, device: generic-cia402, mechanics: { encoder_counts_per_rev: 1000 } }
)");
  const auto line = build_line(plan.buses.at(0));
  ASSERT_EQ(line->size(), 3U);
  EXPECT_EQ(line->slave(1).persona, "generic-cia402-2axis");
  EXPECT_EQ(line->slave(1).name, "axes r, l");
  EXPECT_EQ(line->slave(1).identity, (SiiIdentity{0x00000000, 0x00020192, 1, 2}));
  const auto* duo = dynamic_cast<const Cia402Slave*>(line->slave(1).parts.app.get());
  ASSERT_NE(duo, nullptr);
  ASSERT_EQ(duo->axes(), 2U);
  EXPECT_EQ(duo->drive(0).config().position_units_per_rev, 4096.0);
  EXPECT_EQ(duo->drive(1).config().position_units_per_rev, 8192.0);
  // Both axes' PDOs assigned at power-on: 2 x 17 bytes out, 2 x 15 in.
  EXPECT_EQ(duo->output_size(), 34U);
  EXPECT_EQ(duo->input_size(), 30U);
  EXPECT_EQ(line->slave(2).persona, "generic-cia402");
  EXPECT_EQ(line->slave(2).name, "axis g");
  EXPECT_EQ(count(*line), 3);
}

TEST(EthercatLineBuilder, AFactoryErrorNamesThePosition) {
  PersonaRegistry personas = PersonaRegistry::builtin();
  personas.add("generic-cia402", [](const SlaveRequest&) -> SimSlaveParts { throw std::invalid_argument("no drive today"); });
  const config::Plan plan = plan_of(kDriveAndIo);
  try {
    build_line(plan.buses.at(0), personas);
    FAIL() << "built";
  } catch (const LineBuildError& e) {
    EXPECT_STREQ(e.what(), "bus ec0 position 1 (axis x): no drive today");
  }
}

class EthercatLineConsole : public ::testing::Test {
 protected:
  EthercatLineConsole() : plan_(plan_of(test::three_io_config("eth1"))), line_(build_line(plan_.buses.at(0))) {
    console_.add(*line_);
  }
  // AL control at the slave at `position` (0-based), by auto-increment address.
  void request(std::uint16_t position, AlState s) {
    const std::array<std::uint8_t, 2> v{static_cast<std::uint8_t>(s), 0};
    ASSERT_TRUE(through(*line_, Command::APWR, physical_address(auto_increment_adp(position), reg::kAlControl), 2, v));
  }

  config::Plan plan_;
  std::unique_ptr<BuiltLine> line_;
  LineConsole console_;
};

TEST_F(EthercatLineConsole, PowerLossAndReturn) {
  ASSERT_EQ(count(*line_), 3);
  ASSERT_EQ(count(*line_), 3);
  EXPECT_EQ(console_.command("status"),
            "status: ec0:1 generic-io station=0x0000 state=INIT code=0x0000 frames=2; ec0:2 generic-io station=0x0000 "
            "state=INIT code=0x0000 frames=2; ec0:3 generic-io station=0x0000 state=INIT code=0x0000 frames=2;");
  // Slave 2 off: it and slave 3 behind it vanish from the count.
  EXPECT_EQ(console_.command("power-off 2"), "ok power-off ec0:2");
  EXPECT_EQ(count(*line_), 1);
  EXPECT_EQ(console_.command("status"),
            "status: ec0:1 generic-io station=0x0000 state=INIT code=0x0000 frames=3; ec0:2 generic-io off; ec0:3 "
            "generic-io station=0x0000 state=INIT code=0x0000 frames=2;");
  // Addresses set and PRE-OP reached before the power came back: slave 2 restarts in INIT at 0.
  const std::array<std::uint8_t, 2> station{0x01, 0x10};
  ASSERT_TRUE(through(*line_, Command::APWR, physical_address(auto_increment_adp(0), reg::kStationAddress), 2, station));
  request(0, AlState::PreOp);
  EXPECT_EQ(console_.command("power-on ec0:2"), "ok power-on ec0:2");
  EXPECT_EQ(count(*line_), 3);
  EXPECT_EQ(line_->slave(1).esc->state(), AlState::Init);
  const std::string s = console_.command("status");
  EXPECT_NE(s.find("ec0:1 generic-io station=0x1001 state=PRE-OP code=0x0000 frames=6;"), std::string::npos) << s;
  EXPECT_NE(s.find("ec0:2 generic-io station=0x0000 state=INIT code=0x0000 frames=3;"), std::string::npos) << s;
}

TEST_F(EthercatLineConsole, CableBreakDropAndCorrupt) {
  EXPECT_EQ(console_.command("break-after 1"), "ok break-after ec0:1");
  EXPECT_EQ(count(*line_), 1);
  EXPECT_NE(console_.command("status").find(" ec0 cable cut after 1;"), std::string::npos);
  EXPECT_EQ(console_.command("mend"), "ok mend ec0");
  EXPECT_EQ(count(*line_), 3);

  EXPECT_EQ(console_.command("drop 2"), "ok drop ec0 2");
  EXPECT_FALSE(count(*line_));
  EXPECT_FALSE(count(*line_));
  EXPECT_EQ(count(*line_), 3);

  // A corrupted frame is lost at the first slave, which counts it in its RX error counter (0300h).
  EXPECT_EQ(console_.command("corrupt 2 ec0"), "ok corrupt ec0 2");
  EXPECT_FALSE(count(*line_));
  EXPECT_FALSE(count(*line_));
  const auto errors = through(*line_, Command::APRD, physical_address(auto_increment_adp(0), reg::kRxErrorCounter), 1);
  ASSERT_TRUE(errors);
  EXPECT_EQ(errors->data.at(0), 2);
  EXPECT_EQ(line_->line().counters().corrupted, 2U);
  EXPECT_EQ(line_->line().counters().dropped, 2U);
}

TEST_F(EthercatLineConsole, AStuckSlaveRefusesWithItsCode) {
  EXPECT_EQ(console_.command("stick 2 pre-op 0x001A"), "ok stick ec0:2 PRE-OP 0x001A (synchronization error)");
  request(1, AlState::PreOp);
  EXPECT_EQ(line_->slave(1).esc->state(), AlState::PreOp);
  request(1, AlState::SafeOp);
  EXPECT_EQ(line_->slave(1).esc->state(), AlState::PreOp);
  EXPECT_EQ(line_->slave(1).esc->al_status_code(), 0x001A);
  EXPECT_NE(console_.command("status").find("ec0:2 generic-io station=0x0000 state=PRE-OP+ERR code=0x001A frames=2 "
                                            "stuck=PRE-OP;"),
            std::string::npos)
      << console_.command("status");
  EXPECT_EQ(console_.command("unstick 2"), "ok unstick ec0:2");
  EXPECT_FALSE(line_->stuck_at(1));
}

TEST_F(EthercatLineConsole, BadCommandsAreAnsweredWithTheReason) {
  EXPECT_EQ(console_.command("power-off 9"), "error: no simulated EtherCAT slave 9 (the line has 3)");
  EXPECT_EQ(console_.command("power-off 0"), "error: \"0\" is not a slave position 1.. (or BUS:K)");
  EXPECT_EQ(console_.command("power-off"), "error: power-off takes K");
  EXPECT_EQ(console_.command("power-on ec9:1"), "error: no simulated EtherCAT line ec9");
  EXPECT_EQ(console_.command("drop 0"), "error: drop takes N [BUS] (N frames, 1..1000000)");
  EXPECT_EQ(console_.command("mend ec9"), "error: no simulated EtherCAT line ec9");
  EXPECT_EQ(console_.command("stick 1 OP 0x11"),
            "error: stick: \"OP\" is not INIT, PRE-OP or SAFE-OP (unstick lifts the limit)");
  EXPECT_EQ(console_.command("stick 1 SAFE-OP 0x10000"), "error: stick: the AL status code is 0x0001..0xFFFF, got \"0x10000\"");
  EXPECT_EQ(console_.command("stick 1"),
            "error: stick takes K STATE CODE (STATE INIT, PRE-OP or SAFE-OP; CODE 0x0001..0xFFFF)");
  EXPECT_EQ(console_.command("status now"), "error: status takes no arguments");
  EXPECT_EQ(console_.command("reboot 1").rfind("error: unknown command \"reboot\" (power-off K, ", 0), 0U);
  EXPECT_EQ(console_.command("   "), "error: empty command");
}

}  // namespace
}  // namespace drivegate::ethercat::sim

namespace drivegate::ethercat::sim {
namespace {

// `io K [BYTE...]`: the bytes the master wrote reach the slave's outputs, the inputs are set from
// the console (the slave does not loop them back); `drive K` names what is not a drive.
TEST_F(EthercatLineConsole, IoShowsAndSetsAGenericSlavesBytes) {
  EXPECT_EQ(console_.command("io 1"), "io ec0:1 out=0000 in=0000");
  EXPECT_EQ(console_.command("io 1 0x12 52"), "ok io ec0:1 out=0000 in=1234");
  EXPECT_EQ(console_.command("io 3 0xAB"), "ok io ec0:3 out= in=ab000000");
  EXPECT_EQ(console_.command("io 1"), "io ec0:1 out=0000 in=1234");
  EXPECT_EQ(console_.command("io 2 1 2"), "error: io: ec0:2 has 1 input bytes");
  EXPECT_EQ(console_.command("io 2 0x100"), "error: io: \"0x100\" is not a byte (0..255 or 0x00..0xFF)");
  EXPECT_EQ(console_.command("io"), "error: io takes K [BYTE...]");
  EXPECT_EQ(console_.command("drive 1"), "error: ec0:1 (generic-io) is not a CiA 402 drive");
  EXPECT_EQ(console_.command("drive 1 2"), "error: drive takes K");
}

TEST(EthercatLineConsoleDrive, DriveShowsTheModel) {
  const config::Plan plan = plan_of(R"(gateway: { name: simtool-test }
buses:
  - { name: ec0, type: ethercat, cycle_time: 1ms, options: { interface: eth1 } }
axes:
  - { name: x, bus: ec0, address: 1, device: generic-cia402, mechanics: { encoder_counts_per_rev: 4096 } }
)");
  const auto line = build_line(plan.buses.at(0));
  LineConsole console;
  console.add(*line);
  const std::string d = console.command("drive 1");
  EXPECT_EQ(d.rfind("drive ec0:1 generic-cia402 state=", 0), 0U) << d;
  EXPECT_NE(d.find(" pos=0 error=0x0000 sync0=off"), std::string::npos) << d;
  EXPECT_EQ(console.command("io 1"), "error: ec0:1 (generic-cia402) is not a generic I/O slave");
  EXPECT_EQ(console.command("power-off 1"), "ok power-off ec0:1");
  EXPECT_EQ(console.command("drive 1"), "drive ec0:1 generic-cia402 off");
}

}  // namespace
}  // namespace drivegate::ethercat::sim
