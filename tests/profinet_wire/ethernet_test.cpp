// Ethernet II + FrameID [IEC 61158-6-10: the RT frame and the coding of the field FrameID; IEEE 802.1Q].
#include "adapters/profinet/wire/ethernet.hpp"

#include <gtest/gtest.h>

#include <array>

#include "tests/profinet_wire/bytes.hpp"

namespace drivegate::profinet {
namespace {

using test::Bytes;
using test::hex;

constexpr MacAddress kDevice{0x00, 0x1B, 0x1B, 0x12, 0x34, 0x56};
constexpr MacAddress kController{0x02, 0x00, 0x00, 0x00, 0x00, 0x01};

TEST(PnEthernet, FrameIdClasses) {
  EXPECT_EQ(classify_frame_id(0x7FFF), FrameClass::Other);  // RT class 2/3 and PTCP below 8000h
  EXPECT_EQ(classify_frame_id(0x8000), FrameClass::RtCyclic);
  EXPECT_EQ(classify_frame_id(0xBFFF), FrameClass::RtCyclic);
  EXPECT_EQ(classify_frame_id(0xC000), FrameClass::RtCyclic);
  EXPECT_EQ(classify_frame_id(0xFBFF), FrameClass::RtCyclic);
  EXPECT_EQ(classify_frame_id(0xFC00), FrameClass::Other);
  EXPECT_EQ(classify_frame_id(0xFC01), FrameClass::AlarmHigh);
  EXPECT_EQ(classify_frame_id(0xFE01), FrameClass::AlarmLow);
  EXPECT_EQ(classify_frame_id(0xFEFC), FrameClass::DcpHello);
  EXPECT_EQ(classify_frame_id(0xFEFD), FrameClass::DcpGetSet);
  EXPECT_EQ(classify_frame_id(0xFEFE), FrameClass::DcpIdentifyRequest);
  EXPECT_EQ(classify_frame_id(0xFEFF), FrameClass::DcpIdentifyResponse);
  EXPECT_EQ(classify_frame_id(0xFF00), FrameClass::Other);
  EXPECT_TRUE(is_dcp(FrameClass::DcpGetSet));
  EXPECT_FALSE(is_dcp(FrameClass::AlarmLow));
  EXPECT_TRUE(is_alarm(FrameClass::AlarmLow));
  EXPECT_EQ(to_string(FrameClass::RtCyclic), "RT class 1 cyclic");
}

TEST(PnEthernet, UntaggedHeaderBytes) {
  std::array<std::uint8_t, 64> buf{};
  EthernetHeader h;
  h.dst = kDcpIdentifyMulticast;
  h.src = kController;
  h.frame_id = frame_id::kDcpIdentifyRequest;
  ASSERT_EQ(encode_ethernet_header(h, buf), 16U);
  EXPECT_EQ(Bytes(buf.begin(), buf.begin() + 16), hex("01 0E CF 00 00 00  02 00 00 00 00 01  88 92  FE FE"));
  ASSERT_EQ(pad_frame(buf, 16), 60U);
  EXPECT_EQ(buf[59], 0);
}

TEST(PnEthernet, PriorityTaggedHeaderBytes) {
  std::array<std::uint8_t, 64> buf{};
  EthernetHeader h;
  h.dst = kDevice;
  h.src = kController;
  h.vlan = true;
  h.priority = kPriorityRtCyclic;
  h.frame_id = 0x8001;
  ASSERT_EQ(encode_ethernet_header(h, buf), 20U);
  // TCI C000h: PCP 6, DEI 0, VID 0 (a priority tag) [IEEE 802.1Q §9.6].
  EXPECT_EQ(Bytes(buf.begin(), buf.begin() + 20),
            hex("00 1B 1B 12 34 56  02 00 00 00 00 01  81 00 C0 00  88 92  80 01"));
  const EthernetView v = decode_ethernet(std::span<const std::uint8_t>(buf).first(60));
  ASSERT_TRUE(v.ok()) << to_string(v.error);
  EXPECT_TRUE(v.header.vlan);
  EXPECT_EQ(v.header.priority, 6);
  EXPECT_EQ(v.header.vlan_id, 0);
  EXPECT_EQ(v.header.frame_id, 0x8001);
  EXPECT_EQ(v.header.dst, kDevice);
  EXPECT_EQ(v.header.src, kController);
  EXPECT_EQ(v.frame_class, FrameClass::RtCyclic);
  EXPECT_EQ(v.pdu_offset, 20U);
  EXPECT_EQ(v.pdu.size(), 40U);
}

TEST(PnEthernet, EncoderRefusals) {
  std::array<std::uint8_t, 64> buf{};
  EthernetHeader h;
  EXPECT_EQ(encode_ethernet_header(h, std::span(buf).first(15)), 0U);
  h.vlan = true;
  EXPECT_EQ(encode_ethernet_header(h, std::span(buf).first(19)), 0U);
  h.priority = 8;
  EXPECT_EQ(encode_ethernet_header(h, buf), 0U);
  h.priority = 0;
  h.vlan_id = 0x1000;
  EXPECT_EQ(encode_ethernet_header(h, buf), 0U);
  EXPECT_EQ(pad_frame(std::span(buf).first(59), 20), 0U);
  EXPECT_EQ(pad_frame(std::span(buf).first(10), 20), 0U);
  EXPECT_EQ(pad_frame(buf, 62), 62U);
}

TEST(PnEthernet, MalformedFrames) {
  const Bytes good = hex("01 0E CF 00 00 00  02 00 00 00 00 01  88 92  FE FE");
  EXPECT_TRUE(decode_ethernet(good).ok());
  EXPECT_EQ(decode_ethernet(std::span(good).first(13)).error, EthernetError::TruncatedHeader);
  EXPECT_EQ(decode_ethernet(std::span(good).first(15)).error, EthernetError::TruncatedFrameId);
  Bytes other = good;
  other[13] = 0xA4;
  EXPECT_EQ(decode_ethernet(other).error, EthernetError::WrongEtherType);
  const Bytes tag_cut = hex("01 0E CF 00 00 00  02 00 00 00 00 01  81 00 C0");
  EXPECT_EQ(decode_ethernet(tag_cut).error, EthernetError::TruncatedHeader);
  const Bytes tag_no_id = hex("01 0E CF 00 00 00  02 00 00 00 00 01  81 00 C0 00 88 92 80");
  EXPECT_EQ(decode_ethernet(tag_no_id).error, EthernetError::TruncatedFrameId);
  const Bytes tag_other = hex("01 0E CF 00 00 00  02 00 00 00 00 01  81 00 C0 00 08 00 45 00");
  EXPECT_EQ(decode_ethernet(tag_other).error, EthernetError::WrongEtherType);
  Bytes jumbo(1519, 0);
  EXPECT_EQ(decode_ethernet(jumbo).error, EthernetError::TooLong);
  EXPECT_EQ(to_string(EthernetError::WrongEtherType), "EtherType is not 8892h (PROFINET)");
}

TEST(PnEthernet, MacText) {
  EXPECT_STREQ(mac_text(MacAddress{0x00, 0x1B, 0x1B, 0x12, 0x34, 0xFE}).data(), "00:1b:1b:12:34:fe");
}

TEST(PnEthernet, ParseMacTakesSixHexOctets) {
  const MacAddress mac{0x00, 0x1B, 0x1B, 0x00, 0x0A, 0xFE};
  for (const char* good : {"00:1b:1b:00:0a:fe", "00-1B-1B-00-0A-FE"}) {
    const auto parsed = parse_mac(good);
    ASSERT_TRUE(parsed) << good;
    EXPECT_EQ(*parsed, mac) << good;
  }
  EXPECT_STREQ(mac_text(*parse_mac(mac_text(mac).data())).data(), "00:1b:1b:00:0a:fe");
  for (const char* bad : {"", "00:1b:1b:00:0a", "00:1b:1b:00:0a:fe:05", "00:1b:1b:00:0a:f", "00:1b:1b-00:0a:fe",
                          "00:1b:1b:00:0a:0g", "001b.1b00.0afe", "00:1b:1b:00:0a:fe ", "00:1b:1b:00:0a:+f"})
    EXPECT_FALSE(parse_mac(bad)) << bad;
}

}  // namespace
}  // namespace drivegate::profinet
