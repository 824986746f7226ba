// The CANopen device profiles in the tree, and every problem a profile's canopen section can have.
#include <gtest/gtest.h>

#include <algorithm>

#include "config/canopen/plan.hpp"
#include "config/device_profile.hpp"
#include "config/object_text.hpp"
#include "tests/config/test_support.hpp"

namespace drivegate::config {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using cia402::ObjectId;

DeviceProfile load(const std::string& name) {
  return load_device_profile(fs::path{DRIVEGATE_DEVICE_DIR_SOURCE} / (name + ".yaml"));
}

std::vector<std::string> map_text(const PdoSpec& pdo) {
  std::vector<std::string> out;
  for (const auto& e : pdo.entries) out.push_back(object_text(e.object) + " " + std::string{to_string(e.type)});
  return out;
}

using Strings = std::vector<std::string>;

bool lists(const DeviceProfile& p, ObjectId id) {
  return std::find(p.cyclic_objects.begin(), p.cyclic_objects.end(), id) != p.cyclic_objects.end();
}

bool has_write(const DeviceProfile& p, ObjectId id) {
  for (const auto& w : p.section<CanopenDeviceSpec>().startup_writes)
    if (w.def.id == id) return true;
  return false;
}
// The profile's start-up write of `id` (an empty one when there is none: has_write() says).
const StartupWrite& write_of(const DeviceProfile& p, ObjectId id) {
  static const StartupWrite kNone{};
  for (const auto& w : p.section<CanopenDeviceSpec>().startup_writes)
    if (w.def.id == id) return w;
  return kNone;
}

TEST(CanopenProfiles, KollmorgenAkd) {
  const DeviceProfile p = load("kollmorgen-akd");
  ASSERT_TRUE(p.has_section<CanopenDeviceSpec>());
  const auto& co = p.section<CanopenDeviceSpec>();
  EXPECT_EQ(p.identity.vendor_id, 0x6AU);
  EXPECT_EQ(co.device_type, 0x00020192U);
  EXPECT_EQ(co.device_type_mask, 0x00FFFFFFU);
  EXPECT_EQ(co.persona, "akd");
  EXPECT_EQ(co.error_control, ErrorControl::Heartbeat);
  EXPECT_TRUE(co.consumer_heartbeat);
  EXPECT_EQ(co.pdo_policy, PdoPolicy::Write);
  for (const auto m : {core::Mode::ProfilePosition, core::Mode::ProfileVelocity, core::Mode::ProfileTorque,
                       core::Mode::Homing, core::Mode::InterpolatedPosition, core::Mode::CyclicPosition})
    EXPECT_TRUE(p.modes.contains(m));
  EXPECT_FALSE(p.modes.contains(core::Mode::Velocity));
  EXPECT_FALSE(p.modes.contains(core::Mode::CyclicVelocity));
  EXPECT_EQ(p.homing_methods, (std::vector<std::int16_t>{-7, -6, -5, -4, -3, 1, 2, 8, 12, 17, 18, 24, 28, 33, 34, 35}));
  // Units: 2^20 per rev by the factor-group writes, velocity 1/1000 rpm.
  const core::NativeUnits n = p.units.resolve(4096);
  EXPECT_DOUBLE_EQ(n.position_per_rev, 1048576.0);
  EXPECT_DOUBLE_EQ(n.velocity_per_rps, 60000.0);
  EXPECT_DOUBLE_EQ(n.acceleration_per_rps2, 1048576.0);
  ASSERT_TRUE(has_write(p, {0x36E9, 0}));
  EXPECT_EQ(write_of(p, {0x36E9, 0}).value & 0x11, 0x11);  // fault reset via CW only, CiA 402 scaling
  for (const cia402::ObjectId id : {cia402::ObjectId{0x6092, 1}, {0x608F, 1}, {0x605A, 0}})
    ASSERT_TRUE(has_write(p, id)) << std::hex << id.index;
  EXPECT_EQ(write_of(p, {0x6092, 1}).value, 1048576);
  EXPECT_EQ(write_of(p, {0x608F, 1}).value, 1048576);
  EXPECT_EQ(write_of(p, {0x605A, 0}).def.type, cia402::DataType::I16);
  // The complete EMCY table (part 1 §9.4) with the fault numbers.
  EXPECT_EQ(p.fault_texts.size(), 209U);
  EXPECT_EQ(p.fault_texts.at(0x8130), "F129: Life guard (node guarding) error or heartbeat error");
  EXPECT_EQ(p.fault_texts.at(0xFF01).rfind("F702: ", 0), 0U);
  EXPECT_EQ(p.fault_texts.at(0x8781), "n125: Warning: fieldbus synchronisation lost");
  ASSERT_EQ(co.emcy_fields.size(), 1U);
  EXPECT_EQ(co.emcy_fields[0].byte, 3);
  EXPECT_EQ(co.emcy_fields[0].name, "category");
  EXPECT_TRUE(co.emcy_zero_needs_clear_register);
  // Every PDO fits a frame and the targets of every mode are mapped.
  for (const auto* pdos : {&co.rpdos, &co.tpdos})
    for (const auto& pdo : *pdos) EXPECT_LE(pdo.mapped_bytes(), 8) << pdo.number;
  for (const ObjectId id : {ObjectId{0x6040, 0}, ObjectId{0x6060, 0}, ObjectId{0x607A, 0}, ObjectId{0x60FF, 0},
                            ObjectId{0x6071, 0}, ObjectId{0x60C1, 1}, ObjectId{0x6041, 0}, ObjectId{0x6064, 0}})
    EXPECT_TRUE(lists(p, id)) << object_text(id);
  ASSERT_EQ(co.tpdos.size(), 3U);
  EXPECT_EQ(co.tpdos[2].transmission_type, 255);
  EXPECT_EQ(co.tpdos[2].inhibit_time_100us, 100);
  EXPECT_EQ(co.tpdos[2].event_timer_ms, 100);
  EXPECT_TRUE(p.quirk("homing_objects_not_pdo_mappable"));
  EXPECT_TRUE(p.quirk("no_sync_producer"));
}

TEST(CanopenProfiles, NordSk500p) {
  const DeviceProfile p = load("nord-sk500p");
  const auto& co = p.section<CanopenDeviceSpec>();
  for (const auto m : {core::Mode::ProfilePosition, core::Mode::Velocity, core::Mode::ProfileVelocity,
                       core::Mode::ProfileTorque, core::Mode::Homing})
    EXPECT_TRUE(p.modes.contains(m));
  EXPECT_FALSE(p.modes.contains(core::Mode::CyclicPosition));
  EXPECT_FALSE(p.modes.contains(core::Mode::InterpolatedPosition));
  const core::NativeUnits n = p.units.resolve(4096);
  EXPECT_DOUBLE_EQ(n.position_per_rev, 1000.0);  // 0.001 rev
  EXPECT_DOUBLE_EQ(n.velocity_per_rps, 60.0);    // rpm
  EXPECT_DOUBLE_EQ(n.acceleration_per_rps2, 60.0);  // rpm/s
  EXPECT_EQ(p.homing_methods.size(), 29U);
  EXPECT_EQ(std::count(p.homing_methods.begin(), p.homing_methods.end(), 37), 0);
  EXPECT_EQ(std::count(p.homing_methods.begin(), p.homing_methods.end(), 15), 0);
  EXPECT_TRUE(p.quirk("mode_object_always_valid"));
  // NORD's RxPDO1 with the mode byte, padded to 8 bytes on the wire (§8.1).
  ASSERT_EQ(co.rpdos.size(), 4U);
  EXPECT_EQ(map_text(co.rpdos[0]), (Strings{"6040h u16", "6042h i16", "6060h i8"}));
  EXPECT_EQ(co.rpdos[0].dlc, 8);
  EXPECT_EQ(co.rpdos[0].mapped_bytes(), 5);
  EXPECT_EQ(map_text(co.rpdos[3]), (Strings{"60FFh i32", "6071h i16"}));
  EXPECT_EQ(map_text(co.tpdos[0]), (Strings{"6041h u16", "6044h i16", "6061h i8", "6077h i16"}));
  // Derived cyclic image: every mapped object, RPDOs first.
  ASSERT_EQ(p.cyclic_objects.size(), 15U);
  EXPECT_EQ(p.cyclic_objects.front(), (ObjectId{0x6040, 0}));
  EXPECT_EQ(p.cyclic_objects.back(), (ObjectId{0x606C, 0}));
  ASSERT_TRUE(has_write(p, {0x605D, 0}));
  EXPECT_EQ(write_of(p, {0x605D, 0}).value, 1);
  ASSERT_TRUE(has_write(p, {0x6046, 1}));
  EXPECT_EQ(write_of(p, {0x6046, 1}).value, 0);
  ASSERT_TRUE(has_write(p, {0x608A, 0}));
  EXPECT_EQ(write_of(p, {0x608A, 0}).def.type, cia402::DataType::U8);
  EXPECT_NE(p.fault_texts.at(0x2310).find("unverified"), std::string::npos);
}

TEST(CanopenProfiles, StoeberSd6) {
  const DeviceProfile p = load("stoeber-sd6");
  const auto& co = p.section<CanopenDeviceSpec>();
  EXPECT_EQ(p.identity.vendor_id, 0xB9U);
  EXPECT_EQ(co.device_type, 0x00020192U);
  EXPECT_EQ(co.pdo_policy, PdoPolicy::Verify);
  EXPECT_EQ(co.fixed_mapping_count, 6);
  EXPECT_EQ(co.error_control, ErrorControl::Guarding);
  EXPECT_FALSE(co.consumer_heartbeat);
  EXPECT_EQ(co.sdo_channels, 4);
  EXPECT_TRUE(co.startup_writes.empty());
  EXPECT_EQ(co.sync_periods, (std::vector<core::Duration>{1ms, 2ms, 4ms, 8ms}));
  ASSERT_TRUE(co.parameter_naming);
  EXPECT_EQ(co.parameter_naming->base, 0x2000);
  EXPECT_EQ(co.parameter_naming->group_stride, 0x200);
  EXPECT_EQ(co.parameter_naming->max_line, 511);
  ASSERT_EQ(co.emcy_fields.size(), 2U);
  EXPECT_EQ(co.emcy_fields[0].name, "event");
  EXPECT_EQ(co.emcy_fields[1].byte, 4);
  EXPECT_EQ(co.emcy_fields[1].name, "cause");
  EXPECT_TRUE(p.quirk("no_transmission_type_255"));
  for (const auto* pdos : {&co.rpdos, &co.tpdos})
    for (const auto& pdo : *pdos) {
      EXPECT_TRUE(pdo.transmission_type == 254 || pdo.transmission_type <= 240) << pdo.number;
      EXPECT_LE(pdo.entries.size(), 6U);
      EXPECT_LE(pdo.mapped_bytes(), 8);
    }
  EXPECT_EQ(p.fault_texts.at(0x7500), "Communication (event 52: cause 1 CAN life guarding event, cause 3 CAN bus off)");
  EXPECT_EQ(p.fault_texts.size(), 41U);
}

TEST(CanopenProfiles, GenericMapsEqualItsCyclicObjects) {
  const DeviceProfile p = load("generic-cia402");
  ASSERT_TRUE(p.has_section<CanopenDeviceSpec>());
  EXPECT_EQ(p.section<CanopenDeviceSpec>().persona, "generic");
  EXPECT_EQ(p.section<CanopenDeviceSpec>().device_type_mask, 0x0000FFFFU);
  std::size_t mapped = 0;
  for (const auto* pdos : {&p.section<CanopenDeviceSpec>().rpdos, &p.section<CanopenDeviceSpec>().tpdos})
    for (const auto& pdo : *pdos)
      for (const auto& e : pdo.entries) {
        EXPECT_TRUE(lists(p, e.object)) << object_text(e.object);
        ++mapped;
      }
  EXPECT_EQ(mapped, p.cyclic_objects.size());
}

// Start-up write values are range-checked by their type's limits.
TEST(CanopenProfiles, TypeLimits) {
  using cia402::DataType;
  EXPECT_EQ(type_min(DataType::I8), -128);
  EXPECT_EQ(type_max(DataType::I8), 127);
  EXPECT_EQ(type_min(DataType::U8), 0);
  EXPECT_EQ(type_max(DataType::U8), 255);
  EXPECT_EQ(type_min(DataType::I16), -32768);
  EXPECT_EQ(type_max(DataType::I16), 32767);
  EXPECT_EQ(type_min(DataType::U16), 0);
  EXPECT_EQ(type_max(DataType::U16), 65535);
  EXPECT_EQ(type_min(DataType::I32), -2147483648LL);
  EXPECT_EQ(type_max(DataType::I32), 2147483647LL);
  EXPECT_EQ(type_min(DataType::U32), 0);
  EXPECT_EQ(type_max(DataType::U32), 4294967295LL);
  EXPECT_EQ(data_type_names(), (Strings{"i8", "u8", "i16", "u16", "i32", "u32"}));
}

TEST(CanopenProfiles, SimServoHasNoCanopenSection) { EXPECT_FALSE(load("sim-servo").has_section<CanopenDeviceSpec>()); }

class CanopenProfileErrors : public test::TempDir {
 protected:
  // A valid profile head (lines 1-4) followed by `canopen` text starting on line 5.
  std::string errors_of(const std::string& canopen, const std::string& extra_head = "") {
    const fs::path p = write("drive.yaml", "name: drive\nvendor: test\nmodes: [pp, pv, hm]\n"
                                           "units: { position: { per_rev: counts }, velocity: { unit: position_per_s }, "
                                           "acceleration: { unit: position_per_s2 } }\n" +
                                               canopen + extra_head);
    file_ = p.string();
    try {
      load_device_profile(p);
    } catch (const ConfigError& e) {
      return e.what();
    }
    return "(loaded without error)";
  }
  std::string at(int line, int column) const {
    return file_ + ":" + std::to_string(line) + ":" + std::to_string(column) + ": ";
  }
  std::string file_;
};

const std::string kMaps = R"(  rpdos: [{ number: 1, map: ["0x6040 u16", "0x6060 i8"] }]
  tpdos: [{ number: 1, map: ["0x6041 u16", "0x6061 i8"] }]
)";

