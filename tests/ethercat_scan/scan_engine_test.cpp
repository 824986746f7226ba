// The EtherCAT scan (adapters/ethercat/scan.hpp) on the simulator's line in virtual time: a line
// built from a plan (ESR TrioDrive at 1, a 2-in/1-out I/O slave at 2, a generic CiA 402 drive at 3),
// served through SimLineLink as `transport: sim` serves it. What the slaves are comes from the
// simulator's personas (SII identities, 1000h, 1C12h/1C13h); the profiles are the repository's.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <string>

#include "adapters/ethercat/scan.hpp"
#include "adapters/ethercat/sim/line_builder.hpp"
#include "adapters/ethercat/sim_transport.hpp"
#include "config/loader.hpp"
#include "daemon/scan.hpp"

namespace drivegate::ethercat {
namespace {

using namespace std::chrono_literals;

const char* kLine = R"(gateway: { name: scan-test }
buses:
  - name: ec0
    type: ethercat
    cycle_time: 1ms
    options: { transport: sim }
    io:
      - { name: panel, position: 2, vendor_id: 0x99, product_code: 0x1000, inputs: 2, outputs: 1 }
axes:
  - { name: esr, bus: ec0, address: 1, device: esr-triodrive, mechanics: { encoder_counts_per_rev: 4096 } }
  - { name: gen, bus: ec0, address: 3, device: generic-cia402, mechanics: { encoder_counts_per_rev: 4096 } }
)";

config::LoadOptions load_options() {
  config::LoadOptions o;
  o.device_dirs = {DRIVEGATE_DEVICE_DIR_SOURCE};
  o.bus_types = config::BusTypeRegistry::builtin();
  return o;
}

// Virtual time: every wait moves the clock on and runs the line's PDI side (as SimLinePeer does).
class VirtualClock final : public ScanClock {
 public:
  explicit VirtualClock(SimLinePeer& peer) : peer_(peer) {}
  core::TimePoint now() override { return now_; }
  void wait(core::TimePoint until, const Link&) override {
    now_ = std::max(until, now_);
    peer_.step(now_);
  }
  core::TimePoint now_{std::chrono::seconds(100)};

