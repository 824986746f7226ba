#pragma once
// SDO frame layouts [CiA 301 §7.2.4.3; AKD part 1 §10.3; SD6 digest §6.4]. Every SDO frame has
// DLC 8; byte 0 is the command specifier, bytes 1-2 the index (LSB first) and byte 3 the sub-index
// for initiate and abort frames. Decoding is split by direction because client (ccs) and server
// (scs) specifiers reuse the same numbers. Block transfer is recognised but not implemented (none
// of the reference drives offers it: AKD part 1 §17 item 7, SD6 quirk 19).
#include <array>
#include <cstdint>
#include <span>

#include "profiles/cia402/objects.hpp"
#include "profiles/cia402/sdo_abort.hpp"

namespace drivegate::canopen {

using cia402::ObjectId;
using SdoBytes = std::array<std::uint8_t, 8>;

enum class SdoCommand : std::uint8_t {
  // client -> server (ccs)
  DownloadSegmentRequest,   // ccs 0
  InitiateDownloadRequest,  // ccs 1
  InitiateUploadRequest,    // ccs 2
  UploadSegmentRequest,     // ccs 3
  // server -> client (scs)
  UploadSegmentResponse,     // scs 0
  DownloadSegmentResponse,   // scs 1
  InitiateUploadResponse,    // scs 2
  InitiateDownloadResponse,  // scs 3
  // both directions (cs 4)
  Abort,
  // cs 5/6: block transfer, not supported
  Block,
};

struct SdoMessage {
  SdoCommand command = SdoCommand::Abort;
  ObjectId object{};           // initiate and abort frames
  bool expedited = false;      // initiate: e bit
  bool size_indicated = false; // initiate: s bit
  std::uint32_t size = 0;      // initiate, not expedited, size indicated: total byte count
  bool toggle = false;         // segments
  bool last = false;           // segments: c bit (no more segments)
  std::uint8_t length = 0;     // expedited or segment: number of valid bytes in `data`
                               // (expedited without size indication: 4)
  std::array<std::uint8_t, 7> data{};  // expedited: bytes 4..7; segment: bytes 1..7
  std::uint32_t abort_code = 0;
};

enum class SdoDecodeError : std::uint8_t {
  None,
  WrongLength,      // DLC != 8
  UnknownCommand,   // specifier 7, or a specifier the direction does not use
};
const char* to_string(SdoDecodeError e) noexcept;

struct SdoDecoded {
  SdoDecodeError error = SdoDecodeError::None;
  SdoMessage message{};
};

// Decode a frame a client sent (for the server) / a server sent (for the client).
SdoDecoded decode_sdo_request(std::span<const std::uint8_t> payload) noexcept;
SdoDecoded decode_sdo_response(std::span<const std::uint8_t> payload) noexcept;

// Encoders: each returns the 8 payload bytes.
SdoBytes sdo_upload_request(ObjectId o) noexcept;                                     // 40h
SdoBytes sdo_download_expedited(ObjectId o, std::uint32_t value, std::uint8_t size) noexcept;  // 2Fh/2Bh/27h/23h
SdoBytes sdo_download_initiate(ObjectId o, std::uint32_t total_size) noexcept;       // 21h
SdoBytes sdo_download_segment(bool toggle, std::span<const std::uint8_t> bytes, bool last) noexcept;
SdoBytes sdo_upload_segment_request(bool toggle) noexcept;                            // 60h/70h
SdoBytes sdo_download_response(ObjectId o) noexcept;                                  // 60h
SdoBytes sdo_download_segment_response(bool toggle) noexcept;                         // 20h/30h
SdoBytes sdo_upload_expedited_response(ObjectId o, std::uint32_t value, std::uint8_t size) noexcept;  // 4Fh..43h
SdoBytes sdo_upload_initiate_response(ObjectId o, std::uint32_t total_size) noexcept;  // 41h
SdoBytes sdo_upload_segment(bool toggle, std::span<const std::uint8_t> bytes, bool last) noexcept;
SdoBytes sdo_abort(ObjectId o, std::uint32_t code) noexcept;                          // 80h

}  // namespace drivegate::canopen
