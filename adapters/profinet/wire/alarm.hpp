#pragma once
// Alarms over RTA, the acyclic real-time transport [IEC 61158-6-10: the RTA-PDU and its protocol
// machines APMS/APMR, the AlarmNotification-PDU and AlarmAck-PDU with their BlockHeader; field
// order and masks cross-checked with Wireshark's PNIO alarm dissector]. The RTA-PDU follows FrameID FC01h (alarm high) or FE01h (alarm low):
//
//   RTA header (12)   AlarmDstEndpoint u16 | AlarmSrcEndpoint u16 (the alarm references of the
//                     AlarmCR blocks) | PDUType u8: bits 0-3 type (1 DATA, 2 NACK, 3 ACK, 4 ERR),
//                     bits 4-7 version (1) | AddFlags u8: bits 0-3 WindowSize (1), bit 4 TACK
//                     (the receiver shall acknowledge at once) | SendSeqNum u16 | AckSeqNum u16 |
//                     VarPartLen u16
//   RTA-SDU           VarPartLen octets: DATA carries one AlarmNotification or AlarmAck block,
//                     ERR a PNIOStatus, NACK and ACK nothing
//
//   AlarmNotification BlockHeader (type 0001h high / 0002h low, BlockLength = octets after the
//                     length field, version 1.0) | AlarmType u16 | API u32 | SlotNumber u16 |
//                     SubslotNumber u16 | ModuleIdentNumber u32 | SubmoduleIdentNumber u32 |
//                     AlarmSpecifier u16 | [UserStructureIdentifier u16 | data]
//   AlarmAck          BlockHeader (8001h high / 8002h low, version 1.0) | AlarmType u16 | API u32 |
//                     SlotNumber u16 | SubslotNumber u16 | AlarmSpecifier u16 | PNIOStatus (4)
//
// Numbers are big-endian. Encoders return the octet count (0 when the span is too small or an
// argument invalid); decoders return views into the input and an AlarmError with a text.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