TEST_F(CanopenProfileErrors, MinimalSectionLoadsAndDerivesTheCyclicImage) {
  EXPECT_EQ(errors_of("canopen:\n" + kMaps), "(loaded without error)");
  const DeviceProfile p = load_device_profile(dir_ / "drive.yaml");
  EXPECT_EQ(p.cyclic_objects, (std::vector<ObjectId>{{0x6040, 0}, {0x6060, 0}, {0x6041, 0}, {0x6061, 0}}));
  EXPECT_EQ(p.section<CanopenDeviceSpec>().rpdos[0].transmission_type, 1);  // default: every SYNC
  EXPECT_EQ(p.section<CanopenDeviceSpec>().persona, "generic");
}

TEST_F(CanopenProfileErrors, PdoSizeAndEntries) {
  const std::string e = errors_of(R"(canopen:
  rpdos:
    - { number: 1, map: ["0x6040 u16", "0x607A i32", "0x60FF i32"] }
    - { number: 2, map: ["0x2001 u8", "0x2002 u8", "0x2003 u8", "0x2004 u8", "0x2005 u8", "0x2006 u8", "0x2007 u8", "0x2008 u8", "0x2009 u8"] }
    - { number: 2, map: [] }
  tpdos: [{ number: 5, map: ["0x6041 u16"] }]
)");
  EXPECT_REPORTED(e, at(7, 7) + "canopen.rpdos[0]: 10 bytes mapped, a PDO holds at most 8");
  EXPECT_REPORTED(e, at(8, 25) + "canopen.rpdos[1].map: 9 entries mapped, a PDO holds at most 8");
  EXPECT_REPORTED(e, at(8, 7) + "canopen.rpdos[1]: 9 bytes mapped, a PDO holds at most 8");
  EXPECT_REPORTED(e, at(9, 17) + "canopen.rpdos[2].number: RPDO 2 is already defined by canopen.rpdos[1].number");
  EXPECT_REPORTED(e, at(9, 25) + "canopen.rpdos[2].map: must map at least one object (leave the PDO out to disable it)");
  EXPECT_REPORTED(e, at(10, 21) + "canopen.tpdos[0].number: must be an integer in 1..4, got \"5\"");
}

