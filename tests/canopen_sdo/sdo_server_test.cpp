// Simulated SDO server: the digests' conversations byte-exact from the server side, the SD6 42h
// persona, fault injection, the CiA 301 protocol aborts, and bad input.
#include <gtest/gtest.h>

#include "adapters/canopen/sim/sdo_server.hpp"
#include "sdo_test_support.hpp"
#include "tests/support/alloc_counter.hpp"

namespace drivegate::canopen {
namespace {

using namespace std::chrono_literals;
using namespace test_sdo;
using sim::SdoServer;
using sim::SdoServerConfig;

constexpr core::TimePoint kT0{std::chrono::seconds(10)};
const SdoServerConfig kNode5{0x605, 0x585, 1000ms, false};

Frames poll(SdoServer& s, core::TimePoint now, TxQueue& tx) {
  s.poll(now, tx);
  return drain(tx);
}

// What the server answers to one request.
Frames ask(SdoServer& s, const Bytes& request, core::TimePoint now = kT0) {
  TxQueue tx;
  EXPECT_TRUE(s.on_frame(frame(0x605, request), now));
  return poll(s, now, tx);
}

// The server's half of a conversation: client steps are fed in, server steps must come out.
void play_server(SdoServer& s, const Conversation& conv) {
  TxQueue tx;
  for (std::size_t i = 0; i < conv.size(); ++i) {
    SCOPED_TRACE(testing::Message() << "step " << i + 1);
    if (conv[i].from_client) {
      EXPECT_TRUE(s.on_frame(frame(0x605, conv[i].data), kT0));
    } else {
      EXPECT_EQ(poll(s, kT0, tx), (Frames{{0x585, conv[i].data}}));
    }
  }
  EXPECT_TRUE(poll(s, kT0, tx).empty());
}

Sent abort_frame(Bytes object3, std::uint32_t code) {
  return {0x585,
          {0x80, object3[0], object3[1], object3[2], static_cast<std::uint8_t>(code), static_cast<std::uint8_t>(code >> 8),
           static_cast<std::uint8_t>(code >> 16), static_cast<std::uint8_t>(code >> 24)}};
}

TEST(SdoServerVectors, Sd6Tv1SegmentedDownloadNode5) {
  TestBackend od;
  od.add(kTvObject, {});
  SdoServer s(kNode5, od);
  play_server(s, sd6_tv1());
  EXPECT_EQ(od.value(kTvObject), counting(16));
  EXPECT_EQ(od.writes(), 1U);
  EXPECT_FALSE(s.transfer_open());
  EXPECT_EQ(s.counters().completed, 1U);
}

TEST(SdoServerVectors, Sd6Tv2SegmentedUploadNode5) {
  TestBackend od;
  od.add(kTvObject, counting(16));
  SdoServer s(kNode5, od);
  play_server(s, sd6_tv2());
  EXPECT_FALSE(s.transfer_open());
  EXPECT_EQ(s.counters().completed, 1U);
}

// AKD part 1 §14 vectors 10 and 16 and SD6 §11.2 D-1/D-3/D-4, D-13 from the drive's side.
TEST(SdoServerVectors, ExpeditedAnswersAndBackendAborts) {
  TestBackend od;
  od.add({0x1000, 0}, {0x92, 0x01, 0x02, 0x00}, false);
  od.add({0x1017, 0}, {0, 0});
  od.add({0x1010, 1}, {0, 0, 0, 0});
  SdoServer s(kNode5, od);
  EXPECT_EQ(ask(s, {0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0}), (Frames{{0x585, {0x43, 0x00, 0x10, 0x00, 0x92, 0x01, 0x02, 0x00}}}));
  EXPECT_EQ(ask(s, {0x2B, 0x17, 0x10, 0x00, 0x64, 0, 0, 0}), (Frames{{0x585, {0x60, 0x17, 0x10, 0x00, 0, 0, 0, 0}}}));
  EXPECT_EQ(od.value({0x1017, 0}), (Bytes{0x64, 0x00}));
  EXPECT_EQ(ask(s, {0x23, 0x10, 0x10, 0x01, 0x73, 0x61, 0x76, 0x65}), (Frames{{0x585, {0x60, 0x10, 0x10, 0x01, 0, 0, 0, 0}}}));
  EXPECT_EQ(od.value({0x1010, 1}), (Bytes{'s', 'a', 'v', 'e'}));
  EXPECT_EQ(ask(s, {0x40, 0x22, 0x22, 0x00, 0, 0, 0, 0}), Frames{abort_frame({0x22, 0x22, 0x00}, 0x06020000)});
  EXPECT_EQ(ask(s, {0x23, 0x00, 0x10, 0x00, 1, 2, 3, 4}), Frames{abort_frame({0x00, 0x10, 0x00}, 0x06010002)});
  EXPECT_EQ(s.counters().aborts_sent, 2U);
  EXPECT_EQ(s.counters().completed, 3U);
}

// The SD6 persona answers small uploads with 42h (stoeber-sd6-canopen.md §6.4, §11.2 D-1).
TEST(SdoServerPersona, UploadWithoutSizeAnswers42h) {
  TestBackend od;
  od.add({0x1000, 0}, {0x92, 0x01, 0x02, 0x00});
  od.add({0x6041, 0}, {0x37, 0x02});
  od.add({0x6061, 0}, {0xFE});
  od.add(kTvObject, counting(16));
  SdoServer s({0x605, 0x585, 1000ms, true}, od);
  EXPECT_EQ(ask(s, {0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0}), (Frames{{0x585, {0x42, 0x00, 0x10, 0x00, 0x92, 0x01, 0x02, 0x00}}}));
  EXPECT_EQ(ask(s, {0x40, 0x41, 0x60, 0x00, 0, 0, 0, 0}), (Frames{{0x585, {0x42, 0x41, 0x60, 0x00, 0x37, 0x02, 0, 0}}}));
  EXPECT_EQ(ask(s, {0x40, 0x61, 0x60, 0x00, 0, 0, 0, 0}), (Frames{{0x585, {0x42, 0x61, 0x60, 0x00, 0xFE, 0, 0, 0}}}));
  play_server(s, sd6_tv2());  // longer objects are segmented as usual
  s.set_upload_without_size(false);
  EXPECT_EQ(ask(s, {0x40, 0x41, 0x60, 0x00, 0, 0, 0, 0}), (Frames{{0x585, {0x4B, 0x41, 0x60, 0x00, 0x37, 0x02, 0, 0}}}));
  EXPECT_EQ(ask(s, {0x40, 0x61, 0x60, 0x00, 0, 0, 0, 0}), (Frames{{0x585, {0x4F, 0x61, 0x60, 0x00, 0xFE, 0, 0, 0}}}));
}

TEST(SdoServerFaults, InjectedAbortHitsTheNextRequestForThatObjectOnly) {
  TestBackend od;
  od.add({0x6040, 0}, {0, 0});
  od.add({0x6041, 0}, {0x37, 0x02});
  SdoServer s(kNode5, od);
  s.inject_abort({0x6040, 0}, 0x08000022);
  // Another object is not affected while the injection waits.
  EXPECT_EQ(ask(s, {0x40, 0x41, 0x60, 0x00, 0, 0, 0, 0}).at(0).data[0], 0x4B);
  EXPECT_EQ(ask(s, {0x2B, 0x40, 0x60, 0x00, 0x0F, 0, 0, 0}), Frames{abort_frame({0x40, 0x60, 0x00}, 0x08000022)});
  EXPECT_EQ(od.writes(), 0U);
  EXPECT_EQ(ask(s, {0x2B, 0x40, 0x60, 0x00, 0x0F, 0, 0, 0}), (Frames{{0x585, {0x60, 0x40, 0x60, 0x00, 0, 0, 0, 0}}}));
  EXPECT_EQ(s.counters().injected, 1U);
}

TEST(SdoServerFaults, SilentServerAnswersNothing) {
  TestBackend od;
  od.add(kTvObject, counting(16));
  SdoServer s(kNode5, od);
  TxQueue tx;
  s.on_frame(frame(0x605, sd6_tv2()[0].data), kT0);
  s.set_silent(true);  // the answer already produced is lost, the transfer forgotten
  EXPECT_FALSE(s.transfer_open());
  EXPECT_TRUE(poll(s, kT0, tx).empty());
  EXPECT_TRUE(s.on_frame(frame(0x605, {0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0}), kT0));
  EXPECT_TRUE(poll(s, kT0 + 5s, tx).empty());
  EXPECT_EQ(s.counters().ignored_silent, 1U);
  s.set_silent(false);
  play_server(s, sd6_tv2());
}

TEST(SdoServerErrors, ToggleErrorsAbortWith05030000) {
  TestBackend od;
  od.add(kTvObject, counting(16));
  SdoServer s(kNode5, od);
  ask(s, sd6_tv1()[0].data);
  // First segment with toggle 1.
  EXPECT_EQ(ask(s, {0x10, 1, 2, 3, 4, 5, 6, 7}), Frames{abort_frame({0x00, 0x20, 0x01}, 0x05030000)});
  EXPECT_FALSE(s.transfer_open());
  EXPECT_EQ(od.writes(), 0U);

  ask(s, sd6_tv2()[0].data);
  ask(s, {0x60, 0, 0, 0, 0, 0, 0, 0});
  EXPECT_EQ(ask(s, {0x60, 0, 0, 0, 0, 0, 0, 0}), Frames{abort_frame({0x00, 0x20, 0x01}, 0x05030000)});
  EXPECT_EQ(s.counters().toggle_errors, 2U);
}

TEST(SdoServerErrors, UnknownBlockAndOrphanSegmentsAbortWith05040001) {
  TestBackend od;
  od.add(kTvObject, counting(16));
  SdoServer s(kNode5, od);
  // Idle: a segment without an initiate, in either direction.
  EXPECT_EQ(ask(s, {0x00, 1, 2, 3, 4, 5, 6, 7}), Frames{abort_frame({0, 0, 0}, 0x05040001)});
  EXPECT_EQ(ask(s, {0x60, 0, 0, 0, 0, 0, 0, 0}), Frames{abort_frame({0, 0, 0}, 0x05040001)});
  EXPECT_EQ(s.counters().unexpected, 2U);
  // Block download / block upload initiates (ccs 6 / 5) and specifier 7.
  EXPECT_EQ(ask(s, {0xC6, 0x00, 0x10, 0x00, 0x10, 0, 0, 0}), Frames{abort_frame({0x00, 0x10, 0x00}, 0x05040001)});
  EXPECT_EQ(ask(s, {0xA4, 0x00, 0x10, 0x00, 0x7F, 0, 0, 0}), Frames{abort_frame({0x00, 0x10, 0x00}, 0x05040001)});
  EXPECT_EQ(ask(s, {0xE0, 0x00, 0x10, 0x00, 0, 0, 0, 0}), Frames{abort_frame({0, 0, 0}, 0x05040001)});
  EXPECT_EQ(s.counters().unknown_command, 3U);
  // Within a transfer, the abort names the transfer's object and ends it.
  ask(s, sd6_tv2()[0].data);
  EXPECT_EQ(ask(s, {0xE0, 0, 0, 0, 0, 0, 0, 0}), Frames{abort_frame({0x00, 0x20, 0x01}, 0x05040001)});
  EXPECT_FALSE(s.transfer_open());
  // A download segment inside an upload does not fit either.
  ask(s, sd6_tv2()[0].data);
  EXPECT_EQ(ask(s, {0x00, 1, 2, 3, 4, 5, 6, 7}), Frames{abort_frame({0x00, 0x20, 0x01}, 0x05040001)});
  EXPECT_EQ(s.counters().aborts_sent, 7U);
}

TEST(SdoServerErrors, IdleTransferTimesOutWith05040000) {
  TestBackend od;
  od.add(kTvObject, {});
  SdoServer s(kNode5, od);
  TxQueue tx;
  EXPECT_EQ(s.next_deadline(), core::TimePoint::max());
  s.on_frame(frame(0x605, sd6_tv1()[0].data), kT0);
  EXPECT_EQ(s.next_deadline(), core::TimePoint::min());  // the answer waits for poll()
  EXPECT_EQ(poll(s, kT0, tx).size(), 1U);
  EXPECT_EQ(s.next_deadline(), kT0 + 1000ms);
  s.on_frame(frame(0x605, sd6_tv1()[2].data), kT0 + 500ms);
  EXPECT_EQ(poll(s, kT0 + 500ms, tx).size(), 1U);
  EXPECT_EQ(s.next_deadline(), kT0 + 1500ms);
  EXPECT_TRUE(poll(s, kT0 + 1499ms, tx).empty());
  EXPECT_EQ(poll(s, kT0 + 1500ms, tx), Frames{abort_frame({0x00, 0x20, 0x01}, 0x05040000)});
  EXPECT_FALSE(s.transfer_open());
  EXPECT_EQ(s.counters().timeouts, 1U);
  EXPECT_EQ(s.next_deadline(), core::TimePoint::max());
  EXPECT_EQ(od.writes(), 0U);
}

TEST(SdoServerErrors, SizeLimitsAndMismatches) {
  TestBackend od;
  static_assert(SdoServer::kBufferSize == 4096);
  od.add({0x3000, 0}, Bytes(4140, 0xAB));
  od.add(kTvObject, {});
  SdoServer s(kNode5, od);
  // More than the 4 KiB buffer: out of memory, either direction.
  EXPECT_EQ(ask(s, {0x40, 0x00, 0x30, 0x00, 0, 0, 0, 0}), Frames{abort_frame({0x00, 0x30, 0x00}, 0x05040005)});
  EXPECT_EQ(ask(s, {0x21, 0x00, 0x30, 0x00, 0x2C, 0x10, 0, 0}), Frames{abort_frame({0x00, 0x30, 0x00}, 0x05040005)});
  // Announced 8 bytes, sent 14.
  ask(s, {0x21, 0x00, 0x20, 0x01, 0x08, 0, 0, 0});
  ask(s, {0x00, 1, 2, 3, 4, 5, 6, 7});
  EXPECT_EQ(ask(s, {0x11, 8, 9, 10, 11, 12, 13, 14}), Frames{abort_frame({0x00, 0x20, 0x01}, 0x06070012)});
  // Announced 16 bytes, ended after 7.
  ask(s, sd6_tv1()[0].data);
  EXPECT_EQ(ask(s, {0x01, 1, 2, 3, 4, 5, 6, 7}), Frames{abort_frame({0x00, 0x20, 0x01}, 0x06070013)});
  EXPECT_EQ(od.writes(), 0U);
  // Without a size the server takes what comes (up to its buffer).
  ask(s, {0x20, 0x00, 0x20, 0x01, 0, 0, 0, 0});
  EXPECT_EQ(ask(s, {0x03, 1, 2, 3, 4, 5, 6, 0}), (Frames{{0x585, {0x20, 0, 0, 0, 0, 0, 0, 0}}}));
  EXPECT_EQ(od.value(kTvObject), (Bytes{1, 2, 3, 4, 5, 6}));
}

// A client that timed out retries from the initiate: the open transfer gives way to it.
TEST(SdoServerErrors, NewInitiateReplacesAnOpenTransfer) {
  TestBackend od;
  od.add(kTvObject, counting(16));
  SdoServer s(kNode5, od);
  ask(s, sd6_tv2()[0].data);
  ask(s, sd6_tv2()[2].data);
  play_server(s, sd6_tv2());
  EXPECT_EQ(s.counters().replaced, 1U);
  // A client abort closes a transfer silently.
  ask(s, sd6_tv2()[0].data);
  EXPECT_TRUE(ask(s, {0x80, 0x00, 0x20, 0x01, 0x00, 0x00, 0x04, 0x05}).empty());
  EXPECT_FALSE(s.transfer_open());
  EXPECT_EQ(s.counters().aborts_received, 1U);
}

TEST(SdoServerBadInput, WrongLengthIsDroppedAndCounted) {
  TestBackend od;
  od.add(kTvObject, {});
  SdoServer s(kNode5, od);
  TxQueue tx;
  const Conversation tv1 = sd6_tv1();
  s.on_frame(frame(0x605, tv1[0].data), kT0);
  poll(s, kT0, tx);
  CanFrame rtr = frame(0x605, {});
  rtr.remote = true;
  rtr.dlc = 8;
  CanFrame nine = frame(0x605, tv1[2].data);
  nine.dlc = 9;
  for (const CanFrame& f : {frame(0x605, {0x00, 1, 2, 3, 4, 5, 6}), frame(0x605, {}), nine, rtr}) {
    EXPECT_TRUE(s.on_frame(f, kT0));
    EXPECT_TRUE(poll(s, kT0, tx).empty());
    EXPECT_TRUE(s.transfer_open());
  }
  EXPECT_EQ(s.counters().malformed, 4U);
  // Other COB-IDs are not this server's.
  EXPECT_FALSE(s.on_frame(frame(0x606, tv1[2].data), kT0));
  EXPECT_FALSE(s.on_frame(frame(0x585, tv1[2].data), kT0));
  CanFrame extended = frame(0x605, tv1[2].data);
  extended.extended = true;
  EXPECT_FALSE(s.on_frame(extended, kT0));
  // The transfer goes on.
  play_server(s, Conversation(tv1.begin() + 2, tv1.end()));
  EXPECT_EQ(od.value(kTvObject), counting(16));
}

TEST(SdoServerAllocation, FramesInAndOutAllocateNothing) {
  TestBackend od;
  od.add(kTvObject, counting(16));
  SdoServer s(kNode5, od);
  TxQueue tx;
  std::array<CanFrame, 8> requests{};
  const Conversation tv1 = sd6_tv1();
  const Conversation tv2 = sd6_tv2();
  for (std::size_t i = 0; i < 8; i += 2) {
    requests[i] = frame(0x605, tv1[i].data);
    requests[i + 1] = frame(0x605, tv2[i].data);
  }
  std::size_t allocations = 0;
  {
    const drivegate::test::AllocationScope scope;
    for (std::size_t i = 0; i < 8; i += 2) {
      s.on_frame(requests[i], kT0);
      s.poll(kT0, tx);
    }
    for (std::size_t i = 1; i < 8; i += 2) {
      s.on_frame(requests[i], kT0);
      s.poll(kT0, tx);
      (void)s.next_deadline();
    }
    s.on_frame(requests[0], kT0);
    s.poll(kT0 + 2s, tx);  // times out
    allocations = scope.count();
  }
  EXPECT_EQ(allocations, 0U);
  EXPECT_EQ(tx.size(), 10U);
  EXPECT_EQ(s.counters().completed, 2U);
  EXPECT_EQ(s.counters().timeouts, 1U);
}

}  // namespace
}  // namespace drivegate::canopen
