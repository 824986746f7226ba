#pragma once
// CiA 301 SDO abort codes (also used for CoE mailbox aborts, which share the codes
// [ETG.1000.6 §5.6.2.7.2]): the ones the CANopen and EtherCAT clients, servers and simulators raise
// or act on, and their texts.
#include <cstdint>
#include <string_view>

namespace drivegate::cia402 {

// [CiA 301 §7.2.4.3.17 "SDO abort codes"; AKD part 1 §10.4]
namespace sdo_abort_code {
inline constexpr std::uint32_t kNone = 0;  // no abort (not a CiA 301 code: success)
inline constexpr std::uint32_t kToggle = 0x05030000;          // toggle bit not alternated
inline constexpr std::uint32_t kTimeout = 0x05040000;         // SDO protocol timed out
inline constexpr std::uint32_t kUnknownCommand = 0x05040001;  // command specifier not valid or unknown
inline constexpr std::uint32_t kOutOfMemory = 0x05040005;
inline constexpr std::uint32_t kUnsupportedAccess = 0x06010000;
inline constexpr std::uint32_t kWriteOnly = 0x06010001;  // attempt to read a write-only object
inline constexpr std::uint32_t kReadOnly = 0x06010002;   // attempt to write a read-only object
// Sub-index cannot be written, sub-index 0 must be 0 first (ETG.1000.6 Table 41; also CiA 301).
inline constexpr std::uint32_t kSubindexZeroFirst = 0x06010003;
inline constexpr std::uint32_t kNoObject = 0x06020000;
inline constexpr std::uint32_t kNotMappable = 0x06040041;
inline constexpr std::uint32_t kPdoLength = 0x06040042;
inline constexpr std::uint32_t kTypeMismatch = 0x06070010;  // data type / length does not match
inline constexpr std::uint32_t kTooLong = 0x06070012;       // length of service parameter too high
inline constexpr std::uint32_t kTooShort = 0x06070013;      // length of service parameter too low
inline constexpr std::uint32_t kNoSubIndex = 0x06090011;
inline constexpr std::uint32_t kValueRange = 0x06090030;
inline constexpr std::uint32_t kValueTooHigh = 0x06090031;
inline constexpr std::uint32_t kValueTooLow = 0x06090032;
inline constexpr std::uint32_t kGeneral = 0x08000000;
inline constexpr std::uint32_t kCannotStore = 0x08000020;
inline constexpr std::uint32_t kDeviceState = 0x08000022;  // ... because of the present device state
}  // namespace sdo_abort_code

std::string_view sdo_abort_text(std::uint32_t abort_code) noexcept;

}  // namespace drivegate::cia402