TEST_F(CanopenProfileErrors, EntrySyntaxTypesAndTransmissionTypes) {
  const std::string e = errors_of(R"(canopen:
  rpdos:
    - { number: 1, transmission_type: 250, map: ["0x6040 u16", "0x6060 int8", "0x6071", "6072 u16", "0x607A i32 x", "0x6060 u16", "0x6040 u16"] }
    - { number: 2, transmission_type: 256, dlc: 1, map: ["0x60FF i32"] }
  tpdos: [{ number: 1, transmission_type: 254, dlc: 8, map: ["0x6041 u16"] }]
)");
  EXPECT_REPORTED(e, at(7, 39) + "canopen.rpdos[0].transmission_type: must be 0..240 (synchronous), 254 or 255 "
                                 "(event-driven), got 250");
  EXPECT_REPORTED(e, at(7, 64) + "canopen.rpdos[0].map[1]: type \"int8\" must be one of i8, u8, i16, u16, i32, u32, "
                                 "did you mean \"i8\"?");
  EXPECT_REPORTED(e, at(7, 79) + "canopen.rpdos[0].map[2]: must be \"INDEX[:SUB] TYPE\" such as \"0x6040 u16\"");
  EXPECT_REPORTED(e, "canopen.rpdos[0].map[3]: must be \"INDEX[:SUB] TYPE\"");
  EXPECT_REPORTED(e, "canopen.rpdos[0].map[4]: must be \"INDEX[:SUB] TYPE\"");
  EXPECT_REPORTED(e, "canopen.rpdos[0].map[5]: 0x6060 is i8 in CiA 402, got u16");
  EXPECT_REPORTED(e, "canopen.rpdos[0].map[6]: 0x6040 is already mapped in canopen.rpdos[0].map[0]");
  EXPECT_REPORTED(e, at(8, 39) + "canopen.rpdos[1].transmission_type: must be an integer in 0..255, got \"256\"");
  EXPECT_REPORTED(e, "canopen.rpdos[1].dlc: must be 0 (the mapped length) or 4..8 (at least the mapped bytes), got 1");
  EXPECT_REPORTED(e, "canopen.tpdos[0].dlc: unknown field");
}

