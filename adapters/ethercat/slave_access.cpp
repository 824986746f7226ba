#include "adapters/ethercat/slave_access.hpp"

#include <algorithm>

#include "profiles/cia402/objects.hpp"

namespace drivegate::ethercat {

namespace {

// The CiA 402 profile area that a multi-axis slave repeats per axis [ETG.6010 §4: axis n at
// 6000h + n x 800h].
constexpr bool profile_area(std::uint16_t index) noexcept { return index >= 0x6000 && index <= 0x67FF; }

// CoE SDO abort 08000022h "data cannot be transferred because of the present device state"
// [ETG.1000.6 SDO abort codes, as CiA 301].
constexpr std::uint32_t kAbortDeviceState = 0x08000022;

// A reference names the object's place in the slave's data itself, so that an access in the
// cycle reads no table: bit 15 an output, bits 11-14 the data type, bits 0-10 the byte offset (a
// slave's outputs or inputs travel in one datagram, at most 1486 bytes [ETG.1000.4 §5.3]). The
// largest place, an output U32 at 7FFh, is AFFFh: never ImageRef's "not mapped" FFFFh.
constexpr std::uint16_t kPlaceOutput = 0x8000;
constexpr std::uint16_t kPlaceOffsetMask = 0x07FF;
constexpr std::uint16_t place_of(const MappedObject& m) noexcept {
  return static_cast<std::uint16_t>((m.output ? kPlaceOutput : 0U) | (static_cast<unsigned>(m.type) << 11) | m.offset);
}
constexpr cia402::DataType type_at(std::uint16_t place) noexcept {
  return static_cast<cia402::DataType>((place >> 11) & 0x0F);
}

// The first cell of `key` in a table of mask + 1 cells (Fibonacci hashing).
constexpr std::size_t first_cell(std::uint32_t key, std::size_t mask) noexcept {
  return static_cast<std::size_t>((key * 0x9E3779B1U) >> 16) & mask;
}

}  // namespace

SlaveAccess::SlaveAccess(std::size_t slave, const std::vector<MappedObject>& objects, int slave_axis,
                         std::uint16_t axis_offset, CoeSdoClient* coe, std::vector<EcatOwnedObject> owned,
                         std::span<const cia402::FaultText> faults)
    : slave_(slave),
      slave_axis_(slave_axis),
      axis_offset_(axis_offset),
      coe_(coe),
      owned_(std::move(owned)),
      faults_(faults) {
  std::size_t size = 16;
  while (size < 2 * objects.size()) size *= 2;
  table_.assign(size, MappedObject{});
  table_mask_ = size - 1;
  for (const MappedObject& m : objects) {
    if (m.id.index == 0) continue;
    std::size_t c = first_cell(m.id.key(), table_mask_);
    // An object mapped twice: the first entry is the one found, as a scan in order would.
    while (table_[c].id.index != 0 && !(table_[c].id == m.id)) c = (c + 1) & table_mask_;
    if (table_[c].id.index == 0) table_[c] = m;
  }
  cw_place_ = resolve(cia402::obj::kControlword.id).slot();
}

cia402::ObjectId SlaveAccess::on_slave(cia402::ObjectId id) const noexcept {
  if (slave_axis_ == 0 || !profile_area(id.index)) return id;
  const auto index = static_cast<std::uint32_t>(id.index) + static_cast<std::uint32_t>(slave_axis_) * axis_offset_;
  return index <= 0xFFFF ? cia402::ObjectId{static_cast<std::uint16_t>(index), id.sub} : id;
}

cia402::ImageRef SlaveAccess::resolve(cia402::ObjectId id) const noexcept {
  const cia402::ObjectId on = on_slave(id);
  if (on.index == 0) return {};
  for (std::size_t c = first_cell(on.key(), table_mask_); table_[c].id.index != 0; c = (c + 1) & table_mask_) {
    const MappedObject& m = table_[c];
    if (!(m.id == on)) continue;
    if (m.offset > kPlaceOffsetMask) return {};  // beyond any datagram: cannot be in the image
    return cia402::ImageRef::at(place_of(m), 0);
  }
  return {};
}

void SlaveAccess::begin_cycle(bool operational, bool fresh) noexcept {
  operational_ = operational;
  fresh_ = fresh;
  if (coe_ == nullptr || cancelled_ == 0) return;
  // Cancelled requests are taken from the client once they end.
  for (auto& p : pending_) {
    if (p.id == 0 || !p.cancelled) continue;
    const auto st = coe_->result(p.id).status;
    if (st == CoeSdoStatus::Queued || st == CoeSdoStatus::InFlight) continue;
    if (st != CoeSdoStatus::Unknown) coe_->take(p.id);
    p.id = 0;
    p.cancelled = false;
    --cancelled_;
  }
}

void SlaveAccess::forget_requests() noexcept {
  for (auto& p : pending_) {
    if (p.id != 0 && coe_ != nullptr) coe_->take(p.id);
    p.id = 0;
    p.cancelled = false;
    p.into = {};
  }
  cancelled_ = 0;
  fault_valid_ = false;
}

void SlaveAccess::on_emergency(const CoeEmergency& e) noexcept {
  if (e.error_code == 0) {  // "error reset or no error" [CiA 301 Table 21, as CoE carries it]
    fault_valid_ = false;
    return;
  }
  fault_valid_ = true;
  fault_code_ = e.error_code;
  fault_text_.assign(cia402::error_code_text(e.error_code, faults_));
}

cia402::DriveFaultReport SlaveAccess::fault_report() const noexcept {
  if (!fault_valid_) return {};
  return {true, fault_code_, fault_text_.view()};
}

void SlaveAccess::override_controlword(bool on, std::uint16_t value) noexcept {
  cw_override_ = on;
  cw_value_ = value;
  if (on) {
    // Written straight into the image: the profile's own writes are dropped meanwhile.
    const bool was = cw_override_;
    cw_override_ = false;
    write(cia402::obj::kControlword.id, value);
    cw_override_ = was;
  }
}

std::uint16_t SlaveAccess::statusword() const noexcept {
  return static_cast<std::uint16_t>(read(cia402::obj::kStatusword.id) & 0xFFFF);
}

std::int64_t SlaveAccess::read(cia402::ImageRef ref) const noexcept {
  if (!ref.current(mapping_generation()) || cx_ == nullptr) return 0;
  const std::uint16_t place = ref.slot();
  // An output reads back as the image holds it (what the next frame sends).
  const std::span<const std::uint8_t> bytes = (place & kPlaceOutput) != 0 ? cx_->outputs(slave_) : cx_->inputs(slave_);
  const cia402::DataType type = type_at(place);
  const std::size_t offset = place & kPlaceOffsetMask;
  const std::size_t n = cia402::size_of(type);
  if (offset + n > bytes.size()) return 0;
  std::uint64_t raw = 0;
  for (std::size_t i = 0; i < n; ++i) raw |= std::uint64_t{bytes[offset + i]} << (8 * i);
  return cia402::normalise(type, static_cast<std::int64_t>(raw));
}

void SlaveAccess::write(cia402::ImageRef ref, std::int64_t value) noexcept {
  if (!ref.current(mapping_generation()) || cx_ == nullptr) return;
  const std::uint16_t place = ref.slot();
  if ((place & kPlaceOutput) == 0) return;
  if (cw_override_ && place == cw_place_) return;
  const std::span<std::uint8_t> bytes = cx_->outputs(slave_);
  const std::size_t offset = place & kPlaceOffsetMask;
  const std::size_t n = cia402::size_of(type_at(place));
  if (offset + n > bytes.size()) return;
  const auto raw = static_cast<std::uint64_t>(value);
  for (std::size_t i = 0; i < n; ++i) bytes[offset + i] = static_cast<std::uint8_t>(raw >> (8 * i));
}

SlaveAccess::Pending* SlaveAccess::free_slot() noexcept {
  for (auto& p : pending_)
    if (p.id == 0) return &p;
  return nullptr;
}

SlaveAccess::Pending* SlaveAccess::slot_for(CoeSdoId id) noexcept {
  if (id == 0) return nullptr;
  for (auto& p : pending_)
    if (p.id == id && !p.cancelled) return &p;
  return nullptr;
}

cia402::RequestId SlaveAccess::track(Pending* p, CoeSdoId id, Kind kind, cia402::DataType type) noexcept {
  if (id == 0) return cia402::kNoRequest;
  p->id = id;
  p->kind = kind;
  p->type = type;
  p->cancelled = false;
  return id;
}

cia402::RequestId SlaveAccess::submit_read(cia402::ObjectDef def) noexcept {
  Pending* p = can_request() ? free_slot() : nullptr;
  if (p == nullptr) return cia402::kNoRequest;
  const cia402::ObjectId id = on_slave(def.id);
  return track(p, coe_->upload_value(id.index, id.sub), Kind::Value, def.type);
}

cia402::RequestId SlaveAccess::submit_write(cia402::ObjectDef def, std::int64_t value) noexcept {
  Pending* p = can_request() ? free_slot() : nullptr;
  if (p == nullptr) return cia402::kNoRequest;
  const cia402::ObjectId id = on_slave(def.id);
  return track(p,
               coe_->download_value(id.index, id.sub, static_cast<std::uint32_t>(value & 0xFFFFFFFF),
                                    cia402::size_of(def.type)),
               Kind::Value, def.type);
}

cia402::RequestId SlaveAccess::submit_upload(cia402::ObjectId id, std::span<std::uint8_t> into,
                                             std::uint8_t /*expected_size*/) noexcept {
  // CoE uploads always state their size (expedited: the size bits; normal: the complete size):
  // ETG.1000.6 §5.6.2.4. The expected size is not needed.
  Pending* p = can_request() ? free_slot() : nullptr;
  if (p == nullptr) return cia402::kNoRequest;
  const cia402::ObjectId on = on_slave(id);
  const std::size_t room = std::min(into.size(), p->buffer.size());
  p->into = into;
  return track(p, coe_->upload(on.index, on.sub, std::span<std::uint8_t>(p->buffer.data(), room)), Kind::Upload,
               cia402::DataType::U32);
}

cia402::RequestId SlaveAccess::submit_download(cia402::ObjectId id, std::span<const std::uint8_t> data) noexcept {
  Pending* p = can_request() ? free_slot() : nullptr;
  if (p == nullptr || data.size() > p->buffer.size()) return cia402::kNoRequest;
  const cia402::ObjectId on = on_slave(id);
  std::copy(data.begin(), data.end(), p->buffer.begin());
  return track(p, coe_->download(on.index, on.sub, std::span<const std::uint8_t>(p->buffer.data(), data.size())),
               Kind::Download, cia402::DataType::U32);
}

cia402::RequestResult SlaveAccess::poll(cia402::RequestId id) noexcept {
  Pending* p = slot_for(id);
  if (p == nullptr || coe_ == nullptr) return {};
  const CoeSdoResult r = coe_->result(id);
  switch (r.status) {
    case CoeSdoStatus::Queued:
    case CoeSdoStatus::InFlight: return {cia402::RequestState::Pending, 0, 0, 0, true};
    case CoeSdoStatus::Done: {
      cia402::RequestResult out{cia402::RequestState::Done, 0, 0, 0, true};
      if (p->kind == Kind::Value) {
        out.value = cia402::normalise(p->type, static_cast<std::int64_t>(r.value));
      } else if (p->kind == Kind::Upload) {
        const std::size_t n = std::min({r.size, p->into.size(), p->buffer.size()});
        std::copy_n(p->buffer.begin(), n, p->into.begin());
        out.size = static_cast<std::uint32_t>(n);
        out.value = static_cast<std::int64_t>(r.value);
      }
      coe_->take(id);
      *p = Pending{};
      return out;
    }
    case CoeSdoStatus::Failed:
      coe_->take(id);
      *p = Pending{};
      return {cia402::RequestState::Failed, 0, r.abort_code != 0 ? r.abort_code : kAbortDeviceState, 0, true};
    case CoeSdoStatus::Unknown: break;
  }
  *p = Pending{};
  return {};
}

void SlaveAccess::cancel(cia402::RequestId id) noexcept {
  Pending* p = slot_for(id);
  if (p == nullptr) return;
  p->cancelled = true;  // the client has no cancel: the request runs out and is taken then
  ++cancelled_;
  p->into = {};
}

// What the EtherCAT bus configures on every start and relies on (ETG.1000.6 PDO assignment and
// mapping objects, SM parameters; digest "What a master must do" steps 4-5).
std::string_view SlaveAccess::owner_of(cia402::ObjectId id) const noexcept {
  const auto in = [&](unsigned lo, unsigned hi) { return id.index >= lo && id.index <= hi; };
  if (id.index == 0x1C12 || id.index == 0x1C13) return "owned by the EtherCAT bus (PDO assignment)";
  if (in(0x1600, 0x17FF)) return "owned by the EtherCAT bus (RxPDO mapping)";
  if (in(0x1A00, 0x1BFF)) return "owned by the EtherCAT bus (TxPDO mapping)";
  if (id.index == 0x1C32 || id.index == 0x1C33) return "owned by the EtherCAT bus (SM synchronisation)";
  const cia402::ObjectId on = on_slave(id);
  for (const auto& o : owned_)
    if (o.id == on) return o.what;
  if (id.index == 0x6007)
    return "owned by the EtherCAT bus (6007h: what the drive does when the master stops)";
  return {};
}

void SlaveAccess::control_lost(std::string_view why) noexcept {
  control_lost_ = true;
  lost_why_.assign(why);
}

}  // namespace drivegate::ethercat
