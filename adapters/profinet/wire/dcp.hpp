#pragma once
// PN-DCP, the Discovery and basic Configuration Protocol [IEC 61158-6-10 §4.3: the DCP-PDU
// header and the DCP blocks]. The PDU follows the FrameID (FEFCh hello, FEFDh get/set, FEFEh
// identify request, FEFFh identify response; wire/ethernet.hpp):
//
//   header (10)   ServiceID u8 (3 Get, 4 Set, 5 Identify, 6 Hello) | ServiceType u8 (0 request,
//                 1 response success, 5 response "request not supported") | Xid u32 |
//                 ResponseDelay u16 (Identify request: ResponseDelayFactor, else reserved 0) |
//                 DCPDataLength u16 (octets of blocks that follow, their padding included)
//   block         Option u8 | Suboption u8 | DCPBlockLength u16 | value (DCPBlockLength octets) |
//                 one pad octet 00h when DCPBlockLength is odd (not counted in the block length)
//
// The value starts with a u16 BlockQualifier in Set requests and a u16 BlockInfo in Identify and
// Get responses; Identify request filter blocks and Get requests (a list of Option/Suboption
// pairs) carry none. Numbers are big-endian. Encoders write into a caller's span and return the
// octet count (0 when it does not fit or an argument is invalid); decoders return views into
// their input and an error value with a text. Nothing allocates.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "adapters/profinet/wire/ethernet.hpp"