TEST_F(CanopenProfileErrors, DirectionsAndRequiredObjects) {
  const std::string e = errors_of(R"(canopen:
  rpdos: [{ number: 1, map: ["0x6060 i8", "0x6041 u16"] }]
  tpdos: [{ number: 1, map: ["0x6061 i8", "0x6041 u16"] }]
)");
  EXPECT_REPORTED(e, at(7, 43) + "canopen.tpdos[0].map[1]: 0x6041 is also mapped in canopen.rpdos[0].map[1]; an object is either "
                     "sent or received");
  EXPECT_REPORTED(e, at(6, 10) + "canopen.rpdos: must map 0x6040 (controlword): the gateway drives every axis through it");
  const std::string only_rx = errors_of("canopen:\n  rpdos: [{ number: 1, map: [\"0x6040 u16\"] }]\n");
  EXPECT_REPORTED(only_rx, at(6, 3) + "canopen.tpdos: must map 0x6041 (statusword)");
}

TEST_F(CanopenProfileErrors, QuirksConstrainTheMaps) {
  const std::string e = errors_of(R"(canopen:
  rpdos: [{ number: 1, transmission_type: 255, map: ["0x6040 u16"] }]
  tpdos: [{ number: 1, map: ["0x6041 u16"] }]
quirks: { no_transmission_type_255: true, mode_object_always_valid: true }
)");
  EXPECT_REPORTED(e, at(6, 43) + "canopen.rpdos[0].transmission_type: 255 is reserved on this device (quirk "
                                 "no_transmission_type_255); use 254 (event-driven) or 1..240 (synchronous)");
  EXPECT_REPORTED(e, "canopen.rpdos: must map 0x6060 (modes of operation): quirk mode_object_always_valid needs 6060h");
}

