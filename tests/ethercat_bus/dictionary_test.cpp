// The drives' object names read over SDO Information once they are in OP [ETG.1000.6 §5.6.3]:
// names resolve to the object, sub-index and type once read (case, spaces and underscores aside),
// ambiguous ones are refused with the candidates, a client's SDO is not held up behind the reading,
// a drive without SDO Information gets a sentence saying so, the names are read again after a
// power loss, and nothing allocates in the cycle while they are read.
#include <gtest/gtest.h>

#include "tests/ethercat_bus/bus_harness.hpp"
#include "tests/support/alloc_counter.hpp"

namespace drivegate::ethercat::test {
namespace {

using State = SlaveDictionary::State;

// Slave index of the harness' generic drive (position 3) and of the ESR (position 1).
constexpr std::size_t kGen = 2;
constexpr std::size_t kEsr = 0;

const SlaveDictionary& dict(const EcatHarness& h, std::size_t slave) { return *h.bus->dictionary(slave); }

bool read_all(EcatHarness& h) {
  return h.run_until([&] { return dict(h, kGen).state() == State::Done && dict(h, kEsr).state() == State::Done; }, 60s);
}

void expect_object(const core::NamedObject& o, std::uint16_t index, std::uint8_t sub, core::ParamType type) {
  ASSERT_TRUE(o.found) << o.error;
  EXPECT_EQ(o.index, index);
  EXPECT_EQ(o.sub, sub);
  EXPECT_EQ(o.type, type);
}

TEST(EthercatDictionary, NamesResolveToObjectSubAndTypeOnceRead) {
  EcatHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details();
  ASSERT_TRUE(read_all(h)) << "gen " << dict(h, kGen).progress() << " of " << dict(h, kGen).listed();
  EXPECT_GT(dict(h, kGen).listed(), 20U);
  EXPECT_EQ(dict(h, kGen).progress(), dict(h, kGen).listed());
  const std::size_t gen = h.axis("gen");
  const std::size_t esr = h.axis("esr");
  expect_object(h.bus->find_object(gen, "Controlword"), 0x6040, 0, core::ParamType::U16);
  expect_object(h.bus->find_object(gen, "  position_ACTUAL   value "), 0x6064, 0, core::ParamType::I32);
  expect_object(h.bus->find_object(gen, "identity:serial_number"), 0x1018, 4, core::ParamType::U32);
  expect_object(h.bus->find_object(gen, "Sync manager 2 parameter:Synchronization type"), 0x1C32, 1,
                core::ParamType::U16);
  // The ESR's own types and manufacturer objects (dunker-ethercat-coe.md §7.3, quirk 1).
  expect_object(h.bus->find_object(esr, "modes of operation"), 0x6060, 0, core::ParamType::I16);
  expect_object(h.bus->find_object(esr, "acceleration time"), 0x5EF4, 0, core::ParamType::U32);
  EXPECT_NE(h.bus->find_object(esr, "acceleration time").source.find("slave 1"), std::string::npos);

  // Every mapping object has a "SubIndex 001": the name is refused with the candidates.
  const core::NamedObject twice = h.bus->find_object(gen, "Receive PDO mapping:SubIndex 001");
  EXPECT_FALSE(twice.found);
  EXPECT_NE(twice.error.find("names "), std::string::npos) << twice.error;
  EXPECT_NE(twice.error.find("1600:1 'Receive PDO mapping:SubIndex 001'"), std::string::npos) << twice.error;
  EXPECT_NE(twice.error.find("1601:1"), std::string::npos) << twice.error;

  const core::NamedObject none = h.bus->find_object(gen, "Flux capacitor");
  EXPECT_FALSE(none.found);
  EXPECT_NE(none.error.find("no object named 'Flux capacitor' in the dictionary of slave 3 ("), std::string::npos)
      << none.error;
  // The I/O slave has no axis; a bus axis out of range has no names.
  EXPECT_TRUE(h.bus->find_object(99, "Controlword").error.empty());
}

TEST(EthercatDictionary, NamesWaitUntilTheWholeListIsRead) {
  EcatHarness h;
  const std::size_t gen = h.axis("gen");
  const core::NamedObject early = h.bus->find_object(gen, "Controlword");
  EXPECT_FALSE(early.found);
  EXPECT_NE(early.error.find("is read over SDO Information once it is in OP"), std::string::npos) << early.error;
  ASSERT_TRUE(h.run_until([&] { return dict(h, kGen).state() == State::Reading && dict(h, kGen).progress() > 3; }, 10s))
      << h.details();
  const core::NamedObject reading = h.bus->find_object(gen, "Controlword");
  EXPECT_FALSE(reading.found);
  const std::string want = "the dictionary of slave 3 is still being read (" + std::to_string(dict(h, kGen).progress()) +
                           " of " + std::to_string(dict(h, kGen).listed()) + " objects); use INDEX:SUB or try again";
  EXPECT_EQ(reading.error, want);
}

// A client's upload while the names are read waits for at most the one dictionary request in
// flight: no longer than two uploads on an idle mailbox.
TEST(EthercatDictionary, ClientSdoGoesFirst) {
  EcatHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details();
  ASSERT_TRUE(h.run_until([&] { return dict(h, kGen).progress() > 5; }, 10s));
  std::vector<core::Duration> during;
  for (int i = 0; i < 5; ++i) {
    ASSERT_EQ(dict(h, kGen).state(), State::Reading);
    const auto start = h.now;
    const core::ParamReply r = h.param("gen", false, 0x1018, 2, core::ParamType::U32);
    ASSERT_TRUE(r.ok) << r.error.view();
    during.push_back(h.now - start);
    h.cycle();  // the dictionary's next request goes out first, then ours again
  }
  ASSERT_TRUE(read_all(h));
  const auto start = h.now;
  ASSERT_TRUE(h.param("gen", false, 0x1018, 2, core::ParamType::U32).ok);
  const core::Duration idle = h.now - start;
  for (const core::Duration d : during) EXPECT_LE(d, 2 * idle) << "idle mailbox: " << idle.count() << " ns";
}

// The ESR's SII without SDO Information: the bus does not ask it, and says so.
TEST(EthercatDictionary, SlaveWithoutSdoInformationSaysSo) {
  EcatHarness h(kLine, false);
  const auto& bp = h.plan.buses.at(0);
  for (const auto& a : bp.axes) h.specs.push_back(a.spec);
  auto memory = std::make_unique<MemoryLink>(64);
  h.link = memory.get();
  h.line = std::make_unique<sim::SimLine>(*h.link);
  sim::Cia402SlaveOptions no_info;
  no_info.sdo_information = false;
  h.esr = sim::make_cia402_device("esr-triodrive", no_info);
  h.panel = std::make_unique<sim::GenericIoSlave>(2, 2, kPanelId);
  h.panel_esc = std::make_unique<sim::EscSlave>(sim::EscConfig{}, h.panel->sii(), h.panel.get());
  h.gen = sim::make_cia402_device("generic-cia402");
  h.line->add(*h.esr.esc);
  h.line->add(*h.panel_esc);
  h.line->add(*h.gen.esc);
  h.bus = std::make_unique<EthercatBus>(bp, std::move(memory), std::make_unique<LinePeer>(*h.line));
  h.runner = std::make_unique<core::BusRunner>(*h.bus, h.specs);
  h.bus->open(h.now);
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details();
  h.cycle();
  EXPECT_EQ(dict(h, kEsr).state(), State::Unsupported);
  EXPECT_EQ(h.bus->find_object(h.axis("esr"), "Controlword").error,
            "slave 1 does not support SDO Information (mailbox CoE details in its SII); give the axis an `esi:` file or "
            "use INDEX:SUB");
  ASSERT_TRUE(h.run_until([&] { return dict(h, kGen).state() == State::Done; }, 60s));
  expect_object(h.bus->find_object(h.axis("gen"), "Controlword"), 0x6040, 0, core::ParamType::U16);
}

// After a power loss the drive is configured from scratch, and its names are read again.
TEST(EthercatDictionary, ReadAgainAfterTheSlaveComesBack) {
  EcatHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details();
  ASSERT_TRUE(read_all(h));
  const std::size_t listed = dict(h, kGen).listed();
  h.line->power_off(2);
  ASSERT_TRUE(h.run_until([&] { return h.bus->link_state(h.axis("gen")) == core::LinkState::Lost; }, 2s));
  h.line->power_on(2);
  ASSERT_TRUE(h.run_until([&] { return h.up("gen"); }, 10s)) << h.details();
  h.cycle();
  EXPECT_EQ(dict(h, kGen).state(), State::Reading);
  EXPECT_NE(h.bus->find_object(h.axis("gen"), "Controlword").error.find("still being read"), std::string::npos);
  ASSERT_TRUE(h.run_until([&] { return dict(h, kGen).state() == State::Done; }, 60s));
  EXPECT_EQ(dict(h, kGen).listed(), listed);
  expect_object(h.bus->find_object(h.axis("gen"), "Controlword"), 0x6040, 0, core::ParamType::U16);
  EXPECT_EQ(h.bus->restarts(kGen), 1U);
}

// The reading runs in the cycle: nothing allocates while the names come in.
TEST(EthercatDictionary, NoAllocationPerCycleWhileReading) {
  EcatHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details();
  ASSERT_TRUE(h.run_until([&] { return dict(h, kGen).progress() > 0; }, 10s));
  const std::size_t before = dict(h, kGen).progress();
  {
    const drivegate::test::AllocationScope scope;
    for (int i = 0; i < 500; ++i) {
      h.now += 1ms;
      h.runner->cycle(h.now);
    }
    EXPECT_EQ(scope.count(), 0U);
  }
  EXPECT_EQ(dict(h, kGen).state(), State::Reading);
  EXPECT_GT(dict(h, kGen).progress(), before);
}

}  // namespace
}  // namespace drivegate::ethercat::test
