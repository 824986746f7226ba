#pragma once
// One CAN frame as python-can's udp_multicast interface puts it in a UDP datagram: a msgpack map
// with the keys timestamp, arbitration_id, is_extended_id, is_remote_frame, is_error_frame,
// channel, dlc, data, is_fd, bitrate_switch, error_state_indicator
// [python-can can/interfaces/udp_multicast/utils.py: pack_message / unpack_message].
//
// Hand-written rather than msgpack-c: msgpack-c allocates a zone per unpacked message and the
// receive path runs every cycle, where nothing may allocate. Only this one map is understood.
//
// The encoder writes the map exactly as python-can does (same key order, smallest int encodings,
// float64 timestamp, data as bin), so its bytes equal pack_message()'s for the same frame.
// The decoder accepts keys in any order, any msgpack int or float width, a nil/str/int channel,
// data as bin or str, and skips keys it does not know (whatever their value). It rejects what
// python-can's Message(check=True) would reject and everything that is not a classic CAN frame.
// Both run on caller-provided buffers and never read or write past them.
#include <cstddef>
#include <cstdint>
#include <span>

#include "adapters/canopen/wire/can_frame.hpp"

namespace drivegate::canopen {

// The largest encoded frame: 8 data bytes and a 29-bit id (uint32 encoding).
inline constexpr std::size_t kMsgpackFrameMaxSize = 164;

// Encodes `frame` (a data or remote frame; the timestamp field is `timestamp_s`, seconds) into
// `out`. Returns the number of bytes written, or 0 when the frame is not valid() or `out` is too
// small.
std::size_t encode_msgpack_frame(const CanFrame& frame, double timestamp_s, std::span<std::uint8_t> out) noexcept;

enum class MsgpackFrameError : std::uint8_t {
  None,
  Malformed,      // not msgpack (the reserved type byte C1h)
  Truncated,      // the datagram ends inside a value
  NotAMap,        // the top-level object is not a map
  BadKey,         // a key that is not a string
  DuplicateKey,   // a known key given twice
  WrongType,      // a known key with a value of the wrong msgpack type
  MissingField,   // arbitration_id or is_extended_id absent
  IdOutOfRange,   // negative, or beyond 11/29 bits
  DlcOutOfRange,  // negative or > 8
  DataTooLong,    // more than 8 data bytes
  Inconsistent,   // dlc != data length, remote frame with data, remote error frame
  CanFd,          // is_fd, bitrate_switch or error_state_indicator set
  TrailingBytes,  // bytes after the map
};

const char* to_string(MsgpackFrameError e) noexcept;

struct MsgpackFrameDecoded {
  MsgpackFrameError error = MsgpackFrameError::None;
  CanFrame frame;            // valid() when error == None; timestamp left at its default
  bool error_frame = false;  // is_error_frame: a controller error report, not a bus frame
  double timestamp_s = 0.0;  // the sender's timestamp field (0 when absent)
};

MsgpackFrameDecoded decode_msgpack_frame(std::span<const std::uint8_t> bytes) noexcept;

}  // namespace drivegate::canopen
