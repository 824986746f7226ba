// The EtherCAT drive personas (ethercat_persona.hpp): each field cites the digest section it follows.
#include "adapters/ethercat/sim/ethercat_persona.hpp"

#include <array>
#include <stdexcept>

namespace drivegate::ethercat::sim {
namespace {

using cia402::DataType;
using cia402::ObjectId;
using cia402::sim::Access;

constexpr std::uint32_t map(std::uint16_t index, std::uint8_t sub, std::uint8_t bits) noexcept {
  return (static_cast<std::uint32_t>(index) << 16) | (static_cast<std::uint32_t>(sub) << 8) | bits;
}
constexpr EcatVendorObject stored(std::uint16_t index, std::uint8_t sub, DataType type, std::int64_t value,
                                  std::string_view name = {}) noexcept {
  return {{{index, sub}, type}, Access::ReadWrite, value, EcatVendorSource::Stored, name};
}
constexpr EcatVendorObject constant(std::uint16_t index, std::uint8_t sub, DataType type, std::int64_t value,
                                    std::string_view name = {}) noexcept {
  return {{{index, sub}, type}, Access::ReadOnly, value, EcatVendorSource::Stored, name};
}

// ---------------------------------------------------------------------------------------------
// ESR TrioDrive D/ES (dunker-ethercat-coe.md)

// Factory mapping (§7.1): only RPDO1/TPDO1 assigned, 2 bytes each way. 1A01h entry 2 is printed
// 60600010 but described as 6061h (erratum 2): the corrected 60610010 is used.
constexpr std::array<std::uint32_t, 1> kEsrRx1{map(0x6040, 0, 16)};
constexpr std::array<std::uint32_t, 2> kEsrRx2{map(0x6040, 0, 16), map(0x6060, 0, 16)};
constexpr std::array<std::uint32_t, 1> kEsrTx1{map(0x6041, 0, 16)};
constexpr std::array<std::uint32_t, 2> kEsrTx2{map(0x6041, 0, 16), map(0x6061, 0, 16)};
// Only 1600h/1601h/1A00h/1A01h are consistent in the manual (§7.1, quirk 3): 1602h/1603h and
// 1614h/1615h do not exist here (06020000h).
constexpr std::array<EcatPdoDefault, 2> kEsrRxPdos{{{0x1600, kEsrRx1}, {0x1601, kEsrRx2}}};
constexpr std::array<EcatPdoDefault, 2> kEsrTxPdos{{{0x1A00, kEsrTx1}, {0x1A01, kEsrTx2}}};
// 1C12h/1C13h defaults as printed (§11.2): 1600h..1603h / 1A00h..1A03h with count 1. Entries 3
// and 4 name mapping objects that do not exist: a count of 3 or 4 is refused (06090030h).
constexpr std::array<std::uint16_t, 4> kEsrRxAssign{0x1600, 0x1601, 0x1602, 0x1603};
constexpr std::array<std::uint16_t, 4> kEsrTxAssign{0x1A00, 0x1A01, 0x1A02, 0x1A03};

// The whitelist (§7.3, quirk 5). 5F54h/5F56h/5F5Eh (arrays, sub-indexes not documented) are not
// modelled: mapping them is refused like any absent object.
constexpr std::array<ObjectId, 16> kEsrRxMappable{{
    {0x5E9C, 0}, {0x5EF4, 0}, {0x5EF5, 0}, {0x5EF6, 0}, {0x5EF7, 0}, {0x6040, 0}, {0x6060, 0}, {0x6071, 0},
    {0x6073, 0}, {0x607A, 0}, {0x6081, 0}, {0x6086, 0}, {0x60B1, 0}, {0x60C1, 1}, {0x5F54, 0}, {0x5F56, 0},
}};
constexpr std::array<ObjectId, 18> kEsrTxMappable{{
    {0x1001, 0}, {0x5E93, 0}, {0x5E95, 0}, {0x5E96, 0}, {0x5E9F, 0}, {0x5F03, 0}, {0x5F0B, 0}, {0x5F0C, 0},
    {0x5F1C, 0}, {0x603F, 0}, {0x6041, 0}, {0x6061, 0}, {0x6063, 0}, {0x6064, 0}, {0x606C, 0}, {0x6078, 0},
    {0x6079, 0}, {0x5F54, 0},
}};

// Quirks 1 and 2: 6060h/6061h INTEGER16, 6081h INTEGER32.
constexpr std::array<EcatTypeOverride, 3> kEsrTypes{{
    {{0x6060, 0}, DataType::I16},
    {{0x6061, 0}, DataType::I16},
    {{0x6081, 0}, DataType::I32},
}};

// Whitelisted manufacturer objects and CiA objects the model lacks (§7.3; types and the
// manufacturer objects' names from there).
// Values are illustrative (6710.101 is not available): they are stored, the model ignores them.
// 60C0h, 60C3h, 60C4h (§11.2): constants whose writes are accepted and ignored.
constexpr std::array<EcatVendorObject, 28> kEsrObjects{{
    constant(0x5E93, 0, DataType::U16, 0, "I2t utilisation"),
    constant(0x5E95, 0, DataType::I32, 0, "Position encoder measured value 2"),
    constant(0x5E96, 0, DataType::I32, 0, "Position encoder measured value 2 in LE"),
    constant(0x5E9F, 0, DataType::I32, 0, "Position encoder measured value 1 in LE"),
    constant(0x5F03, 0, DataType::U32, 1000, "Motor temperature sensor resistance"),
    constant(0x5F0B, 0, DataType::I16, 35, "Heatsink temperature"),
    constant(0x5F0C, 0, DataType::I16, 40, "Motor temperature"),
    constant(0x5F1C, 0, DataType::I32, 0, "Position encoder measured value"),
    stored(0x5E9C, 0, DataType::U16, 1000, "Maximum current magnitude 2"),
    stored(0x5EF4, 0, DataType::U32, 100, "Acceleration time"),
    stored(0x5EF5, 0, DataType::U32, 100, "Deceleration time"),
    stored(0x5EF6, 0, DataType::U32, 50, "Quick-stop time"),
    stored(0x5EF7, 0, DataType::U32, 3000, "Velocity reference value"),
    stored(0x6073, 0, DataType::U16, 1000),     // maximum current magnitude
    {{{0x6078, 0}, DataType::I16}, Access::ReadOnly, 0, EcatVendorSource::TorqueActual},  // current actual
    constant(0x6079, 0, DataType::U16, 325),    // DC-link voltage, U16 (quirk 2)
    stored(0x6086, 0, DataType::I16, 0),        // velocity ramp shape
    stored(0x60C0, 0, DataType::I16, 0),        // interpolation sub mode: 0 linear only
    constant(0x60C3, 0, DataType::U8, 2),
    stored(0x60C3, 1, DataType::U8, 0),         // synchronize on group
    stored(0x60C3, 2, DataType::U8, 1),         // ip sync every 1 event
    constant(0x60C4, 0, DataType::U8, 6),
    stored(0x60C4, 1, DataType::U32, 1),        // max buffer size
    stored(0x60C4, 2, DataType::U32, 1),        // actual size
    stored(0x60C4, 3, DataType::U8, 0),         // buffer organisation FIFO
    stored(0x60C4, 4, DataType::U16, 0),        // buffer position
    stored(0x60C4, 5, DataType::U8, 1),         // size of data record
    stored(0x60C4, 6, DataType::U8, 1),         // buffer clear
}};

// 60FFh is not in the whitelist and "may not exist at all" (quirk 2); no vl mode objects.
constexpr std::array<ObjectId, 8> kEsrHidden{{
    {0x60FF, 0}, {0x6042, 0}, {0x6043, 0}, {0x6044, 0}, {0x6048, 1}, {0x6048, 2}, {0x6049, 1}, {0x6049, 2},
}};

// Quirk 8: written, answered with success, not applied.
constexpr std::array<ObjectId, 10> kEsrIgnored{{
    {0x60C0, 0}, {0x60C2, 2}, {0x60C3, 1}, {0x60C3, 2}, {0x60C4, 1}, {0x60C4, 2}, {0x60C4, 3}, {0x60C4, 4},
    {0x60C4, 5}, {0x60C4, 6},
}};

// 60C2h:01 2..10 ms (§11.2, TV-3); 60C1h:01 -2^24..2^24-1 encoder steps (§11.2).
constexpr std::array<EcatObjectRange, 2> kEsrRanges{{{{0x60C2, 1}, 2, 10}, {{0x60C1, 1}, -16777216, 16777215}}};
// 60C2h:01 = 4 ms, 60C2h:02 = -3 (§11.2).
constexpr std::array<EcatObjectValue, 2> kEsrDefaults{{{{0x60C2, 1}, 4}, {{0x60C2, 2}, -3}}};

// pp, tq and ip (profiles/devices/esr-triodrive.yaml `modes`; mode numbers [EXT] §9.2).
constexpr std::array<std::int8_t, 3> kEsrModes{1, 4, 7};

constexpr EthercatPersona kEsr{
    .name = "esr-triodrive",
    .vendor_id = 0x0000000F,     // "15" (§10; radix unknown, erratum 13): the profile's first identity
    .product_code = 0x00006755,  // "6755" TrioDrive, read as hex like the profile's first identity
    .revision = 0x00000001,      // "device specific" (§11.2)
    .device_type = 0x00020192,   // TV-2
    .device_name = "TrioDrive D/ES",  // §10
    .hardware_version = "sim-1",
    .software_version = "drivegate-sim 1.0",
    .sii_group = "Drive",
    .sii_order = "ESR TrioDrive D/ES F7",
    .dc_supported = false,  // quirk 9
    .modes = kEsrModes,
    .initial_mode = 0,
    .rx_pdos = kEsrRxPdos,
    .tx_pdos = kEsrTxPdos,
    .max_entries = 8,  // §7.2
    .assign_slots = 4,
    .rx_assign = kEsrRxAssign,
    .rx_assign_count = 1,
    .tx_assign = kEsrTxAssign,
    .tx_assign_count = 1,
    .rx_mappable = kEsrRxMappable,
    .tx_mappable = kEsrTxMappable,
    .rx_mapping_writable_in_safeop = true,  // quirk 4
    .process_data_capacity = 128,           // 4 PDOs x 8 entries x 4 bytes (§7.2 [DERIVED])
    .type_overrides = kEsrTypes,
    .vendor_objects = kEsrObjects,
    .hidden = kEsrHidden,
    .ignored_writes = kEsrIgnored,
    .ranges = kEsrRanges,
    .application_defaults = kEsrDefaults,
    .store_parameters = false,          // quirk 10
    .sync_manager_parameters = false,   // quirk 9
    .abort_option_default = 0,          // quirk 6
    .abort_option_max = 1,              // §11.2: 0 or 1
    .abort_on_requested_leave_op = false,  // §8.2: the SM watchdog only
    .comm_loss_code = 0x8100,           // App. C
    .controlword_bit6_absolute = true,  // quirk 14 [EXT]
    .ip_status_bit12 = false,           // quirk 7
    .fine_interpolation = true,         // §12: 1 ms fine interpolator
    .transition_error_emcy = true,      // App. C: A000h
    .emcy_on_fault_clear = false,       // §8.1: every fault is sent; nothing says the clearing is
};

// ---------------------------------------------------------------------------------------------
// Generic CiA 402 (profiles/devices/generic-cia402.yaml)

// Power-on mapping = the device profile's (a drive commissioned with it): 17 output bytes,
// 15 input bytes. 1601h..1603h and 1A01h..1A03h are empty.
constexpr std::array<std::uint32_t, 6> kGenRx1{map(0x6040, 0, 16), map(0x6060, 0, 8), map(0x6071, 0, 16),
                                               map(0x607A, 0, 32), map(0x60FF, 0, 32), map(0x60C1, 1, 32)};
constexpr std::array<std::uint32_t, 6> kGenTx1{map(0x6041, 0, 16), map(0x6061, 0, 8), map(0x6077, 0, 16),
                                               map(0x603F, 0, 16), map(0x6064, 0, 32), map(0x606C, 0, 32)};
constexpr std::array<EcatPdoDefault, 4> kGenRxPdos{{{0x1600, kGenRx1}, {0x1601, {}}, {0x1602, {}}, {0x1603, {}}}};
constexpr std::array<EcatPdoDefault, 4> kGenTxPdos{{{0x1A00, kGenTx1}, {0x1A01, {}}, {0x1A02, {}}, {0x1A03, {}}}};
constexpr std::array<std::uint16_t, 1> kGenRxAssign{0x1600};
constexpr std::array<std::uint16_t, 1> kGenTxAssign{0x1A00};
// pp, pv, tq, hm, ip, csp, csv, cst (the profile's `modes`).
constexpr std::array<std::int8_t, 8> kGenModes{1, 3, 4, 6, 7, 8, 9, 10};

constexpr EthercatPersona kGeneric{
    .name = "generic-cia402",
    // Not a registered vendor: the generic profile matches any slave whose 1000h names CiA 402.
    .vendor_id = 0x00000000,
    .product_code = 0x00000192,
    .revision = 0x00000001,
    .device_type = 0x00020192,
    .device_name = "drivegate simulated CiA 402 drive",
    .hardware_version = "sim-1",
    .software_version = "drivegate-sim 1.0",
    .sii_group = "Drive",
    .sii_order = "SIM-CIA402",
    .dc_supported = true,
    .modes = kGenModes,
    .initial_mode = 0,
    .rx_pdos = kGenRxPdos,
    .tx_pdos = kGenTxPdos,
    .max_entries = 16,
    .assign_slots = 4,
    .rx_assign = kGenRxAssign,
    .rx_assign_count = 1,
    .tx_assign = kGenTxAssign,
    .tx_assign_count = 1,
    .rx_mappable = {},
    .tx_mappable = {},
    .rx_mapping_writable_in_safeop = false,
    .process_data_capacity = 256,
    .type_overrides = {},
    .vendor_objects = {},
    .hidden = {},
    .ignored_writes = {},
    .ranges = {},
    .application_defaults = {},
    .store_parameters = true,
    .sync_manager_parameters = true,
    // CiA 402 6007h: 1 = fault signal; 2 disable voltage, 3 quick stop. The default of 1 is
    // what drives commonly ship with [STD, not from a digest].
    .abort_option_default = 1,
    .abort_option_max = 3,
    .abort_on_requested_leave_op = true,
    .comm_loss_code = 0x8100,
    .controlword_bit6_absolute = false,
    .ip_status_bit12 = true,
    .fine_interpolation = false,
    .transition_error_emcy = false,
    .emcy_on_fault_clear = true,
};

// ---------------------------------------------------------------------------------------------
// Generic two-axis CiA 402 (profiles/devices/generic-cia402-2axis.yaml)

// A modular device with two drive channels [ETG.6010 §4]: axis 1's profile objects at + 800h.
// Power-on mapping = the device profile's: one RxPDO and one TxPDO per axis (1600h/1A00h axis 0,
// 1601h/1A01h axis 1, each as generic-cia402's), both assigned; 34 output bytes, 30 input bytes.
constexpr std::uint16_t kAxis1 = 0x800;
constexpr std::uint16_t ax1(std::uint16_t index) noexcept { return static_cast<std::uint16_t>(index + kAxis1); }
constexpr std::array<std::uint32_t, 6> kGen2Rx2{map(ax1(0x6040), 0, 16), map(ax1(0x6060), 0, 8),
                                                map(ax1(0x6071), 0, 16), map(ax1(0x607A), 0, 32),
                                                map(ax1(0x60FF), 0, 32), map(ax1(0x60C1), 1, 32)};
constexpr std::array<std::uint32_t, 6> kGen2Tx2{map(ax1(0x6041), 0, 16), map(ax1(0x6061), 0, 8),
                                                map(ax1(0x6077), 0, 16), map(ax1(0x603F), 0, 16),
                                                map(ax1(0x6064), 0, 32), map(ax1(0x606C), 0, 32)};
constexpr std::array<EcatPdoDefault, 4> kGen2RxPdos{{{0x1600, kGenRx1}, {0x1601, kGen2Rx2}, {0x1602, {}}, {0x1603, {}}}};
constexpr std::array<EcatPdoDefault, 4> kGen2TxPdos{{{0x1A00, kGenTx1}, {0x1A01, kGen2Tx2}, {0x1A02, {}}, {0x1A03, {}}}};
constexpr std::array<std::uint16_t, 2> kGen2RxAssign{0x1600, 0x1601};
constexpr std::array<std::uint16_t, 2> kGen2TxAssign{0x1A00, 0x1A01};

constexpr EthercatPersona kGeneric2Axis{
    .name = "generic-cia402-2axis",
    // Not a registered vendor (as generic-cia402); its own product code, so that a profile can
    // tell it from a single-axis drive by identity.
    .vendor_id = 0x00000000,
    .product_code = 0x00020192,
    .revision = 0x00000001,
    .device_type = 0x00020192,
    .device_name = "drivegate simulated two-axis CiA 402 drive",
    .hardware_version = "sim-1",
    .software_version = "drivegate-sim 1.0",
    .sii_group = "Drive",
    .sii_order = "SIM-CIA402-2AX",
    .dc_supported = true,
    .modes = kGenModes,
    .initial_mode = 0,
    .rx_pdos = kGen2RxPdos,
    .tx_pdos = kGen2TxPdos,
    .max_entries = 16,
    .assign_slots = 4,
    .rx_assign = kGen2RxAssign,
    .rx_assign_count = 2,
    .tx_assign = kGen2TxAssign,
    .tx_assign_count = 2,
    .rx_mappable = {},
    .tx_mappable = {},
    .rx_mapping_writable_in_safeop = false,
    .process_data_capacity = 256,
    .type_overrides = {},
    .vendor_objects = {},
    .hidden = {},
    .ignored_writes = {},
    .ranges = {},
    .application_defaults = {},
    .store_parameters = true,
    .sync_manager_parameters = true,
    .abort_option_default = 1,  // per axis (6007h, 6807h), as generic-cia402
    .abort_option_max = 3,
    .abort_on_requested_leave_op = true,
    .comm_loss_code = 0x8100,
    .controlword_bit6_absolute = false,
    .ip_status_bit12 = true,
    .fine_interpolation = false,
    .transition_error_emcy = false,
    .emcy_on_fault_clear = true,
    .axes = 2,
    .axis_offset = kAxis1,
};

constexpr std::array<const EthercatPersona*, 3> kPersonas{&kEsr, &kGeneric, &kGeneric2Axis};

}  // namespace

const EthercatPersona* find_ethercat_persona(std::string_view name) noexcept {
  for (const EthercatPersona* p : kPersonas) {
    if (p->name == name) return p;
  }
  return nullptr;
}

std::string ethercat_persona_names() {
  std::string names;
  for (const EthercatPersona* p : kPersonas) {
    if (!names.empty()) names += ", ";
    names += p->name;
  }
  return names;
}

const EthercatPersona& ethercat_persona_for(std::string_view name) {
  if (const EthercatPersona* p = find_ethercat_persona(name)) return *p;
  throw std::invalid_argument("unknown EtherCAT drive persona \"" + std::string(name) + "\" (known: " +
                              ethercat_persona_names() + ")");
}

}  // namespace drivegate::ethercat::sim