TEST_F(CanopenProfileErrors, CyclicObjectsMustEqualTheMaps) {
  const std::string e = errors_of("canopen:\n" + kMaps, "cyclic_objects: [\"0x6040\", \"0x6041\", \"0x6064\"]\n");
  EXPECT_REPORTED(e, at(8, 17) + "cyclic_objects: must list exactly the objects of the canopen PDO maps (or be left "
                                 "out to derive them): not mapped: 0x6064; mapped but not listed: 0x6060 0x6061");
}

TEST_F(CanopenProfileErrors, DerivedImageMustCarryCyclicTargets) {
  const fs::path p = write("drive.yaml", R"(name: drive
vendor: test
modes: [pp, csv]
units: { position: { per_rev: counts }, velocity: { unit: position_per_s }, acceleration: { unit: position_per_s2 } }
canopen:
)" + kMaps);
  try {
    load_device_profile(p);
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_REPORTED(std::string{e.what()},
                    p.string() + ":6:3: canopen: the PDO maps (the cyclic image) must include 0x60FF (target velocity) "
                                 "for mode csv");
  }
}

TEST_F(CanopenProfileErrors, ScalarFields) {
  const std::string e = errors_of(R"(canopen:
  device_type_mask: 0
  persona: akdd
  sdo_channels: 5
  error_control: polling
  pdo_policy: write
  fixed_mapping_count: 6
  sync_periods: [1ms, 0, fast]
  colour: red
)" + kMaps);
  EXPECT_REPORTED(e, at(6, 21) + "canopen.device_type_mask: must be an integer in 1..4294967295, got \"0\"");
  EXPECT_REPORTED(e, at(7, 12) + "canopen.persona: must be one of akd, nord-sk500p, stoeber-sd6, generic, generic-no-heartbeat, generic-no-watch, generic-fixed-heartbeat, got \"akdd\", "
                                 "did you mean \"akd\"?");
  EXPECT_REPORTED(e, at(8, 17) + "canopen.sdo_channels: must be an integer in 1..4, got \"5\"");
  EXPECT_REPORTED(e, at(9, 18) + "canopen.error_control: must be one of heartbeat, guarding, got \"polling\"");
  EXPECT_REPORTED(e, at(11, 24) + "canopen.fixed_mapping_count: only with pdo_policy: verify");
  EXPECT_REPORTED(e, at(12, 23) + "canopen.sync_periods[1]: must be a duration in 100us..1s such as 250us, 1ms, 0.5s or 2s "
                                 "(a bare number is seconds), got \"0\"");
  EXPECT_REPORTED(e, at(12, 26) + "canopen.sync_periods[2]:");
  EXPECT_REPORTED(e, at(13, 3) + "canopen.colour: unknown field");
}

