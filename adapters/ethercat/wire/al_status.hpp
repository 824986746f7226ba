#pragma once
// AL status codes (register 0x0134) in words [ETG.1000.6 §5.3.2 Table 11 "AL Status Codes", with
// the later additions of ETG.1020 (0x0004-0x000E, 0x002E, 0x0052, 0x0070)]. 0x8000-0xFFFF are
// vendor specific; other codes not in the table are reserved.
#include <cstdint>
#include <string_view>

namespace drivegate::ethercat {

// Selected codes the master acts on.
namespace al_status_code {
inline constexpr std::uint16_t kNoError = 0x0000;
inline constexpr std::uint16_t kUnspecified = 0x0001;
inline constexpr std::uint16_t kInvalidStateChange = 0x0011;
inline constexpr std::uint16_t kUnknownState = 0x0012;
inline constexpr std::uint16_t kBootstrapNotSupported = 0x0013;
inline constexpr std::uint16_t kInvalidMailboxConfigPreOp = 0x0016;
inline constexpr std::uint16_t kInvalidSmConfig = 0x0017;
inline constexpr std::uint16_t kSmWatchdog = 0x001B;
inline constexpr std::uint16_t kInvalidOutputConfig = 0x001D;
inline constexpr std::uint16_t kInvalidInputConfig = 0x001E;
inline constexpr std::uint16_t kInvalidWatchdogConfig = 0x001F;
inline constexpr std::uint16_t kInvalidDcSyncConfig = 0x0030;
inline constexpr std::uint16_t kDcInvalidSyncCycleTime = 0x0035;
inline constexpr std::uint16_t kVendorFirst = 0x8000;
}  // namespace al_status_code

// Text of an AL status code: the table's text, "vendor specific" for 0x8000-0xFFFF, "reserved"
// for any other code.
std::string_view al_status_text(std::uint16_t code) noexcept;
// True for a code listed in the table (not reserved, not vendor specific).
bool al_status_known(std::uint16_t code) noexcept;

}  // namespace drivegate::ethercat
