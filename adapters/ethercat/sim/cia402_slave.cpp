// Cia402Slave: see cia402_slave.hpp.
#include "adapters/ethercat/sim/cia402_slave.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "adapters/ethercat/wire/al_status.hpp"
#include "adapters/ethercat/wire/registers.hpp"
#include "adapters/ethercat/wire/sii.hpp"
#include "core/bytes.hpp"

namespace drivegate::ethercat::sim {
namespace {

namespace abort = cia402::sdo_abort_code;
using cia402::DataType;
using cia402::ObjectId;
using cia402::sim::Access;

constexpr ObjectId kControlword{0x6040, 0};
constexpr ObjectId kStatusword{0x6041, 0};
constexpr ObjectId kIpDataRecord{0x60C1, 1};
constexpr ObjectId kAbortOption{0x6007, 0};
// The profile area a multi-axis slave repeats per axis [ETG.6010 §4].
constexpr std::uint16_t kProfileArea = 0x6000;

// Access bits [ETG.1000.6 §5.6.3.6]: read in every state, write in every state / in PRE-OP.
constexpr std::uint16_t kReadAll = object_access::kReadPreOp | object_access::kReadSafeOp | object_access::kReadOp;
constexpr std::uint16_t kWriteAll = object_access::kWritePreOp | object_access::kWriteSafeOp | object_access::kWriteOp;

// "save" as 1010h:01 takes it [CiA 301 §7.5.2.13].
constexpr std::uint32_t kSaveSignature = 0x65766173;

// 1C32h/1C33h [ETG.1020 synchronisation, SM output/input parameter]: sub-index 0 = 32 (20h);
// 04h sync modes supported: bit 0 free run, bit 1 SM synchronous, bits 2-3 = 01 DC SYNC0.
constexpr std::uint16_t kSyncModesSupported = 0x0007;
constexpr std::uint32_t kMinCycleNs = 125000;
constexpr std::uint16_t kSyncFreeRun = 0;
constexpr std::uint16_t kSyncSm = 1;
constexpr std::uint16_t kSyncDc0 = 2;
constexpr std::uint16_t kSyncSm2ForInputs = 0x22;  // 1C33h: inputs latched with the SM2 event

std::uint16_t coe_type(DataType t) noexcept {  // CoE data type codes [ETG.1000.6 Table 64]
  switch (t) {
    case DataType::I8: return data_type::kInteger8;
    case DataType::U8: return data_type::kUnsigned8;
    case DataType::I16: return data_type::kInteger16;
    case DataType::U16: return data_type::kUnsigned16;
    case DataType::I32: return data_type::kInteger32;
    case DataType::U32: return data_type::kUnsigned32;
  }
  return data_type::kUnsigned32;
}

std::uint16_t access_bits(Access a) noexcept {
  switch (a) {
    case Access::ReadOnly: return kReadAll;
    case Access::WriteOnly: return kWriteAll;
    case Access::ReadWrite: return kReadAll | kWriteAll;
  }
  return kReadAll;
}

std::uint32_t to_raw(std::int64_t value, std::uint8_t size) noexcept {
  const auto bits = static_cast<std::uint32_t>(value);  // two's complement, as on the wire
  return size >= 4 ? bits : bits & ((1U << (8U * size)) - 1U);
}

bool faulted(core::AxisState s) noexcept {
  return s == core::AxisState::Fault || s == core::AxisState::FaultReactionActive;
}

bool rx_mapping_index(std::uint16_t i) noexcept { return i >= 0x1600 && i <= 0x17FF; }
bool tx_mapping_index(std::uint16_t i) noexcept { return i >= 0x1A00 && i <= 0x1BFF; }

std::string_view object_name(std::uint16_t index) noexcept {
  if (rx_mapping_index(index)) return "Receive PDO mapping";
  if (tx_mapping_index(index)) return "Transmit PDO mapping";
  switch (index) {
    case 0x1000: return "Device type";
    case 0x1001: return "Error register";
    case 0x1008: return "Manufacturer device name";
    case 0x1009: return "Manufacturer hardware version";
    case 0x100A: return "Manufacturer software version";
    case 0x1010: return "Store parameters";
    case 0x1018: return "Identity";
    case 0x1C00: return "Sync manager communication type";
    case 0x1C12: return "Sync manager 2 PDO assignment";
    case 0x1C13: return "Sync manager 3 PDO assignment";
    case 0x1C32: return "Sync manager 2 parameter";
    case 0x1C33: return "Sync manager 3 parameter";
    case 0x6007: return "Abort connection option code";
    case 0x603F: return "Error code";
    case 0x6040: return "Controlword";
    case 0x6041: return "Statusword";
    case 0x6060: return "Modes of operation";
    case 0x6061: return "Modes of operation display";
    case 0x6062: return "Position demand value";
    case 0x6063: return "Position actual internal value";
    case 0x6064: return "Position actual value";
    case 0x606C: return "Velocity actual value";
    case 0x6071: return "Target torque";
    case 0x6072: return "Max torque";
    case 0x6073: return "Max current";
    case 0x6077: return "Torque actual value";
    case 0x6078: return "Current actual value";
    case 0x6079: return "DC link voltage";
    case 0x607A: return "Target position";
    case 0x6081: return "Profile velocity";
    case 0x6083: return "Profile acceleration";
    case 0x6084: return "Profile deceleration";
    case 0x6086: return "Motion profile type";
    case 0x6098: return "Homing method";
    case 0x60B1: return "Velocity offset";
    case 0x60B2: return "Torque offset";
    case 0x60C0: return "Interpolation sub mode select";
    case 0x60C1: return "Interpolation data record";
    case 0x60C2: return "Interpolation time period";
    case 0x60C3: return "Interpolation sync definition";
    case 0x60C4: return "Interpolation data configuration";
    case 0x60FD: return "Digital inputs";
    case 0x60FF: return "Target velocity";
    case 0x6502: return "Supported drive modes";
    default: return index < 0x6000 ? "Manufacturer object" : "Device profile object";
  }
}

// The names of the sub-indexes where the standards give them [CiA 301 identity object 1018h and
// store parameters 1010h; ETG.1020 SM synchronisation 1C32h/1C33h; CiA 402 interpolation objects],
// else "SubIndex 001" as ESI files (and the slave stacks that generate them) name them, sub-index 0
// too: each entry has its own name in the entry description
// [ETG.1000.6 §5.6.3.6], so a client can name it OBJECT:SUB.
constexpr auto kSubIndexNames = [] {
  std::array<std::array<char, 12>, 256> names{};
  for (std::size_t i = 0; i < names.size(); ++i) {
    constexpr std::string_view kPrefix = "SubIndex ";
    for (std::size_t c = 0; c < kPrefix.size(); ++c) names[i][c] = kPrefix[c];
    names[i][9] = static_cast<char>('0' + i / 100);
    names[i][10] = static_cast<char>('0' + i / 10 % 10);
    names[i][11] = static_cast<char>('0' + i % 10);
  }
  return names;
}();

std::string_view entry_name(std::uint16_t index, std::uint8_t sub) noexcept {
  constexpr std::array<std::string_view, 5> kIdentity{"", "Vendor ID", "Product code", "Revision number", "Serial number"};
  constexpr std::array<std::string_view, 7> kBuffer{"",
                                                    "Maximum buffer size",
                                                    "Actual buffer size",
                                                    "Buffer organization",
                                                    "Buffer position",
                                                    "Size of data record",
                                                    "Buffer clear"};
  switch (index) {
    case 0x1010:
      if (sub == 1) return "Save all parameters";
      break;
    case 0x1018:
      if (sub >= 1 && std::size_t{sub} < kIdentity.size()) return kIdentity[sub];
      break;
    case 0x1C32:
    case 0x1C33:
      switch (sub) {
        case 0x01: return "Synchronization type";
        case 0x02: return "Cycle time";
        case 0x03: return "Shift time";
        case 0x04: return "Synchronization types supported";
        case 0x05: return "Minimum cycle time";
        case 0x06: return "Calc and copy time";
        case 0x09: return "Delay time";
        case 0x0B: return "SM event missed";
        case 0x0C: return "Cycle time too small";
        case 0x20: return "Sync error";
        default: break;
      }
      break;
    case 0x60C1:
      if (sub == 1) return "Interpolation data record 1";
      break;
    case 0x60C2:
      if (sub == 1) return "Interpolation time period value";
      if (sub == 2) return "Interpolation time index";
      break;
    case 0x60C3:
      if (sub == 1) return "Synchronize on group";
      if (sub == 2) return "Ip sync every n event";
      break;
    case 0x60C4:
      if (sub >= 1 && std::size_t{sub} < kBuffer.size()) return kBuffer[sub];
      break;
    default: break;
  }
  return {kSubIndexNames[sub].data(), kSubIndexNames[sub].size()};
}

cia402::sim::DriveModelConfig model_config(const EthercatPersona& p, const Cia402SlaveOptions& o, std::size_t axis) {
  cia402::sim::DriveModelConfig c = axis >= 1 && axis - 1 < o.more_drives.size() ? o.more_drives[axis - 1] : o.drive;
  c.supported_modes.assign(p.modes.begin(), p.modes.end());
  c.identity = cia402::sim::DriveIdentity{p.vendor_id, p.product_code, p.revision, o.serial};
  c.device_type = p.device_type;
  c.initial_mode = p.initial_mode;
  return c;
}

[[noreturn]] void refuse(const EthercatPersona& p, const char* what) {
  throw std::invalid_argument("EtherCAT persona \"" + std::string(p.name) + "\": " + what);
}

}  // namespace

Cia402Slave::Cia402Slave(const EthercatPersona& persona, Cia402SlaveOptions options)
    : persona_(persona), vendor_(persona.vendor_objects.size()) {
  const auto& p = persona_;
  const std::uint32_t axes_end = std::uint32_t{kProfileArea} + std::uint32_t{p.axes} * p.axis_offset;
  if (p.axes < 1 || std::size_t{p.axes} > kMaxAxes || (p.axes > 1 && (p.axis_offset == 0 || axes_end > 0x10000U)))
    refuse(p, "an axis count or axis offset the simulator cannot hold");
  axes_.resize(p.axes);
  for (std::size_t n = 0; n < axes_.size(); ++n)
    axes_[n].model = std::make_unique<cia402::sim::DriveModel>(model_config(p, options, n));
  for (const auto& v : p.vendor_objects) {
    if (!vendor_.add(v.def, v.access, v.value)) refuse(p, "manufacturer object table is inconsistent");
  }
  if (p.rx_pdos.size() > kMaxPdos || p.tx_pdos.size() > kMaxPdos || p.max_entries > kMaxEntries ||
      p.assign_slots > kMaxAssign || p.rx_assign.size() > p.assign_slots || p.tx_assign.size() > p.assign_slots ||
      p.rx_assign_count > p.rx_assign.size() || p.tx_assign_count > p.tx_assign.size()) {
    refuse(p, "more PDOs, entries or assignment slots than the simulator holds");
  }
  for (const auto* list : {&p.rx_pdos, &p.tx_pdos}) {
    for (const auto& d : *list) {
      if (d.entries.size() > p.max_entries) refuse(p, "a default mapping longer than the entry limit");
    }
  }
  rx_.resize(p.rx_pdos.size());
  tx_.resize(p.tx_pdos.size());
  for (const auto& d : p.application_defaults) {
    if (put_app(d.id, d.value) != 0) refuse(p, "a power-on value the drive refuses");
  }
  restore_defaults();
  for (const auto* list : {&rx_, &tx_}) {
    const bool receive = list == &rx_;
    for (const Pdo& d : *list) {
      for (std::size_t k = 0; k < d.count; ++k) {
        if (check_entry(d.entries[k], receive) != 0) refuse(p, "a default mapping entry the drive cannot map");
      }
    }
  }
  if (assigned_bytes(true) > p.process_data_capacity || assigned_bytes(false) > p.process_data_capacity) {
    refuse(p, "default process data larger than its capacity");
  }
  build_entries();
  build_sii(options.serial, options.station_alias, options.sdo_information);
}

Cia402Slave::~Cia402Slave() = default;

EscConfig Cia402Slave::esc_config() const noexcept {
  EscConfig c;
  c.dc_supported = persona_.dc_supported;  // ESR: no DC (quirk 9)
  return c;
}

// ---------------------------------------------------------------------------------------------
// Power-on values

void Cia402Slave::restore_defaults() noexcept {
  const auto& p = persona_;
  plan_valid_ = false;
  for (std::size_t i = 0; i < rx_.size(); ++i) {
    rx_[i] = Pdo{};
    rx_[i].index = p.rx_pdos[i].index;
    rx_[i].count = static_cast<std::uint8_t>(p.rx_pdos[i].entries.size());
    std::copy(p.rx_pdos[i].entries.begin(), p.rx_pdos[i].entries.end(), rx_[i].entries.begin());
  }
  for (std::size_t i = 0; i < tx_.size(); ++i) {
    tx_[i] = Pdo{};
    tx_[i].index = p.tx_pdos[i].index;
    tx_[i].count = static_cast<std::uint8_t>(p.tx_pdos[i].entries.size());
    std::copy(p.tx_pdos[i].entries.begin(), p.tx_pdos[i].entries.end(), tx_[i].entries.begin());
  }
  rx_assign_ = Assign{};
  rx_assign_.count = p.rx_assign_count;
  std::copy(p.rx_assign.begin(), p.rx_assign.end(), rx_assign_.pdos.begin());
  tx_assign_ = Assign{};
  tx_assign_.count = p.tx_assign_count;
  std::copy(p.tx_assign.begin(), p.tx_assign.end(), tx_assign_.pdos.begin());
  vendor_.reset_to_defaults();
  sm_out_sync_mode_ = kSyncFreeRun;
  sm_out_cycle_ns_ = 0;
  sm_in_sync_mode_ = kSyncFreeRun;
  for (std::size_t n = 0; n < axes_.size(); ++n) {
    AxisState& a = axes_[n];
    a.abort_option = p.abort_option_default;
    a.ip_active = false;
    a.ip_elapsed_ns = 0;
    // Axis 0's objects: every axis takes them at its own offset.
    for (const auto& d : p.application_defaults) {
      ObjectId id = d.id;
      if (n > 0 && id.index >= kProfileArea && id.index < kProfileArea + p.axis_offset)
        id.index = static_cast<std::uint16_t>(id.index + n * p.axis_offset);
      (void)put_app(id, d.value);
    }
  }
}

void Cia402Slave::power_cycle() noexcept {
  for (AxisState& a : axes_) {
    a.model->power_cycle();
    a.comm_fault_raised = false;
  }
  restore_defaults();
  started_ = false;
  al_error_seen_ = false;
}

Cia402Slave::Located Cia402Slave::locate(ObjectId id) const noexcept {
  // Single-axis slaves keep the whole 6000h..FFFFh range on their one model.
  if (axes_.size() <= 1 || id.index < kProfileArea) return {0, id};
  const auto n = static_cast<std::size_t>((id.index - kProfileArea) / persona_.axis_offset);
  if (n >= axes_.size()) return {0, id};
  return {n, ObjectId{static_cast<std::uint16_t>(id.index - n * persona_.axis_offset), id.sub}};
}

// ---------------------------------------------------------------------------------------------
// Objects

bool Cia402Slave::hidden(ObjectId id) const noexcept {
  const auto& h = persona_.hidden;
  return std::find(h.begin(), h.end(), locate(id).local) != h.end();
}

bool Cia402Slave::ignored(ObjectId id) const noexcept {
  const auto& l = persona_.ignored_writes;
  return std::find(l.begin(), l.end(), locate(id).local) != l.end();
}

const EcatVendorObject* Cia402Slave::vendor_object(ObjectId id) const noexcept {
  for (const auto& v : persona_.vendor_objects) {
    if (v.def.id == id) return &v;
  }
  return nullptr;
}

std::string_view Cia402Slave::text_of(ObjectId id) const noexcept {
  switch (id.index) {
    case 0x1008: return persona_.device_name;
    case 0x1009: return persona_.hardware_version;
    case 0x100A: return persona_.software_version;
    default: return {};
  }
}

std::optional<DataType> Cia402Slave::type_of(ObjectId id) const noexcept {
  if (hidden(id)) return std::nullopt;
  if (const EcatVendorObject* v = vendor_object(id)) return v->def.type;
  const Located at = locate(id);
  const auto t = axes_[at.axis].model->dictionary().type_of(at.local);
  if (!t) return std::nullopt;
  for (const auto& o : persona_.type_overrides) {
    if (o.id == at.local) return o.type;
  }
  return t;
}

std::optional<Access> Cia402Slave::access_of(ObjectId id) const noexcept {
  if (hidden(id)) return std::nullopt;
  if (const EcatVendorObject* v = vendor_object(id)) return v->access;
  const Located at = locate(id);
  return axes_[at.axis].model->dictionary().access_of(at.local);
}

std::optional<DataType> Cia402Slave::mappable(ObjectId id, bool receive) const noexcept {
  const auto& list = receive ? persona_.rx_mappable : persona_.tx_mappable;
  if (!list.empty()) {
    if (std::find(list.begin(), list.end(), locate(id).local) == list.end()) return std::nullopt;  // whitelist (ESR §7.3)
  } else if (id.index < 0x2000) {
    return std::nullopt;  // communication objects are not process data
  }
  const auto type = type_of(id);
  const auto access = access_of(id);
  if (!type || !access) return std::nullopt;
  if (receive ? *access == Access::ReadOnly : *access == Access::WriteOnly) return std::nullopt;
  return type;
}

std::uint32_t Cia402Slave::check_entry(std::uint32_t entry, bool receive) const noexcept {
  const ObjectId id{static_cast<std::uint16_t>(entry >> 16), static_cast<std::uint8_t>(entry >> 8)};
  const auto bits = entry & 0xFFU;
  const auto type = mappable(id, receive);
  // Whole objects only, with their exact length [CiA 301 §7.5.2.36; dunker §7.2].
  if (!type || bits != 8U * cia402::size_of(*type)) return abort::kNotMappable;
  return 0;
}

Cia402Slave::Pdo* Cia402Slave::pdo(std::uint16_t index, bool* receive) noexcept {
  for (auto* list : {&rx_, &tx_}) {
    for (Pdo& p : *list) {
      if (p.index == index) {
        if (receive != nullptr) *receive = list == &rx_;
        return &p;
      }
    }
  }
  return nullptr;
}
const Cia402Slave::Pdo* Cia402Slave::pdo(std::uint16_t index, bool* receive) const noexcept {
  return const_cast<Cia402Slave*>(this)->pdo(index, receive);
}

std::size_t Cia402Slave::pdo_bytes(const Pdo& p) const noexcept {
  std::size_t bits = 0;
  for (std::size_t k = 0; k < p.count; ++k) bits += p.entries[k] & 0xFFU;
  return (bits + 7) / 8;
}

std::size_t Cia402Slave::assigned_bytes(bool receive) const noexcept {
  const Assign& a = receive ? rx_assign_ : tx_assign_;
  std::size_t n = 0;
  for (std::size_t k = 0; k < a.count; ++k) {
    bool rx = false;
    const Pdo* p = pdo(a.pdos[k], &rx);
    if (p != nullptr && rx == receive) n += pdo_bytes(*p);
  }
  return n;
}

Cia402Slave::Resolved Cia402Slave::resolve(ObjectId id) const noexcept {
  Resolved r;
  r.id = id;
  r.at = locate(id);
  r.type = type_of(id);
  r.access = access_of(id);
  r.model_type = axes_[r.at.axis].model->dictionary().type_of(r.at.local);
  r.model_value = axes_[r.at.axis].model->dictionary().value_address(r.at.local);
  r.vendor = vendor_object(id);
  r.hidden = hidden(id);
  r.ignored = ignored(id);
  return r;
}

const Cia402Slave::Plan& Cia402Slave::plan() const noexcept {
  if (!plan_valid_) build_plan();
  return plan_;
}

void Cia402Slave::build_plan() const noexcept {
  // The walk of apply_outputs()/fill_inputs(): each assigned mapping object found by its index.
  const auto flatten = [this](const Assign& a, std::array<MappedEntry, kMaxAssign * kMaxEntries>& out) {
    std::size_t n = 0;
    for (std::size_t k = 0; k < a.count; ++k) {
      const Pdo* d = pdo(a.pdos[k], nullptr);
      if (d == nullptr) continue;
      for (std::size_t e = 0; e < d->count && n < out.size(); ++e) {
        const std::uint32_t m = d->entries[e];
        out[n].object = resolve({static_cast<std::uint16_t>(m >> 16), static_cast<std::uint8_t>(m >> 8)});
        out[n].bytes = static_cast<std::uint8_t>((m & 0xFFU) / 8);
        ++n;
      }
    }
    return n;
  };
  plan_.rx_n = flatten(rx_assign_, plan_.rx);
  plan_.tx_n = flatten(tx_assign_, plan_.tx);
  plan_.output_bytes = assigned_bytes(true);
  plan_.input_bytes = assigned_bytes(false);
  plan_valid_ = true;
}

Cia402Slave::Value Cia402Slave::get(const Resolved& r) const noexcept {
  const ObjectId id = r.id;
  const Located at = r.at;
  if (!r.type) {
    if (r.hidden) return {abort::kNoObject, 0, 0};
    const bool vendor_index = std::any_of(persona_.vendor_objects.begin(), persona_.vendor_objects.end(),
                                          [&](const EcatVendorObject& v) { return v.def.id.index == id.index; });
    return {vendor_index ? abort::kNoSubIndex : axes_[at.axis].model->dictionary().missing_code(at.local), 0, 0};
  }
  if (r.access == Access::WriteOnly) return {abort::kWriteOnly, 0, 0};
  const AxisState& axis = axes_[at.axis];
  std::int64_t value = 0;
  if (r.vendor != nullptr) {
    if (r.vendor->source == EcatVendorSource::TorqueActual) {
      value = std::clamp<std::int64_t>(std::llround(axes_[0].model->torque()), cia402::sim::type_min(r.vendor->def.type),
                                       cia402::sim::type_max(r.vendor->def.type));
    } else {
      value = vendor_.get(id).value_or(0);
    }
  } else if (r.model_value != nullptr) {
    value = *r.model_value;
  }
  if (at.local == kControlword) value = from_model_controlword(axis, static_cast<std::uint16_t>(value));
  // ESR: no "ip mode active" bit in ip (quirk 7).
  if (at.local == kStatusword && !persona_.ip_status_bit12 &&
      axis.model->active_mode() == cia402::op_mode::kInterpolatedPosition) {
    value &= ~std::int64_t{0x1000};
  }
  const std::uint8_t size = cia402::size_of(*r.type);
  return {0, to_raw(value, size), size};
}

std::uint32_t Cia402Slave::put_app(const Resolved& r, std::int64_t value) noexcept {
  const Located at = r.at;
  AxisState& axis = axes_[at.axis];
  for (const auto& range : persona_.ranges) {
    if (range.id == at.local) {
      if (value > range.max) return abort::kValueTooHigh;
      if (value < range.min) return abort::kValueTooLow;
    }
  }
  if (r.vendor != nullptr) return vendor_.set(r.id, value);
  const auto model_type = r.model_type;
  if (!model_type || r.hidden) return abort::kNoObject;
  // A wider type on the wire than in the model (ESR 6060h as INTEGER16): values the model's type
  // cannot hold are out of range.
  if (value < cia402::sim::type_min(*model_type) || value > cia402::sim::type_max(*model_type)) {
    return abort::kValueRange;
  }
  if (at.local == kControlword) value = to_model_controlword(axis, static_cast<std::uint16_t>(value));
  if (at.local == kIpDataRecord && persona_.fine_interpolation) {
    // ESR fine interpolator [dunker §12]: a new set-point is reached over one 60C2h period in
    // 1 ms steps (advance()).
    if (!axis.ip_active || value != axis.ip_target) {
      axis.ip_start = static_cast<std::int32_t>(axis.model->dictionary().get(kIpDataRecord).value_or(0));
      axis.ip_target = static_cast<std::int32_t>(value);
      axis.ip_elapsed_ns = 0;
      axis.ip_active = true;
    }
    return 0;
  }
  return axis.model->write_object(at.local, value);
}

std::uint32_t Cia402Slave::put(ObjectId id, std::uint32_t raw, std::size_t size, AlState /*state*/) noexcept {
  // CiA 301 order of checks: the object, access, the length, then the value.
  const auto type = type_of(id);
  if (!type) return get(id).abort;
  if (access_of(id) == Access::ReadOnly) return abort::kReadOnly;
  if (size != cia402::size_of(*type)) return abort::kTypeMismatch;
  if (ignored(id)) return 0;  // ESR quirk 8: accepted, not applied
  return put_app(id, cia402::normalise(*type, raw));
}

std::uint16_t Cia402Slave::to_model_controlword(const AxisState& a, std::uint16_t cw) const noexcept {
  // ESR: bit 6 = 1 is an absolute move in pp (quirk 14 [EXT]); the model follows CiA 402 (1 = relative).
  if (persona_.controlword_bit6_absolute && a.model->active_mode() == cia402::op_mode::kProfilePosition) {
    return static_cast<std::uint16_t>(cw ^ 0x0040U);
  }
  return cw;
}
std::uint16_t Cia402Slave::from_model_controlword(const AxisState& a, std::uint16_t cw) const noexcept {
  return to_model_controlword(a, cw);
}

// ---------------------------------------------------------------------------------------------
// Communication objects

std::optional<Cia402Slave::Value> Cia402Slave::get_comm(ObjectId id) const noexcept {
  const auto& p = persona_;
  const auto sub = id.sub;
  const Value no_sub{abort::kNoSubIndex, 0, 0};
  if (rx_mapping_index(id.index) || tx_mapping_index(id.index)) {
    const Pdo* d = pdo(id.index, nullptr);
    if (d == nullptr) return Value{abort::kNoObject, 0, 0};
    if (sub == 0) return Value{0, d->count, 1};
    if (sub > p.max_entries) return no_sub;
    return Value{0, d->entries[sub - 1U], 4};
  }
  if (const Located at = locate(id); at.local.index == kAbortOption.index) {
    if (sub == 0) return Value{0, to_raw(axes_[at.axis].abort_option, 2), 2};
    return no_sub;
  }
  switch (id.index) {
    case 0x1010:
      if (!p.store_parameters) return std::nullopt;
      if (sub == 0) return Value{0, 1, 1};
      if (sub == 1) return Value{0, 1, 4};  // bit 0: saves on command
      return no_sub;
    case 0x1C00:  // SM0 mailbox out 1, SM1 mailbox in 2, SM2 outputs 3, SM3 inputs 4 [dunker §11.2]
      if (sub <= 4) return Value{0, sub == 0 ? 4U : sub, 1};
      return no_sub;
    case 0x1C12:
    case 0x1C13: {
      const Assign& a = id.index == 0x1C12 ? rx_assign_ : tx_assign_;
      if (sub == 0) return Value{0, a.count, 1};
      if (sub > p.assign_slots) return no_sub;
      return Value{0, a.pdos[sub - 1U], 2};
    }
    case 0x1C32:
    case 0x1C33: {
      if (!p.sync_manager_parameters) return std::nullopt;
      const bool out = id.index == 0x1C32;
      switch (sub) {
        case 0x00: return Value{0, 0x20, 1};
        case 0x01: return Value{0, out ? sm_out_sync_mode_ : sm_in_sync_mode_, 2};
        case 0x02: return Value{0, sm_out_cycle_ns_, 4};
        case 0x03: return Value{0, 0, 4};  // shift time
        case 0x04: return Value{0, kSyncModesSupported, 2};
        case 0x05: return Value{0, kMinCycleNs, 4};
        case 0x06: return Value{0, 0, 4};  // calc and copy time
        case 0x09: return Value{0, 0, 4};  // delay time
        case 0x0B: return Value{0, 0, 2};  // SM event missed counter
        case 0x0C: return Value{0, 0, 2};  // cycle time too small counter
        case 0x20: return Value{0, 0, 1};  // sync error
        default: return no_sub;
      }
    }
    default:
      return std::nullopt;
  }
}

std::optional<std::uint32_t> Cia402Slave::put_comm(ObjectId id, std::uint32_t raw, std::size_t size,
                                                   AlState state) noexcept {
  const auto& p = persona_;
  const auto sub = id.sub;
  if (rx_mapping_index(id.index) || tx_mapping_index(id.index)) {
    bool receive = false;
    Pdo* d = pdo(id.index, &receive);
    if (d == nullptr) return abort::kNoObject;
    return put_pdo(*d, receive, sub, raw, size, state);
  }
  if (const Located at = locate(id); at.local.index == kAbortOption.index) {
    if (sub != 0) return abort::kNoSubIndex;
    if (size != 2) return abort::kTypeMismatch;
    const auto v = cia402::normalise(DataType::I16, raw);
    // CiA 402: 0..3 (negative values are manufacturer-specific, none here); ESR 0..1 (§11.2).
    if (v < 0 || v > p.abort_option_max) return abort::kValueRange;
    axes_[at.axis].abort_option = static_cast<std::int16_t>(v);
    return 0;
  }
  switch (id.index) {
    case 0x1010:
      if (!p.store_parameters) return std::nullopt;
      if (sub == 0) return abort::kReadOnly;
      if (sub != 1) return abort::kNoSubIndex;
      if (size != 4) return abort::kTypeMismatch;
      // Accepted; nothing survives a power cycle in the simulator.
      return raw == kSaveSignature ? 0 : abort::kCannotStore;
    case 0x1C00:
      return sub <= 4 ? abort::kReadOnly : abort::kNoSubIndex;
    case 0x1C12:
      return put_assign(rx_assign_, true, sub, raw, size, state);
    case 0x1C13:
      return put_assign(tx_assign_, false, sub, raw, size, state);
    case 0x1C32:
    case 0x1C33: {
      if (!p.sync_manager_parameters) return std::nullopt;
      const auto v = get_comm(id);
      if (v && v->abort != 0) return v->abort;
      const bool out = id.index == 0x1C32;
      if (sub != 0x01 && !(sub == 0x02 && out)) return abort::kReadOnly;
      if (v && size != v->size) return abort::kTypeMismatch;
      if (state != AlState::PreOp) return abort::kDeviceState;
      if (sub == 0x02) {
        sm_out_cycle_ns_ = raw;
        return 0;
      }
      const bool ok = raw == kSyncFreeRun || raw == kSyncSm || raw == kSyncDc0 || (!out && raw == kSyncSm2ForInputs);
      if (!ok) return abort::kValueRange;
      (out ? sm_out_sync_mode_ : sm_in_sync_mode_) = static_cast<std::uint16_t>(raw);
      return 0;
    }
    default:
      return std::nullopt;
  }
}

std::uint32_t Cia402Slave::put_pdo(Pdo& d, bool receive, std::uint8_t sub, std::uint32_t raw, std::size_t size,
                                   AlState state) noexcept {
  const auto& p = persona_;
  plan_valid_ = false;
  if (sub > p.max_entries) return abort::kNoSubIndex;  // a 9th entry on ESR (§7.2)
  if (size != (sub == 0 ? 1U : 4U)) return abort::kTypeMismatch;
  // Mapping in PRE-OP; ESR RxPDO mapping also in SAFE-OP (quirk 4).
  const bool writable = state == AlState::PreOp || (state == AlState::SafeOp && receive && p.rx_mapping_writable_in_safeop);
  if (!writable) return abort::kDeviceState;
  if (sub == 0) {
    if (raw > p.max_entries) return abort::kValueTooHigh;
    std::size_t bits = 0;
    for (std::size_t k = 0; k < raw; ++k) {
      if (d.entries[k] == 0 || check_entry(d.entries[k], receive) != 0) return abort::kNotMappable;
      bits += d.entries[k] & 0xFFU;
    }
    if ((bits + 7) / 8 > p.process_data_capacity) return abort::kPdoLength;
    d.count = static_cast<std::uint8_t>(raw);
    return 0;
  }
  // Count-zero rule: entries change only while sub-index 0 is 0 [ETG.1000.6 PDO mapping].
  if (d.count != 0) return cia402::sdo_abort_code::kSubindexZeroFirst;
  if (raw != 0 && check_entry(raw, receive) != 0) return abort::kNotMappable;
  d.entries[sub - 1U] = raw;
  return 0;
}

std::uint32_t Cia402Slave::put_assign(Assign& a, bool receive, std::uint8_t sub, std::uint32_t raw, std::size_t size,
                                      AlState state) noexcept {
  const auto& p = persona_;
  plan_valid_ = false;
  if (sub > p.assign_slots) return abort::kNoSubIndex;
  if (size != (sub == 0 ? 1U : 2U)) return abort::kTypeMismatch;
  if (state != AlState::PreOp) return abort::kDeviceState;  // [ETG.1000.6: assignment in PRE-OP]
  // The mapping object of this direction, or null.
  const auto find = [&](std::uint32_t index) -> const Pdo* {
    bool rx = false;
    const Pdo* d = index <= 0xFFFF ? pdo(static_cast<std::uint16_t>(index), &rx) : nullptr;
    return (d != nullptr && rx == receive) ? d : nullptr;
  };
  if (sub == 0) {
    if (raw > p.assign_slots) return abort::kValueTooHigh;
    std::size_t bytes = 0;
    for (std::size_t k = 0; k < raw; ++k) {
      const Pdo* d = find(a.pdos[k]);
      if (d == nullptr) return abort::kValueRange;
      bytes += pdo_bytes(*d);
    }
    if (bytes > p.process_data_capacity) return abort::kPdoLength;
    a.count = static_cast<std::uint8_t>(raw);
    return 0;
  }
  if (a.count != 0) return cia402::sdo_abort_code::kSubindexZeroFirst;
  if (raw != 0 && find(raw) == nullptr) return abort::kValueRange;  // ESR: 1602h does not exist (quirk 3)
  a.pdos[sub - 1U] = static_cast<std::uint16_t>(raw);
  return 0;
}

// ---------------------------------------------------------------------------------------------
// ObjectDictionary (the CoE server's view)

OdReadResult Cia402Slave::read(std::uint16_t index, std::uint8_t subindex, std::span<std::uint8_t> out,
                               AlState /*state*/) noexcept {
  const ObjectId id{index, subindex};
  if (index >= 0x1008 && index <= 0x100A) {
    const std::string_view t = text_of(id);
    if (t.empty()) return {abort::kNoObject, 0};
    if (subindex != 0) return {abort::kNoSubIndex, 0};
    if (t.size() > out.size()) return {abort::kOutOfMemory, 0};
    std::copy(t.begin(), t.end(), out.begin());
    return {0, t.size()};
  }
  const Value v = get_comm(id).value_or(get(id));
  if (v.abort != 0) return {v.abort, 0};
  if (v.size > out.size()) return {abort::kOutOfMemory, 0};
  for (std::size_t k = 0; k < v.size; ++k) out[k] = static_cast<std::uint8_t>(v.raw >> (8U * k));
  return {0, v.size};
}

std::uint32_t Cia402Slave::write(std::uint16_t index, std::uint8_t subindex, std::span<const std::uint8_t> data,
                                 AlState state) noexcept {
  const ObjectId id{index, subindex};
  if (index >= 0x1008 && index <= 0x100A) {
    if (text_of(id).empty()) return abort::kNoObject;
    return subindex == 0 ? abort::kReadOnly : abort::kNoSubIndex;
  }
  if (data.empty() || data.size() > 4) {
    // Every object here is 1..4 bytes: the object's own abort first, else a length mismatch.
    const Value v = get_comm(id).value_or(get(id));
    return v.abort != 0 ? v.abort : abort::kTypeMismatch;
  }
  std::uint32_t raw = 0;
  for (std::size_t k = 0; k < data.size(); ++k) raw |= static_cast<std::uint32_t>(data[k]) << (8U * k);
  if (const auto c = put_comm(id, raw, data.size(), state)) return *c;
  return put(id, raw, data.size(), state);
}

const Cia402Slave::Entry* Cia402Slave::find_entry(ObjectId id) const noexcept {
  const auto it = std::lower_bound(entries_.begin(), entries_.end(), id.key(),
                                   [](const Entry& e, std::uint32_t k) { return e.id.key() < k; });
  return (it != entries_.end() && it->id == id) ? &*it : nullptr;
}

std::size_t Cia402Slave::list(OdListType type, std::span<std::uint16_t> out) const noexcept {
  std::size_t n = 0;
  for (std::size_t i = 0; i < entries_.size();) {
    const std::uint16_t index = entries_[i].id.index;
    bool match = type == OdListType::All;
    for (; i < entries_.size() && entries_[i].id.index == index; ++i) {
      const auto a = entries_[i].access;
      if ((type == OdListType::RxPdoMappable && (a & object_access::kRxPdoMappable) != 0) ||
          (type == OdListType::TxPdoMappable && (a & object_access::kTxPdoMappable) != 0)) {
        match = true;
      }
    }
    if (!match) continue;
    if (n < out.size()) out[n] = index;
    ++n;
  }
  return n;
}

bool Cia402Slave::describe_object(std::uint16_t index, SdoInfoObjectDescription& out) const noexcept {
  const auto first = std::lower_bound(entries_.begin(), entries_.end(), ObjectId{index, 0}.key(),
                                      [](const Entry& e, std::uint32_t k) { return e.id.key() < k; });
  if (first == entries_.end() || first->id.index != index) return false;
  out = SdoInfoObjectDescription{};
  out.index = index;
  out.name = name_of(index);
  for (auto it = first; it != entries_.end() && it->id.index == index; ++it) {
    out.max_subindex = std::max(out.max_subindex, it->id.sub);
    if (it->id.sub <= 1) out.data_type = it->data_type;  // sub-index 1's for arrays and records
  }
  const bool array = index == 0x1018 || index == 0x1C00 || index == 0x1C12 || index == 0x1C13 || index == 0x60C3;
  out.object_code = out.max_subindex == 0 ? object_code::kVariable : (array ? object_code::kArray : object_code::kRecord);
  return true;
}

bool Cia402Slave::describe_entry(std::uint16_t index, std::uint8_t subindex, SdoInfoEntryDescription& out) const noexcept {
  const Entry* e = find_entry({index, subindex});
  if (e == nullptr) return false;
  const Entry* sub1 = find_entry({index, 1});
  out = SdoInfoEntryDescription{};
  out.index = index;
  out.subindex = subindex;
  out.data_type = e->data_type;
  out.bit_length = e->bits;
  out.object_access = e->access;
  // A variable: the object's name; an array's or record's entry: its own.
  out.name = sub1 == nullptr ? name_of(index) : entry_name(locate({index, 0}).local.index, subindex);
  return true;
}

std::string_view Cia402Slave::name_of(std::uint16_t index) const noexcept {
  if (const EcatVendorObject* v = vendor_object({index, 0}); v != nullptr && !v->name.empty()) return v->name;
  return object_name(locate({index, 0}).local.index);
}

void Cia402Slave::build_entries() {
  const auto& p = persona_;
  const std::uint16_t rw_preop = kReadAll | object_access::kWritePreOp;
  auto add = [this](ObjectId id, std::uint16_t type, std::uint16_t access, std::uint16_t bits, Kind kind) {
    entries_.push_back(Entry{id, type, access, bits, kind});
  };
  for (std::uint16_t i = 0x1008; i <= 0x100A; ++i) {
    const auto t = text_of({i, 0});
    if (!t.empty()) add({i, 0}, data_type::kVisibleString, kReadAll, static_cast<std::uint16_t>(8 * t.size()), Kind::Text);
  }
  if (p.store_parameters) {
    add({0x1010, 0}, data_type::kUnsigned8, kReadAll, 8, Kind::Comm);
    add({0x1010, 1}, data_type::kUnsigned32, kReadAll | kWriteAll, 32, Kind::Comm);
  }
  for (std::uint8_t s = 0; s <= 4; ++s) add({0x1C00, s}, data_type::kUnsigned8, kReadAll, 8, Kind::Comm);
  for (const auto* list : {&rx_, &tx_}) {
    const bool receive = list == &rx_;
    const std::uint16_t a = static_cast<std::uint16_t>(
        rw_preop | (receive && p.rx_mapping_writable_in_safeop ? object_access::kWriteSafeOp : 0));
    for (const Pdo& d : *list) {
      add({d.index, 0}, data_type::kUnsigned8, a, 8, Kind::Comm);
      for (std::uint8_t s = 1; s <= p.max_entries; ++s) add({d.index, s}, data_type::kUnsigned32, a, 32, Kind::Comm);
    }
  }
  for (const std::uint16_t i : {std::uint16_t{0x1C12}, std::uint16_t{0x1C13}}) {
    add({i, 0}, data_type::kUnsigned8, rw_preop, 8, Kind::Comm);
    for (std::uint8_t s = 1; s <= p.assign_slots; ++s) add({i, s}, data_type::kUnsigned16, rw_preop, 16, Kind::Comm);
  }
  if (p.sync_manager_parameters) {
    for (const std::uint16_t i : {std::uint16_t{0x1C32}, std::uint16_t{0x1C33}}) {
      constexpr std::array<std::uint8_t, 11> kSubs{0x00, 0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x09, 0x0B, 0x0C, 0x20};
      for (const std::uint8_t s : kSubs) {
        const auto v = get_comm({i, s});
        const bool writable = s == 0x01 || (s == 0x02 && i == 0x1C32);
        const std::uint16_t type = v->size == 1 ? (s == 0x20 ? data_type::kBoolean : data_type::kUnsigned8)
                                                : (v->size == 2 ? data_type::kUnsigned16 : data_type::kUnsigned32);
        add({i, s}, type, writable ? rw_preop : kReadAll, static_cast<std::uint16_t>(s == 0x20 ? 1 : 8 * v->size), Kind::Comm);
      }
    }
  }
  for (std::size_t n = 0; n < axes_.size(); ++n)
    add({static_cast<std::uint16_t>(kAbortOption.index + n * p.axis_offset), 0}, data_type::kInteger16,
        kReadAll | kWriteAll, 16, Kind::Comm);
  auto application = [&](ObjectId id, Kind kind) {
    const auto type = type_of(id);
    const auto access = access_of(id);
    if (!type || !access) return;
    auto a = access_bits(*access);
    if (mappable(id, true)) a = static_cast<std::uint16_t>(a | object_access::kRxPdoMappable);
    if (mappable(id, false)) a = static_cast<std::uint16_t>(a | object_access::kTxPdoMappable);
    add(id, coe_type(*type), a, static_cast<std::uint16_t>(8 * cia402::size_of(*type)), kind);
  };
  for (const auto& v : p.vendor_objects) application(v.def.id, Kind::Vendor);
  // The models' dictionaries have no iteration: probe the areas they fill (1000h..1FFFh,
  // 6000h..6FFFh; a multi-axis slave's axes beyond 6FFFh too).
  const auto last = std::max<std::uint32_t>(
      0x6FFF, static_cast<std::uint32_t>(kProfileArea + axes_.size() * p.axis_offset - 1U));
  for (std::uint32_t index = 0x1000; index <= last; ++index) {
    if (index == 0x2000) index = 0x6000;
    for (std::uint8_t sub = 0; sub <= 8; ++sub) {
      const ObjectId id{static_cast<std::uint16_t>(index), sub};
      const Located at = locate(id);
      if (axes_[at.axis].model->dictionary().type_of(at.local) && vendor_object(id) == nullptr) application(id, Kind::Model);
    }
  }
  std::stable_sort(entries_.begin(), entries_.end(), [](const Entry& a, const Entry& b) { return a.id.key() < b.id.key(); });
  entries_.erase(std::unique(entries_.begin(), entries_.end(), [](const Entry& a, const Entry& b) { return a.id == b.id; }),
                 entries_.end());
}

void Cia402Slave::build_sii(std::uint32_t serial, std::uint16_t alias, bool sdo_information) {
  const auto& p = persona_;
  // The power-on assigned PDOs as TXPDO/RXPDO categories [ETG.1000.6 §5.4], SM2/SM3 lengths from
  // them. Entry data types are the CoE codes (low byte).
  std::vector<std::vector<SiiBuildEntry>> entries;
  std::vector<SiiBuildPdo> rx_pdos;
  std::vector<SiiBuildPdo> tx_pdos;
  entries.reserve(2 * kMaxAssign);
  for (const auto* a : {&rx_assign_, &tx_assign_}) {
    const bool receive = a == &rx_assign_;
    for (std::size_t k = 0; k < a->count; ++k) {
      const Pdo* d = pdo(a->pdos[k], nullptr);
      if (d == nullptr) continue;
      auto& list = entries.emplace_back();
      for (std::size_t e = 0; e < d->count; ++e) {
        const std::uint32_t m = d->entries[e];
        const ObjectId id{static_cast<std::uint16_t>(m >> 16), static_cast<std::uint8_t>(m >> 8)};
        const auto type = type_of(id).value_or(DataType::U32);
        list.push_back(SiiBuildEntry{id.index, id.sub, object_name(id.index), static_cast<std::uint8_t>(coe_type(type)),
                                     static_cast<std::uint8_t>(m & 0xFFU), 0});
      }
      const SiiBuildPdo pd{d->index, static_cast<std::uint8_t>(receive ? 2 : 3), 0,
                           receive ? std::string_view("Outputs") : std::string_view("Inputs"), 0, list};
      (receive ? rx_pdos : tx_pdos).push_back(pd);
    }
  }
  const std::array<std::uint8_t, 3> fmmus{sii_fmmu_usage::kOutputs, sii_fmmu_usage::kInputs, sii_fmmu_usage::kSyncMStatus};
  const std::array<SiiSyncManager, 4> sms{
      SiiSyncManager{kDriveMailboxOut, kDriveMailboxSize, sm_control::kMailboxOut, 0, 1, sii_sm_type::kMailboxOut},
      SiiSyncManager{kDriveMailboxIn, kDriveMailboxSize, sm_control::kMailboxIn, 0, 1, sii_sm_type::kMailboxIn},
      SiiSyncManager{kDriveOutputs, static_cast<std::uint16_t>(assigned_bytes(true)), sm_control::kOutputs, 0, 1,
                     sii_sm_type::kOutputs},
      SiiSyncManager{kDriveInputs, static_cast<std::uint16_t>(assigned_bytes(false)), sm_control::kInputs, 0, 1,
                     sii_sm_type::kInputs},
  };
  // DC category: free run and SYNC0 (assign/activate 0300h: cyclic operation + SYNC0 [ETG.2010]).
  std::array<SiiBuildDc, 2> dcs{};
  dcs[0].name = "FreeRun";
  dcs[1].name = "DC SYNC0";
  dcs[1].dc.assign_activate = 0x0300;
  dcs[1].dc.cycle_time0 = 1000000;
  SiiProfile profile;
  profile.header.station_alias = alias;
  profile.header.identity = SiiIdentity{p.vendor_id, p.product_code, p.revision, serial};
  profile.header.standard_mailbox = SiiMailbox{kDriveMailboxOut, kDriveMailboxSize, kDriveMailboxIn, kDriveMailboxSize};
  profile.header.mailbox_protocols = mailbox_protocol::kCoE;
  profile.group = p.sii_group;
  profile.image = "";
  profile.order = p.sii_order;
  profile.name = p.device_name;
  profile.general.coe_details = static_cast<std::uint8_t>(coe_details::kSdo | (sdo_information ? coe_details::kSdoInfo : 0) |
                                                         coe_details::kPdoAssign | coe_details::kPdoConfig);
  profile.general.ds402_channels = static_cast<std::uint8_t>(axes_.size());
  profile.general.physical_ports = 0x0011;  // ports 0 and 1 MII
  profile.fmmus = fmmus;
  profile.sync_managers = sms;
  profile.rx_pdos = rx_pdos;
  profile.tx_pdos = tx_pdos;
  if (p.dc_supported) profile.dcs = dcs;
  for (const std::size_t bytes : {std::size_t{2048}, std::size_t{4096}}) {
    profile.eeprom_bytes = bytes;
    sii_.assign(bytes, 0);
    const SiiBuildResult r = drivegate::ethercat::build_sii(profile, sii_);
    if (r.ok()) {
      sii_.resize(r.size);
      return;
    }
    if (r.error != SiiBuildError::ContentTooLarge) break;
  }
  refuse(p, "its SII image cannot be built");
}

// ---------------------------------------------------------------------------------------------
// ESC state machine and cycle

std::uint16_t Cia402Slave::on_state_change(AlState from, AlState to) noexcept {
  // 1C32h:01 = 2 (DC SYNC0) needs SYNC0 running before OP: 0981h cyclic operation + SYNC0
  // [ETG.1020 synchronisation; ETG.1000.6 AL status code 0030h].
  if (from == AlState::SafeOp && to == AlState::Op && persona_.sync_manager_parameters && sm_out_sync_mode_ == kSyncDc0) {
    const std::uint8_t act = esc_ != nullptr ? esc_->memory()[reg::kDcActivation] : 0;
    const std::uint8_t need = dc_activation::kCyclicOperation | dc_activation::kSync0;
    if ((act & need) != need) return al_status_code::kInvalidDcSyncConfig;
  }
  return 0;
}

void Cia402Slave::on_state_entered(AlState from, AlState to) noexcept {
  if (from != AlState::Op || to == AlState::Op) return;
  // The ESC clears 0440h bit 0 before it leaves OP for an expired SM watchdog (esc_slave.cpp
  // watchdog_check): that tells the watchdog from a requested transition.
  const bool watchdog = esc_ != nullptr && (esc_->memory()[reg::kWatchdogStatusProcessData] & 0x01U) == 0;
  // A requested exit counts only while the drive runs: a master that disables the drive first
  // (digest "What a master must do", step 13) leaves OP without a reaction.
  // Per axis: the watchdog concerns them all, a requested exit only those that run.
  bool any = false;
  for (AxisState& a : axes_) {
    const bool running = a.model->state() == core::AxisState::OperationEnabled;
    if (watchdog || (persona_.abort_on_requested_leave_op && running)) {
      comm_loss(a);
      any = true;
    }
  }
  if (any) ++counters_.comm_losses;
}

void Cia402Slave::comm_loss(AxisState& a) noexcept {
  // 6007h [CiA 402; dunker §8.2]: 1 fault (EMCY comm_loss_code), 2 disable voltage, 3 quick stop.
  switch (a.abort_option) {
    case 1:
      a.model->inject_fault(persona_.comm_loss_code);
      a.comm_fault_raised = true;
      break;
    case 2:
      (void)a.model->write_object(kControlword, 0x0000);
      break;
    case 3:
      (void)a.model->write_object(kControlword, 0x0002);
      break;
    default:
      break;  // 0: no reaction (ESR default: the drive keeps its last set-point, §12)
  }
}

void Cia402Slave::exchange(std::span<const std::uint8_t> outputs, std::span<std::uint8_t> inputs, AlState state,
                           std::uint64_t now_ns) noexcept {
  // RxPDOs are applied in OP only [dunker §5: SAFE-OP "not applied"].
  if (state == AlState::Op && outputs.size() >= output_size()) apply_outputs(outputs);
  advance(now_ns);
  report_emcys();
  watch_al_status();
  fill_inputs(inputs);
}

void Cia402Slave::apply_outputs(std::span<const std::uint8_t> outputs) noexcept {
  const Plan& pl = plan();
  std::size_t at = 0;
  for (std::size_t k = 0; k < pl.rx_n; ++k) {
    const MappedEntry& m = pl.rx[k];
    const std::size_t n = m.bytes;
    if (at + n > outputs.size()) return;
    std::uint32_t raw = 0;
    for (std::size_t b = 0; b < n; ++b) raw |= static_cast<std::uint32_t>(outputs[at + b]) << (8U * b);
    at += n;
    if (!m.object.type || m.object.ignored) continue;
    if (put_app(m.object, cia402::normalise(*m.object.type, raw)) != 0) ++counters_.refused_pdo_values;
  }
}

void Cia402Slave::fill_inputs(std::span<std::uint8_t> inputs) const noexcept {
  const Plan& pl = plan();
  std::size_t at = 0;
  for (std::size_t k = 0; k < pl.tx_n; ++k) {
    const MappedEntry& m = pl.tx[k];
    const std::size_t n = m.bytes;
    if (at + n > inputs.size()) return;
    const Value v = get(m.object);
    for (std::size_t b = 0; b < n; ++b) inputs[at + b] = static_cast<std::uint8_t>(v.raw >> (8U * b));
    at += n;
  }
}

void Cia402Slave::advance(std::uint64_t now_ns) noexcept {
  if (!started_) {
    started_ = true;
    model_ns_ = now_ns;
    return;
  }
  if (now_ns <= model_ns_) return;
  if (now_ns - model_ns_ > kMaxCatchUpNs) model_ns_ = now_ns - kMaxCatchUpNs;  // a stalled line: no jump
  while (now_ns - model_ns_ >= kModelStepNs) {
    for (AxisState& a : axes_) {
      cia402::sim::DriveModel& model = *a.model;
      if (a.ip_active) {
        // 60C2h period = units x 10^index s (index -3: ms) [dunker §11.2].
        const auto units = model.dictionary().get(cia402::obj::kIpTimePeriodUnits.id).value_or(1);
        auto index = model.dictionary().get(cia402::obj::kIpTimePeriodIndex.id).value_or(-3);
        double period_ns = static_cast<double>(std::max<std::int64_t>(units, 1));
        for (index += 9; index > 0; --index) period_ns *= 10.0;
        a.ip_elapsed_ns += kModelStepNs;
        const double f = std::min(1.0, static_cast<double>(a.ip_elapsed_ns) / period_ns);
        const double v = static_cast<double>(a.ip_start) + (static_cast<double>(a.ip_target) - a.ip_start) * f;
        (void)model.write_object(kIpDataRecord, std::llround(v));
      }
      model.step(core::Duration(kModelStepNs));
    }
    model_ns_ += kModelStepNs;
  }
  // The communication fault has no lasting cause: once raised, a fault reset clears it.
  for (AxisState& a : axes_) {
    if (a.comm_fault_raised && faulted(a.model->state())) {
      a.comm_fault_raised = false;
      if (!a.injected) a.model->clear_fault_cause();
    }
  }
}

void Cia402Slave::report_emcys() noexcept {
  for (AxisState& a : axes_) {
    while (const auto e = a.model->take_pending_emcy()) {
      if (e->error_code == 0 && !persona_.emcy_on_fault_clear) continue;
      // ESR: bytes 3..7 always zero (quirk 11).
      const CoeEmergency emcy{e->error_code, e->error_register, {}};
      if (esc_ == nullptr || !esc_->post_emergency(emcy)) ++counters_.emcy_dropped;
    }
  }
}

void Cia402Slave::watch_al_status() noexcept {
  // The ESC refuses PRE-OP -> SAFE-OP with 001Dh/001Eh before asking the application; the drive
  // sees the refusal in AL status and reports A000h [dunker App. C, §5]. The SM watchdog (001Bh)
  // has its own reaction (6007h).
  if (esc_ == nullptr) return;
  const auto mem = esc_->memory();
  const bool error = (core::get_u16(mem, reg::kAlStatus) & kAlErrorBit) != 0;
  const std::uint16_t code = core::get_u16(mem, reg::kAlStatusCode);
  if (error && !al_error_seen_ && persona_.transition_error_emcy && code != al_status_code::kSmWatchdog) {
    const CoeEmergency emcy{0xA000, 0x01, {}};
    if (!esc_->post_emergency(emcy)) ++counters_.emcy_dropped;
  }
  al_error_seen_ = error;
}

// ---------------------------------------------------------------------------------------------
// Factory

std::unique_ptr<Cia402Slave> make_cia402_slave(std::string_view persona, Cia402SlaveOptions options) {
  return std::make_unique<Cia402Slave>(ethercat_persona_for(persona), std::move(options));
}

Cia402Device make_cia402_device(std::string_view persona, Cia402SlaveOptions options) {
  Cia402Device d;
  d.app = make_cia402_slave(persona, std::move(options));
  d.esc = std::make_unique<EscSlave>(d.app->esc_config(), d.app->sii(), d.app.get());
  return d;
}

}  // namespace drivegate::ethercat::sim
