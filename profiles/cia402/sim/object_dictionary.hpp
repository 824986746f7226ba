#pragma once
// The simulated drive's object dictionary: typed entries keyed by ObjectId with access rights, an
// optional min/max and a default. Storage is one vector reserved at construction and kept sorted
// (the order a dictionary listing shows), with a hash index beside it sized at construction, so
// lookups are O(1) and reads/writes never allocate: a simulated line of 64 drives looks objects up
// thousands of times per cycle.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "profiles/cia402/objects.hpp"
#include "profiles/cia402/sdo_abort.hpp"

namespace drivegate::cia402::sim {

enum class Access : std::uint8_t { ReadOnly, ReadWrite, WriteOnly };

// The CiA 301 SDO abort codes (profiles/cia402/sdo_abort.hpp) under the name the dictionary and
// the drive model use; kStatePrevents is sdo_abort_code::kDeviceState.
namespace abort_code {
using namespace cia402::sdo_abort_code;
inline constexpr std::uint32_t kStatePrevents = cia402::sdo_abort_code::kDeviceState;
}  // namespace abort_code

struct ObjectEntry {
  ObjectId id;
  DataType type = DataType::U32;
  Access access = Access::ReadWrite;
  std::int64_t value = 0;
  std::int64_t default_value = 0;
  std::int64_t min = 0;  // effective bounds: the type's range narrowed by the optional min/max
  std::int64_t max = 0;
};

struct ReadResult {
  std::uint32_t abort_code = abort_code::kNone;
  std::int64_t value = 0;
};

// Smallest and largest value a CiA data type holds.
std::int64_t type_min(DataType t) noexcept;
std::int64_t type_max(DataType t) noexcept;

class ObjectDictionary {
 public:
  // Reserves room for `capacity` entries; add() beyond that fails instead of reallocating.
  explicit ObjectDictionary(std::size_t capacity);

  // Construction phase (allocation-free as well, but not meant for the cycle). Returns false for a
  // duplicate id, a full dictionary, a default outside the bounds or min > max.
  bool add(ObjectDef def, Access access, std::int64_t default_value, std::optional<std::int64_t> min = std::nullopt,
           std::optional<std::int64_t> max = std::nullopt);

  // Raw value regardless of access rights (the drive's own view). nullopt when the object is absent.
  [[nodiscard]] std::optional<std::int64_t> get(ObjectId id) const noexcept;
  // Where the object's value lives, for a caller that reads it every cycle without a lookup;
  // nullptr when absent. Valid for the dictionary's life once the construction phase (add()) ends.
  [[nodiscard]] const std::int64_t* value_address(ObjectId id) const noexcept;
  [[nodiscard]] std::optional<DataType> type_of(ObjectId id) const noexcept;
  [[nodiscard]] std::optional<Access> access_of(ObjectId id) const noexcept;

  // A master's write: checks existence, access and range. Returns 0 or a CiA 301 abort code.
  std::uint32_t set(ObjectId id, std::int64_t value) noexcept;
  // A master's read: checks existence and access.
  [[nodiscard]] ReadResult read(ObjectId id) const noexcept;

  // The drive's own update of an object (statusword, actuals): ignores access, clamps to the
  // entry's bounds so a value never wraps. Returns false when the object is absent or was clamped.
  bool store(ObjectId id, std::int64_t value) noexcept;

  // Back to the defaults (power cycle).
  void reset_to_defaults() noexcept;

  // The abort code a lookup of an absent object gets: object vs. sub-index does not exist.
  [[nodiscard]] std::uint32_t missing_code(ObjectId id) const noexcept;

  [[nodiscard]] std::size_t size() const noexcept { return entries_.size(); }

 private:
  [[nodiscard]] const ObjectEntry* find(ObjectId id) const noexcept;
  ObjectEntry* find(ObjectId id) noexcept;

  void rebuild_index() noexcept;

  std::size_t capacity_ = 0;
  std::vector<ObjectEntry> entries_;  // sorted by ObjectId::key()
  // Open addressing with linear probing over entries_ (position + 1; 0 = empty), at most half full.
  std::vector<std::uint16_t> index_;
  std::size_t index_mask_ = 0;
};

}  // namespace drivegate::cia402::sim
