// PN-DCP [IEC 61158-6-10 §4.3]: byte-exact PDUs (the PDU after the FrameID) built from the
// standard's layouts (the DCP-PDU header: ServiceID, ServiceType, Xid, ResponseDelay,
// DCPDataLength; the blocks: Option, Suboption, DCPBlockLength, BlockQualifier/BlockInfo,
// pad octet after an odd block), and malformed input for every decoder. Vendor and device IDs are
// illustrative values, not a real device's.
#include "adapters/profinet/wire/dcp.hpp"

#include <gtest/gtest.h>

#include <array>
#include <string>

#include "tests/profinet_wire/bytes.hpp"

namespace drivegate::profinet {
namespace {

using test::Bytes;
using test::hex;

constexpr std::uint32_t kXid = 0x01020304;

Bytes encoded(std::size_t n, const std::array<std::uint8_t, 1500>& buf) { return Bytes(buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n)); }

IpSuite ip(std::array<std::uint8_t, 4> a, std::array<std::uint8_t, 4> m, std::array<std::uint8_t, 4> g) {
  IpSuite s;
  s.address = a;
  s.netmask = m;
  s.gateway = g;
  return s;
}

TEST(PnDcp, IdentifyAllRequestBytes) {
  std::array<std::uint8_t, 1500> buf{};
  const std::size_t n = encode_identify_all_request(buf, kXid, 1);
  // Identify(5) request(0) Xid ResponseDelayFactor 1, DCPDataLength 4 | AllSelector FFh FFh length 0.
  EXPECT_EQ(encoded(n, buf), hex("05 00 01 02 03 04 00 01 00 04  FF FF 00 00"));
  const DcpIdentifyFilter f = decode_identify_request(decode_dcp(encoded(n, buf)));
  ASSERT_EQ(f.error, DcpError::None) << to_string(f.error);
  EXPECT_TRUE(f.all);
  EXPECT_FALSE(f.has_name);
  EXPECT_EQ(encode_identify_all_request(buf, kXid, 0x1901), 0U);  // above the largest ResponseDelayFactor
}

TEST(PnDcp, IdentifyByNameRequestBytes) {
  std::array<std::uint8_t, 1500> buf{};
  const std::size_t n = encode_identify_name_request(buf, kXid, 0x0080, "akd-1");
  // NameOfStation filter without BlockQualifier; 5 octets, so one pad octet (counted in DCPDataLength).
  EXPECT_EQ(encoded(n, buf), hex("05 00 01 02 03 04 00 80 00 0A  02 02 00 05 61 6B 64 2D 31 00"));
  const Bytes frame = encoded(n, buf);
  const DcpPdu pdu = decode_dcp(frame);
  ASSERT_TRUE(pdu.ok());
  EXPECT_EQ(pdu.header.service, DcpService::Identify);
  EXPECT_EQ(pdu.header.type, DcpServiceType::Request);
  EXPECT_EQ(pdu.header.xid, kXid);
  EXPECT_EQ(pdu.header.response_delay, 0x0080);
  const DcpIdentifyFilter f = decode_identify_request(pdu);
  ASSERT_EQ(f.error, DcpError::None);
  EXPECT_FALSE(f.all);
  EXPECT_TRUE(f.has_name);
  EXPECT_EQ(f.name_of_station, "akd-1");
  EXPECT_EQ(encode_identify_name_request(buf, kXid, 1, "AKD-1"), 0U);  // not a valid NameOfStation
  EXPECT_EQ(encode_identify_name_request(std::span(buf).first(19), kXid, 1, "akd-1"), 0U);
}

DcpDeviceInfo akd_like() {
  static constexpr std::array<std::uint8_t, 4> kOptions{0x01, 0x02, 0x02, 0x02};
  DcpDeviceInfo d;
  d.has_type_of_station = true;
  d.type_of_station = "AKD";
  d.has_name_of_station = true;
  d.name_of_station = "akd-1";
  d.has_device_id = true;
  d.vendor_id = 0x002A;
  d.device_id = 0x0301;
  d.has_device_role = true;
  d.device_role = device_role::kIoDevice;
  d.has_device_options = true;
  d.device_options = kOptions;
  d.has_device_instance = true;
  d.instance_low = 1;
  d.has_ip = true;
  d.ip_block_info = ip_block_info::kSet;
  d.ip = ip({192, 168, 0, 10}, {255, 255, 255, 0}, {0, 0, 0, 0});
  return d;
}

// An Identify response with the blocks a device answers an Identify-All with.
const Bytes kIdentifyResponse = hex(
    "05 01 01 02 03 04 00 00 00 4C"
    "02 01 00 05 00 00 41 4B 44 00"                             // TypeOfStation "AKD" + pad
    "02 02 00 07 00 00 61 6B 64 2D 31 00"                       // NameOfStation "akd-1" + pad
    "02 03 00 06 00 00 00 2A 03 01"                             // DeviceID vendor 002Ah device 0301h
    "02 04 00 04 00 00 01 00"                                   // DeviceRole IO device
    "02 05 00 06 00 00 01 02 02 02"                             // DeviceOptions 1/2, 2/2
    "02 07 00 04 00 00 00 01"                                   // DeviceInstance 0.1
    "01 02 00 0E 00 01 C0 A8 00 0A FF FF FF 00 00 00 00 00");   // IP set: 192.168.0.10/24, no gateway

TEST(PnDcp, IdentifyResponseBytes) {
  std::array<std::uint8_t, 1500> buf{};
  const std::size_t n = encode_identify_response(buf, kXid, akd_like());
  EXPECT_EQ(encoded(n, buf), kIdentifyResponse);
}

TEST(PnDcp, IdentifyResponseDecodes) {
  const DcpDeviceInfoView v = decode_device_info(decode_dcp(kIdentifyResponse));
  ASSERT_EQ(v.error, DcpError::None) << to_string(v.error);
  const DcpDeviceInfo& d = v.info;
  EXPECT_EQ(d.type_of_station, "AKD");
  EXPECT_EQ(d.name_of_station, "akd-1");
  EXPECT_EQ(d.vendor_id, 0x002A);
  EXPECT_EQ(d.device_id, 0x0301);
  EXPECT_EQ(d.device_role, device_role::kIoDevice);
  ASSERT_EQ(d.device_option_count(), 2U);
  EXPECT_EQ(d.device_option(0), dcp_option::kIpParameter);
  EXPECT_EQ(d.device_option(1), dcp_option::kNameOfStation);
  EXPECT_EQ(d.device_option(2), 0);
  EXPECT_EQ(d.instance_high, 0);
  EXPECT_EQ(d.instance_low, 1);
  EXPECT_TRUE(d.has_ip);
  EXPECT_EQ(d.ip_block_info, ip_block_info::kSet);
  EXPECT_EQ(d.ip, ip({192, 168, 0, 10}, {255, 255, 255, 0}, {0, 0, 0, 0}));
  EXPECT_FALSE(d.has_mac);
  EXPECT_FALSE(d.has_dhcp);
  EXPECT_EQ(d.other_blocks, 0U);
  // The name is a view into the frame.
  EXPECT_EQ(reinterpret_cast<const std::uint8_t*>(d.name_of_station.data()), kIdentifyResponse.data() + 26);
}

TEST(PnDcp, IdentifyResponseOptionalBlocks) {
  static constexpr std::array<std::uint8_t, 5> kClientId{0x00, 'a', 'k', 'd', '1'};
  DcpDeviceInfo d;
  d.has_mac = true;
  d.mac = MacAddress{0x00, 0x1B, 0x1B, 0x12, 0x34, 0x56};
  d.has_oem_device_id = true;
  d.oem_vendor_id = 0x1234;
  d.oem_device_id = 0x5678;
  d.has_dhcp = true;
  d.dhcp_suboption = 61;
  d.dhcp = kClientId;
  d.has_device_initiative = true;
  d.device_initiative = 1;
  std::array<std::uint8_t, 1500> buf{};
  const std::size_t n = encode_identify_response(buf, 7, d);
  EXPECT_EQ(encoded(n, buf), hex("05 01 00 00 00 07 00 00 00 2A"
                                 "02 08 00 06 00 00 12 34 56 78"
                                 "01 01 00 08 00 00 00 1B 1B 12 34 56"
                                 "03 3D 00 07 00 00 00 61 6B 64 31 00"
                                 "06 01 00 04 00 00 00 01"));
  const Bytes frame = encoded(n, buf);
  const DcpDeviceInfoView v = decode_device_info(decode_dcp(frame));
  ASSERT_EQ(v.error, DcpError::None);
  EXPECT_EQ(v.info.mac, d.mac);
  EXPECT_EQ(v.info.oem_device_id, 0x5678);
  EXPECT_EQ(v.info.dhcp_suboption, 61);
  EXPECT_EQ(Bytes(v.info.dhcp.begin(), v.info.dhcp.end()), Bytes(kClientId.begin(), kClientId.end()));
  EXPECT_EQ(v.info.device_initiative, 1);
}

TEST(PnDcp, SetNameRequestBytes) {
  std::array<std::uint8_t, 1500> buf{};
  const std::size_t n = encode_set_name_request(buf, kXid, "akd-1", DcpQualifier::Permanent);
  // Set(4) request: NameOfStation with BlockQualifier 0001h (permanent), 7 octets + pad.
  EXPECT_EQ(encoded(n, buf), hex("04 00 01 02 03 04 00 00 00 0C  02 02 00 07 00 01 61 6B 64 2D 31 00"));
  const Bytes frame = encoded(n, buf);
  const DcpPdu pdu = decode_dcp(frame);
  DcpBlockReader r(pdu.blocks);
  DcpBlock b;
  ASSERT_TRUE(r.next(b));
  DcpSetBlock s;
  ASSERT_EQ(read_set_block(b, s), DcpError::None);
  EXPECT_EQ(s.id, dcp_option::kNameOfStation);
  EXPECT_EQ(s.qualifier, 1);
  EXPECT_EQ(std::string(s.data.begin(), s.data.end()), "akd-1");
  EXPECT_FALSE(r.next(b));
  EXPECT_EQ(r.error(), DcpError::None);
  EXPECT_EQ(encode_set_name_request(buf, kXid, "192.168.0.1", DcpQualifier::Temporary), 0U);
}

TEST(PnDcp, SetIpRequestBytes) {
  std::array<std::uint8_t, 1500> buf{};
  const std::size_t n = encode_set_ip_request(buf, kXid, ip({192, 168, 0, 10}, {255, 255, 255, 0}, {192, 168, 0, 1}),
                                              DcpQualifier::Temporary);
  EXPECT_EQ(encoded(n, buf),
            hex("04 00 01 02 03 04 00 00 00 12  01 02 00 0E 00 00 C0 A8 00 0A FF FF FF 00 C0 A8 00 01"));
  const Bytes frame = encoded(n, buf);
  const DcpPdu pdu = decode_dcp(frame);
  DcpBlockReader r(pdu.blocks);
  DcpBlock b;
  ASSERT_TRUE(r.next(b));
  DcpSetBlock s;
  ASSERT_EQ(read_set_block(b, s), DcpError::None);
  EXPECT_EQ(s.qualifier, static_cast<std::uint16_t>(DcpQualifier::Temporary));
  IpSuite got;
  ASSERT_EQ(read_ip_suite(s.data, got), DcpError::None);
  EXPECT_EQ(got, ip({192, 168, 0, 10}, {255, 255, 255, 0}, {192, 168, 0, 1}));
}

TEST(PnDcp, SignalRequestBytes) {
  std::array<std::uint8_t, 1500> buf{};
  const std::size_t n = encode_set_signal_request(buf, kXid);
  // Control/Signal: BlockQualifier 0, SignalValue 0100h (flash once).
  EXPECT_EQ(encoded(n, buf), hex("04 00 01 02 03 04 00 00 00 08  05 03 00 04 00 00 01 00"));
}

TEST(PnDcp, SetResponseBytesAndDecode) {
  std::array<std::uint8_t, 1500> buf{};
  const std::array<DcpSetResult, 2> results{{{dcp_option::kNameOfStation, DcpBlockError::NoError},
                                             {dcp_option::kIpParameter, DcpBlockError::InOperation}}};
  const std::size_t n = encode_set_response(buf, kXid, results);
  // Control/Response blocks: Option, Suboption, BlockError; 3 octets + pad each.
  EXPECT_EQ(encoded(n, buf), hex("04 01 01 02 03 04 00 00 00 10  05 04 00 03 02 02 00 00  05 04 00 03 01 02 06 00"));
  std::array<DcpSetResult, 4> got{};
  const DcpSetResponse s = decode_set_response(decode_dcp(encoded(n, buf)), got);
  ASSERT_EQ(s.error, DcpError::None);
  EXPECT_EQ(s.count, 2U);
  EXPECT_TRUE(s.any_failed);
  EXPECT_FALSE(s.all_ok());
  EXPECT_EQ(got[0].id, dcp_option::kNameOfStation);
  EXPECT_EQ(got[0].error, DcpBlockError::NoError);
  EXPECT_EQ(got[1].id, dcp_option::kIpParameter);
  EXPECT_EQ(got[1].error, DcpBlockError::InOperation);
  EXPECT_EQ(to_string(got[1].error), "device in operation, SET not possible");
  std::array<DcpSetResult, 1> one{};
  EXPECT_EQ(decode_set_response(decode_dcp(encoded(n, buf)), one).error, DcpError::TooManyBlocks);
  // The last block's pad octet may be missing.
  const Bytes no_pad = hex("04 01 01 02 03 04 00 00 00 07  05 04 00 03 02 02 00");
  const DcpSetResponse s2 = decode_set_response(decode_dcp(no_pad), got);
  EXPECT_EQ(s2.error, DcpError::None);
  EXPECT_TRUE(s2.all_ok());
}

TEST(PnDcp, GetRequestBytes) {
  std::array<std::uint8_t, 1500> buf{};
  const std::array<std::uint16_t, 2> opts{dcp_option::kNameOfStation, dcp_option::kIpParameter};
  const std::size_t n = encode_get_request(buf, kXid, opts);
  EXPECT_EQ(encoded(n, buf), hex("03 00 01 02 03 04 00 00 00 04  02 02 01 02"));
  const Bytes frame = encoded(n, buf);
  const DcpGetRequest g = decode_get_request(decode_dcp(frame));
  ASSERT_EQ(g.error, DcpError::None);
  ASSERT_EQ(g.count(), 2U);
  EXPECT_EQ(g.option(0), dcp_option::kNameOfStation);
  EXPECT_EQ(g.option(1), dcp_option::kIpParameter);
  EXPECT_EQ(g.option(2), 0);
  EXPECT_EQ(encode_get_request(buf, kXid, {}), 0U);
}

TEST(PnDcp, GetResponseReadsLikeIdentify) {
  const Bytes get_rsp = hex("03 01 01 02 03 04 00 00 00 0C  02 02 00 07 00 00 61 6B 64 2D 31 00");
  const DcpDeviceInfoView v = decode_device_info(decode_dcp(get_rsp));
  ASSERT_EQ(v.error, DcpError::None);
  EXPECT_EQ(v.info.name_of_station, "akd-1");
}

TEST(PnDcp, HelloBytes) {
  DcpDeviceInfo d;
  d.has_name_of_station = true;
  d.name_of_station = "akd-1";
  d.has_device_initiative = true;
  d.device_initiative = 1;
  std::array<std::uint8_t, 1500> buf{};
  const std::size_t n = encode_hello(buf, 9, d);
  // Hello(6) request with response blocks (BlockInfo 0).
  EXPECT_EQ(encoded(n, buf), hex("06 00 00 00 00 09 00 00 00 14  02 02 00 07 00 00 61 6B 64 2D 31 00  06 01 00 04 00 00 00 01"));
  const Bytes frame = encoded(n, buf);
  const DcpDeviceInfoView v = decode_device_info(decode_dcp(frame));
  ASSERT_EQ(v.error, DcpError::None);
  EXPECT_EQ(v.info.name_of_station, "akd-1");
  EXPECT_EQ(v.info.device_initiative, 1);
}

TEST(PnDcp, WriterRefusesWhatDoesNotFit) {
  std::array<std::uint8_t, 1500> buf{};
  EXPECT_EQ(encode_identify_all_request(std::span(buf).first(13), kXid, 1), 0U);
  DcpWriter tiny{std::span(buf).first(9), DcpService::Get, DcpServiceType::Request, 1};
  EXPECT_TRUE(tiny.failed());
  EXPECT_EQ(tiny.finish(), 0U);
  DcpWriter w{std::span(buf).first(16), DcpService::Get, DcpServiceType::Request, 1};
  EXPECT_TRUE(w.add_option(0x0202));
  EXPECT_TRUE(w.add_option(0x0102));
  EXPECT_TRUE(w.add_option(0x0103));
  EXPECT_FALSE(w.add_option(0x0104));
  EXPECT_EQ(w.finish(), 0U);
  // A block needs its pad octet to fit too.
  DcpWriter odd{std::span(buf).first(17), DcpService::Identify, DcpServiceType::Request, 1};
  EXPECT_FALSE(odd.add_raw(dcp_option::kNameOfStation, std::array<std::uint8_t, 3>{'a', 'b', 'c'}));
  // Set response with no result, odd device options.
  EXPECT_EQ(encode_set_response(buf, 1, {}), 0U);
  DcpDeviceInfo d;
  static constexpr std::array<std::uint8_t, 3> kOdd{1, 2, 3};
  d.has_device_options = true;
  d.device_options = kOdd;
  EXPECT_EQ(encode_identify_response(buf, 1, d), 0U);
}

TEST(PnDcp, MalformedHeaders) {
  const Bytes good = hex("05 00 01 02 03 04 00 01 00 04  FF FF 00 00");
  EXPECT_TRUE(decode_dcp(good).ok());
  EXPECT_EQ(decode_dcp(std::span(good).first(9)).error, DcpError::TruncatedHeader);
  EXPECT_EQ(decode_dcp(std::span(good).first(13)).error, DcpError::DataLengthBeyondPdu);  // length lies
  Bytes b = good;
  b[0] = 7;
  EXPECT_EQ(decode_dcp(b).error, DcpError::UnknownService);
  b = good;
  b[1] = 2;
  EXPECT_EQ(decode_dcp(b).error, DcpError::UnknownServiceType);
  // Ethernet padding after DCPDataLength is not a block.
  Bytes padded = good;
  padded.resize(44, 0);
  const DcpPdu p = decode_dcp(padded);
  ASSERT_TRUE(p.ok());
  EXPECT_EQ(p.blocks.size(), 4U);
  // Each decoder refuses the other services and passes header errors on.
  EXPECT_EQ(decode_device_info(decode_dcp(good)).error, DcpError::UnexpectedService);
  std::array<DcpSetResult, 2> r{};
  EXPECT_EQ(decode_set_response(decode_dcp(good), r).error, DcpError::UnexpectedService);
  EXPECT_EQ(decode_get_request(decode_dcp(good)).error, DcpError::UnexpectedService);
  EXPECT_EQ(decode_identify_request(decode_dcp(kIdentifyResponse)).error, DcpError::UnexpectedService);
  EXPECT_EQ(decode_identify_request(decode_dcp(std::span(good).first(5))).error, DcpError::TruncatedHeader);
  EXPECT_EQ(decode_device_info(decode_dcp(std::span(good).first(5))).error, DcpError::TruncatedHeader);
  EXPECT_EQ(decode_set_response(decode_dcp(std::span(good).first(5)), r).error, DcpError::TruncatedHeader);
  EXPECT_EQ(decode_get_request(decode_dcp(std::span(good).first(5))).error, DcpError::TruncatedHeader);
}

TEST(PnDcp, MalformedBlocks) {
  // Block header cut off: 3 octets of data.
  EXPECT_EQ(decode_identify_request(decode_dcp(hex("05 00 00 00 00 01 00 01 00 03  FF FF 00"))).error,
            DcpError::TruncatedBlockHeader);
  // Block length lies: 6 announced, 2 present.
  EXPECT_EQ(decode_identify_request(decode_dcp(hex("05 00 00 00 00 01 00 01 00 06  02 02 00 06 61 62"))).error,
            DcpError::BlockBeyondData);
  // No filter at all.
  EXPECT_EQ(decode_identify_request(decode_dcp(hex("05 00 00 00 00 01 00 01 00 00"))).error, DcpError::NoBlocks);
  // IP parameter with an odd length (13: one octet short, then its pad).
  EXPECT_EQ(decode_device_info(decode_dcp(hex("05 01 00 00 00 01 00 00 00 12"
                                              "01 02 00 0D 00 01 C0 A8 00 0A FF FF FF 00 00 00 00 00")))
                .error,
            DcpError::BadBlockLength);
  // DeviceID of 3 octets, DeviceRole of 1, DeviceInstance of 3, MAC of 5, odd DeviceOptions.
  for (const char* v : {"02 03 00 05 00 00 00 2A 03 00", "02 04 00 03 00 00 01 00", "02 07 00 05 00 00 00 01 02 00",
                        "01 01 00 07 00 00 00 1B 1B 12 34 00", "02 05 00 05 00 00 01 02 02 00",
                        "02 08 00 04 00 00 12 34", "06 01 00 03 00 00 01 00"}) {
    Bytes pdu = hex("05 01 00 00 00 01 00 00 00 00");
    const Bytes block = hex(v);
    pdu[9] = static_cast<std::uint8_t>(block.size());
    pdu.insert(pdu.end(), block.begin(), block.end());
    EXPECT_EQ(decode_device_info(decode_dcp(pdu)).error, DcpError::BadBlockLength) << v;
  }
  // A response block without its BlockInfo.
  EXPECT_EQ(decode_device_info(decode_dcp(hex("05 01 00 00 00 01 00 00 00 06  02 02 00 01 61 00"))).error,
            DcpError::BlockTooShort);
  // Set request block without its BlockQualifier.
  DcpBlock b;
  b.option = 2;
  b.suboption = 2;
  DcpSetBlock s;
  EXPECT_EQ(read_set_block(b, s), DcpError::BlockTooShort);
  IpSuite ipv;
  EXPECT_EQ(read_ip_suite(std::array<std::uint8_t, 11>{}, ipv), DcpError::BadBlockLength);
  // Set responses: not Control/Response, a Response block of 4 octets, none at all.
  std::array<DcpSetResult, 2> r{};
  EXPECT_EQ(decode_set_response(decode_dcp(hex("04 01 00 00 00 01 00 00 00 08  05 03 00 04 00 00 01 00")), r).error,
            DcpError::WrongResponseBlock);
  EXPECT_EQ(decode_set_response(decode_dcp(hex("04 01 00 00 00 01 00 00 00 08  05 04 00 04 02 02 00 00")), r).error,
            DcpError::BadBlockLength);
  EXPECT_EQ(decode_set_response(decode_dcp(hex("04 01 00 00 00 01 00 00 00 00")), r).error, DcpError::NoBlocks);
  EXPECT_EQ(decode_set_response(decode_dcp(hex("04 01 00 00 00 01 00 00 00 02  05 04")), r).error,
            DcpError::TruncatedBlockHeader);
  // Get requests: odd option list, empty.
  EXPECT_EQ(decode_get_request(decode_dcp(hex("03 00 00 00 00 01 00 00 00 03  02 02 01"))).error,
            DcpError::OddGetRequest);
  EXPECT_EQ(decode_get_request(decode_dcp(hex("03 00 00 00 00 01 00 00 00 00"))).error, DcpError::NoBlocks);
  EXPECT_EQ(to_string(DcpError::BlockBeyondData), "DCPBlockLength runs past DCPDataLength");
}

TEST(PnDcp, Names) {
  EXPECT_EQ(dcp_option_name(dcp_option::kNameOfStation), "NameOfStation");
  EXPECT_EQ(dcp_option_name(dcp_option::kDhcpClientId), "DHCP client identifier");
  EXPECT_EQ(dcp_option_name(0x0799), "unknown");
  EXPECT_EQ(to_string(DcpService::Identify), "Identify");
  EXPECT_EQ(to_string(DcpServiceType::ResponseNotSupported), "response: request not supported");
  EXPECT_EQ(to_string(static_cast<DcpBlockError>(9)), "unknown block error");
}

TEST(PnDcp, IpSuiteProblems) {
  const auto suite = [](std::array<std::uint8_t, 4> a, std::array<std::uint8_t, 4> m, std::array<std::uint8_t, 4> g) {
    IpSuite s;
    s.address = a;
    s.netmask = m;
    s.gateway = g;
    return s;
  };
  EXPECT_EQ(ip_suite_problem(suite({192, 168, 0, 10}, {255, 255, 255, 0}, {192, 168, 0, 1})), "");
  EXPECT_EQ(ip_suite_problem(suite({192, 168, 0, 10}, {255, 255, 255, 0}, {0, 0, 0, 0})), "");
  EXPECT_EQ(ip_suite_problem(suite({192, 168, 0, 10}, {255, 255, 255, 0}, {192, 168, 0, 10})), "");
  EXPECT_EQ(ip_suite_problem(suite({10, 0, 0, 1}, {255, 255, 255, 254}, {0, 0, 0, 0})), "");
  EXPECT_EQ(ip_suite_problem(IpSuite{}), "");
  EXPECT_EQ(ip_suite_problem(suite({0, 0, 0, 0}, {255, 255, 255, 0}, {0, 0, 0, 0})),
            "the address is 0.0.0.0 but netmask or gateway is not");
  EXPECT_EQ(ip_suite_problem(suite({192, 168, 0, 10}, {255, 0, 255, 0}, {0, 0, 0, 0})),
            "the netmask's ones are not contiguous");
  EXPECT_EQ(ip_suite_problem(suite({192, 168, 0, 10}, {0, 0, 0, 0}, {0, 0, 0, 0})), "the netmask is 0.0.0.0");
  EXPECT_EQ(ip_suite_problem(suite({0, 1, 2, 3}, {255, 0, 0, 0}, {0, 0, 0, 0})),
            "the address is in 0.0.0.0/8 (this network)");
  EXPECT_EQ(ip_suite_problem(suite({127, 0, 0, 1}, {255, 0, 0, 0}, {0, 0, 0, 0})),
            "the address is a loopback address (127.0.0.0/8)");
  EXPECT_EQ(ip_suite_problem(suite({239, 1, 1, 1}, {255, 255, 255, 0}, {0, 0, 0, 0})),
            "the address is multicast or reserved (224.0.0.0 and above)");
  EXPECT_EQ(ip_suite_problem(suite({192, 168, 0, 0}, {255, 255, 255, 0}, {0, 0, 0, 0})),
            "the address is the subnet's network address");
  EXPECT_EQ(ip_suite_problem(suite({192, 168, 0, 255}, {255, 255, 255, 0}, {0, 0, 0, 0})),
            "the address is the subnet's broadcast address");
  EXPECT_EQ(ip_suite_problem(suite({192, 168, 0, 10}, {255, 255, 255, 0}, {192, 168, 1, 1})),
            "the gateway is outside the address's subnet");
}

}  // namespace
}  // namespace drivegate::profinet