TEST_F(CanopenProfileErrors, DeviceTypeMaskNeedsDeviceType) {
  const std::string e = errors_of("canopen:\n  device_type_mask: 0xFFFF\n" + kMaps);
  EXPECT_REPORTED(e, at(6, 21) + "canopen.device_type_mask: only with device_type");
}

TEST_F(CanopenProfileErrors, ErrorControlMustLetTheDriveWatchTheGateway) {
  const std::string hb = errors_of("canopen:\n  consumer_heartbeat: false\n" + kMaps);
  EXPECT_REPORTED(hb, at(6, 23) + "canopen.consumer_heartbeat: false with error_control: heartbeat leaves the drive "
                                  "unable to notice a dead gateway; use error_control: guarding");
  const std::string guard = errors_of("canopen:\n  error_control: guarding\n  consumer_heartbeat: true\n" + kMaps);
  EXPECT_REPORTED(guard, at(7, 23) + "canopen.consumer_heartbeat: only with error_control: heartbeat");
  EXPECT_EQ(errors_of("canopen:\n  error_control: guarding\n" + kMaps), "(loaded without error)");
  EXPECT_FALSE(load_device_profile(dir_ / "drive.yaml").section<CanopenDeviceSpec>().consumer_heartbeat);
}

TEST_F(CanopenProfileErrors, GatewayWatch) {
  const std::string bad = errors_of("canopen:\n  gateway_watch: never\n" + kMaps);
  EXPECT_REPORTED(bad, at(6, 18) + "canopen.gateway_watch: must be one of heartbeat, guarding, required, optional, "
                                   "got \"never\"");
  const std::string guard = errors_of("canopen:\n  error_control: guarding\n  gateway_watch: optional\n" + kMaps);
  EXPECT_REPORTED(guard, at(7, 18) + "canopen.gateway_watch: only guarding with error_control: guarding");
  EXPECT_EQ(errors_of("canopen:\n  gateway_watch: optional\n" + kMaps), "(loaded without error)");
  EXPECT_EQ(load_device_profile(dir_ / "drive.yaml").section<CanopenDeviceSpec>().gateway_watch, GatewayWatch::Optional);
  EXPECT_EQ(errors_of("canopen:\n  error_control: guarding\n" + kMaps), "(loaded without error)");
  EXPECT_EQ(load_device_profile(dir_ / "drive.yaml").section<CanopenDeviceSpec>().gateway_watch, GatewayWatch::Guarding);
}

