// The `ethercat:` section of device profiles (config/ethercat/device_section.cpp): the reference
// drive's profile as the digest describes it, and what the reader refuses.
#include <gtest/gtest.h>

#include <algorithm>

#include "config/device_profile.hpp"
#include "config/ethercat/plan.hpp"
#include "tests/config/test_support.hpp"

namespace drivegate::config::test {
namespace {

namespace fs = std::filesystem;

TEST(EthercatProfiles, EsrTriodriveIsTheDigestsDrive) {
  const DeviceProfile p = load_device_profile(fs::path{DRIVEGATE_DEVICE_DIR_SOURCE} / "esr-triodrive.yaml");
  ASSERT_TRUE(p.has_section<EthercatDeviceSpec>());
  const auto& e = p.section<EthercatDeviceSpec>();
  // Vendor 15, product 6755/6745 read both as hex-coded and as decimal (dunker-ethercat-coe.md §10).
  ASSERT_EQ(e.identities.size(), 4U);
  for (const auto& id : e.identities) EXPECT_EQ(id.vendor_id, 0x0FU);
  EXPECT_EQ(e.identities[1].product_code, 6755U);
  EXPECT_EQ(e.identities[3].product_code, 6745U);
  EXPECT_FALSE(e.distributed_clocks);  // quirk 9
  EXPECT_FALSE(e.coe_store);           // quirk 10
  EXPECT_EQ(e.max_entries, 8);         // §7.2
  EXPECT_EQ(e.rx_pdo_indexes, (std::vector<std::uint16_t>{0x1600, 0x1601}));
  EXPECT_EQ(e.tx_pdo_indexes, (std::vector<std::uint16_t>{0x1A00, 0x1A01}));
  ASSERT_EQ(e.rxpdos.size(), 1U);
  EXPECT_EQ(e.rxpdos[0].index, 0x1600);
  ASSERT_EQ(e.rxpdos[0].entries.size(), 7U);
  // 6060h mapped as 16 bits: the raw entry 60600010h (§7.1, quirk 1).
  EXPECT_EQ(e.rxpdos[0].entries[1].object, (cia402::ObjectId{0x6060, 0}));
  EXPECT_EQ(e.rxpdos[0].entries[1].bits, 16);
  EXPECT_EQ(e.rxpdos[0].bits(), 16 + 16 + 32 + 32 + 32 + 16 + 16);
  ASSERT_EQ(e.txpdos.size(), 1U);
  EXPECT_EQ(e.txpdos[0].entries[1].bits, 16);  // 6061h
  // 6007h := 1, or a dead master leaves the drive running (§8.2, quirk 6).
  ASSERT_EQ(e.startup_writes.size(), 1U);
  EXPECT_EQ(e.startup_writes[0].def.id, (cia402::ObjectId{0x6007, 0}));
  EXPECT_EQ(e.startup_writes[0].value, 1);
  EXPECT_EQ(e.ignored_writes.size(), 4U);  // quirk 8
  // The cyclic image comes from the PDOs, outputs first.
  ASSERT_EQ(p.cyclic_objects.size(), 14U);
  EXPECT_EQ(p.cyclic_objects[0], (cia402::ObjectId{0x6040, 0}));
  EXPECT_EQ(p.cyclic_objects[4], (cia402::ObjectId{0x60C1, 1}));
}

TEST(EthercatProfiles, GenericDriveRunsOnDistributedClocksWithItsCyclicObjects) {
  const DeviceProfile p = load_device_profile(fs::path{DRIVEGATE_DEVICE_DIR_SOURCE} / "generic-cia402.yaml");
  ASSERT_TRUE(p.has_section<EthercatDeviceSpec>());
  const auto& e = p.section<EthercatDeviceSpec>();
  EXPECT_TRUE(e.identities.empty());  // any CiA 402 slave
  EXPECT_TRUE(e.distributed_clocks);
  EXPECT_EQ(e.max_entries, 254);
  std::size_t mapped = 0;
  for (const auto* pdos : {&e.rxpdos, &e.txpdos})
    for (const auto& pdo : *pdos) mapped += pdo.entries.size();
  EXPECT_EQ(mapped, p.cyclic_objects.size());
}

constexpr const char* kHead = R"(name: ecat-drive
vendor: test
modes: [csp]
units:
  position: { per_rev: counts }
  velocity: { unit: position_per_s }
  acceleration: { unit: position_per_s2 }
)";

class EthercatProfileErrors : public TempDir {
 protected:
  std::string errors_of_profile(const std::string& body) {
    const auto file = write("ecat-drive.yaml", std::string{kHead} + body);
    Problems problems;
    const auto p = parse_device_profile(file, problems, BusTypeRegistry::builtin());
    std::string out;
    for (const auto& d : problems.errors()) out += d.to_string() + "\n";
    if (p) out += "(parsed)";
    return out;
  }
};

TEST_F(EthercatProfileErrors, TheDevicesLimitsAreEnforced) {
  const std::string e = errors_of_profile(R"(ethercat:
  pdo_indexes: { rx: [0x1600], tx: [0x1A00] }
  max_entries: 2
  mappable: { rx: ["0x6040", "0x607A"], tx: ["0x6041", "0x6064"] }
  rxpdos:
    - { index: 0x1601, map: ["0x6040 u16", "0x607A i32", "0x60FF i32"] }
  txpdos:
    - { index: 0x1A00, map: ["0x6041 u16", "0x6064 i32"] }
)");
  EXPECT_REPORTED(e, "ethercat.rxpdos[0].index: 0x1601 is not a mapping object of this device; it has 0x1600");
  EXPECT_REPORTED(e, "ethercat.rxpdos[0].map: 3 entries mapped, a PDO of this device holds at most 2");
  EXPECT_REPORTED(e, "ethercat.rxpdos[0].map[2]: 0x60FF may not be mapped into an RxPDO of this device (its "
                     "rx_mappable list)");
  EXPECT_EQ(e.find("(parsed)"), std::string::npos);
}

TEST_F(EthercatProfileErrors, SixteenBitModeObjectsNeedTheQuirk) {
  const std::string e = errors_of_profile(R"(cyclic_objects: ["0x6040", "0x6060", "0x607A", "0x6041", "0x6061"]
ethercat:
  rxpdos: [{ index: 0x1600, map: ["0x6040 u16", "0x6060 i16", "0x607A i32"] }]
  txpdos: [{ index: 0x1A00, map: ["0x6041 u16", "0x6061 i16"] }]
)");
  EXPECT_REPORTED(e, "ethercat.rxpdos[0].map[1]: 0x6060 is i8 in CiA 402, got i16 (a device with 16-bit mode "
                     "objects needs quirk mode_objects_16bit)");
  const std::string ok = errors_of_profile(R"(quirks: { mode_objects_16bit: true }
ethercat:
  rxpdos: [{ index: 0x1600, map: ["0x6040 u16", "0x6060 i16", "0x607A i32"] }]
  txpdos: [{ index: 0x1A00, map: ["0x6041 u16", "0x6061 i16"] }]
)");
  EXPECT_EQ(ok, "(parsed)");
  const std::string narrow = errors_of_profile(R"(quirks: { mode_objects_16bit: true }
ethercat:
  rxpdos: [{ index: 0x1600, map: ["0x6040 u16", "0x6060 i8", "0x607A i32"] }]
  txpdos: [{ index: 0x1A00, map: ["0x6041 u16"] }]
)");
  EXPECT_REPORTED(narrow, "ethercat.rxpdos[0].map[1]: 0x6060 is INTEGER16 on this device (quirk mode_objects_16bit), got i8");
}

TEST_F(EthercatProfileErrors, ControlwordStatuswordAndGatewayOwnedObjects) {
  const std::string e = errors_of_profile(R"(cyclic_objects: ["0x6040", "0x6041", "0x607A"]
ethercat:
  rxpdos: [{ index: 0x1600, map: ["0x607A i32"] }]
  txpdos: [{ index: 0x1A00, map: ["0x6064 i32", "0x607A i32"] }]
  startup_writes:
    - { object: "0x1C12:1", type: u16, value: 0x1601, why: "another PDO" }
    - { object: "0x6040", type: u16, value: 15, why: "enable at once" }
)");
  EXPECT_REPORTED(e, "ethercat.txpdos[0].map[1]: 0x607A is also mapped in ethercat.rxpdos[0].map[0]; an object is either "
                     "sent or received");
  EXPECT_REPORTED(e, "ethercat.rxpdos: must map 0x6040 (controlword)");
  EXPECT_REPORTED(e, "ethercat.txpdos: must map 0x6041 (statusword)");
  EXPECT_REPORTED(e, "ethercat.startup_writes: 0x1C12:1 is a PDO mapping or assignment object");
  EXPECT_REPORTED(e, "ethercat.startup_writes[1].object: 0x6040 is the controlword");
  EXPECT_REPORTED(e, "cyclic_objects: must list exactly the objects of the ethercat PDO maps (or be left out to derive "
                     "them): not mapped: 0x6040 0x6041; mapped but not listed: 0x6064");
}

// Without cyclic_objects the first bus section that maps objects gives the cyclic image (canopen,
// registered first); every other one must map the same objects, whatever the registration order.
TEST_F(EthercatProfileErrors, EveryBusSectionMapsTheSameCyclicImage) {
  const std::string e = errors_of_profile(R"(canopen:
  rpdos: [{ number: 1, map: ["0x6040 u16", "0x607A i32"] }]
  tpdos: [{ number: 1, map: ["0x6041 u16"] }]
ethercat:
  rxpdos: [{ index: 0x1600, map: ["0x6040 u16", "0x607A i32"] }]
  txpdos: [{ index: 0x1A00, map: ["0x6041 u16", "0x6064 i32"] }]
)");
  EXPECT_REPORTED(e, "ethercat: the ethercat PDO maps must carry the same objects as the canopen PDO maps (the cyclic "
                     "image): mapped but not cyclic: 0x6064");
  const std::string same = errors_of_profile(R"(canopen:
  rpdos: [{ number: 1, map: ["0x6040 u16", "0x607A i32"] }]
  tpdos: [{ number: 1, map: ["0x6041 u16"] }]
ethercat:
  rxpdos: [{ index: 0x1600, map: ["0x6040 u16", "0x607A i32"] }]
  txpdos: [{ index: 0x1A00, map: ["0x6041 u16"] }]
)");
  EXPECT_EQ(same, "(parsed)");
}

// A two-axis slave [ETG.6010 §4]: the PDO entries as the slave numbers them (axis 1 at + 800h);
// each axis' cyclic image is axis 0's objects.
TEST(EthercatProfiles, TwoAxisDriveMapsBothAxesAndEachSeesOneImage) {
  const DeviceProfile p = load_device_profile(fs::path{DRIVEGATE_DEVICE_DIR_SOURCE} / "generic-cia402-2axis.yaml");
  ASSERT_TRUE(p.has_section<EthercatDeviceSpec>());
  const auto& e = p.section<EthercatDeviceSpec>();
  EXPECT_EQ(e.axes, 2);
  EXPECT_EQ(e.axis_offset, 0x800);
  EXPECT_EQ(e.persona, "generic-cia402-2axis");
  ASSERT_EQ(e.identities.size(), 1U);
  EXPECT_EQ(e.identities[0].product_code, 0x00020192U);
  ASSERT_EQ(e.rxpdos.size(), 2U);
  ASSERT_EQ(e.txpdos.size(), 2U);
  EXPECT_EQ(e.rxpdos[1].index, 0x1601);
  EXPECT_EQ(e.rxpdos[1].entries[0].object, (cia402::ObjectId{0x6840, 0}));
  EXPECT_EQ(e.txpdos[1].entries[0].object, (cia402::ObjectId{0x6841, 0}));
  EXPECT_EQ(e.rxpdos[1].bits(), e.rxpdos[0].bits());
  // One axis' image: the generic drive's twelve objects, as axis 0 numbers them.
  const DeviceProfile g = load_device_profile(fs::path{DRIVEGATE_DEVICE_DIR_SOURCE} / "generic-cia402.yaml");
  EXPECT_EQ(p.cyclic_objects, g.cyclic_objects);
}

TEST_F(EthercatProfileErrors, EveryAxisOfAMultiAxisSlaveMapsWhatAxisZeroMaps) {
  const std::string e = errors_of_profile(R"(cyclic_objects: ["0x6040", "0x607A", "0x6041", "0x6064"]
ethercat:
  axes: 2
  rxpdos:
    - { index: 0x1600, map: ["0x6040 u16", "0x607A i32"] }
    - { index: 0x1601, map: ["0x6840 u16", "0x6860 i16"] }
  txpdos:
    - { index: 0x1A00, map: ["0x6041 u16", "0x6064 i32"] }
    - { index: 0x1A01, map: ["0x6864 i32"] }
)");
  // 6860h is axis 1's 6060h: INTEGER8 in CiA 402.
  EXPECT_REPORTED(e, "ethercat.rxpdos[1].map[1]: 0x6060 is i8 in CiA 402, got i16 (0x6860 is axis 1's 0x6060)");
  EXPECT_REPORTED(e, "ethercat.rxpdos: axis 1 of the slave (its objects at + 0x0800) must map what axis 0 maps, as axis "
                     "0 numbers them: not mapped: 0x607A 0x6041; mapped but not mapped for axis 0: 0x6060");
  const std::string ok = errors_of_profile(R"(ethercat:
  axes: 2
  axis_offset: 0x100
  rxpdos: [{ index: 0x1600, map: ["0x6040 u16", "0x607A i32", "0x6140 u16", "0x617A i32"] }]
  txpdos: [{ index: 0x1A00, map: ["0x6041 u16", "0x6064 i32", "0x6141 u16", "0x6164 i32"] }]
)");
  EXPECT_EQ(ok, "(parsed)");
}

}  // namespace
}  // namespace drivegate::config::test