namespace drivegate::profinet {

inline constexpr std::size_t kDcpHeaderSize = 10;
inline constexpr std::size_t kDcpBlockHeaderSize = 4;
// Largest DCPDataLength: 1500 payload octets - FrameID - header.
inline constexpr std::size_t kDcpMaxDataLength = kMaxPayloadSize - kFrameIdSize - kDcpHeaderSize;
// ResponseDelayFactor of an Identify request: a device answers after a random 0..factor × 10 ms;
// 1 is "no spread", the largest allowed value is 1900h [IEC 61158-6-10 §4.3, coding of the field
// ResponseDelayFactor].
inline constexpr std::uint16_t kDcpMaxResponseDelayFactor = 0x1900;

enum class DcpService : std::uint8_t { Get = 3, Set = 4, Identify = 5, Hello = 6 };
enum class DcpServiceType : std::uint8_t { Request = 0, ResponseSuccess = 1, ResponseNotSupported = 5 };
std::string_view to_string(DcpService s) noexcept;      // "Get", "Set", "Identify", "Hello", "?"
std::string_view to_string(DcpServiceType t) noexcept;  // "request", "response success", ...

// Option << 8 | Suboption [IEC 61158-6-10 §4.3, coding of the fields Option and Suboption].
namespace dcp_option {
inline constexpr std::uint16_t kMacAddress = 0x0101;
inline constexpr std::uint16_t kIpParameter = 0x0102;  // IP address, netmask, gateway
inline constexpr std::uint16_t kFullIpSuite = 0x0103;  // + 4 DNS servers
inline constexpr std::uint16_t kTypeOfStation = 0x0201;  // "DeviceVendorValue", the device's type name
inline constexpr std::uint16_t kNameOfStation = 0x0202;
inline constexpr std::uint16_t kDeviceId = 0x0203;       // VendorID u16, DeviceID u16
inline constexpr std::uint16_t kDeviceRole = 0x0204;     // role bits u8, reserved u8
inline constexpr std::uint16_t kDeviceOptions = 0x0205;  // the options the device supports, as pairs
inline constexpr std::uint16_t kAliasName = 0x0206;
inline constexpr std::uint16_t kDeviceInstance = 0x0207;  // high u8, low u8
inline constexpr std::uint16_t kOemDeviceId = 0x0208;
inline constexpr std::uint16_t kStandardGateway = 0x0209;
inline constexpr std::uint16_t kDhcpHostName = 0x030C;   // DHCP option 12
inline constexpr std::uint16_t kDhcpVendorSpecific = 0x032B;  // DHCP option 43
inline constexpr std::uint16_t kDhcpServerId = 0x0336;   // DHCP option 54
inline constexpr std::uint16_t kDhcpParameterRequestList = 0x0337;  // DHCP option 55
inline constexpr std::uint16_t kDhcpClassId = 0x033C;    // DHCP option 60
inline constexpr std::uint16_t kDhcpClientId = 0x033D;   // DHCP option 61
inline constexpr std::uint16_t kDhcpFqdn = 0x0351;       // DHCP option 81
inline constexpr std::uint16_t kDhcpUuid = 0x0361;       // DHCP option 97
inline constexpr std::uint16_t kDhcpControl = 0x03FF;    // control DHCP for address resolution
inline constexpr std::uint16_t kStartTransaction = 0x0501;
inline constexpr std::uint16_t kEndTransaction = 0x0502;
inline constexpr std::uint16_t kSignal = 0x0503;
inline constexpr std::uint16_t kResponse = 0x0504;
inline constexpr std::uint16_t kFactoryReset = 0x0505;
inline constexpr std::uint16_t kResetToFactory = 0x0506;
inline constexpr std::uint16_t kDeviceInitiative = 0x0601;
inline constexpr std::uint16_t kAllSelector = 0xFFFF;
constexpr std::uint8_t option_of(std::uint16_t id) noexcept { return static_cast<std::uint8_t>(id >> 8); }
constexpr std::uint8_t suboption_of(std::uint16_t id) noexcept { return static_cast<std::uint8_t>(id & 0xFF); }
}  // namespace dcp_option
// "NameOfStation", "IP parameter", "DHCP client identifier", "Signal", ..., "unknown".
std::string_view dcp_option_name(std::uint16_t id) noexcept;

// BlockQualifier of a Set request [IEC 61158-6-10 §4.3, BlockQualifier]: bit 0 = save the value permanently.
enum class DcpQualifier : std::uint16_t { Temporary = 0x0000, Permanent = 0x0001 };
// SignalValue of Control/Signal: flash once (the device's LED or display blinks) [§4.3, SignalValue].
inline constexpr std::uint16_t kDcpSignalFlashOnce = 0x0100;

// BlockInfo of the IP parameter in a response [IEC 61158-6-10 §4.3, BlockInfo of IP]: bits
// 0-6 how the address was set, bit 7 an address conflict was detected.
namespace ip_block_info {
inline constexpr std::uint16_t kNotSet = 0x0000;
inline constexpr std::uint16_t kSet = 0x0001;
inline constexpr std::uint16_t kSetByDhcp = 0x0002;
inline constexpr std::uint16_t kConflict = 0x0080;
}  // namespace ip_block_info

// DeviceRoleDetails bits [IEC 61158-6-10 §4.3, DeviceRoleDetails].
namespace device_role {
inline constexpr std::uint8_t kIoDevice = 0x01;
inline constexpr std::uint8_t kIoController = 0x02;
inline constexpr std::uint8_t kIoMultidevice = 0x04;
inline constexpr std::uint8_t kSupervisor = 0x08;
}  // namespace device_role

// BlockError of a Control/Response block [IEC 61158-6-10 §4.3, BlockError].
enum class DcpBlockError : std::uint8_t {
  NoError = 0,
  OptionNotSupported = 1,
  SuboptionNotSupported = 2,  // or no data set available
  SuboptionNotSet = 3,
  ResourceError = 4,
  SetNotPossible = 5,         // local reasons
  InOperation = 6,            // the device is in operation (an AR is established), SET not possible
};
std::string_view to_string(DcpBlockError e) noexcept;

struct IpSuite {
  std::array<std::uint8_t, 4> address{};
  std::array<std::uint8_t, 4> netmask{};
  std::array<std::uint8_t, 4> gateway{};
  bool operator==(const IpSuite&) const = default;
};
// What makes an IP suite unusable for a device, or "" when it is usable: a netmask whose ones are
// not contiguous, an address in 0/8 (but 0.0.0.0), 127/8, 224/3 or the subnet's network or
// broadcast address, a gateway outside the subnet. 0.0.0.0/0.0.0.0/0.0.0.0 is "no address" (a
// Set with it takes the address away) and passes; a gateway of 0.0.0.0 or equal to the address
// means "no gateway" [IEC 61158-6-10 §4.3, coding of the IP parameter: StandardGateway].
std::string_view ip_suite_problem(const IpSuite& ip) noexcept;

struct DcpHeader {
  DcpService service = DcpService::Identify;
  DcpServiceType type = DcpServiceType::Request;
  std::uint32_t xid = 0;
  std::uint16_t response_delay = 0;
  std::uint16_t data_length = 0;  // written by the encoders
};

enum class DcpError : std::uint8_t {
  None,
  TruncatedHeader,          // fewer than 10 octets
  DataLengthBeyondPdu,      // DCPDataLength larger than the octets after the header
  UnknownService,           // ServiceID other than 3..6
  UnknownServiceType,       // ServiceType other than 0, 1, 5
  UnexpectedService,        // a decoder for another service or type (e.g. a Set given to the Identify decoder)
  TruncatedBlockHeader,     // fewer than 4 octets left for a block header
  BlockBeyondData,          // DCPBlockLength runs past DCPDataLength
  BlockTooShort,            // shorter than its BlockQualifier/BlockInfo or fixed fields
  BadBlockLength,           // a fixed-size block (IP parameter, DeviceID, ...) with another length
  OddGetRequest,            // a Get request whose option list has an odd length
  NoBlocks,                 // a request or response without the block it needs
  WrongResponseBlock,       // a Set response block other than Control/Response
  TooManyBlocks,            // more response blocks than the caller's array holds
};
std::string_view to_string(DcpError e) noexcept;

struct DcpBlock {
  std::uint8_t option = 0;
  std::uint8_t suboption = 0;
  std::span<const std::uint8_t> value{};  // DCPBlockLength octets
  std::uint16_t id() const noexcept { return static_cast<std::uint16_t>((option << 8) | suboption); }
};

struct DcpPdu {
  DcpError error = DcpError::None;
  DcpHeader header{};
  std::span<const std::uint8_t> blocks{};  // DCPDataLength octets (Ethernet padding excluded)
  bool ok() const noexcept { return error == DcpError::None; }
};
// Decodes the header of the PDU after the FrameID (the whole rest of the frame may be passed).
DcpPdu decode_dcp(std::span<const std::uint8_t> pdu) noexcept;

// Walks the blocks of a PDU; next() stops at the end or at the first malformed block (error()).
// A block with an odd length may omit its pad octet when it is the last one.
class DcpBlockReader {
 public:
  explicit DcpBlockReader(std::span<const std::uint8_t> blocks) noexcept : data_(blocks) {}
  bool next(DcpBlock& out) noexcept;
  DcpError error() const noexcept { return error_; }