 private:
  SimLinePeer& peer_;
};

struct Scanned {
  std::vector<ScannedSlave> slaves;
  std::string line_text;
  core::Duration took{};
  std::shared_ptr<sim::BuiltLine> line;
};

Scanned scan(const std::string& yaml, const EthercatScanSettings& settings = {}) {
  const config::Plan plan = config::load_plan_from_string(yaml, "scan-test.yaml", load_options());
  Scanned s;
  s.line = sim::build_line(plan.buses.at(0));
  SimLineLink link(s.line);
  SimLinePeer peer(s.line);
  link.open();
  VirtualClock clock(peer);
  const auto start = clock.now();
  s.slaves = scan_line(link, settings, clock, s.line_text);
  s.took = clock.now() - start;
  return s;
}

std::vector<config::DeviceProfile> profiles() {
  std::vector<std::string> notes;
  auto p = ethercat_scan_profiles({DRIVEGATE_DEVICE_DIR_SOURCE}, config::BusTypeRegistry::builtin(), notes);
  EXPECT_TRUE(notes.empty()) << notes.front();
  return p;
}

TEST(EthercatScan, ThreeSlavesInPreOpWithIdentityMailboxDcAndPdos) {
  const Scanned s = scan(kLine);
  EXPECT_EQ(s.line_text, "");
  ASSERT_EQ(s.slaves.size(), 3U);
  EXPECT_LT(s.took, 10s);
  for (std::size_t k = 0; k < 3; ++k) {
    const ScannedSlave& x = s.slaves[k];
    EXPECT_EQ(x.position, k + 1);
    EXPECT_EQ(x.station, 0x1001 + k);
    EXPECT_TRUE(x.sii_ok);
    EXPECT_TRUE(x.esc_features.has_value()) << k;
    EXPECT_EQ(x.identity, s.line->slave(k).identity) << k;  // the SII's identity
    // Left in PRE-OP, as the simulated ESC says.
    EXPECT_EQ(s.line->slave(k).esc->state(), AlState::PreOp) << k;
    EXPECT_EQ(x.state, AlState::PreOp);
  }
  // The drives: CoE, 1000h names CiA 402 (0192h), PDOs from their 1C12h/1C13h.
  for (const std::size_t k : {0U, 2U}) {
    const ScannedSlave& d = s.slaves[k];
    EXPECT_TRUE(d.coe) << k;
    EXPECT_NE(d.mailbox_protocols & mailbox_protocol::kCoE, 0) << k;
    ASSERT_TRUE(d.device_type.has_value()) << k;
    EXPECT_EQ(*d.device_type & 0xFFFFU, 0x0192U) << k;
    EXPECT_EQ(d.pdo_source, "1C12h/1C13h") << k;
    ASSERT_FALSE(d.rxpdos.empty()) << k;
    ASSERT_FALSE(d.txpdos.empty()) << k;
    // The first RxPDO maps the controlword 6040h:00, 16 bits (every CiA 402 profile's PDOs do).
    ASSERT_FALSE(d.rxpdos[0].entries.empty());
    EXPECT_EQ(d.rxpdos[0].entries[0].index, 0x6040);
    EXPECT_EQ(d.rxpdos[0].entries[0].bits, 16);
    ASSERT_TRUE(d.identity_object[0].has_value());
    EXPECT_EQ(*d.identity_object[0], d.identity.vendor_id);
  }
  // The I/O slave: no CoE, its sizes from the SII's SyncM categories.
  const ScannedSlave& io = s.slaves[1];
  EXPECT_FALSE(io.coe);
  EXPECT_EQ(io.identity.vendor_id, 0x99U);
  EXPECT_EQ(io.identity.product_code, 0x1000U);
  EXPECT_EQ(io.sm_input_bytes, 2U);
  EXPECT_EQ(io.sm_output_bytes, 1U);
  EXPECT_FALSE(io.device_type.has_value());
}

TEST(EthercatScan, ProfilesMatchedAndTheSkeletonPassesTheConfigurationChecks) {
  const Scanned s = scan(kLine);
  core::ScanResult r = ethercat_scan_result(s.slaves, s.line_text, "ecs0", profiles());
  ASSERT_EQ(r.devices.size(), 3U);
  EXPECT_EQ(r.devices[0].profile, "esr-triodrive");
  EXPECT_TRUE(r.devices[0].drive);
  EXPECT_EQ(r.devices[0].address.number, 1);
  EXPECT_EQ(r.devices[0].address.text, "position 1 (1001h)");
  EXPECT_EQ(r.devices[1].profile, "");
  EXPECT_FALSE(r.devices[1].drive);
  EXPECT_EQ(r.devices[2].profile, "generic-cia402");
  EXPECT_TRUE(r.devices[2].drive);
  EXPECT_NE(r.devices[2].profile_reason.find("1000h"), std::string::npos) << r.devices[2].profile_reason;
  ASSERT_EQ(r.bus_lists.size(), 1U);
  EXPECT_EQ(r.bus_lists[0].first, "io");
  ASSERT_EQ(r.bus_lists[0].second.size(), 1U);
  EXPECT_EQ(r.bus_lists[0].second[0],
            "{ name: io-2, position: 2, vendor_id: 0x00000099, product_code: 0x00001000, inputs: 2, outputs: 1 }");

  const std::string table = daemon::format_scan_table(r);
  EXPECT_NE(table.find("3 devices"), std::string::npos) << table;
  EXPECT_NE(table.find("mailbox protocols: CoE"), std::string::npos) << table;
  EXPECT_NE(table.find("distributed clocks: "), std::string::npos) << table;
  EXPECT_NE(table.find("PDOs (1C12h/1C13h): outputs 1600h [6040:00/16"), std::string::npos) << table;

  const std::string yaml = daemon::scan_skeleton(r, load_options());
  EXPECT_NE(yaml.find("    io:\n      - { name: io-2, position: 2"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("device: esr-triodrive"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("device: generic-cia402"), std::string::npos) << yaml;
  // What --check-config runs: the loader with the build's registry.
  const config::Plan plan = config::load_plan_from_string(yaml, "skeleton.yaml", load_options());
  ASSERT_EQ(plan.buses.size(), 1U);
  EXPECT_EQ(plan.buses[0].axes.size(), 2U);
  EXPECT_EQ(plan.buses[0].section<config::EthercatBusOptions>().interface, "ecs0");
  ASSERT_EQ(plan.buses[0].section<config::EthercatBusOptions>().io.size(), 1U);
}

// A two-axis slave (objects 800h apart per axis) becomes two axes of the skeleton, each picked by
// its `ethercat: { axis: N }`, and the configuration checks take both.
TEST(EthercatScan, MultiAxisSlaveGivesOneSkeletonAxisPerAxis) {
  const Scanned s = scan(R"(gateway: { name: scan-test }
buses:
  - { name: ec0, type: ethercat, cycle_time: 1ms, options: { transport: sim } }
axes:
  - { name: x, bus: ec0, address: 1, device: generic-cia402-2axis, ethercat: { axis: 0 },
      mechanics: { encoder_counts_per_rev: 4096 } }
  - { name: y, bus: ec0, address: 1, device: generic-cia402-2axis, ethercat: { axis: 1 },
      mechanics: { encoder_counts_per_rev: 4096 } }
)");
  core::ScanResult r = ethercat_scan_result(s.slaves, s.line_text, "ecs0", profiles());
  ASSERT_EQ(r.devices.size(), 1U);
  EXPECT_EQ(r.devices[0].profile, "generic-cia402-2axis") << r.devices[0].profile_reason;
  EXPECT_EQ(r.devices[0].axis_keys, (std::vector<std::string>{"ethercat: { axis: 0 }", "ethercat: { axis: 1 }"}));
  const std::string yaml = daemon::scan_skeleton(r, load_options());
  EXPECT_NE(yaml.find("  - name: generic-cia402-2axis-1-0 "), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("  - name: generic-cia402-2axis-1-1 "), std::string::npos) << yaml;
  const config::Plan plan = config::load_plan_from_string(yaml, "skeleton.yaml", load_options());
  ASSERT_EQ(plan.buses.at(0).axes.size(), 2U);
  for (int n = 0; n < 2; ++n) {
    const auto& axis = plan.buses[0].axes[static_cast<std::size_t>(n)];
    EXPECT_EQ(axis.address, 1);
    EXPECT_EQ(axis.section<config::EthercatAxisSpec>().slave_axis, n);
  }
}

// SDO Information [ETG.1000.6 §5.6.3]: the drives' SIIs offer it (CoE details bit 1), so their
// object lists are read (counted by area in the table); with objects=1 every object's name too.
// The I/O slave has no mailbox: nothing to list.
TEST(EthercatScan, SdoInformationListsTheDrivesObjects) {
  const Scanned s = scan(kLine);
  for (const std::size_t k : {0U, 2U}) {
    const ScannedSlave& d = s.slaves[k];
    EXPECT_TRUE(d.sdo_info) << k;
    ASSERT_TRUE(d.objects_read) << k;
    // The list is the simulated drive's own dictionary, in its order.
    auto* od = s.line->slave(k).parts.app->object_dictionary();
    ASSERT_NE(od, nullptr);
    std::vector<std::uint16_t> truth(1024);
    truth.resize(od->list(OdListType::All, truth));
    ASSERT_EQ(d.objects.size(), truth.size()) << k;
    for (std::size_t i = 0; i < truth.size(); ++i) EXPECT_EQ(d.objects[i].index, truth[i]) << k << "/" << i;
    EXPECT_TRUE(d.objects[0].name.empty());  // names only with objects=1
    for (const auto& n : d.notes) EXPECT_EQ(n.find("SDO Information"), std::string::npos) << n;
  }
  EXPECT_FALSE(s.slaves[1].objects_read);
  core::ScanResult r = ethercat_scan_result(s.slaves, s.line_text, "ecs0", profiles());
  std::string table = daemon::format_scan_table(r);
  const std::string count = "object dictionary (SDO Information): " + std::to_string(s.slaves[2].objects.size()) +
                            " objects: ";
  EXPECT_NE(table.find(count), std::string::npos) << table;
  EXPECT_NE(table.find("communication (1000h-1FFFh)"), std::string::npos) << table;
  EXPECT_NE(table.find("profile (6000h-9FFFh)"), std::string::npos) << table;
  EXPECT_EQ(table.find("6040h Controlword"), std::string::npos) << table;

  EthercatScanSettings named;
  named.object_names = true;
  const Scanned n = scan(kLine, named);
  EXPECT_LT(n.took, 10s);
  const ScannedSlave& gen = n.slaves[2];
  ASSERT_TRUE(gen.objects_read);
  const auto it = std::find_if(gen.objects.begin(), gen.objects.end(), [](const auto& o) { return o.index == 0x6040; });
  ASSERT_NE(it, gen.objects.end());
  EXPECT_EQ(it->name, "Controlword");
  for (const auto& o : gen.objects) EXPECT_FALSE(o.name.empty()) << std::hex << o.index;
  r = ethercat_scan_result(n.slaves, n.line_text, "ecs0", profiles());
  table = daemon::format_scan_table(r);
  EXPECT_NE(table.find("\n      6040h Controlword\n"), std::string::npos) << table;
  EXPECT_NE(table.find("\n      1C12h Sync manager 2 PDO assignment (array)\n"), std::string::npos) << table;
}

TEST(EthercatScan, AnEmptyLineHasNoDevices) {
  // No slave at all: the count's BRD comes back with WKC 0 (a line of zero simulated slaves).
  auto line = std::make_shared<sim::BuiltLine>("empty");
  line->open();
  SimLineLink link(line);
  SimLinePeer peer(line);
  VirtualClock clock(peer);
  std::string text;
  const auto slaves = scan_line(link, EthercatScanSettings{}, clock, text);
  EXPECT_TRUE(slaves.empty());
  EXPECT_FALSE(text.empty());
  const core::ScanResult r = ethercat_scan_result(slaves, text, "ecs0", profiles());
  EXPECT_NE(daemon::format_scan_table(r).find("no devices answered"), std::string::npos);
}

TEST(EthercatScan, ThePlanTakesAnInterfaceAndRefusesOtherOptions) {
  const auto types = config::BusTypeRegistry::builtin();
  core::ScanRequest q;
  q.bus_type = "ethercat";
  q.where = "eth1";
  EXPECT_EQ(ethercat_scan_plan(q, types).section<config::EthercatBusOptions>().interface, "eth1");
  q.where = "raw?interface=eth2&sdo_timeout=2s";
  const auto p = ethercat_scan_plan(q, types);
  EXPECT_EQ(p.section<config::EthercatBusOptions>().interface, "eth2");
  EXPECT_EQ(p.section<config::EthercatBusOptions>().sdo_timeout, 2s);
  q.where = "eth1?bitrate=5";
  EXPECT_THROW(ethercat_scan_plan(q, types), core::ScanError);
  // objects: the scan's own option, not the bus'.
  q.where = "eth1?objects=1";
  EXPECT_EQ(ethercat_scan_plan(q, types).section<config::EthercatBusOptions>().interface, "eth1");
  EXPECT_TRUE(ethercat_scan_object_names(q));
  q.where = "eth1";
  EXPECT_FALSE(ethercat_scan_object_names(q));
  q.where = "eth1?objects=2";
  EXPECT_THROW(ethercat_scan_plan(q, types), core::ScanError);
  q.where = "sim";
  EXPECT_THROW(ethercat_scan_plan(q, types), core::ScanError);
  q.where = "";
  EXPECT_THROW(ethercat_scan_plan(q, types), core::ScanError);
}

}  // namespace
}  // namespace drivegate::ethercat