namespace drivegate::profinet {

inline constexpr std::size_t kRtaHeaderSize = 12;
inline constexpr std::uint8_t kRtaVersion = 1;
inline constexpr std::uint8_t kRtaWindowSize = 1;  // the only window size RTA uses
// Sequence numbers count 0..7FFFh and wrap; a sender starts with SendSeqNum FFFFh and AckSeqNum
// FFFEh, so its first DATA goes out numbered FFFFh, the next 0 [IEC 61158-6-10, APMS/APMR initial
// values; the numbering of the first DATA as p-net's pf_alarm.c does it, controller/rta_endpoint.hpp].
inline constexpr std::uint16_t kRtaSeqMax = 0x7FFF;
inline constexpr std::uint16_t kRtaInitialSendSeq = 0xFFFF;
inline constexpr std::uint16_t kRtaInitialAckSeq = 0xFFFE;
constexpr std::uint16_t next_rta_seq(std::uint16_t seq) noexcept {
  if (seq == 0xFFFE) return 0xFFFF;
  if (seq == 0xFFFF) return 0;
  return static_cast<std::uint16_t>((seq + 1) & kRtaSeqMax);
}

enum class RtaPduType : std::uint8_t { Data = 1, Nack = 2, Ack = 3, Err = 4 };
std::string_view to_string(RtaPduType t) noexcept;  // "DATA-RTA-PDU", ...

struct RtaHeader {
  std::uint16_t dst_endpoint = 0;
  std::uint16_t src_endpoint = 0;
  RtaPduType type = RtaPduType::Data;
  std::uint8_t version = kRtaVersion;
  std::uint8_t window_size = kRtaWindowSize;
  bool tack = false;
  std::uint16_t send_seq = 0;
  std::uint16_t ack_seq = 0;
  std::uint16_t var_part_len = 0;  // set by encode_rta
  bool operator==(const RtaHeader&) const = default;
};

// The four octets of a PNIOStatus (ErrorCode, ErrorDecode, ErrorCode1, ErrorCode2) as AlarmAck
// and ERR-RTA-PDU carry them [IEC 61158-6-10, coding of the field PNIOStatus]; the texts live with
// the RPC codecs.
struct RtaPnioStatus {
  std::uint8_t code = 0;
  std::uint8_t decode = 0;
  std::uint8_t code1 = 0;
  std::uint8_t code2 = 0;
  bool ok() const noexcept { return code == 0 && decode == 0 && code1 == 0 && code2 == 0; }
  bool operator==(const RtaPnioStatus&) const = default;
};

enum class AlarmError : std::uint8_t {
  None,
  TruncatedRtaHeader,     // fewer than 12 octets
  VarPartBeyondPdu,       // VarPartLen larger than the octets after the header
  UnknownPduType,         // PDUType type other than 1..4
  UnsupportedVersion,     // PDUType version other than 1
  UnexpectedVarPart,      // NACK or ACK with VarPartLen > 0, ERR with less than a PNIOStatus, DATA with none
  TruncatedBlockHeader,   // fewer than 6 octets for the BlockHeader
  WrongBlockType,         // not the block the decoder reads (0001h/0002h or 8001h/8002h)
  UnsupportedBlockVersion,  // BlockVersion other than 1.0
  BlockLengthMismatch,    // BlockLength not the octets that follow (too short for the fixed fields,
                          // running past VarPartLen, or octets left after the block)
  BufferTooSmall,         // encoder: the caller's span is too small
  DataTooLong,            // encoder: alarm data beyond one frame
  NotChannelDiagnosis,    // a UserStructureIdentifier other than 8000h, 8002h, 8003h
  ChannelDiagnosisLength, // channel diagnosis data not a whole number of entries
};
std::string_view to_string(AlarmError e) noexcept;

// Writes the 12-octet header with h.var_part_len as given; false when `out` is too small.
bool encode_rta_header(const RtaHeader& h, std::span<std::uint8_t> out) noexcept;
// The header with VarPartLen = var_part.size(), then var_part (which may already sit at out[12]).
// Returns 12 + var_part.size(), 0 when it does not fit or the var part is longer than 1486 octets.
std::size_t encode_rta(std::span<std::uint8_t> out, RtaHeader h, std::span<const std::uint8_t> var_part) noexcept;

struct RtaView {
  AlarmError error = AlarmError::None;
  RtaHeader header{};
  std::span<const std::uint8_t> var_part{};  // VarPartLen octets, Ethernet padding excluded
  bool ok() const noexcept { return error == AlarmError::None; }
};
// `pdu`: the octets after FrameID FC01h/FE01h.
RtaView decode_rta(std::span<const std::uint8_t> pdu) noexcept;
// The PNIOStatus of an ERR-RTA-PDU.
RtaPnioStatus rta_error_status(const RtaView& v) noexcept;
std::size_t encode_rta_error(std::span<std::uint8_t> out, RtaHeader h, const RtaPnioStatus& status) noexcept;

// ---- AlarmNotification / AlarmAck ---------------------------------------------------------------

namespace alarm_block {
inline constexpr std::uint16_t kNotificationHigh = 0x0001;
inline constexpr std::uint16_t kNotificationLow = 0x0002;
inline constexpr std::uint16_t kAckHigh = 0x8001;
inline constexpr std::uint16_t kAckLow = 0x8002;
}  // namespace alarm_block

enum class AlarmPriority : std::uint8_t { High, Low };
const char* to_string(AlarmPriority p) noexcept;  // "high", "low"

// AlarmType [IEC 61158-6-10, coding of the field AlarmType].
namespace alarm_type {
inline constexpr std::uint16_t kDiagnosis = 0x0001;
inline constexpr std::uint16_t kProcess = 0x0002;
inline constexpr std::uint16_t kPull = 0x0003;
inline constexpr std::uint16_t kPlug = 0x0004;
inline constexpr std::uint16_t kStatus = 0x0005;
inline constexpr std::uint16_t kUpdate = 0x0006;
inline constexpr std::uint16_t kRedundancy = 0x0007;
inline constexpr std::uint16_t kControlledBySupervisor = 0x0008;
inline constexpr std::uint16_t kReleasedBySupervisor = 0x0009;
inline constexpr std::uint16_t kPlugWrongSubmodule = 0x000A;
inline constexpr std::uint16_t kReturnOfSubmodule = 0x000B;
inline constexpr std::uint16_t kDiagnosisDisappears = 0x000C;
inline constexpr std::uint16_t kMulticastMismatch = 0x000D;
inline constexpr std::uint16_t kPortDataChange = 0x000E;
inline constexpr std::uint16_t kSyncDataChanged = 0x000F;
inline constexpr std::uint16_t kIsochronousModeProblem = 0x0010;
inline constexpr std::uint16_t kNetworkComponentProblem = 0x0011;
inline constexpr std::uint16_t kTimeDataChanged = 0x0012;
inline constexpr std::uint16_t kDynamicFramePackingProblem = 0x0013;
inline constexpr std::uint16_t kUploadAndRetrieval = 0x001E;
inline constexpr std::uint16_t kPullModule = 0x001F;
}  // namespace alarm_type
// "Diagnosis", "Pull", "Return of submodule", ..., "manufacturer specific" (0020h-007Fh),
// "reserved for profiles" (0080h-00FFh), "reserved".
std::string_view alarm_type_name(std::uint16_t type) noexcept;

// UserStructureIdentifier [IEC 61158-6-10, coding of the field UserStructureIdentifier].
namespace user_structure {
inline constexpr std::uint16_t kChannelDiagnosis = 0x8000;
inline constexpr std::uint16_t kMultiple = 0x8001;
inline constexpr std::uint16_t kExtChannelDiagnosis = 0x8002;
inline constexpr std::uint16_t kQualifiedChannelDiagnosis = 0x8003;
inline constexpr std::uint16_t kMaintenance = 0x8100;
}  // namespace user_structure
// "ChannelDiagnosis", ..., "manufacturer specific" (0000h-7FFFh), "reserved".
std::string_view user_structure_name(std::uint16_t usi) noexcept;

// AlarmSpecifier: bits 0-10 SequenceNumber, 11 ChannelDiagnosis, 12 ManufacturerSpecificDiagnosis,
// 13 SubmoduleDiagnosisState, 15 ARDiagnosisState (14 reserved).
struct AlarmSpecifier {
  std::uint16_t sequence = 0;  // 0..7FFh, counted per alarm by the device
  bool channel_diagnosis = false;
  bool manufacturer_diagnosis = false;
  bool submodule_diagnosis = false;  // the submodule has diagnosis after this alarm
  bool ar_diagnosis = false;         // some submodule of the AR has diagnosis
  bool operator==(const AlarmSpecifier&) const = default;
};
std::uint16_t encode_alarm_specifier(const AlarmSpecifier& s) noexcept;  // the sequence masked to 11 bits
AlarmSpecifier decode_alarm_specifier(std::uint16_t raw) noexcept;
constexpr std::uint16_t next_alarm_sequence(std::uint16_t seq) noexcept {
  return static_cast<std::uint16_t>((seq + 1) & 0x07FF);
}

struct AlarmNotification {
  AlarmPriority priority = AlarmPriority::High;
  std::uint16_t alarm_type = alarm_type::kDiagnosis;
  std::uint32_t api = 0;
  std::uint16_t slot = 0;
  std::uint16_t subslot = 0;
  std::uint32_t module_ident = 0;
  std::uint32_t submodule_ident = 0;
  AlarmSpecifier specifier{};
  bool has_user_structure = false;  // an AlarmItem follows: UserStructureIdentifier + data
  std::uint16_t user_structure_id = 0;
  std::span<const std::uint8_t> user_data{};
};
inline constexpr std::size_t kAlarmNotificationFixedSize = 6 + 20;  // BlockHeader + fixed fields
inline constexpr std::size_t kAlarmAckSize = 6 + 16;
// The AlarmNotification block (the RTA-SDU of a DATA-RTA-PDU).
std::size_t encode_alarm_notification(std::span<std::uint8_t> out, const AlarmNotification& n) noexcept;

struct AlarmNotificationView {
  AlarmError error = AlarmError::None;
  AlarmNotification notification{};
  bool ok() const noexcept { return error == AlarmError::None; }
};
AlarmNotificationView decode_alarm_notification(std::span<const std::uint8_t> var_part) noexcept;

struct AlarmAck {
  AlarmPriority priority = AlarmPriority::High;
  std::uint16_t alarm_type = 0;
  std::uint32_t api = 0;
  std::uint16_t slot = 0;
  std::uint16_t subslot = 0;
  AlarmSpecifier specifier{};  // echoed from the notification
  RtaPnioStatus status{};      // all zero: acknowledged
  bool operator==(const AlarmAck&) const = default;
};
// The acknowledgement of `n` with `status`: the fields the controller echoes.
AlarmAck ack_for(const AlarmNotification& n, const RtaPnioStatus& status = {}) noexcept;
std::size_t encode_alarm_ack(std::span<std::uint8_t> out, const AlarmAck& a) noexcept;

struct AlarmAckView {
  AlarmError error = AlarmError::None;
  AlarmAck ack{};
  bool ok() const noexcept { return error == AlarmError::None; }
};
AlarmAckView decode_alarm_ack(std::span<const std::uint8_t> var_part) noexcept;

// ---- Channel diagnosis in an AlarmItem [IEC 61158-6-10, ChannelDiagnosisData,
// ExtChannelDiagnosisData, QualifiedChannelDiagnosisData] ------------------------------------------
//
//   ChannelDiagnosis (USI 8000h)           ChannelNumber u16 | ChannelProperties u16 | ChannelErrorType u16
//   ExtChannelDiagnosis (8002h)            + ExtChannelErrorType u16 | ExtChannelAddValue u32
//   QualifiedChannelDiagnosis (8003h)      + QualifiedChannelQualifier u32
//
// ChannelProperties: bits 0-7 Type (data width), 8 Accumulative, 9-10 Maintenance (0 fault,
// 1 maintenance required, 2 maintenance demanded, 3 qualified), 11-12 Specifier (1 appears,
// 2 disappears, 3 disappears but others remain, 0 all disappear), 13-15 Direction.

inline constexpr std::uint16_t kChannelWholeSubmodule = 0x8000;  // ChannelNumber for the submodule as a whole

struct ChannelDiagnosis {
  std::uint16_t channel = 0;
  std::uint16_t properties = 0;
  std::uint16_t error_type = 0;
  std::uint16_t ext_error_type = 0;  // 8002h/8003h only
  std::uint32_t ext_add_value = 0;   // 8002h/8003h only
  std::uint32_t qualifier = 0;       // 8003h only
  std::uint8_t maintenance() const noexcept { return static_cast<std::uint8_t>((properties >> 9) & 3); }
  std::uint8_t specifier() const noexcept { return static_cast<std::uint8_t>((properties >> 11) & 3); }
  std::uint8_t direction() const noexcept { return static_cast<std::uint8_t>(properties >> 13); }
  bool accumulative() const noexcept { return (properties & 0x0100) != 0; }
  bool appears() const noexcept { return specifier() == 1; }
  bool operator==(const ChannelDiagnosis&) const = default;
};

// The entries of an AlarmItem's data (a view; get() decodes one).
struct ChannelDiagnosisList {
  AlarmError error = AlarmError::None;
  std::uint16_t user_structure_id = 0;
  std::span<const std::uint8_t> data{};
  std::size_t entry_size = 0;
  std::size_t count() const noexcept { return entry_size == 0 ? 0 : data.size() / entry_size; }
  bool get(std::size_t i, ChannelDiagnosis& out) const noexcept;  // false past the end
};
ChannelDiagnosisList decode_channel_diagnosis(std::uint16_t user_structure_id, std::span<const std::uint8_t> data) noexcept;
// "short circuit", "undervoltage", ..., "manufacturer specific" (0100h-7FFFh), "reserved".
std::string_view channel_error_type_name(std::uint16_t type) noexcept;

// The BlockType of the block in a DATA var part (0 when shorter than 2 octets), to pick a decoder.
std::uint16_t alarm_block_type(std::span<const std::uint8_t> var_part) noexcept;

}  // namespace drivegate::profinet