 private:
  std::span<const std::uint8_t> data_;
  std::size_t pos_ = 0;
  DcpError error_ = DcpError::None;
};

// ---- Writing ----------------------------------------------------------------------------------

// Writes a DCP PDU block by block into a caller's buffer (the PDU after the FrameID). Each add_*
// returns false and sticks at the first failure; finish() writes DCPDataLength and returns the
// PDU length (0 after a failure).
class DcpWriter {
 public:
  DcpWriter(std::span<std::uint8_t> out, DcpService service, DcpServiceType type, std::uint32_t xid,
            std::uint16_t response_delay = 0) noexcept;
  // A block with the value as given (filters of an Identify request; the Control/Response block).
  bool add_raw(std::uint16_t id, std::span<const std::uint8_t> value) noexcept;
  // A block whose value is a u16 (BlockQualifier or BlockInfo) and then `data`.
  bool add(std::uint16_t id, std::uint16_t qualifier_or_info, std::span<const std::uint8_t> data) noexcept;
  bool add(std::uint16_t id, std::uint16_t qualifier_or_info, std::string_view text) noexcept;
  // One Option/Suboption pair of a Get request.
  bool add_option(std::uint16_t id) noexcept;
  std::size_t finish() noexcept;
  bool failed() const noexcept { return failed_; }

 private:
  bool begin_block(std::uint16_t id, std::size_t length) noexcept;
  void end_block(std::size_t length) noexcept;

  std::span<std::uint8_t> out_;
  std::size_t pos_ = 0;
  bool failed_ = false;
};

// ---- Identify ----------------------------------------------------------------------------------

// Identify request to kDcpIdentifyMulticast with the AllSelector (FFh/FFh, length 0).
std::size_t encode_identify_all_request(std::span<std::uint8_t> out, std::uint32_t xid,
                                        std::uint16_t response_delay_factor) noexcept;
// Identify request with a NameOfStation filter; `name` must be a valid NameOfStation.
std::size_t encode_identify_name_request(std::span<std::uint8_t> out, std::uint32_t xid,
                                         std::uint16_t response_delay_factor, std::string_view name) noexcept;

struct DcpIdentifyFilter {
  DcpError error = DcpError::None;
  bool all = false;                    // AllSelector present
  bool has_name = false;
  std::string_view name_of_station{};  // NameOfStation filter (a view into the frame)
  std::size_t other_filters = 0;       // filter blocks other than these two (alias, DeviceID, ...)
};
DcpIdentifyFilter decode_identify_request(const DcpPdu& pdu) noexcept;

// What an Identify (or Get) response tells about a device. Views point into the frame.
struct DcpDeviceInfo {
  bool has_type_of_station = false;
  std::string_view type_of_station{};
  bool has_name_of_station = false;
  std::string_view name_of_station{};
  bool has_device_id = false;
  std::uint16_t vendor_id = 0;
  std::uint16_t device_id = 0;
  bool has_device_role = false;
  std::uint8_t device_role = 0;  // device_role:: bits
  bool has_device_options = false;
  std::span<const std::uint8_t> device_options{};  // Option/Suboption pairs (2 octets each)
  bool has_device_instance = false;
  std::uint8_t instance_high = 0;
  std::uint8_t instance_low = 0;
  bool has_oem_device_id = false;
  std::uint16_t oem_vendor_id = 0;
  std::uint16_t oem_device_id = 0;
  bool has_ip = false;
  std::uint16_t ip_block_info = 0;  // ip_block_info:: values
  IpSuite ip{};
  bool has_mac = false;
  MacAddress mac{};
  bool has_dhcp = false;
  std::uint8_t dhcp_suboption = 0;  // the DHCP option number of the block
  std::span<const std::uint8_t> dhcp{};  // its data after the BlockInfo
  bool has_device_initiative = false;
  std::uint16_t device_initiative = 0;  // 1 = the device sends Hello at start-up
  std::size_t other_blocks = 0;         // blocks this struct has no field for

