#pragma once
// PROFINET frames on Ethernet [IEC 61158-6-10: the RT frame (Ethernet II, EtherType 8892h,
// FrameID) and the coding of the field FrameID; IEEE 802.3 §3.2; IEEE 802.1Q §9.6 (the tag)]:
//
//   destination(6) source(6) [TPID 8100h + TCI: PCP bits 13-15, DEI bit 12, VID bits 0-11]
//   EtherType 8892h | FrameID u16 | the PDU of the FrameID's class | padding to 60 octets
//
// All numbers big-endian. A controller sends RT class 1 and alarm frames with a priority tag (VID
// 0: PCP 6 for cyclic and alarm high, 5 for alarm low [IEC 61158-6-10, VLAN priorities of the RT
// frames]); DCP goes untagged.
// Receivers accept both. No allocation: the decoder returns views into the frame.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

namespace drivegate::profinet {

using MacAddress = std::array<std::uint8_t, 6>;

inline constexpr std::uint16_t kEtherType = 0x8892;  // PROFINET real-time (IEEE assignment)
inline constexpr std::uint16_t kVlanTpid = 0x8100;   // IEEE 802.1Q
inline constexpr std::size_t kEthernetHeaderSize = 14;
inline constexpr std::size_t kVlanTagSize = 4;
inline constexpr std::size_t kFrameIdSize = 2;
inline constexpr std::size_t kMinFrameSize = 60;    // without FCS [IEEE 802.3 §3.2.8]
inline constexpr std::size_t kMaxFrameSize = 1518;  // without FCS, with a tag: 1500 payload octets
inline constexpr std::size_t kMaxPayloadSize = 1500;

// Priorities of the tag [IEC 61158-6-10, VLAN priorities]: RT class 1 cyclic and alarm high 6,
// alarm low 5.
inline constexpr std::uint8_t kPriorityRtCyclic = 6;
inline constexpr std::uint8_t kPriorityAlarmHigh = 6;
inline constexpr std::uint8_t kPriorityAlarmLow = 5;

// Multicast destinations of DCP [IEC 61158-6-10 §4.3, DCP multicast MAC addresses]: Identify
// requests go to 01-0E-CF-00-00-00, Hello to 01-0E-CF-00-00-01.
inline constexpr MacAddress kDcpIdentifyMulticast{0x01, 0x0E, 0xCF, 0x00, 0x00, 0x00};
inline constexpr MacAddress kDcpHelloMulticast{0x01, 0x0E, 0xCF, 0x00, 0x00, 0x01};

// FrameIDs [IEC 61158-6-10, coding of the field FrameID].
namespace frame_id {
inline constexpr std::uint16_t kRtClass1First = 0x8000;  // RT class 1, 8000h-BFFFh unicast
inline constexpr std::uint16_t kRtClass1Last = 0xBFFF;
inline constexpr std::uint16_t kRtClass1MulticastFirst = 0xC000;  // RT class 1, C000h-FBFFh (also UDP/multicast)
inline constexpr std::uint16_t kRtClass1MulticastLast = 0xFBFF;
inline constexpr std::uint16_t kAlarmHigh = 0xFC01;
inline constexpr std::uint16_t kAlarmLow = 0xFE01;
inline constexpr std::uint16_t kDcpHello = 0xFEFC;
inline constexpr std::uint16_t kDcpGetSet = 0xFEFD;
inline constexpr std::uint16_t kDcpIdentifyRequest = 0xFEFE;
inline constexpr std::uint16_t kDcpIdentifyResponse = 0xFEFF;
}  // namespace frame_id

// What a FrameID says the PDU behind it is.
enum class FrameClass : std::uint8_t {
  Other,          // every FrameID this codec layer does not handle (RT class 2/3, PTCP, reserved)
  RtCyclic,       // 8000h-BFFFh and C000h-FBFFh: C_SDU + APDU status (wire/rt.hpp)
  AlarmHigh,      // FC01h: RTA-PDU (wire/alarm.hpp)
  AlarmLow,       // FE01h
  DcpHello,       // FEFCh: DCP (wire/dcp.hpp)
  DcpGetSet,      // FEFDh
  DcpIdentifyRequest,   // FEFEh
  DcpIdentifyResponse,  // FEFFh
};
FrameClass classify_frame_id(std::uint16_t id) noexcept;
std::string_view to_string(FrameClass c) noexcept;  // "RT class 1 cyclic", "alarm high", ...
constexpr bool is_dcp(FrameClass c) noexcept {
  return c == FrameClass::DcpHello || c == FrameClass::DcpGetSet || c == FrameClass::DcpIdentifyRequest ||
         c == FrameClass::DcpIdentifyResponse;
}
constexpr bool is_alarm(FrameClass c) noexcept { return c == FrameClass::AlarmHigh || c == FrameClass::AlarmLow; }

struct EthernetHeader {
  MacAddress dst{};
  MacAddress src{};
  bool vlan = false;          // an 802.1Q tag follows the source address
  std::uint8_t priority = 0;  // PCP, 0..7
  std::uint16_t vlan_id = 0;  // VID, 0..4095 (0 = priority tag only)
  std::uint16_t frame_id = 0;
};

// Writes the header with its FrameID and returns where the PDU starts (16, or 20 with a tag); 0
// when `out` cannot hold it or priority/VID are out of range.
std::size_t encode_ethernet_header(const EthernetHeader& h, std::span<std::uint8_t> out) noexcept;
// Zero-pads a frame of `used` octets to the 60-octet minimum; returns the frame length, 0 when
// `out` is shorter than that length or `used` exceeds `out`.
std::size_t pad_frame(std::span<std::uint8_t> out, std::size_t used) noexcept;

enum class EthernetError : std::uint8_t {
  None,
  TruncatedHeader,   // shorter than the Ethernet header (or its tag)
  WrongEtherType,    // not 8892h (after an optional tag)
  TruncatedFrameId,  // no room for the FrameID
  TooLong,           // more than 1518 octets: not one Ethernet frame
};
std::string_view to_string(EthernetError e) noexcept;

struct EthernetView {
  EthernetError error = EthernetError::None;
  EthernetHeader header{};
  FrameClass frame_class = FrameClass::Other;
  std::size_t pdu_offset = 0;            // offset of the octet after the FrameID
  std::span<const std::uint8_t> pdu{};   // the rest of the frame, Ethernet padding included
  bool ok() const noexcept { return error == EthernetError::None; }
};
EthernetView decode_ethernet(std::span<const std::uint8_t> frame) noexcept;

// "00:1b:1b:12:34:56" (17 characters and a terminating NUL), for reports and log lines.
std::array<char, 18> mac_text(const MacAddress& mac) noexcept;
// The reverse: six octets of two hex digits (either case) separated by ':' or '-' (one of them
// throughout); nullopt for anything else.
std::optional<MacAddress> parse_mac(std::string_view text) noexcept;

}  // namespace drivegate::profinet
