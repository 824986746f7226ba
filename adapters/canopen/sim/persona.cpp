// The personas (persona.hpp): each field cites the digest section it follows.
#include "adapters/canopen/sim/persona.hpp"

#include <stdexcept>
#include <string>

#include "adapters/canopen/wire/pdo_mapping.hpp"
#include "adapters/canopen/wire/sdo_codec.hpp"

namespace drivegate::canopen::sim {
namespace {

using cia402::DataType;
using cia402::ObjectId;
using cia402::sim::Access;

constexpr std::uint32_t map(std::uint16_t index, std::uint8_t sub, std::uint8_t bits) noexcept {
  return encode_mapping({{index, sub}, bits});
}

constexpr VendorObject stored(std::uint16_t index, std::uint8_t sub, DataType type, std::int64_t value) noexcept {
  return {{{index, sub}, type}, Access::ReadWrite, value, VendorValue::Stored, false, std::nullopt, std::nullopt};
}
constexpr VendorObject constant(std::uint16_t index, std::uint8_t sub, DataType type, std::int64_t value) noexcept {
  return {{{index, sub}, type}, Access::ReadOnly, value, VendorValue::Stored, false, std::nullopt, std::nullopt};
}
constexpr VendorObject live(std::uint16_t index, DataType type, VendorValue source, bool mappable = false) noexcept {
  return {{{index, 0}, type}, Access::ReadOnly, 0, source, mappable, std::nullopt, std::nullopt};
}

// ---------------------------------------------------------------------------------------------
// Kollmorgen AKD

// Factory mapping, all eight PDOs valid and event-driven (part 1 §12.5); Reset Node returns to it
// (part 1 §17 quirk 10).
constexpr std::array<PdoDefault, 4> kAkdRpdos{{
    {true, 255, {map(0x6040, 0, 16)}},
    {true, 255, {map(0x6040, 0, 16), map(0x6060, 0, 8)}},
    {true, 255, {map(0x6040, 0, 16), map(0x607A, 0, 32)}},
    {true, 255, {map(0x6040, 0, 16), map(0x60FF, 0, 32)}},
}};
constexpr std::array<PdoDefault, 4> kAkdTpdos{{
    {true, 255, {map(0x6041, 0, 16)}},
    {true, 255, {map(0x6041, 0, 16), map(0x6061, 0, 8)}},
    {true, 255, {map(0x6041, 0, 16), map(0x6064, 0, 32)}},
    {true, 255, {map(0x6041, 0, 16), map(0x606C, 0, 32)}},
}};

constexpr std::array<VendorObject, 23> kAkdObjects{{
    // 1002h manufacturer status register, PDO-mappable (part 2 §2.5).
    live(0x1002, DataType::U32, VendorValue::ManufacturerStatus, true),
    // FBUS.PARAM01..10 = 36E5h..36EEh, U32 RW, not mappable (part 1 §3). PARAM01 = the bit rate in
    // kbit/s, PARAM04 = 0 on CANopen; they take effect only after a restart (part 1 §3), so the
    // simulator only stores them.
    stored(0x36E5, 0, DataType::U32, 500),
    stored(0x36E6, 0, DataType::U32, 0),
    stored(0x36E7, 0, DataType::U32, 0),
    stored(0x36E8, 0, DataType::U32, 0),
    stored(0x36E9, 0, DataType::U32, 0),
    stored(0x36EA, 0, DataType::U32, 0),
    stored(0x36EB, 0, DataType::U32, 0),
    stored(0x36EC, 0, DataType::U32, 0),
    stored(0x36ED, 0, DataType::U32, 0),
    stored(0x36EE, 0, DataType::U32, 0),
    // Factor group (part 2 §4.3, §4.4): 204Ch pv scaling 1/1, 608Fh 2^20 increments per rev,
    // 6091h gear and 6092h feed 1/1.
    constant(0x204C, 0, DataType::U8, 2),
    stored(0x204C, 1, DataType::I32, 1),
    stored(0x204C, 2, DataType::I32, 1),
    constant(0x608F, 0, DataType::U8, 2),
    stored(0x608F, 1, DataType::U32, 1048576),
    stored(0x608F, 2, DataType::U32, 1),
    constant(0x6091, 0, DataType::U8, 2),
    stored(0x6091, 1, DataType::U32, 1),
    stored(0x6091, 2, DataType::U32, 1),
    constant(0x6092, 0, DataType::U8, 2),
    stored(0x6092, 1, DataType::U32, 1),
    stored(0x6092, 2, DataType::U32, 1),
}};

// No 605Bh..605Eh option objects (part 2 §15.4); no vl mode, so no vl objects (part 2 §15.9).
constexpr std::array<ObjectId, 11> kAkdHidden{{
    {0x605B, 0}, {0x605C, 0}, {0x605D, 0}, {0x605E, 0},
    {0x6042, 0}, {0x6043, 0}, {0x6044, 0}, {0x6048, 1}, {0x6048, 2}, {0x6049, 1}, {0x6049, 2},
}};
// Homing objects are SDO only (part 2 §15.15).
constexpr std::array<ObjectId, 5> kAkdNotMappable{{{0x6098, 0}, {0x6099, 1}, {0x6099, 2}, {0x609A, 0}, {0x607C, 0}}};

constexpr Persona kAkd{
    .name = "akd",
    .device_type = 0x00020192,  // part 1 §13.1, quirk 13
    .vendor_id = 0x0000006A,    // Kollmorgen (part 1 §13.1)
    .product_code = 0x3630304D,  // "M006" as four ASCII bytes (part 1 quirk 12)
    .revision = 0x00140000,      // CANopen part 0.20 in the upper word (part 1 quirk 12)
    .initial_mode = std::nullopt,
    // Four characters "Yzzz": voltage class and current rating (part 1 §13.1), as in the product
    // code; 1009h "will be supported in the future" (absent here); 100Ah the CANopen part's version,
    // 0.20 as the revision says.
    .device_name = "M006",
    .hardware_version = "",
    .software_version = "0.20",
    .sdo_channels = 1,  // a single SDO server with fixed COB-IDs, no 1200h (part 1 quirk 7)
    .upload_without_size = false,
    .heartbeat_consumer = true,  // one 1016h entry (part 1 §11.2, quirk 11)
    .emcy_inhibit = false,       // no 1015h (part 1 §13.1)
    .emcy_cob_writable = false,  // 1014h RO per chapter 6 (part 1 §13.1)
    .sdo_parameters = false,
    .store_parameters = true,  // 1010h:01 "save" = DRV.NVSAVE (part 2 §2.6)
    .nmt = {.boot_up_after_reset = true, .life_guarding_only_operational = false},  // F129 in any state (part 1 §11.1)
    // Whole bytes, <= 8 entries (part 1 §12.3); RPDO types 1..240 act at every n-th SYNC (quirk 8);
    // types 241..254 are not described (part 1 §12.2).
    .pdo = {.max_entries = 8,
            .fixed_count = 0,
            .transmission_types = {.sync_min = 0, .sync_max = 240, .type_254 = false, .type_255 = true},
            .rpdo_every_nth_sync = true,
            .tpdo_254_on_rpdo = false},
    .pdo_defaults_from_profile = false,
    .rpdo_defaults = kAkdRpdos,
    .tpdo_defaults = kAkdTpdos,
    .vendor_objects = kAkdObjects,
    .hidden = kAkdHidden,
    .not_mappable = kAkdNotMappable,
    .application_defaults = {},
    .supported_modes_cleared = 0x08,  // 6502h reads E5h: the tq bit is missing (part 2 §15.9, part 1 quirk 21)
    .mode_zero_refused = false,
    // Byte 3 "category" (part 1 §9.1): 01h in the manual's example, followed by a 0000h EMCY with
    // the error register (part 2 §12.10 rows 71/72; part 1 §9.2, quirk 4).
    .fault_byte3 = 0x01,
    .emcy_state_follow_up = true,
    .emcy_rules = {},
    .emcy_cause_byte4 = false,  // bytes 4..7 reserved (part 1 §9.1)
    .no_fault_event = 0,
    .comm_loss_code = 0x8130,  // F129 (part 1 §11.1)
    .comm_loss_cause = 0,
};

// ---------------------------------------------------------------------------------------------
// NORD SK 500P

// The EDS default mapping (nord §8.1); RxPDO4, TxPDO3 and TxPDO4 are empty and therefore off.
// The transmission types are not documented: CiA 301's default 255.
constexpr std::array<PdoDefault, 4> kNordRpdos{{
    {true, 255, {map(0x6040, 0, 16), map(0x6042, 0, 16), map(0x6060, 0, 8)}},
    {true, 255, {map(0x6083, 0, 32), map(0x6084, 0, 32)}},
    {true, 255, {map(0x607A, 0, 32), map(0x6081, 0, 32)}},
    {false, 255, {}},
}};
constexpr std::array<PdoDefault, 4> kNordTpdos{{
    {true, 255, {map(0x6041, 0, 16), map(0x6044, 0, 16), map(0x6061, 0, 8), map(0x6077, 0, 16)}},
    {true, 255, {map(0x6064, 0, 32), map(0x606C, 0, 32)}},
    {false, 255, {}},
    {false, 255, {}},
}};

// SDO-only objects of nord §7 the drive model lacks; stored with the documented defaults and ranges.
constexpr std::array<VendorObject, 15> kNordObjects{{
    constant(0x6046, 0, DataType::U8, 2),
    {{{0x6046, 1}, DataType::U32}, Access::ReadWrite, 0, VendorValue::Stored, false, 0, 24000},     // vl min
    {{{0x6046, 2}, DataType::U32}, Access::ReadWrite, 1500, VendorValue::Stored, false, 1, 24000},  // vl max
    constant(0x604A, 0, DataType::U8, 2),
    {{{0x604A, 1}, DataType::U32}, Access::ReadWrite, 1500, VendorValue::Stored, false, 1, 2400000},  // vl quick stop
    {{{0x604A, 2}, DataType::U16}, Access::ReadWrite, 1, VendorValue::Stored, false, 0, 32767},
    {{{0x607E, 0}, DataType::U8}, Access::ReadWrite, 0, VendorValue::Stored, false, 0, 192},    // polarity
    {{{0x6086, 0}, DataType::I16}, Access::ReadWrite, 0, VendorValue::Stored, false, 0, 1},     // profile type
    {{{0x608A, 0}, DataType::U8}, Access::ReadWrite, 0, VendorValue::Stored, false, 0, 1},      // 0 rev, 1 m (quirk 4)
    constant(0x6091, 0, DataType::U8, 2),
    {{{0x6091, 1}, DataType::U32}, Access::ReadWrite, 1, VendorValue::Stored, false, 1, 2147483647},
    {{{0x6091, 2}, DataType::U32}, Access::ReadWrite, 1, VendorValue::Stored, false, 1, 2147483647},
    constant(0x6092, 0, DataType::U8, 2),
    {{{0x6092, 1}, DataType::U32}, Access::ReadWrite, 1, VendorValue::Stored, false, 1, 2147483647},
    {{{0x6092, 2}, DataType::U32}, Access::ReadWrite, 10, VendorValue::Stored, false, 1, 2147483647},
}};

// Objects nord §7 lists as not documented (quirks 9, 13, 20, 22), and no ip / cyclic modes (§1).
constexpr std::array<ObjectId, 19> kNordHidden{{
    {0x603F, 0}, {0x605A, 0}, {0x605B, 0}, {0x605C, 0}, {0x605E, 0}, {0x6062, 0}, {0x607D, 0}, {0x607D, 1},
    {0x607D, 2}, {0x6072, 0}, {0x60F4, 0}, {0x6502, 0}, {0x60C1, 0}, {0x60C1, 1}, {0x60C2, 0}, {0x60C2, 1},
    {0x60C2, 2}, {0x60B1, 0}, {0x60B2, 0},
}};

// 605Dh halt option default 2, the quick-stop ramp (nord §3.6, quirk 12).
constexpr std::array<ObjectValue, 1> kNordDefaults{{{{0x605D, 0}, 2}}};

constexpr Persona kNord{
    .name = "nord-sk500p",
    // Not in the digest: a frequency inverter (nord §1) reports CiA 402 type 01h.
    .device_type = 0x00010192,
    .vendor_id = std::nullopt,
    .product_code = std::nullopt,
    .revision = std::nullopt,
    .initial_mode = 2,  // vl (quirk 2)
    // The digest lists no identity strings: illustrative values (segmented: longer than 4 bytes).
    .device_name = "NORD SK 500P",
    .hardware_version = "",
    .software_version = "V1.2 R0",
    .sdo_channels = 1,
    .upload_without_size = false,
    .heartbeat_consumer = true,
    .emcy_inhibit = true,
    .emcy_cob_writable = true,
    .sdo_parameters = true,
    .store_parameters = true,
    .nmt = {},
    .pdo = {},
    .pdo_defaults_from_profile = false,
    .rpdo_defaults = kNordRpdos,
    .tpdo_defaults = kNordTpdos,
    .vendor_objects = kNordObjects,
    .hidden = kNordHidden,
    .not_mappable = {},
    .application_defaults = kNordDefaults,
    .supported_modes_cleared = 0,
    .mode_zero_refused = true,  // RxPDO1 must always carry a valid mode (quirk 18, §13 step 6)
    // §9: code and register only, the rest unused; 0000h after the reset.
    .fault_byte3 = 0,
    .emcy_state_follow_up = false,
    .emcy_rules = {},
    .emcy_cause_byte4 = false,
    .no_fault_event = 0,
    .comm_loss_code = 0x8100,  // E10.x telegram timeout (§9, unverified for the SK 500P)
    .comm_loss_cause = 0,
};

// ---------------------------------------------------------------------------------------------
// STÖBER SD6

constexpr std::array<VendorObject, 6> kSd6Objects{{
    live(0x1002, DataType::U32, VendorValue::DeviceState, true),  // 1002h = E48 (§10, quirk 13)
    live(0x2053, DataType::U8, VendorValue::NodeId),              // A83 bus address (§2.2)
    live(0x2830, DataType::U8, VendorValue::DeviceState),         // E48 device state (§10)
    live(0x2852, DataType::U8, VendorValue::EventNumber),         // E82 event type (§2.2, §6.9)
    live(0x282B, DataType::U8, VendorValue::EventCause),          // E43 event cause (§2.2, §6.9)
    live(0x20F6, DataType::U8, VendorValue::NmtState),            // A246 NMT state (quirk 18)
}};

// Tab. 17 (§6.9): register as printed (no generic bit 0 with the class bits), event E82 in byte 3.
// 7110h is printed twice; the brake-test row (register 01h) is taken.
constexpr std::array<EmcyRule, 40> kSd6Rules{{
    {0x1000, 0x01, 48}, {0x2110, 0x02, 31}, {0x2230, 0x02, 32}, {0x2310, 0x02, 33}, {0x3110, 0x04, 36},
    {0x3120, 0x04, 46}, {0x3130, 0x01, 83}, {0x3180, 0x01, 84}, {0x4210, 0x08, 38}, {0x4280, 0x08, 39},
    {0x4310, 0x08, 41}, {0x4380, 0x08, 45}, {0x5200, 0x01, 34}, {0x5440, 0x01, 43}, {0x6010, 0x01, 35},
    {0x6320, 0x01, 40}, {0x7110, 0x01, 72}, {0x7120, 0x01, 69}, {0x7303, 0x01, 37}, {0x7304, 0x01, 58},
    {0x7321, 0x01, 82}, {0x7500, 0x10, 52}, {0x7580, 0x01, 88}, {0x8311, 0x01, 47}, {0x8400, 0x01, 56},
    {0x8500, 0x01, 53}, {0x8510, 0x01, 85}, {0x8600, 0x01, 51}, {0x8611, 0x01, 54}, {0x8612, 0x01, 78},
    {0xFF00, 0x01, 60}, {0xFF01, 0x01, 61}, {0xFF02, 0x01, 62}, {0xFF03, 0x01, 63}, {0xFF04, 0x01, 64},
    {0xFF05, 0x01, 65}, {0xFF06, 0x01, 66}, {0xFF07, 0x01, 67}, {0xFF09, 0x01, 44}, {0xFF0A, 0x01, 68},
}};

constexpr Persona kSd6{
    .name = "stoeber-sd6",
    .device_type = 0x00020192,  // TV-7
    .vendor_id = 0x000000B9,    // §10
    .product_code = 40,         // rated power in 0.1 kW (quirk 13): a 4 kW drive
    .revision = std::nullopt,
    .initial_mode = std::nullopt,
    // 1008h is E50 (the device name, segmented when longer than 4 characters), 100Ah E53[3]
    // (stoeber-sd6-canopen.md §10); the values are illustrative. No 1009h.
    .device_name = "SD6 axis controller",
    .hardware_version = "",
    .software_version = "6.5-K",
    .sdo_channels = 4,            // §6.3, quirk 1
    .upload_without_size = true,  // 42h (§6.4, quirk 19)
    .heartbeat_consumer = false,  // no 1016h (quirk 7)
    .emcy_inhibit = true,         // A208
    .emcy_cob_writable = true,    // A207
    .sdo_parameters = true,
    .store_parameters = true,  // 1010h:01 only (quirk 12)
    // Boot-up once at power-on (§6.7, quirk 9); life guarding faults only in Operational (quirk 8).
    .nmt = {.boot_up_after_reset = false, .life_guarding_only_operational = true},
    // Six entries, count fixed at 6 (quirks 4, 5); types 1..240 and 254, which a received RxPDO
    // triggers (quirk 3).
    .pdo = {.max_entries = 6,
            .fixed_count = 6,
            .transmission_types = {.sync_min = 1, .sync_max = 240, .type_254 = true, .type_255 = false},
            .rpdo_every_nth_sync = false,
            .tpdo_254_on_rpdo = true},
    // The mapping is set in DS6 and saved (§6.2): the device profile's maps, as commissioned.
    .pdo_defaults_from_profile = true,
    .rpdo_defaults = {},
    .tpdo_defaults = {},
    .vendor_objects = kSd6Objects,
    .hidden = {},
    .not_mappable = {},
    .application_defaults = {},
    .supported_modes_cleared = 0,
    .mode_zero_refused = false,
    .fault_byte3 = 0,
    .emcy_state_follow_up = false,
    .emcy_rules = kSd6Rules,
    .emcy_cause_byte4 = true,   // E43 (§6.9)
    .no_fault_event = 0x1E,     // E82 = 30 "inactive" when the fault is left (TV-5)
    .comm_loss_code = 0x7500,   // event 52 "communication", cause 1 life guarding (§4.4, D-7)
    .comm_loss_cause = 1,
};

constexpr Persona kGeneric{};

// Plain CiA 301 drives that leave out the optional watch objects: the consumer heartbeat (1016h
// is optional in CiA 301 §7.5.2.31), and also node guarding (100Ch/100Dh).
constexpr Persona generic_without(std::string_view name, bool heartbeat_consumer, bool node_guarding) {
  Persona p{};
  p.name = name;
  p.heartbeat_consumer = heartbeat_consumer;
  p.node_guarding = node_guarding;
  return p;
}
constexpr Persona kGenericNoHeartbeat = generic_without("generic-no-heartbeat", false, true);
constexpr Persona kGenericNoWatch = generic_without("generic-no-watch", false, false);
// A drive whose 1016h:01 entry is fixed (read-only): it has 1016h but takes no gateway entry.
constexpr Persona fixed_heartbeat() {
  Persona p = generic_without("generic-fixed-heartbeat", true, false);
  p.heartbeat_consumer_abort = cia402::sdo_abort_code::kReadOnly;
  return p;
}
constexpr Persona kGenericFixedHeartbeat = fixed_heartbeat();

constexpr std::array<const Persona*, 7> kAll{
    &kAkd, &kNord, &kSd6, &kGeneric, &kGenericNoHeartbeat, &kGenericNoWatch, &kGenericFixedHeartbeat};

}  // namespace

const Persona* find_persona(std::string_view name) noexcept {
  for (const Persona* p : kAll) {
    if (p->name == name) return p;
  }
  return nullptr;
}

const Persona& persona_for(std::string_view name) {
  if (const Persona* p = find_persona(name)) return *p;
  std::string known;
  for (const Persona* p : kAll) known += (known.empty() ? "" : ", ") + std::string(p->name);
  throw std::invalid_argument("unknown simulator persona \"" + std::string(name) + "\" (known: " + known + ")");
}

}  // namespace drivegate::canopen::sim
