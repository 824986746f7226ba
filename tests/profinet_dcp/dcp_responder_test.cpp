// DcpResponder on its own: requests written with the wire encoders go in, its frames are decoded.
// Get, Set with unknown options and bad values, Identify filters, retries, malformed requests.
#include <gtest/gtest.h>

#include "adapters/profinet/wire/byte_order.hpp"
#include "tests/profinet_dcp/hub.hpp"

namespace drivegate::profinet::test {
namespace {

struct Device {
  DcpResponder r{device(0x0123, "drive-1", suite(10))};
  core::TimePoint now{};
  std::array<std::uint8_t, kMaxFrameSize> out{};

  // Sends a request PDU written by `body` (FrameID `id`, to `dst`) and returns the answer due by
  // `wait`, or an empty vector.
  template <typename Body>
  Bytes ask(std::uint16_t id, Body body, MacAddress dst = {}, core::Duration wait = 0ms) {
    std::array<std::uint8_t, kMaxFrameSize> buf{};
    EthernetHeader h;
    h.dst = dst == MacAddress{} ? r.mac() : dst;
    h.src = kControllerMac;
    h.frame_id = id;
    const std::size_t at = encode_ethernet_header(h, buf);
    const std::size_t size = pad_frame(buf, at + body(std::span<std::uint8_t>(buf).subspan(at)));
    EXPECT_TRUE(r.on_frame(std::span<const std::uint8_t>(buf).first(size), now));
    now += wait;
    const std::size_t n = r.poll(now, out);
    return Bytes(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(n));
  }
  Bytes set(std::uint16_t option, std::uint16_t qualifier, std::span<const std::uint8_t> data, std::uint32_t xid = 9) {
    return ask(frame_id::kDcpGetSet, [&](std::span<std::uint8_t> o) {
      DcpWriter w(o, DcpService::Set, DcpServiceType::Request, xid);
      w.add(option, qualifier, data);
      return w.finish();
    });
  }
};

DcpPdu pdu_of(const Bytes& frame) {
  const EthernetView e = decode_ethernet(frame);
  EXPECT_TRUE(e.ok());
  return decode_dcp(e.pdu);
}

DcpSetResult one_result(const Bytes& frame) {
  std::array<DcpSetResult, 4> res{};
  const DcpSetResponse s = decode_set_response(pdu_of(frame), res);
  EXPECT_EQ(s.error, DcpError::None);
  EXPECT_EQ(s.count, 1U);
  return res[0];
}

TEST(PnDcpResponder, SetWithUnknownOptionOrSuboptionGetsTheBlockError) {
  Device d;
  const std::array<std::uint8_t, 2> v{0, 0};
  DcpSetResult r = one_result(d.set(0x7F01, 0, v));
  EXPECT_EQ(r.id, 0x7F01);
  EXPECT_EQ(r.error, DcpBlockError::OptionNotSupported);
  r = one_result(d.set(0x0206, 0, v, 10));  // AliasName: option 2 known, suboption not settable here
  EXPECT_EQ(r.error, DcpBlockError::SuboptionNotSupported);
  r = one_result(d.set(dcp_option::kFactoryReset, 0, v, 11));
  EXPECT_EQ(r.error, DcpBlockError::SuboptionNotSupported);
  EXPECT_EQ(d.r.counters().set_errors, 3U);
  // The same Xid from the same requester again is a retry: the stored answer, nothing done again.
  r = one_result(d.set(dcp_option::kSignal, 0, std::array<std::uint8_t, 2>{1, 0}, 11));
  EXPECT_EQ(r.id, dcp_option::kFactoryReset);
  EXPECT_EQ(d.r.counters().retries_answered, 1U);
  EXPECT_EQ(d.r.counters().signals, 0U);
}

TEST(PnDcpResponder, SetWithBadValuesIsRefusedAndChangesNothing) {
  Device d;
  const std::string_view upper = "Drive-2";
  DcpSetResult r = one_result(d.set(dcp_option::kNameOfStation, 1,
                                    std::span(reinterpret_cast<const std::uint8_t*>(upper.data()), upper.size())));
  EXPECT_EQ(r.error, DcpBlockError::SuboptionNotSet);
  EXPECT_EQ(d.r.name_of_station(), "drive-1");
  const std::array<std::uint8_t, 12> broadcast{192, 168, 0, 255, 255, 255, 255, 0, 0, 0, 0, 0};
  r = one_result(d.set(dcp_option::kIpParameter, 1, broadcast, 10));
  EXPECT_EQ(r.error, DcpBlockError::SuboptionNotSet);
  const std::array<std::uint8_t, 8> short_ip{192, 168, 0, 20, 255, 255, 255, 0};
  r = one_result(d.set(dcp_option::kIpParameter, 1, short_ip, 11));
  EXPECT_EQ(r.error, DcpBlockError::SuboptionNotSet);
  EXPECT_EQ(d.r.ip(), suite(10));
  const std::array<std::uint8_t, 2> blink_forever{0x01, 0x01};
  r = one_result(d.set(dcp_option::kSignal, 0, blink_forever, 12));
  EXPECT_EQ(r.error, DcpBlockError::SuboptionNotSet);
  EXPECT_EQ(d.r.counters().signals, 0U);
}

TEST(PnDcpResponder, EmptyNameRemovesTheName) {
  Device d;
  EXPECT_EQ(one_result(d.set(dcp_option::kNameOfStation, 1, {})).error, DcpBlockError::NoError);
  EXPECT_EQ(d.r.name_of_station(), "");
  d.r.power_cycle();
  EXPECT_EQ(d.r.name_of_station(), "");
}

TEST(PnDcpResponder, SetOfSeveralBlocksAnswersEach) {
  Device d;
  const Bytes reply = d.ask(frame_id::kDcpGetSet, [](std::span<std::uint8_t> o) {
    DcpWriter w(o, DcpService::Set, DcpServiceType::Request, 3);
    const std::array<std::uint8_t, 0> none{};
    w.add(dcp_option::kStartTransaction, 0, none);
    w.add(dcp_option::kNameOfStation, 1, std::string_view("drive-9"));
    w.add(0x7F00, 0, none);
    w.add(dcp_option::kEndTransaction, 0, none);
    return w.finish();
  });
  std::array<DcpSetResult, 4> res{};
  const DcpSetResponse s = decode_set_response(pdu_of(reply), res);
  ASSERT_EQ(s.count, 4U);
  EXPECT_TRUE(s.any_failed);
  EXPECT_EQ(res[0].error, DcpBlockError::NoError);
  EXPECT_EQ(res[1].id, dcp_option::kNameOfStation);
  EXPECT_EQ(res[1].error, DcpBlockError::NoError);
  EXPECT_EQ(res[2].error, DcpBlockError::OptionNotSupported);
  EXPECT_EQ(res[3].error, DcpBlockError::NoError);
  EXPECT_EQ(d.r.name_of_station(), "drive-9");
}

TEST(PnDcpResponder, GetAnswersWhatItHasAndRefusesTheRest) {
  Device d;
  const std::array<std::uint16_t, 4> ask{dcp_option::kNameOfStation, dcp_option::kIpParameter,
                                         dcp_option::kDeviceId, dcp_option::kDhcpClientId};
  const Bytes reply =
      d.ask(frame_id::kDcpGetSet, [&](std::span<std::uint8_t> o) { return encode_get_request(o, 4, ask); });
  const DcpPdu pdu = pdu_of(reply);
  EXPECT_EQ(pdu.header.service, DcpService::Get);
  EXPECT_EQ(pdu.header.xid, 4U);
  const DcpDeviceInfoView v = decode_device_info(pdu);
  ASSERT_EQ(v.error, DcpError::None);
  EXPECT_EQ(v.info.name_of_station, "drive-1");
  EXPECT_EQ(v.info.ip, suite(10));
  EXPECT_EQ(v.info.vendor_id, 0x0118);
  EXPECT_EQ(v.info.other_blocks, 1U);  // the Control/Response block for DHCP
  DcpBlockReader r(pdu.blocks);
  DcpBlock b;
  DcpBlock last;
  while (r.next(b)) last = b;
  ASSERT_EQ(last.id(), dcp_option::kResponse);
  EXPECT_EQ(last.value[0], 3);   // DHCP
  EXPECT_EQ(last.value[1], 61);  // client identifier
  EXPECT_EQ(last.value[2], static_cast<std::uint8_t>(DcpBlockError::OptionNotSupported));
}

TEST(PnDcpResponder, IdentifyFilters) {
  Device d;
  // Another name: silent. Its own name: answered after the MAC-derived delay.
  EXPECT_TRUE(d.ask(frame_id::kDcpIdentifyRequest,
                    [](std::span<std::uint8_t> o) { return encode_identify_name_request(o, 1, 1, "drive-2"); },
                    kDcpIdentifyMulticast)
                  .empty());
  EXPECT_EQ(d.r.counters().identify_not_matched, 1U);
  const core::Duration delay = d.r.response_delay(0x100);
  EXPECT_EQ(delay, std::chrono::milliseconds(10 * (0x0123 % 0x100)));
  EXPECT_TRUE(d.ask(frame_id::kDcpIdentifyRequest,
                    [](std::span<std::uint8_t> o) { return encode_identify_name_request(o, 2, 0x100, "drive-1"); },
                    kDcpIdentifyMulticast, delay - 1ms)
                  .empty());
  EXPECT_EQ(d.r.next_deadline(), d.now + 1ms);
  d.now += 1ms;
  const std::size_t n = d.r.poll(d.now, d.out);
  ASSERT_GT(n, 0U);
  const EthernetView e = decode_ethernet(std::span<const std::uint8_t>(d.out).first(n));
  EXPECT_EQ(e.frame_class, FrameClass::DcpIdentifyResponse);
  EXPECT_EQ(e.header.dst, kControllerMac);
  EXPECT_EQ(decode_dcp(e.pdu).header.xid, 2U);
  // A filter it does not match (DeviceID) goes unanswered; so does an Identify to another unicast MAC.
  EXPECT_TRUE(d.ask(frame_id::kDcpIdentifyRequest,
                    [](std::span<std::uint8_t> o) {
                      DcpWriter w(o, DcpService::Identify, DcpServiceType::Request, 3, 1);
                      const std::array<std::uint8_t, 4> ids{0x01, 0x18, 0x05, 0x01};
                      w.add_raw(dcp_option::kDeviceId, ids);
                      return w.finish();
                    },
                    kDcpIdentifyMulticast)
                  .empty());
  EXPECT_EQ(d.r.counters().identify_other_filter, 1U);
  EXPECT_TRUE(d.ask(frame_id::kDcpIdentifyRequest,
                    [](std::span<std::uint8_t> o) { return encode_identify_all_request(o, 4, 1); }, device_mac(9))
                  .empty());
  EXPECT_EQ(d.r.counters().not_for_us, 1U);
  // A factor of 0 (reserved) is taken as 1, above 1900h as 1900h.
  EXPECT_EQ(d.r.response_delay(0), 0ms);
  EXPECT_EQ(d.r.response_delay(0xFFFF), d.r.response_delay(kDcpMaxResponseDelayFactor));
}

TEST(PnDcpResponder, MalformedRequestsAreCountedAndDropped) {
  Device d;
  // No block; a Set block without its BlockQualifier; a block running past DCPDataLength; a Get with
  // an odd option list; a Set to another MAC.
  EXPECT_TRUE(d.ask(frame_id::kDcpGetSet, [](std::span<std::uint8_t> o) {
                 return DcpWriter(o, DcpService::Set, DcpServiceType::Request, 1).finish();
               }).empty());
  EXPECT_TRUE(d.ask(frame_id::kDcpGetSet, [](std::span<std::uint8_t> o) {
                 DcpWriter w(o, DcpService::Set, DcpServiceType::Request, 2);
                 const std::array<std::uint8_t, 1> one{0};
                 w.add_raw(dcp_option::kSignal, one);
                 return w.finish();
               }).empty());
  EXPECT_TRUE(d.ask(frame_id::kDcpGetSet, [](std::span<std::uint8_t> o) {
                 DcpWriter w(o, DcpService::Set, DcpServiceType::Request, 3);
                 w.add(dcp_option::kNameOfStation, 1, std::string_view("drive-3"));
                 const std::size_t n = w.finish();
                 put_be16(o, kDcpHeaderSize + 2, 40);  // DCPBlockLength beyond the data
                 return n;
               }).empty());
  EXPECT_TRUE(d.ask(frame_id::kDcpGetSet, [](std::span<std::uint8_t> o) {
                 DcpWriter w(o, DcpService::Get, DcpServiceType::Request, 4);
                 const std::array<std::uint8_t, 3> odd{2, 2, 2};
                 w.add_raw(0x0202, odd);
                 const std::size_t n = w.finish();
                 put_be16(o, 8, 3);
                 return n - 1;
               }).empty());
  EXPECT_EQ(d.r.counters().malformed, 4U);
  EXPECT_TRUE(d.ask(frame_id::kDcpGetSet, [](std::span<std::uint8_t> o) { return encode_set_signal_request(o, 5); },
                    device_mac(9))
                  .empty());
  EXPECT_EQ(d.r.counters().not_for_us, 1U);
  EXPECT_EQ(d.r.counters().sets, 0U);
  EXPECT_EQ(d.r.name_of_station(), "drive-1");
}

TEST(PnDcpResponder, RejectsAnUnusableConfig) {
  EXPECT_THROW(DcpResponder(device(1, "Drive-1")), std::invalid_argument);
  IpSuite bad = suite(10);
  bad.gateway = {10, 0, 0, 1};
  EXPECT_THROW(DcpResponder(device(1, "drive-1", bad)), std::invalid_argument);
}

}  // namespace
}  // namespace drivegate::profinet::test
