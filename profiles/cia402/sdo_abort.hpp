#pragma once
// CiA 301 SDO abort codes in words (also used for CoE mailbox aborts, which share the codes).
#include <cstdint>
#include <string_view>

namespace drivegate::cia402 {

std::string_view sdo_abort_text(std::uint32_t abort_code) noexcept;

}  // namespace drivegate::cia402
