#include "profiles/cia402/sim/object_dictionary.hpp"

#include <algorithm>
#include <utility>

namespace drivegate::cia402::sim {

std::int64_t type_min(DataType t) noexcept {
  switch (t) {
    case DataType::I8: return -128;
    case DataType::I16: return -32768;
    case DataType::I32: return -2147483648LL;
    case DataType::U8:
    case DataType::U16:
    case DataType::U32: return 0;
  }
  return 0;
}

std::int64_t type_max(DataType t) noexcept {
  switch (t) {
    case DataType::I8: return 127;
    case DataType::U8: return 255;
    case DataType::I16: return 32767;
    case DataType::U16: return 65535;
    case DataType::I32: return 2147483647LL;
    case DataType::U32: return 4294967295LL;
  }
  return 0;
}

ObjectDictionary::ObjectDictionary(std::size_t capacity) { entries_.reserve(capacity); }

bool ObjectDictionary::add(ObjectDef def, Access access, std::int64_t default_value, std::optional<std::int64_t> min,
                           std::optional<std::int64_t> max) {
  if (entries_.size() == entries_.capacity()) return false;
  ObjectEntry e;
  e.id = def.id;
  e.type = def.type;
  e.access = access;
  e.min = std::max(type_min(def.type), min.value_or(type_min(def.type)));
  e.max = std::min(type_max(def.type), max.value_or(type_max(def.type)));
  if (e.min > e.max || default_value < e.min || default_value > e.max) return false;
  e.value = default_value;
  e.default_value = default_value;
  const auto pos = std::lower_bound(entries_.begin(), entries_.end(), def.id.key(),
                                    [](const ObjectEntry& x, std::uint32_t k) { return x.id.key() < k; });
  if (pos != entries_.end() && pos->id == def.id) return false;
  entries_.insert(pos, e);
  return true;
}

const ObjectEntry* ObjectDictionary::find(ObjectId id) const noexcept {
  const auto pos = std::lower_bound(entries_.begin(), entries_.end(), id.key(),
                                    [](const ObjectEntry& x, std::uint32_t k) { return x.id.key() < k; });
  return (pos != entries_.end() && pos->id == id) ? &*pos : nullptr;
}

ObjectEntry* ObjectDictionary::find(ObjectId id) noexcept {
  return const_cast<ObjectEntry*>(std::as_const(*this).find(id));
}

std::uint32_t ObjectDictionary::missing_code(ObjectId id) const noexcept {
  const auto pos = std::lower_bound(entries_.begin(), entries_.end(), ObjectId{id.index, 0}.key(),
                                    [](const ObjectEntry& x, std::uint32_t k) { return x.id.key() < k; });
  return (pos != entries_.end() && pos->id.index == id.index) ? abort_code::kNoSubIndex : abort_code::kNoObject;
}

std::optional<std::int64_t> ObjectDictionary::get(ObjectId id) const noexcept {
  const ObjectEntry* e = find(id);
  if (e == nullptr) return std::nullopt;
  return e->value;
}

std::optional<DataType> ObjectDictionary::type_of(ObjectId id) const noexcept {
  const ObjectEntry* e = find(id);
  if (e == nullptr) return std::nullopt;
  return e->type;
}

std::optional<Access> ObjectDictionary::access_of(ObjectId id) const noexcept {
  const ObjectEntry* e = find(id);
  if (e == nullptr) return std::nullopt;
  return e->access;
}

std::uint32_t ObjectDictionary::set(ObjectId id, std::int64_t value) noexcept {
  ObjectEntry* e = find(id);
  if (e == nullptr) return missing_code(id);
  if (e->access == Access::ReadOnly) return abort_code::kReadOnly;
  // Outside what the data type can hold at all is a range error; outside the object's own
  // limits says which side [CiA 301 abort codes].
  if (value < type_min(e->type) || value > type_max(e->type)) return abort_code::kValueRange;
  if (value > e->max) return abort_code::kValueTooHigh;
  if (value < e->min) return abort_code::kValueTooLow;
  e->value = value;
  return abort_code::kNone;
}

ReadResult ObjectDictionary::read(ObjectId id) const noexcept {
  const ObjectEntry* e = find(id);
  if (e == nullptr) return {missing_code(id), 0};
  if (e->access == Access::WriteOnly) return {abort_code::kWriteOnly, 0};
  return {abort_code::kNone, e->value};
}

bool ObjectDictionary::store(ObjectId id, std::int64_t value) noexcept {
  ObjectEntry* e = find(id);
  if (e == nullptr) return false;
  e->value = std::clamp(value, e->min, e->max);
  return e->value == value;
}

void ObjectDictionary::reset_to_defaults() noexcept {
  for (ObjectEntry& e : entries_) e.value = e.default_value;
}

}  // namespace drivegate::cia402::sim
