#pragma once
// The types the standards give objects, for parameter access to a drive without an EDS: the CiA
// 301 communication objects (CiA 301 §7.5) and the CiA 402 objects the profile knows
// (objects.hpp and a few more that users commonly read). CoE drives share both tables
// (dunker-ethercat-coe.md §4). Unknown for anything else: vendor objects need an EDS or a --type.
#include "core/param_value.hpp"
#include "profiles/cia402/objects.hpp"

namespace drivegate::cia402 {

[[nodiscard]] core::ParamType standard_param_type(ObjectId id) noexcept;
[[nodiscard]] core::ParamType to_param_type(DataType t) noexcept;

}  // namespace drivegate::cia402
