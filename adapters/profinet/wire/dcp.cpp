#include "adapters/profinet/wire/dcp.hpp"

#include <algorithm>

#include "adapters/profinet/wire/byte_order.hpp"
#include "adapters/profinet/wire/station_name.hpp"

namespace drivegate::profinet {

namespace {

std::span<const std::uint8_t> bytes_of(std::string_view s) noexcept {
  return {reinterpret_cast<const std::uint8_t*>(s.data()), s.size()};
}
std::string_view text_of(std::span<const std::uint8_t> b) noexcept {
  return {reinterpret_cast<const char*>(b.data()), b.size()};
}

bool known_service(std::uint8_t s) noexcept { return s >= 3 && s <= 6; }
bool known_type(std::uint8_t t) noexcept { return t == 0 || t == 1 || t == 5; }

}  // namespace

std::string_view to_string(DcpService s) noexcept {
  switch (s) {
    case DcpService::Get: return "Get";
    case DcpService::Set: return "Set";
    case DcpService::Identify: return "Identify";
    case DcpService::Hello: return "Hello";
  }
  return "?";
}

std::string_view to_string(DcpServiceType t) noexcept {
  switch (t) {
    case DcpServiceType::Request: return "request";
    case DcpServiceType::ResponseSuccess: return "response success";
    case DcpServiceType::ResponseNotSupported: return "response: request not supported";
  }
  return "?";
}

std::string_view dcp_option_name(std::uint16_t id) noexcept {
  switch (id) {
    case dcp_option::kMacAddress: return "MAC address";
    case dcp_option::kIpParameter: return "IP parameter";
    case dcp_option::kFullIpSuite: return "full IP suite";
    case dcp_option::kTypeOfStation: return "TypeOfStation (device vendor)";
    case dcp_option::kNameOfStation: return "NameOfStation";
    case dcp_option::kDeviceId: return "DeviceID";
    case dcp_option::kDeviceRole: return "DeviceRole";
    case dcp_option::kDeviceOptions: return "DeviceOptions";
    case dcp_option::kAliasName: return "AliasName";
    case dcp_option::kDeviceInstance: return "DeviceInstance";
    case dcp_option::kOemDeviceId: return "OEM DeviceID";
    case dcp_option::kStandardGateway: return "standard gateway";
    case dcp_option::kDhcpHostName: return "DHCP host name";
    case dcp_option::kDhcpVendorSpecific: return "DHCP vendor specific";
    case dcp_option::kDhcpServerId: return "DHCP server identifier";
    case dcp_option::kDhcpParameterRequestList: return "DHCP parameter request list";
    case dcp_option::kDhcpClassId: return "DHCP class identifier";
    case dcp_option::kDhcpClientId: return "DHCP client identifier";
    case dcp_option::kDhcpFqdn: return "DHCP FQDN";
    case dcp_option::kDhcpUuid: return "DHCP UUID client identifier";
    case dcp_option::kDhcpControl: return "DHCP control";
    case dcp_option::kStartTransaction: return "start transaction";
    case dcp_option::kEndTransaction: return "end transaction";
    case dcp_option::kSignal: return "Signal";
    case dcp_option::kResponse: return "Response";
    case dcp_option::kFactoryReset: return "factory reset";
    case dcp_option::kResetToFactory: return "reset to factory";
    case dcp_option::kDeviceInitiative: return "DeviceInitiative";
    case dcp_option::kAllSelector: return "all selector";
    default: return "unknown";
  }
}

std::string_view to_string(DcpBlockError e) noexcept {
  switch (e) {
    case DcpBlockError::NoError: return "no error";
    case DcpBlockError::OptionNotSupported: return "option not supported";
    case DcpBlockError::SuboptionNotSupported: return "suboption not supported or no data set available";
    case DcpBlockError::SuboptionNotSet: return "suboption not set";
    case DcpBlockError::ResourceError: return "resource error";
    case DcpBlockError::SetNotPossible: return "SET not possible by local reasons";
    case DcpBlockError::InOperation: return "device in operation, SET not possible";
  }
  return "unknown block error";
}

std::string_view to_string(DcpError e) noexcept {
  switch (e) {
    case DcpError::None: return "no error";
    case DcpError::TruncatedHeader: return "DCP PDU shorter than its 10-octet header";
    case DcpError::DataLengthBeyondPdu: return "DCPDataLength runs past the end of the frame";
    case DcpError::UnknownService: return "unknown DCP ServiceID";
    case DcpError::UnknownServiceType: return "unknown DCP ServiceType";
    case DcpError::UnexpectedService: return "DCP service or service type not the one expected here";
    case DcpError::TruncatedBlockHeader: return "DCP block header cut off by DCPDataLength";
    case DcpError::BlockBeyondData: return "DCPBlockLength runs past DCPDataLength";
    case DcpError::BlockTooShort: return "DCP block shorter than its qualifier, info or fixed fields";
    case DcpError::BadBlockLength: return "DCP block length wrong for its option";
    case DcpError::OddGetRequest: return "DCP Get request with an odd option list length";
    case DcpError::NoBlocks: return "DCP PDU without the block it needs";
    case DcpError::WrongResponseBlock: return "DCP Set response block is not Control/Response";
    case DcpError::TooManyBlocks: return "more DCP response blocks than expected";
  }
  return "?";
}

DcpPdu decode_dcp(std::span<const std::uint8_t> pdu) noexcept {
  DcpPdu p;
  if (pdu.size() < kDcpHeaderSize) {
    p.error = DcpError::TruncatedHeader;
    return p;
  }
  const std::uint8_t service = pdu[0];
  const std::uint8_t type = pdu[1];
  p.header.service = static_cast<DcpService>(service);
  p.header.type = static_cast<DcpServiceType>(type);
  p.header.xid = get_be32(pdu, 2);
  p.header.response_delay = get_be16(pdu, 6);
  p.header.data_length = get_be16(pdu, 8);
  if (!known_service(service)) {
    p.error = DcpError::UnknownService;
    return p;
  }
  if (!known_type(type)) {
    p.error = DcpError::UnknownServiceType;
    return p;
  }
  if (p.header.data_length > pdu.size() - kDcpHeaderSize) {
    p.error = DcpError::DataLengthBeyondPdu;
    return p;
  }
  p.blocks = pdu.subspan(kDcpHeaderSize, p.header.data_length);
  return p;
}

bool DcpBlockReader::next(DcpBlock& out) noexcept {
  if (error_ != DcpError::None || pos_ >= data_.size()) return false;
  if (data_.size() - pos_ < kDcpBlockHeaderSize) {
    error_ = DcpError::TruncatedBlockHeader;
    return false;
  }
  const std::size_t length = get_be16(data_, pos_ + 2);
  const std::size_t value_at = pos_ + kDcpBlockHeaderSize;
  if (length > data_.size() - value_at) {
    error_ = DcpError::BlockBeyondData;
    return false;
  }
  out.option = data_[pos_];
  out.suboption = data_[pos_ + 1];
  out.value = data_.subspan(value_at, length);
  // The pad octet after an odd block [IEC 61158-6-10 §4.3: blocks start on even offsets].
  pos_ = std::min(data_.size(), value_at + length + (length & 1U));
  return true;
}

// ---- Writer -----------------------------------------------------------------------------------

DcpWriter::DcpWriter(std::span<std::uint8_t> out, DcpService service, DcpServiceType type, std::uint32_t xid,
                     std::uint16_t response_delay) noexcept
    : out_(out.first(std::min(out.size(), kDcpHeaderSize + kDcpMaxDataLength))) {
  if (out_.size() < kDcpHeaderSize) {
    failed_ = true;
    return;
  }
  out_[0] = static_cast<std::uint8_t>(service);
  out_[1] = static_cast<std::uint8_t>(type);
  put_be32(out_, 2, xid);
  put_be16(out_, 6, response_delay);
  put_be16(out_, 8, 0);
  pos_ = kDcpHeaderSize;
}

bool DcpWriter::begin_block(std::uint16_t id, std::size_t length) noexcept {
  if (failed_ || length > 0xFFFF || out_.size() - pos_ < kDcpBlockHeaderSize + length + (length & 1U)) {
    failed_ = true;
    return false;
  }
  put_be16(out_, pos_, id);
  put_be16(out_, pos_ + 2, static_cast<std::uint16_t>(length));
  pos_ += kDcpBlockHeaderSize;
  return true;
}

void DcpWriter::end_block(std::size_t length) noexcept {
  pos_ += length;
  if (length & 1U) out_[pos_++] = 0;  // pad to an even offset
}

bool DcpWriter::add_raw(std::uint16_t id, std::span<const std::uint8_t> value) noexcept {
  if (!begin_block(id, value.size())) return false;
  std::copy(value.begin(), value.end(), out_.begin() + static_cast<std::ptrdiff_t>(pos_));
  end_block(value.size());
  return true;
}

bool DcpWriter::add(std::uint16_t id, std::uint16_t qualifier_or_info, std::span<const std::uint8_t> data) noexcept {
  const std::size_t length = 2 + data.size();
  if (!begin_block(id, length)) return false;
  put_be16(out_, pos_, qualifier_or_info);
  std::copy(data.begin(), data.end(), out_.begin() + static_cast<std::ptrdiff_t>(pos_ + 2));
  end_block(length);
  return true;
}

bool DcpWriter::add(std::uint16_t id, std::uint16_t qualifier_or_info, std::string_view text) noexcept {
  return add(id, qualifier_or_info, bytes_of(text));
}

bool DcpWriter::add_option(std::uint16_t id) noexcept {
  if (failed_ || out_.size() - pos_ < 2) {
    failed_ = true;
    return false;
  }
  put_be16(out_, pos_, id);
  pos_ += 2;
  return true;
}

std::size_t DcpWriter::finish() noexcept {
  if (failed_) return 0;
  put_be16(out_, 8, static_cast<std::uint16_t>(pos_ - kDcpHeaderSize));
  return pos_;
}

// ---- Identify ---------------------------------------------------------------------------------

std::size_t encode_identify_all_request(std::span<std::uint8_t> out, std::uint32_t xid,
                                        std::uint16_t response_delay_factor) noexcept {
  if (response_delay_factor > kDcpMaxResponseDelayFactor) return 0;
  DcpWriter w(out, DcpService::Identify, DcpServiceType::Request, xid, response_delay_factor);
  w.add_raw(dcp_option::kAllSelector, {});
  return w.finish();
}

std::size_t encode_identify_name_request(std::span<std::uint8_t> out, std::uint32_t xid,
                                         std::uint16_t response_delay_factor, std::string_view name) noexcept {
  if (response_delay_factor > kDcpMaxResponseDelayFactor || validate_name_of_station(name) != NameError::None) return 0;
  DcpWriter w(out, DcpService::Identify, DcpServiceType::Request, xid, response_delay_factor);
  w.add_raw(dcp_option::kNameOfStation, bytes_of(name));
  return w.finish();
}

DcpIdentifyFilter decode_identify_request(const DcpPdu& pdu) noexcept {
  DcpIdentifyFilter f;
  if (!pdu.ok()) {
    f.error = pdu.error;
    return f;
  }
  if (pdu.header.service != DcpService::Identify || pdu.header.type != DcpServiceType::Request) {
    f.error = DcpError::UnexpectedService;
    return f;
  }
  DcpBlockReader r(pdu.blocks);
  DcpBlock b;
  std::size_t n = 0;
  while (r.next(b)) {
    ++n;
    if (b.id() == dcp_option::kAllSelector) {
      f.all = true;
    } else if (b.id() == dcp_option::kNameOfStation) {
      f.has_name = true;
      f.name_of_station = text_of(b.value);
    } else {
      ++f.other_filters;
    }
  }
  if (r.error() != DcpError::None) {
    f.error = r.error();
  } else if (n == 0) {
    f.error = DcpError::NoBlocks;
  }
  return f;
}

std::uint16_t DcpDeviceInfo::device_option(std::size_t i) const noexcept {
  return 2 * i + 1 < device_options.size() ? get_be16(device_options, 2 * i) : 0;
}

namespace {

std::size_t encode_device_info(std::span<std::uint8_t> out, DcpService service, DcpServiceType type, std::uint32_t xid,
                               const DcpDeviceInfo& info) noexcept {
  if (info.device_options.size() % 2 != 0) return 0;
  DcpWriter w(out, service, type, xid, 0);
  if (info.has_type_of_station) w.add(dcp_option::kTypeOfStation, 0, info.type_of_station);
  if (info.has_name_of_station) w.add(dcp_option::kNameOfStation, 0, info.name_of_station);
  if (info.has_device_id) {
    std::array<std::uint8_t, 4> v{};
    put_be16(v, 0, info.vendor_id);
    put_be16(v, 2, info.device_id);
    w.add(dcp_option::kDeviceId, 0, v);
  }
  if (info.has_device_role) {
    const std::array<std::uint8_t, 2> v{info.device_role, 0};
    w.add(dcp_option::kDeviceRole, 0, v);
  }
  if (info.has_device_options) w.add(dcp_option::kDeviceOptions, 0, info.device_options);
  if (info.has_device_instance) {
    const std::array<std::uint8_t, 2> v{info.instance_high, info.instance_low};
    w.add(dcp_option::kDeviceInstance, 0, v);
  }
  if (info.has_oem_device_id) {
    std::array<std::uint8_t, 4> v{};
    put_be16(v, 0, info.oem_vendor_id);
    put_be16(v, 2, info.oem_device_id);
    w.add(dcp_option::kOemDeviceId, 0, v);
  }
  if (info.has_ip) {
    std::array<std::uint8_t, 12> v{};
    std::copy(info.ip.address.begin(), info.ip.address.end(), v.begin());
    std::copy(info.ip.netmask.begin(), info.ip.netmask.end(), v.begin() + 4);
    std::copy(info.ip.gateway.begin(), info.ip.gateway.end(), v.begin() + 8);
    w.add(dcp_option::kIpParameter, info.ip_block_info, v);
  }
  if (info.has_mac) w.add(dcp_option::kMacAddress, 0, info.mac);
  if (info.has_dhcp) w.add(static_cast<std::uint16_t>(0x0300 | info.dhcp_suboption), 0, info.dhcp);
  if (info.has_device_initiative) {
    std::array<std::uint8_t, 2> v{};
    put_be16(v, 0, info.device_initiative);
    w.add(dcp_option::kDeviceInitiative, 0, v);
  }
  return w.finish();
}

}  // namespace

std::size_t encode_identify_response(std::span<std::uint8_t> out, std::uint32_t xid, const DcpDeviceInfo& info) noexcept {
  return encode_device_info(out, DcpService::Identify, DcpServiceType::ResponseSuccess, xid, info);
}

std::size_t encode_hello(std::span<std::uint8_t> out, std::uint32_t xid, const DcpDeviceInfo& info) noexcept {
  return encode_device_info(out, DcpService::Hello, DcpServiceType::Request, xid, info);
}

DcpError read_ip_suite(std::span<const std::uint8_t> data, IpSuite& out) noexcept {
  if (data.size() != 12) return DcpError::BadBlockLength;
  std::copy(data.begin(), data.begin() + 4, out.address.begin());
  std::copy(data.begin() + 4, data.begin() + 8, out.netmask.begin());
  std::copy(data.begin() + 8, data.begin() + 12, out.gateway.begin());
  return DcpError::None;
}

std::string_view ip_suite_problem(const IpSuite& ip) noexcept {
  const auto u32 = [](const std::array<std::uint8_t, 4>& a) {
    return (std::uint32_t{a[0]} << 24) | (std::uint32_t{a[1]} << 16) | (std::uint32_t{a[2]} << 8) | a[3];
  };
  const std::uint32_t address = u32(ip.address);
  const std::uint32_t mask = u32(ip.netmask);
  const std::uint32_t gateway = u32(ip.gateway);
  if (address == 0 && mask == 0 && gateway == 0) return {};
  if (address == 0) return "the address is 0.0.0.0 but netmask or gateway is not";
  if ((~mask & (~mask + 1)) != 0) return "the netmask's ones are not contiguous";
  if (mask == 0) return "the netmask is 0.0.0.0";
  const std::uint8_t first = ip.address[0];
  if (first == 0) return "the address is in 0.0.0.0/8 (this network)";
  if (first == 127) return "the address is a loopback address (127.0.0.0/8)";
  if (first >= 224) return "the address is multicast or reserved (224.0.0.0 and above)";
  if (mask < 0xFFFFFFFEU) {  // /31 and /32 have no network and broadcast address
    if ((address & ~mask) == 0) return "the address is the subnet's network address";
    if ((address & ~mask) == ~mask) return "the address is the subnet's broadcast address";
  }
  if (gateway != 0 && gateway != address && (gateway & mask) != (address & mask)) {
    return "the gateway is outside the address's subnet";
  }
  return {};
}

DcpDeviceInfoView decode_device_info(const DcpPdu& pdu) noexcept {
  DcpDeviceInfoView v;
  if (!pdu.ok()) {
    v.error = pdu.error;
    return v;
  }
  const bool response = (pdu.header.service == DcpService::Identify || pdu.header.service == DcpService::Get) &&
                        pdu.header.type == DcpServiceType::ResponseSuccess;
  const bool hello = pdu.header.service == DcpService::Hello && pdu.header.type == DcpServiceType::Request;
  if (!response && !hello) {
    v.error = DcpError::UnexpectedService;
    return v;
  }
  DcpDeviceInfo& d = v.info;
  DcpBlockReader r(pdu.blocks);
  DcpBlock b;
  auto fail = [&v](DcpError e) {
    v.error = e;
    return v;
  };
  while (r.next(b)) {
    if (b.value.size() < 2) return fail(DcpError::BlockTooShort);
    const std::uint16_t info = get_be16(b.value, 0);
    const auto data = b.value.subspan(2);
    switch (b.id()) {
      case dcp_option::kTypeOfStation:
        d.has_type_of_station = true;
        d.type_of_station = text_of(data);
        break;
      case dcp_option::kNameOfStation:
        d.has_name_of_station = true;
        d.name_of_station = text_of(data);
        break;
      case dcp_option::kDeviceId:
        if (data.size() != 4) return fail(DcpError::BadBlockLength);
        d.has_device_id = true;
        d.vendor_id = get_be16(data, 0);
        d.device_id = get_be16(data, 2);
        break;
      case dcp_option::kDeviceRole:
        if (data.size() != 2) return fail(DcpError::BadBlockLength);
        d.has_device_role = true;
        d.device_role = data[0];
        break;
      case dcp_option::kDeviceOptions:
        if (data.size() % 2 != 0) return fail(DcpError::BadBlockLength);
        d.has_device_options = true;
        d.device_options = data;
        break;
      case dcp_option::kDeviceInstance:
        if (data.size() != 2) return fail(DcpError::BadBlockLength);
        d.has_device_instance = true;
        d.instance_high = data[0];
        d.instance_low = data[1];
        break;
      case dcp_option::kOemDeviceId:
        if (data.size() != 4) return fail(DcpError::BadBlockLength);
        d.has_oem_device_id = true;
        d.oem_vendor_id = get_be16(data, 0);
        d.oem_device_id = get_be16(data, 2);
        break;
      case dcp_option::kIpParameter:
        if (read_ip_suite(data, d.ip) != DcpError::None) return fail(DcpError::BadBlockLength);
        d.has_ip = true;
        d.ip_block_info = info;
        break;
      case dcp_option::kMacAddress:
        if (data.size() != 6) return fail(DcpError::BadBlockLength);
        d.has_mac = true;
        std::copy(data.begin(), data.end(), d.mac.begin());
        break;
      case dcp_option::kDeviceInitiative:
        if (data.size() != 2) return fail(DcpError::BadBlockLength);
        d.has_device_initiative = true;
        d.device_initiative = get_be16(data, 0);
        break;
      default:
        if (b.option == 3 && !d.has_dhcp) {  // the first DHCP block [option 3: DHCP]
          d.has_dhcp = true;
          d.dhcp_suboption = b.suboption;
          d.dhcp = data;
        } else {
          ++d.other_blocks;
        }
        break;
    }
  }
  if (r.error() != DcpError::None) v.error = r.error();
  return v;
}

// ---- Set / Get --------------------------------------------------------------------------------

std::size_t encode_set_name_request(std::span<std::uint8_t> out, std::uint32_t xid, std::string_view name,
                                    DcpQualifier qualifier) noexcept {
  if (validate_name_of_station(name) != NameError::None) return 0;
  DcpWriter w(out, DcpService::Set, DcpServiceType::Request, xid, 0);
  w.add(dcp_option::kNameOfStation, static_cast<std::uint16_t>(qualifier), name);
  return w.finish();
}

std::size_t encode_set_ip_request(std::span<std::uint8_t> out, std::uint32_t xid, const IpSuite& ip,
                                  DcpQualifier qualifier) noexcept {
  std::array<std::uint8_t, 12> v{};
  std::copy(ip.address.begin(), ip.address.end(), v.begin());
  std::copy(ip.netmask.begin(), ip.netmask.end(), v.begin() + 4);
  std::copy(ip.gateway.begin(), ip.gateway.end(), v.begin() + 8);
  DcpWriter w(out, DcpService::Set, DcpServiceType::Request, xid, 0);
  w.add(dcp_option::kIpParameter, static_cast<std::uint16_t>(qualifier), v);
  return w.finish();
}

std::size_t encode_set_signal_request(std::span<std::uint8_t> out, std::uint32_t xid) noexcept {
  std::array<std::uint8_t, 2> v{};
  put_be16(v, 0, kDcpSignalFlashOnce);
  DcpWriter w(out, DcpService::Set, DcpServiceType::Request, xid, 0);
  w.add(dcp_option::kSignal, 0, v);
  return w.finish();
}

DcpError read_set_block(const DcpBlock& block, DcpSetBlock& out) noexcept {
  if (block.value.size() < 2) return DcpError::BlockTooShort;
  out.id = block.id();
  out.qualifier = get_be16(block.value, 0);
  out.data = block.value.subspan(2);
  return DcpError::None;
}

std::size_t encode_set_response(std::span<std::uint8_t> out, std::uint32_t xid,
                                std::span<const DcpSetResult> results) noexcept {
  if (results.empty()) return 0;
  DcpWriter w(out, DcpService::Set, DcpServiceType::ResponseSuccess, xid, 0);
  for (const DcpSetResult& r : results) {
    const std::array<std::uint8_t, 3> v{dcp_option::option_of(r.id), dcp_option::suboption_of(r.id),
                                        static_cast<std::uint8_t>(r.error)};
    w.add_raw(dcp_option::kResponse, v);
  }
  return w.finish();
}

DcpSetResponse decode_set_response(const DcpPdu& pdu, std::span<DcpSetResult> results) noexcept {
  DcpSetResponse s;
  if (!pdu.ok()) {
    s.error = pdu.error;
    return s;
  }
  if (pdu.header.service != DcpService::Set || pdu.header.type != DcpServiceType::ResponseSuccess) {
    s.error = DcpError::UnexpectedService;
    return s;
  }
  DcpBlockReader r(pdu.blocks);
  DcpBlock b;
  while (r.next(b)) {
    if (b.id() != dcp_option::kResponse) {
      s.error = DcpError::WrongResponseBlock;
      return s;
    }
    if (b.value.size() != 3) {
      s.error = DcpError::BadBlockLength;
      return s;
    }
    if (s.count >= results.size()) {
      s.error = DcpError::TooManyBlocks;
      return s;
    }
    DcpSetResult& out = results[s.count++];
    out.id = static_cast<std::uint16_t>((b.value[0] << 8) | b.value[1]);
    out.error = static_cast<DcpBlockError>(b.value[2]);
    if (b.value[2] != 0) s.any_failed = true;
  }
  if (r.error() != DcpError::None) {
    s.error = r.error();
  } else if (s.count == 0) {
    s.error = DcpError::NoBlocks;
  }
  return s;
}

std::size_t encode_get_request(std::span<std::uint8_t> out, std::uint32_t xid,
                               std::span<const std::uint16_t> options) noexcept {
  if (options.empty()) return 0;
  DcpWriter w(out, DcpService::Get, DcpServiceType::Request, xid, 0);
  for (const std::uint16_t id : options) w.add_option(id);
  return w.finish();
}

std::uint16_t DcpGetRequest::option(std::size_t i) const noexcept {
  return 2 * i + 1 < options.size() ? get_be16(options, 2 * i) : 0;
}

DcpGetRequest decode_get_request(const DcpPdu& pdu) noexcept {
  DcpGetRequest g;
  if (!pdu.ok()) {
    g.error = pdu.error;
    return g;
  }
  if (pdu.header.service != DcpService::Get || pdu.header.type != DcpServiceType::Request) {
    g.error = DcpError::UnexpectedService;
  } else if (pdu.blocks.empty()) {
    g.error = DcpError::NoBlocks;
  } else if (pdu.blocks.size() % 2 != 0) {
    g.error = DcpError::OddGetRequest;
  } else {
    g.options = pdu.blocks;
  }
  return g;
}

}  // namespace drivegate::profinet
