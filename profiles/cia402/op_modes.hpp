#pragma once
// Mapping between the unified modes (core::Mode) and the CiA 402 6060h/6061h values [AKD digest §3.6].
#include <cstdint>
#include <optional>

#include "core/axis_types.hpp"

namespace drivegate::cia402 {

// nullopt for modes CiA 402 does not have (PROFIdrive traversing blocks, None).
std::optional<std::int8_t> to_op_mode(core::Mode mode) noexcept;
// Mode::None for 0 and for manufacturer or unknown values.
core::Mode from_op_mode(std::int8_t value) noexcept;

}  // namespace drivegate::cia402