TEST_F(CanopenProfileErrors, FixedMappingCountLimitsEntries) {
  const std::string e = errors_of(R"(canopen:
  pdo_policy: verify
  fixed_mapping_count: 2
  rpdos: [{ number: 1, map: ["0x6040 u16", "0x6060 i8", "0x6071 i16"] }]
  tpdos: [{ number: 1, map: ["0x6041 u16"] }]
)");
  EXPECT_REPORTED(e, "canopen.rpdos[0].map: 3 entries mapped, a PDO of this device (fixed_mapping_count) holds at most 2");
}

TEST_F(CanopenProfileErrors, StartupWrites) {
  const std::string e = errors_of(R"(canopen:
  startup_writes:
    - { object: "0x605A", type: i16, value: 2, why: quick stop }
    - { object: "0x605A", type: i16, value: 6, why: again }
    - { object: "0x6060", type: u16, value: 1, why: wrong size }
    - { object: "0x1010:1", type: u32, value: 0x65766173, why: save }
    - { object: "0x1600:1", type: u32, value: 0, why: mapping }
    - { object: "0x1017", type: u16, value: 100, why: heartbeat }
    - { object: "0x6040", type: u16, value: 15, why: enable }
    - { object: "A83", type: u8, value: 5, why: no naming }
    - { object: "0x2000", type: u8, value: 256, why: too big }
    - { object: "0x2001", type: u64, value: 1, why: bad type }
    - { object: "0x2002", type: u8, value: 1, why: "" }
    - { object: "0x2003", type: u8, value: 1, colour: red }
)" + kMaps);
  EXPECT_REPORTED(e, at(8, 17) + "canopen.startup_writes[1].object: 0x605A is already written by canopen.startup_writes[0]");
  EXPECT_REPORTED(e, at(9, 17) + "canopen.startup_writes[2].object: 0x6060 is i8 in CiA 402, got u16");
  EXPECT_REPORTED(e, "canopen.startup_writes[3].object: 0x1010:1 stores or restores every drive parameter");
  EXPECT_REPORTED(e, "canopen.startup_writes[4].object: 0x1600:1 is a PDO parameter; PDOs come from the profile's rpdos/tpdos");
  EXPECT_REPORTED(e, "canopen.startup_writes[5].object: 0x1017 is error control; it comes from the bus options");
  EXPECT_REPORTED(e, "canopen.startup_writes[6].object: 0x6040 is the controlword; only the gateway's state machine drives it");
  EXPECT_REPORTED(e, "canopen.startup_writes[7].object: must be an object as \"0x6040\" or \"0x6046:1\" (hex index, "
                     "optional sub-index), got \"A83\"");
  EXPECT_REPORTED(e, "canopen.startup_writes[8].value: must be an integer in 0..255, got \"256\"");
  EXPECT_REPORTED(e, "canopen.startup_writes[9].type: must be one of i8, u8, i16, u16, i32, u32, got \"u64\"");
  EXPECT_REPORTED(e, "canopen.startup_writes[10].why: must say why the drive needs this write");
  EXPECT_REPORTED(e, "canopen.startup_writes[11].colour: unknown field");
  EXPECT_REPORTED(e, "canopen.startup_writes[11].why: missing required field");
}

