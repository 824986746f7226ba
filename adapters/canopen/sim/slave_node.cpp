// SlaveNode: see slave_node.hpp.
#include "adapters/canopen/sim/slave_node.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "adapters/canopen/wire/sdo_codec.hpp"

namespace drivegate::canopen::sim {
namespace {

namespace abort = cia402::sdo_abort_code;
using cia402::DataType;
using cia402::ObjectId;
using cia402::sim::Access;
using core::AxisState;

// "save" as 1010h:01 takes it [CiA 301 §7.5.2.13; AKD part 2 §2.6; SD6 §2.8].
constexpr std::uint32_t kSaveSignature = 0x65766173;
// COB-ID bits 30..11: generate/dynamic, 29-bit frame, extended id bits. None is used here.
constexpr std::uint32_t kCobUnsupported = 0x7FFFF800U;

std::uint32_t to_raw(std::int64_t value, std::uint8_t size) noexcept {
  const auto bits = static_cast<std::uint32_t>(value);  // two's complement, as on the wire
  return size >= 4 ? bits : bits & ((1U << (8U * size)) - 1U);
}

// The CiA 402 state as E48 counts it: 2 ready to switch on, 4 enabled, 7 quick stop (SD6 §10);
// the others in the same CiA 402 order [derived].
std::int64_t device_state_code(AxisState s) noexcept {
  switch (s) {
    case AxisState::Unknown:
    case AxisState::NotReadyToSwitchOn: return 0;
    case AxisState::SwitchOnDisabled: return 1;
    case AxisState::ReadyToSwitchOn: return 2;
    case AxisState::SwitchedOn: return 3;
    case AxisState::OperationEnabled: return 4;
    case AxisState::Fault: return 5;
    case AxisState::FaultReactionActive: return 6;
    case AxisState::QuickStopActive: return 7;
  }
  return 0;
}

// SD6 A246: 4 pre-operational, 5 stopped, 6 operational (quirk 18).
std::int64_t nmt_state_code(NmtState s) noexcept {
  switch (s) {
    case NmtState::PreOperational: return 4;
    case NmtState::Stopped: return 5;
    case NmtState::Operational: return 6;
    default: return 0;
  }
}

bool faulted(AxisState s) noexcept { return s == AxisState::Fault || s == AxisState::FaultReactionActive; }

// The model's writable device-profile objects and their power-on values (what Reset Node restores).
std::vector<ObjectValue> writable_profile_objects(const cia402::sim::ObjectDictionary& od) {
  std::vector<ObjectValue> out;
  for (std::uint32_t index = 0x6000; index <= 0x6FFF; ++index) {
    for (std::uint8_t sub = 0; sub <= 8; ++sub) {
      const ObjectId id{static_cast<std::uint16_t>(index), sub};
      const auto access = od.access_of(id);
      if (access && *access != Access::ReadOnly) out.push_back({id, od.get(id).value_or(0)});
    }
  }
  return out;
}

}  // namespace

SlaveNode::SlaveNode(SlaveNodeConfig config)
    : config_(std::move(config)),
      model_(config_.drive),
      vendor_(config_.persona.vendor_objects.size()),
      model_defaults_(writable_profile_objects(model_.dictionary())),
      byte_objects_(byte_objects_of(config_.persona)),
      nmt_(NmtSlaveConfig{.node = config_.node, .options = config_.persona.nmt}),
      emcy_(EmcyProducerConfig{.node = config_.node}),
      pdos_(*this, config_.persona.pdo, config_.rpdos, config_.tpdos) {
  const auto& p = config_.persona;
  if (p.sdo_channels < 1 || p.sdo_channels > static_cast<int>(kMaxSdoChannels)) {
    throw std::invalid_argument("persona \"" + std::string(p.name) + "\": SDO channels must be 1..4");
  }
  for (const auto& v : p.vendor_objects) {
    if (v.source == VendorValue::Stored && !vendor_.add(v.def, v.access, v.value, v.min, v.max)) {
      throw std::invalid_argument("persona \"" + std::string(p.name) + "\": manufacturer object table is inconsistent");
    }
  }
  for (const auto& d : p.application_defaults) {
    if (model_.write_object(d.id, d.value) != 0) {
      throw std::invalid_argument("persona \"" + std::string(p.name) + "\": a power-on value the drive refuses");
    }
  }
  // Channel 1 has the predefined COB-IDs. Channels 2..4 (SD6 §5.3, quirk 1) are on as a
  // commissioned drive has them, where their COB-IDs cannot collide with channel 1 of another
  // node: only for node-IDs up to 31.
  const NodeId n = config_.node;
  channel_defaults_[0] = {cob::sdo_rx(n), cob::sdo_tx(n), 0};
  for (int k = 2; k <= p.sdo_channels; ++k) {
    const std::uint32_t off = n <= 31 ? 0 : cob::kInvalid;
    channel_defaults_[static_cast<std::size_t>(k - 1)] = {cob::sdo_rx(k, n) | off, cob::sdo_tx(k, n) | off, 0};
  }
  channels_ = channel_defaults_;
  for (std::size_t c = 0; c < kMaxSdoChannels; ++c) open_channel(c);
}

SlaveNode::~SlaveNode() = default;

// ---------------------------------------------------------------------------------------------
// Frames and steps

bool SlaveNode::on_frame(const CanFrame& frame, core::TimePoint now) noexcept {
  if (!powered_) {
    ++counters_.ignored_off;
    return false;
  }
  if (silent_) {
    ++counters_.ignored_silent;
    return false;
  }
  // CANopen here is 11-bit only (AKD part 1 quirk 7): extended frames are other traffic.
  if (frame.extended) return false;
  if (!frame.valid()) {
    ++counters_.malformed;  // a length or id no CAN frame has
    return false;
  }
  now_ = now;
  if (nmt_.on_frame(frame, now)) {
    ++counters_.frames;
    handle_nmt_events();
    return true;
  }
  if (!frame.remote && frame.id == (sync_cob_ & cob::kIdMask)) {
    ++counters_.frames;
    if (frame.dlc > 1) {
      ++counters_.malformed;  // a SYNC carries at most its counter byte [CiA 301 §7.2.5]
    } else if (!nmt_.serves(NmtService::Sync)) {
      ++counters_.ignored_state;
    } else {
      pdos_.on_sync(now, out_);
    }
    return true;
  }
  for (auto& server : sdo_) {
    if (!server || frame.id != server->config().rx_cob) continue;
    ++counters_.frames;
    if (nmt_.serves(NmtService::Sdo)) {
      server->on_frame(frame, now);
    } else {
      ++counters_.ignored_state;
    }
    return true;
  }
  if (pdos_.on_frame(frame, now)) {
    ++counters_.frames;
    return true;
  }
  return false;
}

void SlaveNode::step(core::TimePoint now, TxQueue& tx) noexcept {
  if (!powered_) return;
  now_ = now;
  if (boot_pending_) boot(now);
  for (std::size_t c = 0; c < kMaxSdoChannels; ++c) {
    if (reopen_[c]) open_channel(c);
  }
  // NMT first: after a power-on the boot-up is the node's first frame.
  nmt_.poll(now, out_);
  handle_nmt_events();
  advance_model(now);
  if (pdos_.take_length_error()) {
    // An RPDO shorter than its mapping was not processed: EMCY 8210h, a communication error
    // [CiA 301 §7.2.2.2].
    Emcy e;
    e.code = 0x8210;
    e.error_register = static_cast<std::uint8_t>(error_register() | 0x11U);
    emcy_.raise(e);
  }
  pdos_.poll(now, out_);
  for (auto& server : sdo_) {
    if (server) server->poll(now, out_);
  }
  emcy_.poll(now, out_);
  flush(tx);
}

void SlaveNode::boot(core::TimePoint now) noexcept {
  boot_pending_ = false;
  // A fresh model is at its power-on values already; after a power loss it restarts.
  if (!model_fresh_) model_.power_cycle();
  model_fresh_ = false;
  restore_persona_defaults();
  active_code_ = 0;
  active_cause_ = 0;
  comm_fault_raised_ = false;
  reset_communication();
  nmt_.power_on(now);
  last_step_ = now;
}

void SlaveNode::advance_model(core::TimePoint now) noexcept {
  if (now <= last_step_) return;
  auto dt = std::min<core::Duration>(now - last_step_, kMaxCatchUp);
  last_step_ = now;
  while (dt > core::Duration::zero()) {
    const auto s = std::min(dt, kModelStep);
    model_.step(s);
    dt -= s;
  }
  while (const auto e = model_.take_pending_emcy()) report(*e);
  // A communication loss is a fault without a lasting cause: once raised, it can be reset.
  if (comm_fault_raised_ && faulted(model_.state())) {
    comm_fault_raised_ = false;
    if (!injected_cause_) model_.clear_fault_cause();
  }
}

void SlaveNode::flush(TxQueue& tx) noexcept {
  counters_.tx_full += out_.overflows() - out_overflows_seen_;
  out_overflows_seen_ = out_.overflows();
  for (; !out_.empty(); out_.pop()) {
    CanFrame f = out_.front();
    if (silent_) {
      ++counters_.discarded_silent;
      continue;
    }
    if (damage_left_ > 0) {
      --damage_left_;
      ++counters_.damaged;
      if (damage_ == FrameDamage::WrongDlc) {
        f.dlc = f.dlc == 0 ? std::uint8_t{1} : static_cast<std::uint8_t>(f.dlc - 1);
      } else {
        for (std::size_t i = 0; i < f.dlc; ++i) f.data[i] = static_cast<std::uint8_t>(~f.data[i]);
      }
    }
    if (!tx.push(f)) ++counters_.tx_full;
  }
}

// ---------------------------------------------------------------------------------------------
// NMT and resets

void SlaveNode::handle_nmt_events() noexcept {
  NmtSlaveEvent ev;
  while (nmt_.next_event(ev)) {
    switch (ev.kind) {
      case NmtSlaveEventKind::StateChanged: apply_nmt_state(); break;
      case NmtSlaveEventKind::ResetNode:
        reset_application();
        reset_communication();
        break;
      case NmtSlaveEventKind::ResetCommunication: reset_communication(); break;
      case NmtSlaveEventKind::LifeGuarding:
      case NmtSlaveEventKind::HeartbeatLost: comm_loss(); break;
    }
  }
}

void SlaveNode::apply_nmt_state() noexcept {
  pdos_.set_operational(nmt_.state() == NmtState::Operational);
  emcy_.set_enabled(emcy_valid_ && nmt_.serves(NmtService::Emcy));
}

void SlaveNode::reset_application() noexcept {
  // Values the model refuses now (a homing method while homing runs) keep their current value.
  for (const auto& d : model_defaults_) (void)model_.write_object(d.id, d.value);
  restore_persona_defaults();
}

void SlaveNode::restore_persona_defaults() noexcept {
  vendor_.reset_to_defaults();
  for (auto& b : byte_objects_) b.value.assign(b.power_on.begin(), b.power_on.end());
  // Accepted at construction, so accepted again.
  for (const auto& d : config_.persona.application_defaults) (void)model_.write_object(d.id, d.value);
}

void SlaveNode::reset_communication() noexcept {
  sync_cob_ = cob::kSync;
  cycle_period_ = 0;
  emcy_valid_ = true;
  emcy_.reset();
  pdos_.restore_defaults();
  channels_ = channel_defaults_;
  for (std::size_t c = 0; c < kMaxSdoChannels; ++c) open_channel(c);
  apply_nmt_state();
}

void SlaveNode::open_channel(std::size_t channel) noexcept {
  reopen_[channel] = false;
  const auto& ch = channels_[channel];
  auto& server = sdo_[channel];
  if (((ch.rx | ch.tx) & cob::kInvalid) != 0) {
    server.reset();
    return;
  }
  server.emplace(SdoServerConfig{.rx_cob = ch.rx & cob::kIdMask,
                                 .tx_cob = ch.tx & cob::kIdMask,
                                 .upload_without_size = config_.persona.upload_without_size},
                 static_cast<SdoBackend&>(*this));
}

// ---------------------------------------------------------------------------------------------
// Faults and EMCY

void SlaveNode::comm_loss() noexcept {
  const auto& p = config_.persona;
  ++counters_.comm_losses;
  last_injected_code_ = p.comm_loss_code;
  last_injected_cause_ = p.comm_loss_cause;
  comm_fault_raised_ = true;
  model_.inject_fault(p.comm_loss_code);
}

void SlaveNode::report(const cia402::sim::EmcyEvent& e) noexcept {
  const auto& p = config_.persona;
  Emcy m;
  m.code = e.error_code;
  if (e.error_code == 0) {
    active_code_ = 0;
    active_cause_ = 0;
    m.error_register = e.error_register;
    m.vendor[0] = p.no_fault_event;
    emcy_.raise(m);
    return;
  }
  active_code_ = e.error_code;
  active_cause_ = e.error_code == last_injected_code_ ? last_injected_cause_ : 0;
  const EmcyRule* rule = rule_for(e.error_code);
  m.error_register = rule != nullptr ? rule->error_register : e.error_register;
  m.vendor[0] = rule != nullptr ? rule->event : p.fault_byte3;
  if (p.emcy_cause_byte4) m.vendor[1] = active_cause_;
  emcy_.raise(m);
  if (p.emcy_state_follow_up) {
    Emcy state;
    state.error_register = m.error_register;
    emcy_.raise(state);
  }
}

std::uint8_t SlaveNode::error_register() const noexcept {
  if (active_code_ != 0) {
    if (const EmcyRule* rule = rule_for(active_code_)) return rule->error_register;
  }
  return static_cast<std::uint8_t>(model_.dictionary().get(cia402::obj::kErrorRegister.id).value_or(0));
}

const EmcyRule* SlaveNode::rule_for(std::uint16_t code) const noexcept {
  for (const auto& r : config_.persona.emcy_rules) {
    if (r.code == code) return &r;
  }
  return nullptr;
}

// ---------------------------------------------------------------------------------------------
// Fault injection

void SlaveNode::power_off() noexcept {
  powered_ = false;
  boot_pending_ = false;
  out_.clear();
  // What the drive had not sent yet is lost with the power.
  while (model_.take_pending_emcy()) {
  }
  for (auto& server : sdo_) {
    if (server) server->reset();
  }
}

void SlaveNode::power_on() noexcept {
  if (powered_) return;
  powered_ = true;
  boot_pending_ = true;
}

void SlaveNode::inject_fault(std::uint16_t code, std::uint8_t cause) noexcept {
  injected_cause_ = true;
  last_injected_code_ = code;
  last_injected_cause_ = cause;
  model_.inject_fault(code);
}

void SlaveNode::clear_fault_cause() noexcept {
  injected_cause_ = false;
  comm_fault_raised_ = false;
  model_.clear_fault_cause();
}

void SlaveNode::inject_sdo_abort(ObjectId object, std::uint32_t code) noexcept {
  for (auto& server : sdo_) {
    if (server) server->inject_abort(object, code);
  }
}

void SlaveNode::damage_next(std::uint32_t frames, FrameDamage how) noexcept {
  damage_left_ = frames;
  damage_ = how;
}

const SdoServer* SlaveNode::sdo(int channel) const noexcept {
  if (channel < 1 || channel > static_cast<int>(kMaxSdoChannels)) return nullptr;
  const auto& server = sdo_[static_cast<std::size_t>(channel - 1)];
  return server ? &*server : nullptr;
}

// ---------------------------------------------------------------------------------------------
// Object dictionary

// The byte objects of a persona (slave_node.hpp, ByteObject).
std::vector<SlaveNode::ByteObject> SlaveNode::byte_objects_of(const Persona& p) {
  std::vector<SlaveNode::ByteObject> out;
  const auto add = [&](ObjectId id, bool writable, std::size_t fixed, std::vector<std::uint8_t> bytes) {
    ByteObject o;
    o.id = id;
    o.writable = writable;
    o.fixed = fixed;
    o.power_on = std::move(bytes);
    o.value.reserve(kMaxBytes);
    o.value = o.power_on;
    out.push_back(std::move(o));
  };
  const auto text = [](std::string_view s) { return std::vector<std::uint8_t>(s.begin(), s.end()); };
  if (!p.device_name.empty()) add({0x1008, 0}, false, 0, text(p.device_name));
  if (!p.hardware_version.empty()) add({0x1009, 0}, false, 0, text(p.hardware_version));
  if (!p.software_version.empty()) add({0x100A, 0}, false, 0, text(p.software_version));
  std::vector<std::uint8_t> domain(kMaxBytes);
  for (std::size_t i = 0; i < domain.size(); ++i) domain[i] = static_cast<std::uint8_t>(i * 7 + 1);
  add({0x5FF0, 0}, true, 0, std::move(domain));
  add({0x5FF1, 0}, true, 8, {0xEF, 0xCD, 0xAB, 0x89, 0x67, 0x45, 0x23, 0x01});  // 0123456789ABCDEFh
  add({0x5FF2, 0}, true, 4, {0x00, 0x00, 0xCC, 0x41});                          // 25.5 as REAL32
  return out;
}

SlaveNode::ByteObject* SlaveNode::byte_object(ObjectId id) noexcept {
  for (auto& b : byte_objects_)
    if (b.id == id) return &b;
  return nullptr;
}

SdoReadResult SlaveNode::sdo_read(ObjectId object, std::span<std::uint8_t> out) noexcept {
  if (const ByteObject* b = byte_object(object)) {
    if (b->value.size() <= out.size()) std::copy(b->value.begin(), b->value.end(), out.begin());
    return {0, b->value.size()};  // longer than `out`: the server aborts with 05040005h
  }
  const ValueRead v = read_value(object);
  if (v.abort != 0) return {v.abort, 0};
  put_le(out, 0, v.size, v.raw);
  return {0, v.size};
}

std::uint32_t SlaveNode::sdo_write(ObjectId object, std::span<const std::uint8_t> data) noexcept {
  if (ByteObject* b = byte_object(object)) {
    if (!b->writable) return abort::kReadOnly;
    const std::size_t limit = b->fixed != 0 ? b->fixed : b->value.capacity();
    if (data.size() > limit) return abort::kTooLong;
    if (b->fixed != 0 && data.size() < b->fixed) return abort::kTooShort;
    b->value.assign(data.begin(), data.end());  // within the reserved capacity
    return 0;
  }
  return write_value(object, get_le(data, 0, std::min<std::size_t>(data.size(), 4)), data.size());
}

SlaveNode::ValueRead SlaveNode::read_value(ObjectId id) const noexcept {
  const auto& p = config_.persona;
  if (id == cia402::obj::kErrorRegister.id) return {0, error_register(), 1};
  if (const auto c = read_comm(id)) return *c;
  if (SlavePdos::owns(id.index)) {
    const auto r = pdos_.read(id);
    return {r.abort_code, r.value, r.size};
  }
  if (const VendorObject* v = vendor_object(id)) {
    const auto size = cia402::size_of(v->def.type);
    if (v->access == Access::WriteOnly) return {abort::kWriteOnly, 0, 0};
    return {0, to_raw(vendor_value(*v), size), size};
  }
  if (hidden(id)) return {abort::kNoObject, 0, 0};
  const auto type = model_.dictionary().type_of(id);
  if (!type) return {missing_code(id), 0, 0};
  const auto r = model_.read_object(id);
  if (r.abort_code != 0) return {r.abort_code, 0, 0};
  const auto size = cia402::size_of(*type);
  auto raw = to_raw(r.value, size);
  if (id == cia402::obj::kSupportedDriveModes.id) raw &= ~p.supported_modes_cleared;
  return {0, raw, size};
}

std::uint32_t SlaveNode::write_value(ObjectId id, std::uint32_t raw, std::size_t size) noexcept {
  const auto& p = config_.persona;
  if (const auto c = write_comm(id, raw, size)) return *c;
  if (SlavePdos::owns(id.index)) {
    return size > 4 ? abort::kTypeMismatch : pdos_.write(id, raw, static_cast<std::uint8_t>(size));
  }
  // CiA 301 order of checks: the object, access, the length, then the value.
  if (const VendorObject* v = vendor_object(id)) {
    if (v->access == Access::ReadOnly) return abort::kReadOnly;
    if (size != cia402::size_of(v->def.type)) return abort::kTypeMismatch;
    return vendor_.set(id, cia402::normalise(v->def.type, raw));
  }
  if (hidden(id)) return abort::kNoObject;
  const auto& od = model_.dictionary();
  const auto type = od.type_of(id);
  if (!type) return missing_code(id);
  if (od.access_of(id) == Access::ReadOnly) return abort::kReadOnly;
  if (size != cia402::size_of(*type)) return abort::kTypeMismatch;
  const auto value = cia402::normalise(*type, raw);
  if (p.mode_zero_refused && id == cia402::obj::kModesOfOperation.id && value == 0) return abort::kValueRange;
  return model_.write_object(id, value);
}

std::optional<SlaveNode::ValueRead> SlaveNode::read_comm(ObjectId id) const noexcept {
  const auto& p = config_.persona;
  const auto only_sub0 = [&](std::uint8_t size, std::uint32_t value) {
    return id.sub == 0 ? ValueRead{0, value, size} : ValueRead{abort::kNoSubIndex, 0, 0};
  };
  switch (id.index) {
    case 0x1005: return only_sub0(4, sync_cob_);
    case 0x1006: return only_sub0(4, cycle_period_);
    case 0x100C:
      if (!p.node_guarding) break;
      return only_sub0(2, nmt_.guard_time());
    case 0x100D:
      if (!p.node_guarding) break;
      return only_sub0(1, nmt_.life_time_factor());
    case 0x1010:
      if (!p.store_parameters) break;
      // Sub 0: one entry, "save all"; sub 1 reads 1: the device saves on command [CiA 301].
      if (id.sub == 0) return ValueRead{0, 1, 1};
      if (id.sub == 1) return ValueRead{0, 1, 4};
      return ValueRead{abort::kNoSubIndex, 0, 0};
    case 0x1014: return only_sub0(4, emcy_cob_id());
    case 0x1015:
      if (!p.emcy_inhibit) break;
      return only_sub0(2, emcy_.inhibit_time());
    case 0x1016:
      if (!p.heartbeat_consumer) break;
      if (id.sub == 0) return ValueRead{0, 1, 1};
      if (id.sub == 1) return ValueRead{0, nmt_.heartbeat_consumer(), 4};
      return ValueRead{abort::kNoSubIndex, 0, 0};
    case 0x1017: return only_sub0(2, nmt_.heartbeat_period());
    default: break;
  }
  if (id.index >= 0x1200 && id.index < 0x1200 + kMaxSdoChannels) {
    const std::size_t c = id.index - 0x1200U;
    if (!p.sdo_parameters || c >= static_cast<std::size_t>(p.sdo_channels)) return std::nullopt;
    const auto& ch = channels_[c];
    switch (id.sub) {
      case 0: return ValueRead{0, c == 0 ? 2U : 3U, 1};
      case 1: return ValueRead{0, ch.rx, 4};
      case 2: return ValueRead{0, ch.tx, 4};
      case 3:
        if (c != 0) return ValueRead{0, ch.client, 1};
        break;
      default: break;
    }
    return ValueRead{abort::kNoSubIndex, 0, 0};
  }
  return std::nullopt;
}

std::optional<std::uint32_t> SlaveNode::write_comm(ObjectId id, std::uint32_t raw, std::size_t size) noexcept {
  const auto& p = config_.persona;
  // Sub-index, then length (access is read-write for all of these but the noted ones).
  const auto check = [&](std::uint8_t sub, std::size_t width) -> std::uint32_t {
    if (id.sub != sub) return abort::kNoSubIndex;
    return size == width ? 0 : abort::kTypeMismatch;
  };
  std::uint32_t code = 0;
  switch (id.index) {
    case 0x1005:
      if ((code = check(0, 4)) != 0) return code;
      // An 11-bit SYNC consumer: no generate bit, no 29-bit id (AKD part 1 §7; SD6 §6.1: 1..2047).
      if ((raw & kCobUnsupported) != 0 || (raw & cob::kIdMask) == 0) return abort::kValueRange;
      sync_cob_ = raw;
      return 0;
    case 0x1006:
      if ((code = check(0, 4)) != 0) return code;
      cycle_period_ = raw;
      return 0;
    case 0x100C:
      if (!p.node_guarding) break;
      if ((code = check(0, 2)) != 0) return code;
      nmt_.set_guarding(static_cast<std::uint16_t>(raw), nmt_.life_time_factor(), now_);
      return 0;
    case 0x100D:
      if (!p.node_guarding) break;
      if ((code = check(0, 1)) != 0) return code;
      nmt_.set_guarding(nmt_.guard_time(), static_cast<std::uint8_t>(raw), now_);
      return 0;
    case 0x1010:
      if (!p.store_parameters) break;
      if (id.sub == 0) return abort::kReadOnly;
      if ((code = check(1, 4)) != 0) return code;
      // Accepted and confirmed; the simulated drive keeps no non-volatile copy.
      return raw == kSaveSignature ? 0 : abort::kCannotStore;
    case 0x1014:
      if (id.sub != 0) return abort::kNoSubIndex;
      if (!p.emcy_cob_writable) return abort::kReadOnly;
      if (size != 4) return abort::kTypeMismatch;
      // Only the valid bit may change: the producer sends on 80h + node-ID.
      if ((raw & ~cob::kInvalid) != cob::emcy(config_.node)) return abort::kValueRange;
      emcy_valid_ = (raw & cob::kInvalid) == 0;
      apply_nmt_state();
      return 0;
    case 0x1015:
      if (!p.emcy_inhibit) break;
      if ((code = check(0, 2)) != 0) return code;
      emcy_.set_inhibit_time(static_cast<std::uint16_t>(raw));
      return 0;
    case 0x1016:
      if (!p.heartbeat_consumer) break;
      if (id.sub == 0) return abort::kReadOnly;
      if ((code = check(1, 4)) != 0) return code;
      if (p.heartbeat_consumer_abort != 0) return p.heartbeat_consumer_abort;
      if ((raw >> 24) != 0) return abort::kValueRange;  // bits 31..24 reserved (AKD part 1 §11.2)
      nmt_.set_heartbeat_consumer(raw);
      return 0;
    case 0x1017:
      if ((code = check(0, 2)) != 0) return code;
      nmt_.set_heartbeat_period(static_cast<std::uint16_t>(raw), now_);
      return 0;
    default: break;
  }
  if (id.index >= 0x1200 && id.index < 0x1200 + kMaxSdoChannels) {
    const std::size_t c = id.index - 0x1200U;
    if (p.sdo_parameters && c < static_cast<std::size_t>(p.sdo_channels)) {
      return write_sdo_parameter(c, id.sub, raw, size);
    }
  }
  return std::nullopt;
}

std::uint32_t SlaveNode::write_sdo_parameter(std::size_t channel, std::uint8_t sub, std::uint32_t raw,
                                             std::size_t size) noexcept {
  if (sub > (channel == 0 ? 2 : 3)) return abort::kNoSubIndex;
  // Sub 0 is the entry count; channel 1's COB-IDs are fixed (SD6 §6.3; AKD: no 1200h at all).
  if (sub == 0 || channel == 0) return abort::kReadOnly;
  auto& ch = channels_[channel];
  if (sub == 3) {
    if (size != 1) return abort::kTypeMismatch;
    ch.client = static_cast<std::uint8_t>(raw);
    return 0;
  }
  if (size != 4) return abort::kTypeMismatch;
  // COB-IDs change only in Pre-operational (SD6 §5.4) and only while the entry is invalid
  // [CiA 301 §7.5.2.33].
  if (nmt_.state() != NmtState::PreOperational) return abort::kDeviceState;
  if ((raw & kCobUnsupported) != 0 || ((raw & cob::kInvalid) == 0 && (raw & cob::kIdMask) == 0)) {
    return abort::kValueRange;
  }
  auto& cob = sub == 1 ? ch.rx : ch.tx;
  if (((cob | raw) & cob::kInvalid) == 0 && (raw & cob::kIdMask) != (cob & cob::kIdMask)) return abort::kValueRange;
  cob = raw;
  reopen_[channel] = true;
  return 0;
}

std::uint32_t SlaveNode::emcy_cob_id() const noexcept {
  return cob::emcy(config_.node) | (emcy_valid_ ? 0U : cob::kInvalid);
}

const VendorObject* SlaveNode::vendor_object(ObjectId id) const noexcept {
  for (const auto& v : config_.persona.vendor_objects) {
    if (v.def.id == id) return &v;
  }
  return nullptr;
}

std::uint32_t SlaveNode::missing_code(ObjectId id) const noexcept {
  // A sub-index the persona's manufacturer object does not have, else what the model says.
  const auto& vo = config_.persona.vendor_objects;
  const bool index_known =
      std::any_of(vo.begin(), vo.end(), [&](const VendorObject& v) { return v.def.id.index == id.index; });
  return index_known ? abort::kNoSubIndex : model_.dictionary().missing_code(id);
}

bool SlaveNode::hidden(ObjectId id) const noexcept {
  const auto& h = config_.persona.hidden;
  return std::find(h.begin(), h.end(), id) != h.end();
}

std::int64_t SlaveNode::vendor_value(const VendorObject& v) const noexcept {
  const auto& p = config_.persona;
  switch (v.source) {
    case VendorValue::Stored: return vendor_.get(v.def.id).value_or(v.value);
    case VendorValue::NodeId: return config_.node;
    case VendorValue::DeviceState: return device_state_code(model_.state());
    case VendorValue::NmtState: return nmt_state_code(nmt_.state());
    case VendorValue::EventNumber: {
      if (active_code_ == 0) return p.no_fault_event;
      const EmcyRule* rule = rule_for(active_code_);
      return rule != nullptr ? rule->event : 0;
    }
    case VendorValue::EventCause: return active_code_ == 0 ? 0 : active_cause_;
    case VendorValue::ManufacturerStatus: return manufacturer_status();
  }
  return 0;
}

std::uint32_t SlaveNode::manufacturer_status() const noexcept {
  // AKD 1002h (part 2 §2.5): bit 0 motion active, 3 in position, 14 power stage enabled, 15 fault.
  const auto s = model_.state();
  std::uint32_t bits = 0;
  if (std::abs(model_.velocity()) > 1e-3 * model_.config().position_units_per_rev) bits |= 1U << 0;
  if ((model_.statusword() & 0x0400U) != 0) bits |= 1U << 3;
  if (s == AxisState::OperationEnabled || s == AxisState::QuickStopActive) bits |= 1U << 14;
  if (faulted(s)) bits |= 1U << 15;
  return bits;
}

// PdoObjects ------------------------------------------------------------------------------------

std::optional<cia402::DataType> SlaveNode::mappable(ObjectId id, bool receive) const noexcept {
  if (const VendorObject* v = vendor_object(id)) {
    if (!v->mappable) return std::nullopt;
    if (receive ? v->access == Access::ReadOnly : v->access == Access::WriteOnly) return std::nullopt;
    return v->def.type;
  }
  const auto& nm = config_.persona.not_mappable;
  if (hidden(id) || std::find(nm.begin(), nm.end(), id) != nm.end()) return std::nullopt;
  // The model's communication objects (1000h, 1001h, 1018h) are not process data.
  if (id.index < 0x6000) return std::nullopt;
  const auto& od = model_.dictionary();
  const auto type = od.type_of(id);
  const auto access = od.access_of(id);
  if (!type || !access) return std::nullopt;
  if (receive ? *access == Access::ReadOnly : *access == Access::WriteOnly) return std::nullopt;
  return type;
}

std::int64_t SlaveNode::read(ObjectId id) const noexcept {
  if (const VendorObject* v = vendor_object(id)) return vendor_value(*v);
  return model_.dictionary().get(id).value_or(0);
}

void SlaveNode::write(ObjectId id, std::int64_t value) noexcept {
  if (const VendorObject* v = vendor_object(id)) {
    if (vendor_.set(v->def.id, value) != 0) ++counters_.refused_pdo_values;
    return;
  }
  // NORD: a mode byte of 0 in RxPDO1 is not a mode; the drive keeps its mode (nord quirk 18).
  if (config_.persona.mode_zero_refused && id == cia402::obj::kModesOfOperation.id && value == 0) {
    ++counters_.refused_pdo_values;
    return;
  }
  if (model_.write_object(id, value) != 0) ++counters_.refused_pdo_values;
}

}  // namespace drivegate::canopen::sim
