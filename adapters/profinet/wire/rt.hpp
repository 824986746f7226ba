#pragma once
// RT class 1 cyclic frames [IEC 61158-6-10: the C_SDU and APDU_Status of the RT frame, PPM/CPM
// (cyclic provider and consumer) §4.7]. The PDU behind the FrameID (8000h-FBFFh, wire/ethernet.hpp):
//
//   C_SDU (40..1440 octets)   IO data objects in the order of the connect request: per
//                             submodule its data and then its IOPS, plus an IOCS per submodule
//                             whose data travels the other way; zero padding up to the length
//   APDU_Status (4)           CycleCounter u16 | DataStatus u8 | TransferStatus u8
//
// The C_SDU length is part of the IOCR (IOCRBlockReq DataLength), so a receiver passes it in; it
// is at least 40 so that an untagged frame reaches the 60-octet Ethernet minimum without padding
// behind the status. IOPS/IOCS: bit 7 DataState (1 good), bits 5-6 Instance (where the status was
// detected), bit 0 Extension [IEC 61158-6-10, coding of the field IOxS].
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

namespace drivegate::profinet {

inline constexpr std::size_t kApduStatusSize = 4;
inline constexpr std::uint16_t kMinCsduLength = 40;
inline constexpr std::uint16_t kMaxCsduLength = 1440;
// Largest cycle counter step a consumer accepts as new data: (counter - last) mod 2^16 in
// 1..61440 [IEC 61158-6-10 §4.7.2.1.2, CPM]; 0 is a repeated frame, a larger step an old one.
inline constexpr std::uint16_t kMaxCycleCounterStep = 61440;

// DataStatus bits [IEC 61158-6-10, coding of the field DataStatus].
namespace data_status {
inline constexpr std::uint8_t kStatePrimary = 0x01;   // 1 primary, 0 backup (system redundancy)
inline constexpr std::uint8_t kRedundancy = 0x02;     // with State backup: 1 = no primary AR exists
inline constexpr std::uint8_t kDataValid = 0x04;      // 1 valid, 0 invalid (the consumer ignores the data)
inline constexpr std::uint8_t kReserved1 = 0x08;
inline constexpr std::uint8_t kProviderRun = 0x10;    // 1 RUN, 0 STOP
inline constexpr std::uint8_t kStationOk = 0x20;      // StationProblemIndicator: 1 normal, 0 problem detected
inline constexpr std::uint8_t kReserved2 = 0x40;
inline constexpr std::uint8_t kIgnore = 0x80;         // 1 ignore the frame (not used for RT class 1 data)
// Primary, valid, RUN, station normal: what a controller sends in operation.
inline constexpr std::uint8_t kGood = kStatePrimary | kDataValid | kProviderRun | kStationOk;  // 35h
}  // namespace data_status

// IOPS/IOCS [IEC 61158-6-10, IOxS].
namespace iox_status {
inline constexpr std::uint8_t kGood = 0x80;            // DataState good, detected by the subslot
inline constexpr std::uint8_t kBadBySubslot = 0x00;
inline constexpr std::uint8_t kBadBySlot = 0x20;
inline constexpr std::uint8_t kBadByDevice = 0x40;
inline constexpr std::uint8_t kBadByController = 0x60;
constexpr bool is_good(std::uint8_t iox) noexcept { return (iox & 0x80) != 0; }
}  // namespace iox_status

struct ApduStatus {
  std::uint16_t cycle_counter = 0;
  std::uint8_t data_status = data_status::kGood;
  std::uint8_t transfer_status = 0;  // 0 = OK (RT class 1)

