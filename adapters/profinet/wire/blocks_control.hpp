#pragma once
// PNIO control blocks: the end of parameterisation (PrmEnd, controller -> device), the device's
// ApplicationReady (device -> controller, over the controller's RPC interface) and Release, with
// their responses [IEC 61158-6-10 §5.2.2.7 "IODControlReq/Res", "IOXControlReq/Res",
// "IODReleaseReq/Res"].
//
//   ControlBlock (32): BlockHeader (types 0110h/0112h/0114h, responses | 8000h) | Reserved u16 |
//                      ARUUID | SessionKey u16 | Reserved u16 (AlarmSequenceNumber in the plug
//                      variants) | ControlCommand u16 | ControlBlockProperties u16
#include <cstddef>
#include <cstdint>
#include <span>

#include "adapters/profinet/wire/blocks.hpp"

namespace drivegate::profinet {

// ControlCommand bits [IEC 61158-6-10 "ControlCommand"].
namespace control_command {
inline constexpr std::uint16_t kPrmEnd = 0x0001;
inline constexpr std::uint16_t kApplicationReady = 0x0002;
inline constexpr std::uint16_t kRelease = 0x0004;
inline constexpr std::uint16_t kDone = 0x0008;  // every response
inline constexpr std::uint16_t kReadyForCompanion = 0x0010;
inline constexpr std::uint16_t kReadyForRtClass3 = 0x0020;
inline constexpr std::uint16_t kPrmBegin = 0x0040;
}  // namespace control_command

inline constexpr std::size_t kControlBlockSize = 32;

struct ControlBlock {
  std::uint16_t type = block_type::kPrmEndReq;
  Uuid ar_uuid{};
  std::uint16_t session_key = 0;
  std::uint16_t alarm_sequence_number = 0;  // reserved (0) outside the plug variants
  std::uint16_t command = control_command::kPrmEnd;
  std::uint16_t properties = 0;
  bool operator==(const ControlBlock&) const = default;
};
std::size_t encode_control_block(const ControlBlock& b, std::span<std::uint8_t> out) noexcept;
struct ControlBlockView {
  WireError error = WireError::None;
  ControlBlock block{};
  std::size_t size = 0;
};
// Any of 0110h, 0112h, 0114h and their responses 8110h, 8112h, 8114h.
ControlBlockView decode_control_block(std::span<const std::uint8_t> in) noexcept;

// The response to a control request: type | 8000h, the same AR and session key, command Done.
ControlBlock control_response_for(const ControlBlock& request) noexcept;

}  // namespace drivegate::profinet
