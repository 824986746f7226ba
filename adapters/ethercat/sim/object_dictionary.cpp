#include "adapters/ethercat/sim/object_dictionary.hpp"

#include <algorithm>
#include <cstring>
#include <utility>

namespace drivegate::ethercat::sim {
namespace {

// Access bits by state [ETG.1000.6 §5.6.3.6: read/write in PRE-OP, SAFE-OP, OP].
bool readable(std::uint16_t access, AlState s) noexcept {
  switch (s) {
    case AlState::PreOp: return (access & object_access::kReadPreOp) != 0;
    case AlState::SafeOp: return (access & object_access::kReadSafeOp) != 0;
    case AlState::Op: return (access & object_access::kReadOp) != 0;
    default: return (access & (object_access::kReadPreOp | object_access::kReadSafeOp | object_access::kReadOp)) != 0;
  }
}
bool writable_any(std::uint16_t access) noexcept {
  return (access & (object_access::kWritePreOp | object_access::kWriteSafeOp | object_access::kWriteOp)) != 0;
}
bool writable(std::uint16_t access, AlState s) noexcept {
  switch (s) {
    case AlState::PreOp: return (access & object_access::kWritePreOp) != 0;
    case AlState::SafeOp: return (access & object_access::kWriteSafeOp) != 0;
    case AlState::Op: return (access & object_access::kWriteOp) != 0;
    default: return writable_any(access);
  }
}

// Sort key of the entries: index, then subindex.
constexpr std::uint32_t entry_key(std::uint16_t index, std::uint8_t subindex) noexcept {
  return (static_cast<std::uint32_t>(index) << 8) | subindex;
}

}  // namespace

void SimpleObjectDictionary::add_object(std::uint16_t index, std::uint8_t object_code, std::string_view name) {
  const auto it = std::lower_bound(objects_.begin(), objects_.end(), index,
                                   [](const Object& o, std::uint16_t i) { return o.index < i; });
  if (it != objects_.end() && it->index == index) {
    it->object_code = object_code;
    it->name = name;
    return;
  }
  objects_.insert(it, Object{index, object_code, name});
}

void SimpleObjectDictionary::add_entry(const OdEntrySpec& e) {
  if (find_object(e.index) == nullptr) add_object(e.index, object_code::kVariable, e.name);
  const std::size_t offset = values_.size();
  values_.insert(values_.end(), e.value.begin(), e.value.end());
  largest_ = std::max(largest_, e.value.size());
  const Entry entry{e.index, e.subindex, e.data_type, e.access, e.name, offset, e.value.size()};
  const auto it = std::lower_bound(entries_.begin(), entries_.end(), entry_key(e.index, e.subindex),
                                   [](const Entry& a, std::uint32_t k) { return entry_key(a.index, a.subindex) < k; });
  if (it != entries_.end() && it->index == e.index && it->subindex == e.subindex) {
    *it = entry;
  } else {
    entries_.insert(it, entry);
  }
}

void SimpleObjectDictionary::add_variable(std::uint16_t index, std::uint16_t type, std::uint16_t access,
                                          std::string_view name, std::span<const std::uint8_t> value) {
  add_object(index, object_code::kVariable, name);
  add_entry(OdEntrySpec{index, 0, type, access, name, value});
}

const SimpleObjectDictionary::Object* SimpleObjectDictionary::find_object(std::uint16_t index) const noexcept {
  const auto it = std::lower_bound(objects_.begin(), objects_.end(), index,
                                   [](const Object& o, std::uint16_t i) { return o.index < i; });
  return (it != objects_.end() && it->index == index) ? &*it : nullptr;
}

const SimpleObjectDictionary::Entry* SimpleObjectDictionary::find_entry(std::uint16_t index,
                                                                        std::uint8_t subindex) const noexcept {
  const auto it = std::lower_bound(entries_.begin(), entries_.end(), entry_key(index, subindex),
                                   [](const Entry& e, std::uint32_t k) { return entry_key(e.index, e.subindex) < k; });
  return (it != entries_.end() && it->index == index && it->subindex == subindex) ? &*it : nullptr;
}
SimpleObjectDictionary::Entry* SimpleObjectDictionary::find_entry(std::uint16_t index, std::uint8_t subindex) noexcept {
  return const_cast<Entry*>(std::as_const(*this).find_entry(index, subindex));
}

OdReadResult SimpleObjectDictionary::read(std::uint16_t index, std::uint8_t subindex, std::span<std::uint8_t> out,
                                          AlState state) noexcept {
  if (find_object(index) == nullptr) return {cia402::sdo_abort_code::kNoObject, 0};
  const Entry* e = find_entry(index, subindex);
  if (e == nullptr) return {cia402::sdo_abort_code::kNoSubIndex, 0};
  if (!readable(e->access, state)) {
    return {writable_any(e->access) ? cia402::sdo_abort_code::kWriteOnly : cia402::sdo_abort_code::kDeviceState, 0};
  }
  if (e->size > out.size()) return {cia402::sdo_abort_code::kOutOfMemory, 0};
  if (e->size > 0) std::memcpy(out.data(), values_.data() + e->offset, e->size);
  return {0, e->size};
}

std::uint32_t SimpleObjectDictionary::write(std::uint16_t index, std::uint8_t subindex,
                                            std::span<const std::uint8_t> data, AlState state) noexcept {
  if (find_object(index) == nullptr) return cia402::sdo_abort_code::kNoObject;
  Entry* e = find_entry(index, subindex);
  if (e == nullptr) return cia402::sdo_abort_code::kNoSubIndex;
  if (!writable_any(e->access)) return cia402::sdo_abort_code::kReadOnly;
  if (!writable(e->access, state)) return cia402::sdo_abort_code::kDeviceState;
  if (data.size() > e->size) return cia402::sdo_abort_code::kTooLong;
  if (data.size() < e->size) return cia402::sdo_abort_code::kTooShort;
  if (e->size > 0) std::memcpy(values_.data() + e->offset, data.data(), e->size);
  return 0;
}

std::size_t SimpleObjectDictionary::list(OdListType type, std::span<std::uint16_t> out) const noexcept {
  std::size_t n = 0;
  for (const Object& o : objects_) {
    bool match = type == OdListType::All;
    if (!match) {
      for (const Entry& e : entries_) {
        if (e.index != o.index) continue;
        if ((type == OdListType::RxPdoMappable && (e.access & object_access::kRxPdoMappable)) ||
            (type == OdListType::TxPdoMappable && (e.access & object_access::kTxPdoMappable)) ||
            (type == OdListType::Backup && (e.access & object_access::kBackup)) ||
            (type == OdListType::Startup && (e.access & object_access::kStartup))) {
          match = true;
          break;
        }
      }
    }
    if (!match) continue;
    if (n < out.size()) out[n] = o.index;
    ++n;
  }
  return n;
}

bool SimpleObjectDictionary::describe_object(std::uint16_t index, SdoInfoObjectDescription& out) const noexcept {
  const Object* o = find_object(index);
  if (o == nullptr) return false;
  out = SdoInfoObjectDescription{};
  out.index = index;
  out.object_code = o->object_code;
  out.name = o->name;
  for (const Entry& e : entries_) {
    if (e.index != index) continue;
    out.max_subindex = std::max(out.max_subindex, e.subindex);
    if (e.subindex == (o->object_code == object_code::kVariable ? 0 : 1)) out.data_type = e.data_type;
  }
  return true;
}

bool SimpleObjectDictionary::describe_entry(std::uint16_t index, std::uint8_t subindex,
                                            SdoInfoEntryDescription& out) const noexcept {
  const Entry* e = find_entry(index, subindex);
  if (e == nullptr) return false;
  out = SdoInfoEntryDescription{};
  out.index = index;
  out.subindex = subindex;
  out.data_type = e->data_type;
  out.bit_length = static_cast<std::uint16_t>(e->size * 8);
  out.object_access = e->access;
  out.name = e->name;
  return true;
}

std::span<std::uint8_t> SimpleObjectDictionary::value(std::uint16_t index, std::uint8_t subindex) noexcept {
  Entry* e = find_entry(index, subindex);
  if (e == nullptr) return {};
  return {values_.data() + e->offset, e->size};
}

}  // namespace drivegate::ethercat::sim
