#pragma once
// Error code (603Fh / EMCY) to text: the standard CiA 301 / CiA 402 codes, with a hook for a device
// profile's vendor texts. Lookup order: vendor table by exact code, standard table by exact code,
// then the standard class (first two hex digits, then the first one).
#include <cstdint>
#include <span>
#include <string_view>

namespace drivegate::cia402 {

struct FaultText {
  std::uint16_t code = 0;
  std::string_view text;  // must outlive the controller (static data from the device profile)
};

std::string_view error_code_text(std::uint16_t code, std::span<const FaultText> vendor = {}) noexcept;

}  // namespace drivegate::cia402