  bool primary() const noexcept { return (data_status & data_status::kStatePrimary) != 0; }
  bool data_valid() const noexcept { return (data_status & data_status::kDataValid) != 0; }
  bool provider_run() const noexcept { return (data_status & data_status::kProviderRun) != 0; }
  bool station_problem() const noexcept { return (data_status & data_status::kStationOk) == 0; }
  bool ignore() const noexcept { return (data_status & data_status::kIgnore) != 0; }
  bool operator==(const ApduStatus&) const = default;
};
void encode_apdu_status(const ApduStatus& s, std::span<std::uint8_t, kApduStatusSize> out) noexcept;
ApduStatus decode_apdu_status(std::span<const std::uint8_t, kApduStatusSize> in) noexcept;

// Cycle counter of a frame sent at `time_ns` (any monotonic nanoseconds): the time in 31.25 µs
// units, the unit of SendClockFactor, modulo 2^16 [IEC 61158-6-10, coding of the field CycleCounter].
constexpr std::uint16_t cycle_counter_at(std::uint64_t time_ns) noexcept {
  return static_cast<std::uint16_t>((time_ns / 31250) & 0xFFFF);
}
// True when `counter` is new data after `last` (step 1..61440 modulo 2^16).
constexpr bool cycle_counter_advanced(std::uint16_t last, std::uint16_t counter) noexcept {
  const auto step = static_cast<std::uint16_t>(counter - last);
  return step >= 1 && step <= kMaxCycleCounterStep;
}

// ---- Layout of the C_SDU ------------------------------------------------------------------------

// Which way a submodule's data goes. NoIo submodules (the DAP, interface and port subslots) count
// as input data of length 0: an IOPS in the input CR and an IOCS in the output CR [IEC 61158-6-10,
// IODataObject of a submodule without IO data].
enum class IoKind : std::uint8_t { NoIo, Input, Output, InputOutput };

struct IoSubmodule {
  IoKind kind = IoKind::NoIo;
  std::uint16_t input_length = 0;   // octets device -> controller
  std::uint16_t output_length = 0;  // octets controller -> device
};

// The two directions of a connection: the input CR carries device -> controller frames.
enum class CrDirection : std::uint8_t { Input, Output };

inline constexpr std::uint16_t kNoOffset = 0xFFFF;

// Where one submodule's objects sit in one CR's C_SDU (offsets from the C_SDU start, which is
// what the connect request's FrameOffset fields hold); kNoOffset when absent in this CR.
struct IoPlacement {
  std::uint16_t data_offset = kNoOffset;  // the data this CR provides (then its IOPS)
  std::uint16_t data_length = 0;
  std::uint16_t iops_offset = kNoOffset;
  std::uint16_t iocs_offset = kNoOffset;  // the consumer status for data going the other way
};

enum class LayoutError : std::uint8_t {
  None,
  TooLong,          // the objects need more than 1440 octets
  TooFewPlacements, // the caller's array is shorter than the submodule list
  BadSubmodule,     // a length given for a direction the kind does not have
};
std::string_view to_string(LayoutError e) noexcept;

struct CsduLayout {
  LayoutError error = LayoutError::None;
  std::uint16_t used = 0;    // octets the objects take
  std::uint16_t length = 0;  // the C_SDU length: used, at least 40
  bool ok() const noexcept { return error == LayoutError::None; }
};
// Lays out one CR: first every provided data object followed by its IOPS, in submodule order,
// then the IOCS of every submodule whose data comes the other way, in submodule order.
// `placements[i]` describes `submodules[i]`.
CsduLayout compute_csdu_layout(CrDirection direction, std::span<const IoSubmodule> submodules,
                               std::span<IoPlacement> placements) noexcept;

// ---- Frames ---------------------------------------------------------------------------------------

// Writes C_SDU (`c_sdu`, zero-padded to `c_sdu_length`) and the APDU status into `out` (the PDU
// after the FrameID). Returns c_sdu_length + 4, 0 when the length is outside 40..1440, `c_sdu`
// longer than it, or `out` too small.
std::size_t encode_rt_cyclic(std::span<std::uint8_t> out, std::span<const std::uint8_t> c_sdu,
                             std::uint16_t c_sdu_length, const ApduStatus& status) noexcept;

enum class RtError : std::uint8_t {
  None,
  BadCsduLength,   // the expected length is outside 40..1440
  Truncated,       // fewer octets than C_SDU + APDU status
};
std::string_view to_string(RtError e) noexcept;

struct RtCyclicView {
  RtError error = RtError::None;
  std::span<const std::uint8_t> c_sdu{};
  ApduStatus status{};
  bool ok() const noexcept { return error == RtError::None; }
};
// `pdu`: the octets after the FrameID (Ethernet padding behind the status is ignored).
RtCyclicView decode_rt_cyclic(std::span<const std::uint8_t> pdu, std::uint16_t c_sdu_length) noexcept;

// ---- Input frame check [IEC 61158-6-10 §4.7.2.1.2, CPM receive checks] ---------------------------

enum class RtCheck : std::uint8_t {
  Ok,                // new, valid data from the primary provider in RUN
  WrongFrameId,      // not the FrameID of this input CR
  Truncated,         // shorter than C_SDU + APDU status
  TransferError,     // TransferStatus not 0
  RepeatedCycle,     // cycle counter equal to the last accepted one
  OldCycle,          // cycle counter step beyond 61440: an old frame
  Ignore,            // DataStatus Ignore set
  DataInvalid,       // DataValid clear
  Backup,            // State backup: data of a backup AR
  ProviderStop,      // ProviderState STOP: the data is valid but the device application is stopped
};
std::string_view to_string(RtCheck c) noexcept;
// The frame errors: drop the frame, keep the data hold timer running.
constexpr bool is_frame_error(RtCheck c) noexcept {
  return c == RtCheck::WrongFrameId || c == RtCheck::Truncated || c == RtCheck::TransferError ||
         c == RtCheck::RepeatedCycle || c == RtCheck::OldCycle;
}

struct RtInputCheck {
  RtCheck result = RtCheck::Ok;
  RtCyclicView frame{};         // set once the FrameID and the length passed (every later result)
  bool station_problem = false; // StationProblemIndicator: the device has diagnosis to read
};
// Checks one received PDU of an input CR in the order frame ID, length, transfer status, cycle
// counter (skipped when `has_last` is false: the first frame), Ignore, DataValid, State, Provider.
RtInputCheck check_input_frame(std::uint16_t frame_id, std::span<const std::uint8_t> pdu, std::uint16_t expected_frame_id,
                               std::uint16_t c_sdu_length, bool has_last, std::uint16_t last_cycle_counter) noexcept;

}  // namespace drivegate::profinet
