#pragma once
// The types the standards give objects, for parameter access to a drive without an EDS: the CiA
// 301 communication objects (CiA 301 §7.5) and the CiA 402 objects the profile knows
// (objects.hpp and a few more that users commonly read). CoE drives share both tables
// (dunker-ethercat-coe.md §4). Unknown for anything else: vendor objects need an EDS or a --type.
#include <optional>

#include "core/param_value.hpp"
#include "profiles/cia402/objects.hpp"

namespace drivegate::cia402 {

[[nodiscard]] core::ParamType standard_param_type(ObjectId id) noexcept;
// The CiA 402 type of a device profile object: every object of objects.hpp and the few more in
// the table; nullopt for others. Device profiles are checked against it (config/canopen/device_section.cpp).
[[nodiscard]] std::optional<DataType> profile_object_type(ObjectId id) noexcept;
[[nodiscard]] core::ParamType to_param_type(DataType t) noexcept;

}  // namespace drivegate::cia402
