#pragma once
// The Ethernet II header an EtherCAT frame travels in and the EtherCAT header behind it
// [ETG.1000.4 §5.3; IEEE 802.3 §3.1.1, §3.2.6; IEEE 802.1Q]: one home for the sizes and the
// EtherType, shared by the codecs (wire/frame.hpp) and the link (link/ethercat_link.hpp), which
// moves frames as bytes and looks no further than these headers. Header-only: the link does not
// link the codecs.
//
//   destination(6) source(6) [TPID 8100h + TCI] EtherType 88A4h (big-endian) | EtherCAT header u16 LE
#include <cstddef>
#include <cstdint>

namespace drivegate::ethercat {

inline constexpr std::uint16_t kEtherType = 0x88A4;  // ETG.1000.4 §5.3
inline constexpr std::uint16_t kVlanTpid = 0x8100;   // IEEE 802.1Q
inline constexpr std::size_t kEthernetHeaderSize = 14;  // destination 6, source 6, EtherType 2
inline constexpr std::size_t kEtherTypeOffset = 12;     // big-endian [IEEE 802.3 §3.2.6]
inline constexpr std::size_t kVlanTagSize = 4;
inline constexpr std::size_t kEcatHeaderSize = 2;  // length 11 bits, reserved 1, type 4 (ETG.1000.4 §5.3)
inline constexpr std::size_t kMinFrameSize = 60;    // Ethernet minimum without FCS
inline constexpr std::size_t kMaxFrameSize = 1514;  // Ethernet maximum without FCS: 1500 bytes of payload [IEEE 802.3 §3.2.7]

}  // namespace drivegate::ethercat
