// DcpClient against DcpResponders on the in-memory hub, virtual time: Identify all / by name with
// the response window, Set name / IP / Signal, BlockErrors, timeouts and retries, and the frames
// that are counted and dropped.
#include <gtest/gtest.h>

#include <memory>

#include "tests/profinet_dcp/hub.hpp"

namespace drivegate::profinet::test {
namespace {

struct Segment {
  Hub hub;
  DcpClient client{kControllerMac, DcpClientTiming{}, 0x1000};
  std::vector<std::unique_ptr<DcpResponder>> devices;

  Segment() { hub.add(client); }
  DcpResponder& add(const DcpResponderConfig& c) {
    devices.push_back(std::make_unique<DcpResponder>(c));
    hub.add(*devices.back());
    return *devices.back();
  }
  DcpResult wait(DcpRequestId id) {
    EXPECT_NE(id, kNoDcpRequest);
    const bool ended = hub.run_until([&] {
      const auto s = client.result(id).status;
      return s == DcpRequestStatus::Done || s == DcpRequestStatus::Failed;
    });
    EXPECT_TRUE(ended);
    return client.result(id);
  }
};

// A whole Ethernet frame around a DCP PDU written by `body`.
template <typename Body>
Bytes dcp_frame(const MacAddress& dst, const MacAddress& src, std::uint16_t frame_id, Body body) {
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  EthernetHeader h;
  h.dst = dst;
  h.src = src;
  h.frame_id = frame_id;
  const std::size_t at = encode_ethernet_header(h, buf);
  const std::size_t n = body(std::span<std::uint8_t>(buf).subspan(at));
  const std::size_t size = pad_frame(buf, at + n);
  return Bytes(buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(size));
}

TEST(PnDcpClient, IdentifyWindow) {
  EXPECT_EQ(identify_window(0), 400ms);
  EXPECT_EQ(identify_window(1), 400ms);
  EXPECT_EQ(identify_window(2), 2s);       // 1 s + 20 ms, whole seconds
  EXPECT_EQ(identify_window(0x80), 3s);    // 1 s + 1.28 s
  EXPECT_EQ(identify_window(0x1900), 65s); // 1 s + 64 s
}

TEST(PnDcpClient, IdentifyAllCollectsEveryDeviceWithinTheWindow) {
  Segment seg;
  for (std::uint16_t i = 0; i < 5; ++i) {
    seg.add(device(static_cast<std::uint16_t>(0x0100 + 37 * i), "drive-" + std::to_string(i), suite(static_cast<std::uint8_t>(10 + i))));
  }
  std::array<DcpStation, 8> found{};
  const core::TimePoint start = seg.hub.now;
  const DcpRequestId id = seg.client.identify_all(found, 0x80);
  const DcpResult r = seg.wait(id);
  EXPECT_EQ(r.status, DcpRequestStatus::Done);
  EXPECT_EQ(r.stations, 5U);
  EXPECT_EQ(r.stations_lost, 0U);
  EXPECT_EQ(seg.hub.now - start, identify_window(0x80));  // collected until the window closed
  const auto stations = seg.client.stations(id);
  ASSERT_EQ(stations.size(), 5U);
  for (std::size_t i = 0; i < 5; ++i) {
    const DcpResponder& d = *seg.devices[i];
    const auto it = std::find_if(stations.begin(), stations.end(), [&](const DcpStation& s) { return s.mac == d.mac(); });
    ASSERT_NE(it, stations.end());
    EXPECT_EQ(it->name(), "drive-" + std::to_string(i));
    EXPECT_EQ(it->type_of_station(), "AKD");
    EXPECT_TRUE(it->has_device_id);
    EXPECT_EQ(it->vendor_id, 0x0118);
    EXPECT_EQ(it->device_id, 0x0501);
    EXPECT_EQ(it->ip, suite(static_cast<std::uint8_t>(10 + i)));
    EXPECT_EQ(it->ip_block_info, ip_block_info::kSet);
    EXPECT_EQ(d.counters().identify_answered, 1U);
  }
  // Each answer left after 10 ms × (MAC low 16 bits mod 128) [the spread the factor asks for].
  for (std::size_t k = 1; k < seg.hub.log.size(); ++k) {
    const Bytes& f = seg.hub.log[k];
    MacAddress src{};
    std::copy_n(f.begin() + 6, 6, src.begin());
    const DcpResponder& d = **std::find_if(seg.devices.begin(), seg.devices.end(), [&](const auto& p) { return p->mac() == src; });
    EXPECT_EQ(seg.hub.log_time[k] - start, d.response_delay(0x80));
    EXPECT_EQ(d.response_delay(0x80), std::chrono::milliseconds(10 * (((src[4] << 8) | src[5]) % 0x80)));
  }
  EXPECT_EQ(seg.client.counters().responses, 5U);
  EXPECT_EQ(seg.client.take(id).stations, 5U);
  EXPECT_EQ(seg.client.result(id).status, DcpRequestStatus::Unknown);
}

TEST(PnDcpClient, IdentifyAllKeepsWhatFitsAndCountsTheRest) {
  Segment seg;
  for (std::uint16_t i = 0; i < 4; ++i) seg.add(device(static_cast<std::uint16_t>(i + 1), "d" + std::to_string(i)));
  std::array<DcpStation, 2> found{};
  const DcpResult r = seg.wait(seg.client.identify_all(found, 4));
  EXPECT_EQ(r.stations, 2U);
  EXPECT_EQ(r.stations_lost, 2U);
}

TEST(PnDcpClient, IdentifyByNameFindsOneAndOthersStaySilent) {
  Segment seg;
  seg.add(device(1, "drive-a", suite(10)));
  DcpResponder& b = seg.add(device(2, "drive-b", suite(11)));
  DcpResponder& unnamed = seg.add(device(3, ""));
  std::array<DcpStation, 4> found{};
  const DcpRequestId id = seg.client.identify_name("drive-b", found);
  const DcpResult r = seg.wait(id);
  ASSERT_EQ(r.stations, 1U);
  EXPECT_EQ(found[0].mac, b.mac());
  EXPECT_EQ(found[0].name(), "drive-b");
  EXPECT_EQ(seg.devices[0]->counters().identify_not_matched, 1U);
  EXPECT_EQ(seg.devices[0]->counters().identify_answered, 0U);
  EXPECT_EQ(unnamed.counters().identify_not_matched, 1U);
  // One request frame and one response on the wire.
  EXPECT_EQ(seg.hub.log.size(), 2U);
}

TEST(PnDcpClient, IdentifyByNameListsEveryDeviceWithThatName) {
  Segment seg;
  DcpResponder& a = seg.add(device(0x0105, "twin"));
  DcpResponder& b = seg.add(device(0x0203, "twin"));
  std::array<DcpStation, 4> found{};
  const DcpResult r = seg.wait(seg.client.identify_name("twin", found, 0x10));
  ASSERT_EQ(r.stations, 2U);
  EXPECT_TRUE((found[0].mac == a.mac() && found[1].mac == b.mac()) || (found[0].mac == b.mac() && found[1].mac == a.mac()));
}

TEST(PnDcpClient, RefusesBadArguments) {
  Segment seg;
  std::array<DcpStation, 1> found{};
  EXPECT_EQ(seg.client.identify_all(found, 0), kNoDcpRequest);
  EXPECT_EQ(seg.client.identify_all(found, 0x1901), kNoDcpRequest);
  EXPECT_EQ(seg.client.identify_name("Drive-1", found), kNoDcpRequest);
  EXPECT_EQ(seg.client.set_name(device_mac(1), "a..b", DcpQualifier::Permanent), kNoDcpRequest);
  IpSuite bad = suite(10);
  bad.netmask = {255, 0, 255, 0};
  EXPECT_EQ(seg.client.set_ip(device_mac(1), bad, DcpQualifier::Permanent), kNoDcpRequest);
  EXPECT_EQ(seg.client.counters().refused, 5U);
  EXPECT_TRUE(seg.client.idle());
}

TEST(PnDcpClient, SetNameTemporaryIsLostAtPowerCyclePermanentStays) {
  Segment seg;
  DcpResponder& d = seg.add(device(7, "old-name", suite(10)));
  DcpResult r = seg.wait(seg.client.set_name(d.mac(), "new-name", DcpQualifier::Temporary));
  EXPECT_EQ(r.status, DcpRequestStatus::Done);
  EXPECT_EQ(r.frames_sent, 1);
  EXPECT_EQ(d.name_of_station(), "new-name");
  d.power_cycle();
  EXPECT_EQ(d.name_of_station(), "");  // a temporary name clears the stored one

  r = seg.wait(seg.client.set_name(d.mac(), "kept-name", DcpQualifier::Permanent));
  EXPECT_EQ(r.status, DcpRequestStatus::Done);
  d.power_cycle();
  EXPECT_EQ(d.name_of_station(), "kept-name");
  EXPECT_EQ(d.counters().sets, 2U);
}

TEST(PnDcpClient, SetIpTemporaryAndPermanent) {
  Segment seg;
  DcpResponder& d = seg.add(device(7, "drive-1", suite(10)));
  EXPECT_EQ(seg.wait(seg.client.set_ip(d.mac(), suite(20), DcpQualifier::Permanent)).status, DcpRequestStatus::Done);
  EXPECT_EQ(d.ip(), suite(20));
  EXPECT_EQ(seg.wait(seg.client.set_ip(d.mac(), suite(30), DcpQualifier::Temporary)).status, DcpRequestStatus::Done);
  EXPECT_EQ(d.ip(), suite(30));
  d.power_cycle();
  EXPECT_EQ(d.ip(), IpSuite{});  // temporary: no address after power-up
  // What an Identify reports after that: no IP set.
  std::array<DcpStation, 1> found{};
  ASSERT_EQ(seg.wait(seg.client.identify_all(found, 1)).stations, 1U);
  EXPECT_EQ(found[0].ip_block_info, ip_block_info::kNotSet);
}

TEST(PnDcpClient, SignalFlashesOnce) {
  Segment seg;
  DcpResponder& d = seg.add(device(7, "drive-1"));
  int flashes = 0;
  d.on_signal([&] { ++flashes; });
  const DcpResult r = seg.wait(seg.client.signal(d.mac()));
  EXPECT_EQ(r.status, DcpRequestStatus::Done);
  EXPECT_EQ(r.option, dcp_option::kSignal);
  EXPECT_EQ(flashes, 1);
  EXPECT_EQ(d.counters().signals, 1U);
}

TEST(PnDcpClient, SetRefusedInOperationCarriesTheBlockError) {
  Segment seg;
  DcpResponder& d = seg.add(device(7, "drive-1", suite(10)));
  d.set_in_operation(true);
  const DcpResult r = seg.wait(seg.client.set_ip(d.mac(), suite(20), DcpQualifier::Permanent));
  EXPECT_EQ(r.status, DcpRequestStatus::Failed);
  EXPECT_EQ(r.failure, DcpFailure::BlockError);
  EXPECT_EQ(r.block_error, DcpBlockError::InOperation);
  EXPECT_EQ(to_string(r.failure), "the device refused the value (BlockError)");
  EXPECT_FALSE(to_string(r.block_error).empty());
  EXPECT_EQ(d.ip(), suite(10));
  // The Signal still works in operation.
  EXPECT_EQ(seg.wait(seg.client.signal(d.mac())).status, DcpRequestStatus::Done);
  EXPECT_EQ(seg.client.counters().failed, 1U);
}

TEST(PnDcpClient, SetRetriesAfterALostRequestWithTheSameXid) {
  Segment seg;
  DcpResponder& d = seg.add(device(7, "drive-1", suite(10)));
  int lost = 0;
  seg.hub.drop = [&](std::span<const std::uint8_t> f) {
    const bool set_request = f[12] == 0x88 && f[13] == 0x92 && f[14] == 0xFE && f[15] == 0xFD && f[16] == 4 && f[17] == 0;
    return set_request && lost++ == 0;
  };
  const core::TimePoint start = seg.hub.now;
  const DcpResult r = seg.wait(seg.client.set_name(d.mac(), "drive-2", DcpQualifier::Permanent));
  EXPECT_EQ(r.status, DcpRequestStatus::Done);
  EXPECT_EQ(r.frames_sent, 2);
  EXPECT_EQ(seg.hub.now - start, DcpClientTiming{}.set_timeout);
  EXPECT_EQ(seg.client.counters().retries, 1U);
  ASSERT_EQ(seg.hub.log.size(), 3U);
  EXPECT_TRUE(std::equal(seg.hub.log[0].begin() + 18, seg.hub.log[0].begin() + 22, seg.hub.log[1].begin() + 18));  // Xid
  EXPECT_EQ(d.name_of_station(), "drive-2");
}

TEST(PnDcpClient, ARetryAfterALostResponseIsAnsweredWithoutActingTwice) {
  Segment seg;
  DcpResponder& d = seg.add(device(7, "drive-1"));
  int lost = 0;
  seg.hub.drop = [&](std::span<const std::uint8_t> f) {
    const bool set_response = f[14] == 0xFE && f[15] == 0xFD && f[16] == 4 && f[17] == 1;
    return set_response && lost++ == 0;
  };
  const DcpResult r = seg.wait(seg.client.signal(d.mac()));
  EXPECT_EQ(r.status, DcpRequestStatus::Done);
  EXPECT_EQ(r.frames_sent, 2);
  EXPECT_EQ(d.counters().signals, 1U);
  EXPECT_EQ(d.counters().retries_answered, 1U);
}

TEST(PnDcpClient, SetTimesOutAfterEveryRetry) {
  Segment seg;
  DcpClientTiming timing;
  timing.set_timeout = 200ms;
  timing.set_retries = 3;
  DcpClient client(kControllerMac, timing);
  seg.hub.add(client);
  const core::TimePoint start = seg.hub.now;
  const DcpRequestId id = client.set_ip(device_mac(99), suite(10), DcpQualifier::Temporary);  // nobody there
  ASSERT_TRUE(seg.hub.run_until([&] { return client.result(id).status == DcpRequestStatus::Failed; }));
  const DcpResult r = client.result(id);
  EXPECT_EQ(r.failure, DcpFailure::Timeout);
  EXPECT_EQ(r.frames_sent, 4);
  EXPECT_EQ(seg.hub.now - start, 4 * 200ms);
  EXPECT_EQ(client.counters().timeouts, 1U);
  EXPECT_EQ(client.counters().retries, 3U);
  EXPECT_EQ(to_string(r.failure), "no response (timeout after every retry)");
}

TEST(PnDcpClient, QueueIsFifoAndBounded) {
  Segment seg;
  DcpResponder& d = seg.add(device(7, "drive-1"));
  std::vector<DcpRequestId> ids;
  for (std::size_t i = 0; i < DcpClient::kQueueDepth; ++i) ids.push_back(seg.client.signal(d.mac()));
  EXPECT_EQ(seg.client.signal(d.mac()), kNoDcpRequest);
  EXPECT_EQ(seg.client.counters().queue_full, 1U);
  // A queued request taken before it starts never goes out.
  EXPECT_EQ(seg.client.take(ids[3]).status, DcpRequestStatus::Queued);
  ASSERT_TRUE(seg.hub.run_until([&] { return seg.client.idle(); }));
  EXPECT_EQ(d.counters().signals, DcpClient::kQueueDepth - 1);
  std::uint32_t last_xid = 0;
  for (std::size_t i = 0; i < ids.size(); ++i) {
    if (i == 3) continue;
    const DcpResult r = seg.client.result(ids[i]);
    EXPECT_EQ(r.status, DcpRequestStatus::Done);
    EXPECT_GT(r.xid, last_xid);  // one Xid per request, in submission order
    last_xid = r.xid;
  }
}

TEST(PnDcpClient, ForeignAndMalformedFramesAreCountedAndDropped) {
  Segment seg;
  DcpResponder& d = seg.add(device(7, "drive-1", suite(10)));
  std::array<DcpStation, 4> found{};
  const DcpRequestId id = seg.client.identify_all(found, 1);
  ASSERT_NE(seg.hub.run_until([&] { return seg.hub.log.size() >= 2; }), false);  // request and answer
  const std::uint32_t xid = seg.client.result(id).xid;
  DcpDeviceInfo other;
  other.has_name_of_station = true;
  other.name_of_station = "intruder";
  const MacAddress stranger = device_mac(0x4242);
  // Another Xid, a Set response while an Identify is in flight, a truncated DCP header, a Hello,
  // an Identify request of another controller, and a frame that is not PROFINET.
  seg.hub.inject(dcp_frame(kControllerMac, stranger, frame_id::kDcpIdentifyResponse,
                           [&](std::span<std::uint8_t> o) { return encode_identify_response(o, xid + 1, other); }));
  seg.hub.inject(dcp_frame(kControllerMac, stranger, frame_id::kDcpGetSet, [&](std::span<std::uint8_t> o) {
    const std::array<DcpSetResult, 1> res{{{dcp_option::kSignal, DcpBlockError::NoError}}};
    return encode_set_response(o, xid, res);
  }));
  Bytes truncated = dcp_frame(kControllerMac, stranger, frame_id::kDcpIdentifyResponse,
                              [&](std::span<std::uint8_t> o) { return encode_identify_response(o, xid, other); });
  truncated[16 + 9] = 0xFF;  // DCPDataLength beyond the frame
  seg.hub.inject(truncated);
  seg.hub.inject(dcp_frame(kDcpHelloMulticast, stranger, frame_id::kDcpHello,
                           [&](std::span<std::uint8_t> o) { return encode_hello(o, 5, other); }));
  seg.hub.inject(dcp_frame(kDcpIdentifyMulticast, stranger, frame_id::kDcpIdentifyRequest,
                           [&](std::span<std::uint8_t> o) { return encode_identify_all_request(o, 77, 1); }));
  // What a port that sees all traffic may pass up: a response to another controller, with our Xid.
  EXPECT_TRUE(seg.client.on_frame(dcp_frame(device_mac(0x5555), stranger, frame_id::kDcpIdentifyResponse,
                                            [&](std::span<std::uint8_t> o) { return encode_identify_response(o, xid, other); }),
                                  seg.hub.now));
  Bytes ipv4(60, 0);
  ipv4[12] = 0x08;
  EXPECT_FALSE(seg.client.on_frame(ipv4, seg.hub.now));

  const DcpResult r = seg.wait(id);
  ASSERT_EQ(r.stations, 1U);
  EXPECT_EQ(found[0].mac, d.mac());
  const DcpClientCounters& c = seg.client.counters();
  EXPECT_EQ(c.foreign_xid, 1U);
  EXPECT_EQ(c.wrong_service, 1U);
  EXPECT_EQ(c.malformed, 1U);
  EXPECT_EQ(c.requests_seen, 2U);  // the Hello and the other controller's Identify
  EXPECT_EQ(c.not_for_us, 1U);
  EXPECT_EQ(c.responses, 1U);
  // The device answered the other controller's Identify too (to the other controller).
  EXPECT_EQ(d.counters().identify_answered, 2U);

  // After the window: a late answer is unsolicited; a Set response from another MAC is dropped.
  seg.hub.inject(dcp_frame(kControllerMac, stranger, frame_id::kDcpIdentifyResponse,
                           [&](std::span<std::uint8_t> o) { return encode_identify_response(o, xid, other); }));
  EXPECT_EQ(seg.client.counters().unsolicited, 1U);
}

TEST(PnDcpClient, SetResponseFromAnotherMacDoesNotCount) {
  Segment seg;
  DcpResponder& d = seg.add(device(7, "drive-1"));
  const DcpRequestId id = seg.client.signal(d.mac());
  seg.hub.drop = [](std::span<const std::uint8_t> f) { return f[17] == 1; };  // lose the real answer
  ASSERT_TRUE(seg.hub.run_until([&] { return seg.hub.log.size() >= 1; }));
  const std::uint32_t xid = seg.client.result(id).xid;
  seg.hub.drop = nullptr;
  seg.hub.inject(dcp_frame(kControllerMac, device_mac(8), frame_id::kDcpGetSet, [&](std::span<std::uint8_t> o) {
    const std::array<DcpSetResult, 1> res{{{dcp_option::kSignal, DcpBlockError::NoError}}};
    return encode_set_response(o, xid, res);
  }));
  EXPECT_EQ(seg.client.counters().wrong_source, 1U);
  EXPECT_EQ(seg.client.result(id).status, DcpRequestStatus::InFlight);
  EXPECT_EQ(seg.wait(id).status, DcpRequestStatus::Done);  // the retry's answer
}

TEST(PnDcpClient, TakeWhileInFlightDiscardsTheResult) {
  Segment seg;
  DcpResponder& d = seg.add(device(7, "drive-1"));
  std::array<DcpStation, 2> found{};
  const DcpRequestId id = seg.client.identify_all(found, 0x10);  // the device answers after 70 ms
  ASSERT_TRUE(seg.hub.run_until([&] { return seg.hub.log.size() >= 1; }));
  ASSERT_EQ(seg.hub.log.size(), 1U);
  EXPECT_EQ(seg.client.take(id).status, DcpRequestStatus::InFlight);
  EXPECT_EQ(seg.client.result(id).status, DcpRequestStatus::Unknown);
  const DcpRequestId next = seg.client.signal(d.mac());
  EXPECT_EQ(seg.wait(next).status, DcpRequestStatus::Done);
  EXPECT_EQ(found[0].mac, MacAddress{});  // the answer did not go into the released array
}

TEST(PnDcpClient, BufferTooSmallFailsTheRequestSoPollingEnds) {
  DcpClient client(kControllerMac);
  std::array<DcpStation, 2> found{};
  const DcpRequestId identify = client.identify_all(found, 1);
  const DcpRequestId signal = client.signal(device_mac(7));
  std::array<std::uint8_t, 20> tiny{};  // an Ethernet header and FrameID, no room for DCP
  const core::TimePoint now{std::chrono::seconds(1)};
  // A caller that polls while something is due: bounded, so a regression fails instead of hanging.
  int polls = 0;
  while (client.next_deadline() <= now && polls < 100) {
    EXPECT_EQ(client.poll(now, tiny), 0U);
    ++polls;
  }
  EXPECT_EQ(polls, 1);  // one poll fails both requests
  EXPECT_TRUE(client.idle());
  EXPECT_EQ(client.next_deadline(), core::TimePoint::max());
  for (const DcpRequestId id : {identify, signal}) {
    const DcpResult r = client.result(id);
    EXPECT_EQ(r.status, DcpRequestStatus::Failed);
    EXPECT_EQ(r.failure, DcpFailure::BufferTooSmall);
    EXPECT_EQ(r.frames_sent, 0);
  }
  EXPECT_EQ(to_string(DcpFailure::BufferTooSmall),
            "the request's frame does not fit the buffer given to poll() (not sent)");
  EXPECT_EQ(client.counters().tx_too_small, 2U);
  EXPECT_EQ(client.counters().failed, 2U);
  EXPECT_EQ(client.counters().frames_sent, 0U);
  // A buffer that fits serves the next request as usual.
  std::array<std::uint8_t, kMaxFrameSize> out{};
  (void)client.signal(device_mac(7));
  EXPECT_GT(client.poll(now, out), 0U);
}

}  // namespace
}  // namespace drivegate::profinet::test
