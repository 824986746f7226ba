#pragma once
// Record access headers and the I&M0 record [IEC 61158-6-10 §5.2.2.8 "IODWriteReqHeader",
// "IODWriteResHeader", "IODReadReqHeader", "IODReadResHeader"; §5.2.4.x "I&M0"].
//
//   IODWriteReqHeader 0008h / IODReadReqHeader 0009h (64): SeqNumber u16 | ARUUID | API u32 |
//       SlotNumber u16 | SubslotNumber u16 | Padding 2 | Index u16 | RecordDataLength u32 |
//       RWPadding 24 (read implicit: TargetARUUID 16 + 8)
//   IODWriteResHeader 8008h (64): ... RecordDataLength u32 | AdditionalValue1 u16 |
//       AdditionalValue2 u16 | PNIOStatus 4 | RWPadding 16
//   IODReadResHeader 8009h (64): ... RecordDataLength u32 | AdditionalValue1 u16 |
//       AdditionalValue2 u16 | RWPadding 20
//   The record data follows the header (outside its BlockLength): a write request carries
//   RecordDataLength bytes, a read response too; a read request's RecordDataLength is the most it
//   takes.
//
// PROFIdrive parameter access on the AKD (digest §5.1): write then read record index 47 on slot 1.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "adapters/profinet/wire/blocks.hpp"
#include "adapters/profinet/wire/rpc_status.hpp"

namespace drivegate::profinet {

inline constexpr std::size_t kRecordHeaderSize = 64;

// Record indices a controller uses [IEC 61158-6-10 Table "Index"; PROFIdrive].
namespace record_index {
inline constexpr std::uint16_t kIm0 = 0xAFF0;
inline constexpr std::uint16_t kIm1 = 0xAFF1;
inline constexpr std::uint16_t kAkdParameterAccess = 47;  // digest §5.1
inline constexpr std::uint16_t kProfidriveLocal = 0xB02E;
inline constexpr std::uint16_t kProfidriveGlobal = 0xB02F;
}  // namespace record_index

struct RecordReqHeader {
  std::uint16_t type = block_type::kWriteReqHeader;  // 0008h write, 0009h read
  std::uint16_t sequence_number = 0;
  Uuid ar_uuid{};
  std::uint32_t api = 0;
  std::uint16_t slot = 0;
  std::uint16_t subslot = 0;
  std::uint16_t index = 0;
  std::uint32_t record_data_length = 0;
  Uuid target_ar_uuid{};  // read implicit only; zero otherwise
  bool operator==(const RecordReqHeader&) const = default;
};
std::size_t encode_record_req_header(const RecordReqHeader& h, std::span<std::uint8_t> out) noexcept;

struct RecordResHeader {
  std::uint16_t type = block_type::kWriteResHeader;  // 8008h write, 8009h read
  std::uint16_t sequence_number = 0;
  Uuid ar_uuid{};
  std::uint32_t api = 0;
  std::uint16_t slot = 0;
  std::uint16_t subslot = 0;
  std::uint16_t index = 0;
  std::uint32_t record_data_length = 0;
  std::uint16_t additional_value1 = 0;
  std::uint16_t additional_value2 = 0;
  PnioStatus status{};  // write response only
  bool operator==(const RecordResHeader&) const = default;
};
std::size_t encode_record_res_header(const RecordResHeader& h, std::span<std::uint8_t> out) noexcept;

// The response header for `request` with `length` bytes of record data (the status only matters
// for a write).
RecordResHeader record_response_for(const RecordReqHeader& request, std::uint32_t length,
                                    const PnioStatus& status = {}) noexcept;

struct RecordReqView {
  WireError error = WireError::None;
  RecordReqHeader header{};
  std::span<const std::uint8_t> data{};  // write: RecordDataLength bytes after the header
  std::size_t size = 0;                  // header + data
};
// A write or read request's args: the header and, for a write, its data (which must be there).
RecordReqView decode_record_request(std::span<const std::uint8_t> in) noexcept;

struct RecordResView {
  WireError error = WireError::None;
  RecordResHeader header{};
  std::span<const std::uint8_t> data{};  // read: RecordDataLength bytes after the header
  std::size_t size = 0;
};
RecordResView decode_record_response(std::span<const std::uint8_t> in) noexcept;

// ---- I&M0 [IEC 61158-6-10 "I&M0", PROFINET I&M guideline] ----------------------------------------
//   BlockHeader 0020h v1.0 | VendorIDHigh u8 | VendorIDLow u8 | OrderID 20 octets (visible string,
//   blank padded) | IM_Serial_Number 16 | IM_Hardware_Revision u16 | IM_Software_Revision: prefix
//   char ('V', 'R', 'P', 'U', 'T') + functional enhancement u8 + bug fix u8 + internal change u8 |
//   IM_Revision_Counter u16 | IM_Profile_ID u16 | IM_Profile_Specific_Type u16 | IM_Version
//   major u8 + minor u8 | IM_Supported u16           = 60 bytes

inline constexpr std::size_t kIm0Size = 60;

struct Im0 {
  std::uint16_t vendor_id = 0;
  std::string_view order_id{};       // trailing blanks removed (a view into the record)
  std::string_view serial_number{};  // trailing blanks removed
  std::uint16_t hardware_revision = 0;
  char software_prefix = 'V';
  std::uint8_t software_functional = 0;
  std::uint8_t software_bugfix = 0;
  std::uint8_t software_internal = 0;
  std::uint16_t revision_counter = 0;
  std::uint16_t profile_id = 0;  // 3A00h PROFIdrive
  std::uint16_t profile_specific_type = 0;
  std::uint8_t im_version_major = 1;
  std::uint8_t im_version_minor = 1;
  std::uint16_t im_supported = 0;  // bit 1 I&M1 ... bit 15 I&M15
  bool operator==(const Im0&) const = default;
};
// Blank-pads order ID and serial; 0 when either is too long.
std::size_t encode_im0(const Im0& m, std::span<std::uint8_t> out) noexcept;
struct Im0View {
  WireError error = WireError::None;
  Im0 im0{};
  std::size_t size = 0;
};
Im0View decode_im0(std::span<const std::uint8_t> in) noexcept;

// ---- I&M1 [IEC 61158-6-10 "I&M1", PROFINET I&M guideline]: the plant's tags, written by users ---
//   BlockHeader 0021h v1.0 | IM_Tag_Function 32 octets | IM_Tag_Location 22 octets (visible
//   strings, blank padded)                           = 60 bytes

inline constexpr std::size_t kIm1Size = 60;

struct Im1 {
  std::string_view tag_function{};  // trailing blanks removed (a view into the record)
  std::string_view tag_location{};
  bool operator==(const Im1&) const = default;
};
// Blank-pads both tags; 0 when either is too long.
std::size_t encode_im1(const Im1& m, std::span<std::uint8_t> out) noexcept;
struct Im1View {
  WireError error = WireError::None;
  Im1 im1{};
};
Im1View decode_im1(std::span<const std::uint8_t> in) noexcept;

}  // namespace drivegate::profinet