TEST_F(CanopenProfileErrors, ParameterNamesInStartupWrites) {
  EXPECT_EQ(errors_of(R"(canopen:
  parameter_names: { base: 0x2000, group_stride: 0x200, max_line: 511 }
  startup_writes:
    - { object: A83, type: u8, value: 5, why: node-ID }
    - { object: "E200[0]", type: u16, value: 1, why: test vector TV-6 }
)" + kMaps),
            "(loaded without error)");
  const DeviceProfile p = load_device_profile(dir_ / "drive.yaml");
  ASSERT_EQ(p.section<CanopenDeviceSpec>().startup_writes.size(), 2U);
  EXPECT_EQ(p.section<CanopenDeviceSpec>().startup_writes[0].def.id, (ObjectId{0x2053, 0}));
  EXPECT_EQ(p.section<CanopenDeviceSpec>().startup_writes[1].def.id, (ObjectId{0x28C8, 0}));
  const std::string e = errors_of(R"(canopen:
  parameter_names: { base: 0x2000, group_stride: 0x200, max_line: 511 }
  startup_writes: [{ object: A540, type: i8, value: 2, why: fault reaction }]
)" + kMaps);
  EXPECT_REPORTED(e, at(7, 30) + "canopen.startup_writes[0].object: line 540 is beyond 511");
}

TEST_F(CanopenProfileErrors, ParameterNamingAndEmcy) {
  const std::string e = errors_of(R"(canopen:
  parameter_names: { base: 0x2000, group_stride: 0x200, max_line: 512 }
  emcy: { fields: [{ byte: 3, name: event }, { byte: 3, name: cause }, { byte: 2, name: reg }], zero_needs_clear_register: maybe }
)" + kMaps);
  EXPECT_REPORTED(e, at(6, 67) + "canopen.parameter_names.max_line: must be below group_stride (512) or groups would "
                                 "overlap, got 512");
  EXPECT_REPORTED(e, "canopen.emcy.fields[1].byte: byte 3 is already named by canopen.emcy.fields[0].byte");
  EXPECT_REPORTED(e, "canopen.emcy.fields[2].byte: must be an integer in 3..7, got \"2\"");
  EXPECT_REPORTED(e, "canopen.emcy.zero_needs_clear_register: must be true or false, got \"maybe\"");
  const std::string wide = errors_of("canopen:\n  parameter_names: { base: 0xF000, group_stride: 0x200, max_line: 511 }\n" + kMaps);
  EXPECT_REPORTED(wide, "canopen.parameter_names.group_stride: group Z would reach index 74751, beyond FFFFh");
}

}  // namespace
}  // namespace drivegate::config