  std::size_t device_option_count() const noexcept { return device_options.size() / 2; }
  std::uint16_t device_option(std::size_t i) const noexcept;
};
// Identify response (FrameID FEFFh, sent unicast to the requester); BlockInfo 0 except for the IP
// parameter (ip_block_info). The fields that are set are written in the order TypeOfStation,
// NameOfStation, DeviceID, DeviceRole, DeviceOptions, DeviceInstance, OEM DeviceID, IP, MAC,
// DHCP, DeviceInitiative.
std::size_t encode_identify_response(std::span<std::uint8_t> out, std::uint32_t xid, const DcpDeviceInfo& info) noexcept;
// Hello request (FrameID FEFCh to kDcpHelloMulticast, ServiceID 6): a device with DeviceInitiative
// announces itself at start-up with the same blocks as an Identify response.
std::size_t encode_hello(std::span<std::uint8_t> out, std::uint32_t xid, const DcpDeviceInfo& info) noexcept;

struct DcpDeviceInfoView {
  DcpError error = DcpError::None;
  DcpDeviceInfo info{};
};
// An Identify response, a Get response (ServiceType response success) or a Hello request.
DcpDeviceInfoView decode_device_info(const DcpPdu& pdu) noexcept;

// ---- Set / Get ---------------------------------------------------------------------------------

// Set requests (FrameID FEFDh, unicast). The name must be a valid NameOfStation.
std::size_t encode_set_name_request(std::span<std::uint8_t> out, std::uint32_t xid, std::string_view name,
                                    DcpQualifier qualifier) noexcept;
std::size_t encode_set_ip_request(std::span<std::uint8_t> out, std::uint32_t xid, const IpSuite& ip,
                                  DcpQualifier qualifier) noexcept;
// Control/Signal with BlockQualifier 0 and SignalValue 0100h (flash once).
std::size_t encode_set_signal_request(std::span<std::uint8_t> out, std::uint32_t xid) noexcept;

// One block of a Set request: its BlockQualifier and the data after it.
struct DcpSetBlock {
  std::uint16_t id = 0;
  std::uint16_t qualifier = 0;
  std::span<const std::uint8_t> data{};
};
// Reads the BlockQualifier of a Set request block (BlockTooShort under 2 octets).
DcpError read_set_block(const DcpBlock& block, DcpSetBlock& out) noexcept;
// The 12 octets of an IP parameter value (after qualifier or info): BadBlockLength otherwise.
DcpError read_ip_suite(std::span<const std::uint8_t> data, IpSuite& out) noexcept;

// The result for one block of a Set: the Control/Response block (5/4): Option, Suboption, BlockError.
struct DcpSetResult {
  std::uint16_t id = 0;
  DcpBlockError error = DcpBlockError::NoError;
};
std::size_t encode_set_response(std::span<std::uint8_t> out, std::uint32_t xid,
                                std::span<const DcpSetResult> results) noexcept;
struct DcpSetResponse {
  DcpError error = DcpError::None;
  std::size_t count = 0;  // results written into the caller's array
  bool all_ok() const noexcept { return error == DcpError::None && count > 0 && !any_failed; }
  bool any_failed = false;  // a result with a BlockError other than 0
};
DcpSetResponse decode_set_response(const DcpPdu& pdu, std::span<DcpSetResult> results) noexcept;

// Get request: the Option/Suboption pairs asked for, no lengths.
std::size_t encode_get_request(std::span<std::uint8_t> out, std::uint32_t xid,
                               std::span<const std::uint16_t> options) noexcept;
struct DcpGetRequest {
  DcpError error = DcpError::None;
  std::span<const std::uint8_t> options{};  // pairs
  std::size_t count() const noexcept { return options.size() / 2; }
  std::uint16_t option(std::size_t i) const noexcept;
};
DcpGetRequest decode_get_request(const DcpPdu& pdu) noexcept;

}  // namespace drivegate::profinet
