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

namespace {

constexpr std::size_t first_cell(std::uint32_t key, std::size_t mask) noexcept {
  return static_cast<std::size_t>((key * 0x9E3779B1U) >> 16) & mask;
}

}  // namespace

ObjectDictionary::ObjectDictionary(std::size_t capacity) {
  capacity_ = std::min<std::size_t>(capacity, 0xFFFF);  // positions travel as 16-bit cells
  entries_.reserve(capacity_);
  std::size_t size = 16;
  while (size < 2 * capacity_) size *= 2;
  index_.assign(size, 0);
  index_mask_ = size - 1;
}

void ObjectDictionary::rebuild_index() noexcept {
  std::fill(index_.begin(), index_.end(), std::uint16_t{0});
  for (std::size_t i = 0; i < entries_.size(); ++i) {
    std::size_t c = first_cell(entries_[i].id.key(), index_mask_);
    while (index_[c] != 0) c = (c + 1) & index_mask_;
    index_[c] = static_cast<std::uint16_t>(i + 1);
  }
}

bool ObjectDictionary::add(ObjectDef def, Access access, std::int64_t default_value, std::optional<std::int64_t> min,
                           std::optional<std::int64_t> max) {
  if (entries_.size() >= capacity_) return false;
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
  rebuild_index();  // positions after pos moved
  return true;
}

const ObjectEntry* ObjectDictionary::find(ObjectId id) const noexcept {
  for (std::size_t c = first_cell(id.key(), index_mask_); index_[c] != 0; c = (c + 1) & index_mask_) {
    const ObjectEntry& e = entries_[index_[c] - 1U];
    if (e.id == id) return &e;
  }
  return nullptr;
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

const std::int64_t* ObjectDictionary::value_address(ObjectId id) const noexcept {
  const ObjectEntry* e = find(id);
  return e == nullptr ? nullptr : &e->value;
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
