// SDO client: the digests' conversations byte-exact from the client side, timeouts and retries in
// virtual time, aborts, cancel/reset, several channels, bad input, and no allocation after
// construction.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string_view>

#include "adapters/canopen/master/sdo_client.hpp"
#include "profiles/cia402/sdo_abort.hpp"
#include "sdo_test_support.hpp"
#include "tests/support/alloc_counter.hpp"

namespace drivegate::canopen {
namespace {

using namespace std::chrono_literals;
using namespace test_sdo;

constexpr core::TimePoint kT0{std::chrono::seconds(10)};

SdoClient client_for(NodeId node, SdoTiming timing = {}) {
  const SdoChannelConfig c{node, 1, 0, 0};
  return SdoClient(std::span<const SdoChannelConfig>(&c, 1), timing);
}

Frames poll(SdoClient& c, core::TimePoint now, TxQueue& tx) {
  c.poll(now, tx);
  return drain(tx);
}

// The client's half of a conversation: every client step must come out of the next poll() as
// the only frame; every server step is fed in.
void play_client(SdoClient& c, const Conversation& conv, std::uint32_t rx, std::uint32_t tx_cob) {
  TxQueue tx;
  for (std::size_t i = 0; i < conv.size(); ++i) {
    SCOPED_TRACE(testing::Message() << "step " << i + 1);
    if (conv[i].from_client) {
      EXPECT_EQ(poll(c, kT0, tx), (Frames{{rx, conv[i].data}}));
    } else {
      EXPECT_TRUE(c.on_frame(frame(tx_cob, conv[i].data), kT0));
    }
  }
  EXPECT_TRUE(poll(c, kT0, tx).empty());
}

TEST(SdoClientVectors, Sd6Tv1SegmentedDownloadNode5) {
  SdoClient c = client_for(5);
  const Bytes payload = counting(16);  // write_from() sends from this buffer: it outlives the request
  const auto id = c.write_from(0, kTvObject, payload);
  ASSERT_NE(id, kNoSdoRequest);
  play_client(c, sd6_tv1(), 0x605, 0x585);
  EXPECT_EQ(c.result(id).status, SdoStatus::Done);
  EXPECT_EQ(c.counters().completed, 1U);
  EXPECT_EQ(c.counters().unexpected + c.counters().malformed, 0U);
}

TEST(SdoClientVectors, Sd6Tv2SegmentedUploadNode5) {
  SdoClient c = client_for(5);
  const auto id = c.read(0, kTvObject);
  play_client(c, sd6_tv2(), 0x605, 0x585);
  const SdoResult r = c.result(id);
  EXPECT_EQ(r.status, SdoStatus::Done);
  EXPECT_EQ(r.size, 16);
  const auto d = c.data(id);
  EXPECT_EQ(Bytes(d.begin(), d.end()), counting(16));
}

// AKD part 1 §14: the client's frames for the vectors a master sends, against the responses given
// there (or the CiA 301 confirmation where the digest only gives the request).
struct AkdCase {
  const char* name;
  bool read;
  ObjectId object;
  std::uint32_t value;  // writes
  std::uint8_t size;    // writes
  Bytes request;
  Bytes response;
  SdoStatus status;
  std::uint32_t expect;  // reads: value; failures: abort code
};

TEST(SdoClientVectors, AkdPart1Section14) {
  const Bytes ok_1010{0x60, 0x10, 0x10, 0x01, 0, 0, 0, 0};  // vector 13
  const std::vector<AkdCase> cases = {
      {"9/10 read 1000h", true, {0x1000, 0}, 0, 0, {0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0},
       {0x43, 0x00, 0x10, 0x00, 0x92, 0x01, 0x02, 0x00}, SdoStatus::Done, 0x00020192},
      {"11 read 1018h:01", true, {0x1018, 1}, 0, 0, {0x40, 0x18, 0x10, 0x01, 0, 0, 0, 0},
       {0x43, 0x18, 0x10, 0x01, 0x6A, 0x00, 0x00, 0x00}, SdoStatus::Done, 0x6A},
      {"12/13 save", false, {0x1010, 1}, 0x65766173, 4, {0x23, 0x10, 0x10, 0x01, 0x73, 0x61, 0x76, 0x65}, ok_1010,
       SdoStatus::Done, 0},
      {"14 load", false, {0x1011, 1}, 0x64616F6C, 4, {0x23, 0x11, 0x10, 0x01, 0x6C, 0x6F, 0x61, 0x64},
       {0x60, 0x11, 0x10, 0x01, 0, 0, 0, 0}, SdoStatus::Done, 0},
      {"15 clear 1003h", false, {0x1003, 0}, 0, 1, {0x2F, 0x03, 0x10, 0x00, 0, 0, 0, 0},
       {0x60, 0x03, 0x10, 0x00, 0, 0, 0, 0}, SdoStatus::Done, 0},
      {"16 read 2222h aborted", true, {0x2222, 0}, 0, 0, {0x40, 0x22, 0x22, 0x00, 0, 0, 0, 0},
       {0x80, 0x22, 0x22, 0x00, 0x00, 0x00, 0x02, 0x06}, SdoStatus::Failed, 0x06020000},
      {"17 1A00h:00 aborted", false, {0x1A00, 0}, 2, 1, {0x2F, 0x00, 0x1A, 0x00, 0x02, 0, 0, 0},
       {0x80, 0x00, 0x1A, 0x00, 0x42, 0x00, 0x04, 0x06}, SdoStatus::Failed, 0x06040042},
      {"21 heartbeat 100 ms", false, {0x1017, 0}, 100, 2, {0x2B, 0x17, 0x10, 0x00, 0x64, 0, 0, 0},
       {0x60, 0x17, 0x10, 0x00, 0, 0, 0, 0}, SdoStatus::Done, 0},
      {"22 consumer 127/250 ms", false, {0x1016, 1}, 0x007F00FA, 4, {0x23, 0x16, 0x10, 0x01, 0xFA, 0x00, 0x7F, 0x00},
       {0x60, 0x16, 0x10, 0x01, 0, 0, 0, 0}, SdoStatus::Done, 0},
      {"27 TPDO3 inhibit", false, {0x1802, 3}, 100, 2, {0x2B, 0x02, 0x18, 0x03, 0x64, 0, 0, 0},
       {0x60, 0x02, 0x18, 0x03, 0, 0, 0, 0}, SdoStatus::Done, 0},
      {"28 TPDO4 event timer", false, {0x1803, 5}, 50, 2, {0x2B, 0x03, 0x18, 0x05, 0x32, 0, 0, 0},
       {0x60, 0x03, 0x18, 0x05, 0, 0, 0, 0}, SdoStatus::Done, 0},
      {"29 RPDO1 type 1", false, {0x1400, 2}, 1, 1, {0x2F, 0x00, 0x14, 0x02, 0x01, 0, 0, 0},
       {0x60, 0x00, 0x14, 0x02, 0, 0, 0, 0}, SdoStatus::Done, 0},
      {"34 FBUS.PARAM04", false, {0x36E8, 0}, 1, 4, {0x23, 0xE8, 0x36, 0x00, 0x01, 0x00, 0x00, 0x00},
       {0x60, 0xE8, 0x36, 0x00, 0, 0, 0, 0}, SdoStatus::Done, 0},
  };
  for (const auto& k : cases) {
    SCOPED_TRACE(k.name);
    SdoClient c = client_for(1);
    const auto id = k.read ? c.read(0, k.object) : c.write(0, k.object, k.value, k.size);
    play_client(c, {{true, k.request}, {false, k.response}}, 0x601, 0x581);
    const SdoResult r = c.result(id);
    EXPECT_EQ(r.status, k.status);
    if (k.status == SdoStatus::Failed) {
      EXPECT_EQ(r.abort_code, k.expect);
      EXPECT_EQ(c.counters().aborts_received, 1U);
    } else if (k.read) {
      EXPECT_EQ(r.value, k.expect);
      EXPECT_EQ(r.size, 4);
    }
  }
}

// AKD vector 24 (guard time, then life time factor) and the rule behind it: one request in flight
// per drive (AKD part 1 §10.1), the second waits for the first confirmation.
TEST(SdoClientVectors, AkdVector24OneRequestAtATime) {
  SdoClient c = client_for(1);
  TxQueue tx;
  const auto a = c.write(0, {0x100C, 0}, 100, 2);
  const auto b = c.write(0, {0x100D, 0}, 3, 1);
  EXPECT_EQ(c.pending(0), 2U);
  EXPECT_EQ(poll(c, kT0, tx), (Frames{{0x601, {0x2B, 0x0C, 0x10, 0x00, 0x64, 0, 0, 0}}}));
  EXPECT_TRUE(poll(c, kT0 + 1ms, tx).empty());
  EXPECT_EQ(c.result(b).status, SdoStatus::Queued);
  c.on_frame(frame(0x581, {0x60, 0x0C, 0x10, 0x00, 0, 0, 0, 0}), kT0 + 2ms);
  EXPECT_EQ(poll(c, kT0 + 2ms, tx), (Frames{{0x601, {0x2F, 0x0D, 0x10, 0x00, 0x03, 0, 0, 0}}}));
  EXPECT_EQ(c.result(a).status, SdoStatus::Done);
  EXPECT_EQ(c.result(b).status, SdoStatus::InFlight);
}

// NORD TV-A (nord-sk500p-ds402.md §10): remap TxPDO3 of node 20h over 620h/5A0h. -1 marks the
// bytes the source leaves open ("xx"); the drive's answers fill them with junk the client ignores.
TEST(SdoClientVectors, NordTvARemapTxPdo3) {
  struct Write {
    ObjectId object;
    std::uint32_t value;
    std::uint8_t size;
    std::vector<int> request;
  };
  const std::vector<Write> steps = {
      {{0x1802, 1}, 0xC00003A0, 4, {0x23, 0x02, 0x18, 0x01, 0xA0, 0x03, 0x00, 0xC0}},
      {{0x1A02, 0}, 0, 1, {0x2F, 0x02, 0x1A, 0x00, 0x00, -1, -1, -1}},
      {{0x1A02, 1}, 0x60410010, 4, {0x23, 0x02, 0x1A, 0x01, 0x10, 0x00, 0x41, 0x60}},
      {{0x1A02, 2}, 0x60610008, 4, {0x23, 0x02, 0x1A, 0x02, 0x08, 0x00, 0x61, 0x60}},
      {{0x1A02, 0}, 2, 1, {0x2F, 0x02, 0x1A, 0x00, 0x02, -1, -1, -1}},
      {{0x1802, 1}, 0x400003A0, 4, {0x23, 0x02, 0x18, 0x01, 0xA0, 0x03, 0x00, 0x40}},
  };
  SdoClient c = client_for(0x20);
  TxQueue tx;
  std::vector<SdoRequestId> ids;
  for (const auto& s : steps) ids.push_back(c.write(0, s.object, s.value, s.size));
  for (std::size_t i = 0; i < steps.size(); ++i) {
    SCOPED_TRACE(testing::Message() << "A" << i + 1);
    const Frames sent = poll(c, kT0, tx);
    ASSERT_EQ(sent.size(), 1U);
    EXPECT_EQ(sent[0].id, 0x620U);
    ASSERT_EQ(sent[0].data.size(), 8U);
    for (std::size_t b = 0; b < 8; ++b) {
      if (steps[i].request[b] >= 0) {
        EXPECT_EQ(sent[0].data[b], steps[i].request[b]) << "byte " << b;
      }
    }
    const auto& o = steps[i].object;
    c.on_frame(frame(0x5A0, {0x60, static_cast<std::uint8_t>(o.index & 0xFF), static_cast<std::uint8_t>(o.index >> 8),
                             o.sub, 0xEE, 0xEE, 0xEE, 0xEE}),
               kT0);
    EXPECT_EQ(c.result(ids[i]).status, SdoStatus::Done);
  }
  EXPECT_EQ(c.counters().completed, steps.size());
}

// SD6 answers uploads with 42h (size not indicated): the length is the object's, given by the
// caller (stoeber-sd6-canopen.md §6.4, §11.2 D-1).
TEST(SdoClientExpedited, Sd6ResponseWithoutSizeTakesExpectedSize) {
  SdoClient c = client_for(5);
  const auto device_type = c.read(0, {0x1000, 0}, 4);
  play_client(c, {{true, {0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0}}, {false, {0x42, 0x00, 0x10, 0x00, 0x92, 0x01, 0x02, 0x00}}},
              0x605, 0x585);
  EXPECT_EQ(c.result(device_type).value, 0x00020192U);
  EXPECT_EQ(c.result(device_type).size, 4);

  // A 2-byte statusword: the two bytes after it are not part of the value.
  const auto statusword = c.read(0, {0x6041, 0}, 2);
  play_client(c, {{true, {0x40, 0x41, 0x60, 0x00, 0, 0, 0, 0}}, {false, {0x42, 0x41, 0x60, 0x00, 0x37, 0x02, 0xAA, 0xBB}}},
              0x605, 0x585);
  EXPECT_EQ(c.result(statusword).value, 0x0237U);
  EXPECT_EQ(c.result(statusword).size, 2);
  EXPECT_EQ(c.data(statusword).size(), 2U);

  // Without a known size all four bytes are handed up.
  const auto any = c.read(0, {0x6041, 0});
  play_client(c, {{true, {0x40, 0x41, 0x60, 0x00, 0, 0, 0, 0}}, {false, {0x42, 0x41, 0x60, 0x00, 0x37, 0x02, 0xAA, 0xBB}}},
              0x605, 0x585);
  EXPECT_EQ(c.result(any).size, 4);
  EXPECT_EQ(c.result(any).value, 0xBBAA0237U);

  // A size the server indicates wins over the caller's guess.
  const auto indicated = c.read(0, {0x6061, 0}, 2);
  play_client(c, {{true, {0x40, 0x61, 0x60, 0x00, 0, 0, 0, 0}}, {false, {0x4F, 0x61, 0x60, 0x00, 0xFE, 0, 0, 0}}}, 0x605,
              0x585);
  EXPECT_EQ(c.result(indicated).size, 1);
  EXPECT_EQ(c.result(indicated).value, 0xFEU);
}

TEST(SdoClientTimeouts, RetriesFromInitiateThenAbortsWithTimeout) {
  SdoClient c = client_for(5, {100ms, 2});
  TxQueue tx;
  const Sent request{0x605, {0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0}};
  const auto id = c.read(0, {0x1000, 0});
  EXPECT_EQ(c.next_deadline(), core::TimePoint::min());
  EXPECT_EQ(poll(c, kT0, tx), Frames{request});
  EXPECT_EQ(c.next_deadline(), kT0 + 100ms);
  EXPECT_TRUE(poll(c, kT0 + 99ms, tx).empty());
  EXPECT_EQ(poll(c, kT0 + 100ms, tx), Frames{request});
  EXPECT_EQ(c.next_deadline(), kT0 + 200ms);
  EXPECT_EQ(poll(c, kT0 + 200ms, tx), Frames{request});
  EXPECT_TRUE(poll(c, kT0 + 299ms, tx).empty());
  EXPECT_EQ(c.result(id).status, SdoStatus::InFlight);
  EXPECT_EQ(poll(c, kT0 + 300ms, tx), (Frames{{0x605, {0x80, 0x00, 0x10, 0x00, 0x00, 0x00, 0x04, 0x05}}}));
  EXPECT_EQ(c.result(id).status, SdoStatus::Failed);
  EXPECT_EQ(c.result(id).abort_code, cia402::sdo_abort_code::kTimeout);
  EXPECT_EQ(cia402::sdo_abort_text(c.result(id).abort_code), "SDO protocol timed out");
  EXPECT_EQ(c.counters().retries, 2U);
  EXPECT_EQ(c.counters().timeouts, 1U);
  EXPECT_EQ(c.counters().failed, 1U);
  EXPECT_EQ(c.next_deadline(), core::TimePoint::max());
  EXPECT_TRUE(poll(c, kT0 + 10s, tx).empty());

  // The drive wakes up too late: its answer finds no transfer.
  c.on_frame(frame(0x585, {0x43, 0x00, 0x10, 0x00, 0x92, 0x01, 0x02, 0x00}), kT0 + 11s);
  EXPECT_EQ(c.counters().unexpected, 1U);
  EXPECT_EQ(c.result(id).status, SdoStatus::Failed);
}

TEST(SdoClientTimeouts, AnswerToARetryCompletes) {
  SdoClient c = client_for(5, {100ms, 2});
  TxQueue tx;
  const auto id = c.write(0, {0x1017, 0}, 100, 2);
  poll(c, kT0, tx);
  EXPECT_EQ(poll(c, kT0 + 100ms, tx), (Frames{{0x605, {0x2B, 0x17, 0x10, 0x00, 0x64, 0, 0, 0}}}));
  c.on_frame(frame(0x585, {0x60, 0x17, 0x10, 0x00, 0, 0, 0, 0}), kT0 + 150ms);
  EXPECT_EQ(c.result(id).status, SdoStatus::Done);
  EXPECT_TRUE(poll(c, kT0 + 1s, tx).empty());
  EXPECT_EQ(c.counters().retries, 1U);
  EXPECT_EQ(c.counters().timeouts, 0U);
}

// In the middle of a segmented transfer the server waits for a segment, not an initiate: the
// client aborts at once (sdo_client.hpp), retries or not.
TEST(SdoClientTimeouts, TimeoutBetweenSegmentsAbortsWithoutRetry) {
  SdoClient c = client_for(5, {100ms, 2});
  TxQueue tx;
  const auto id = c.read(0, kTvObject);
  poll(c, kT0, tx);
  c.on_frame(frame(0x585, {0x41, 0x00, 0x20, 0x01, 0x10, 0, 0, 0}), kT0 + 10ms);
  EXPECT_EQ(poll(c, kT0 + 10ms, tx), (Frames{{0x605, {0x60, 0, 0, 0, 0, 0, 0, 0}}}));
  EXPECT_EQ(c.next_deadline(), kT0 + 110ms);
  EXPECT_EQ(poll(c, kT0 + 110ms, tx), (Frames{{0x605, {0x80, 0x00, 0x20, 0x01, 0x00, 0x00, 0x04, 0x05}}}));
  EXPECT_EQ(c.result(id).abort_code, cia402::sdo_abort_code::kTimeout);
  EXPECT_EQ(c.counters().retries, 0U);
  EXPECT_EQ(c.counters().timeouts, 1U);
}

// A full TxQueue loses the frame like the bus would; the timeout sends it again.
TEST(SdoClientTimeouts, RefusedFrameIsSentAgainAtTheTimeout) {
  SdoClient c = client_for(5, {100ms, 1});
  TxQueue tx;
  const CanFrame filler = frame(0x123, {1});
  while (tx.push(filler)) {
  }
  const auto id = c.read(0, {0x1000, 0});
  c.poll(kT0, tx);
  EXPECT_EQ(c.counters().tx_full, 1U);
  tx.clear();
  EXPECT_EQ(poll(c, kT0 + 100ms, tx), (Frames{{0x605, {0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0}}}));
  c.on_frame(frame(0x585, {0x4B, 0x00, 0x10, 0x00, 0x34, 0x12, 0, 0}), kT0 + 120ms);
  EXPECT_EQ(c.result(id).value, 0x1234U);
}

TEST(SdoClientErrors, ToggleErrorInUploadAbortsWith05030000) {
  SdoClient c = client_for(5);
  TxQueue tx;
  const auto id = c.read(0, kTvObject);
  poll(c, kT0, tx);
  c.on_frame(frame(0x585, {0x41, 0x00, 0x20, 0x01, 0x10, 0, 0, 0}), kT0);
  poll(c, kT0, tx);
  c.on_frame(frame(0x585, {0x00, 1, 2, 3, 4, 5, 6, 7}), kT0);
  EXPECT_EQ(poll(c, kT0, tx), (Frames{{0x605, {0x70, 0, 0, 0, 0, 0, 0, 0}}}));
  c.on_frame(frame(0x585, {0x00, 8, 9, 10, 11, 12, 13, 14}), kT0);  // toggle 0 again
  EXPECT_EQ(poll(c, kT0, tx), (Frames{{0x605, {0x80, 0x00, 0x20, 0x01, 0x00, 0x00, 0x03, 0x05}}}));
  EXPECT_EQ(c.result(id).status, SdoStatus::Failed);
  EXPECT_EQ(c.result(id).abort_code, cia402::sdo_abort_code::kToggle);
  EXPECT_TRUE(c.data(id).empty());
}

TEST(SdoClientErrors, ToggleErrorInDownloadAbortsWith05030000) {
  SdoClient c = client_for(5);
  TxQueue tx;
  const Bytes payload = counting(16);  // write_from() sends from this buffer: it outlives the request
  const auto id = c.write_from(0, kTvObject, payload);
  poll(c, kT0, tx);
  c.on_frame(frame(0x585, {0x60, 0x00, 0x20, 0x01, 0, 0, 0, 0}), kT0);
  poll(c, kT0, tx);
  c.on_frame(frame(0x585, {0x30, 0, 0, 0, 0, 0, 0, 0}), kT0);  // confirms toggle 1, sent was 0
  EXPECT_EQ(poll(c, kT0, tx), (Frames{{0x605, {0x80, 0x00, 0x20, 0x01, 0x00, 0x00, 0x03, 0x05}}}));
  EXPECT_EQ(c.result(id).abort_code, cia402::sdo_abort_code::kToggle);
}

TEST(SdoClientErrors, ServerAbortFailsWithTheServersCodeAndText) {
  SdoClient c = client_for(5);
  TxQueue tx;
  const auto id = c.write(0, {0x6060, 0}, 1, 1);
  poll(c, kT0, tx);
  c.on_frame(frame(0x585, {0x80, 0x60, 0x60, 0x00, 0x22, 0x00, 0x00, 0x08}), kT0);
  const SdoResult r = c.result(id);
  EXPECT_EQ(r.status, SdoStatus::Failed);
  EXPECT_EQ(r.abort_code, 0x08000022U);
  EXPECT_EQ(cia402::sdo_abort_text(r.abort_code),
            "data cannot be transferred or stored to the application because of the present device state");
  EXPECT_TRUE(poll(c, kT0, tx).empty());  // no abort answers an abort
  EXPECT_EQ(c.counters().aborts_received, 1U);
}

// A segmented upload may not outgrow kMaxData: refused up front when the size is indicated, at the
// segment that overflows when it is not; both abort with 05040005h.
TEST(SdoClientErrors, UploadLargerThanMaxDataAbortsOutOfMemory) {
  SdoClient c = client_for(5);
  TxQueue tx;
  const auto big = c.read(0, {0x1008, 0});
  poll(c, kT0, tx);
  c.on_frame(frame(0x585, {0x41, 0x08, 0x10, 0x00, 100, 0, 0, 0}), kT0);
  EXPECT_EQ(poll(c, kT0, tx), (Frames{{0x605, {0x80, 0x08, 0x10, 0x00, 0x05, 0x00, 0x04, 0x05}}}));
  EXPECT_EQ(c.result(big).abort_code, cia402::sdo_abort_code::kOutOfMemory);

  const auto unsized = c.read(0, {0x1009, 0});
  poll(c, kT0, tx);
  c.on_frame(frame(0x585, {0x40, 0x09, 0x10, 0x00, 0, 0, 0, 0}), kT0);  // e = 0, s = 0
  bool toggle = false;
  for (std::size_t sent = 0; sent < SdoClient::kMaxData; sent += 7) {
    ASSERT_EQ(poll(c, kT0, tx).size(), 1U);
    c.on_frame(frame(0x585, {static_cast<std::uint8_t>(toggle ? 0x10 : 0x00), 1, 2, 3, 4, 5, 6, 7}), kT0);
    toggle = !toggle;
  }
  EXPECT_EQ(poll(c, kT0, tx), (Frames{{0x605, {0x80, 0x09, 0x10, 0x00, 0x05, 0x00, 0x04, 0x05}}}));
  EXPECT_EQ(c.result(unsized).abort_code, cia402::sdo_abort_code::kOutOfMemory);
  EXPECT_EQ(c.counters().failed, 2U);
}

TEST(SdoClientErrors, LastSegmentShortOfTheIndicatedSizeFails) {
  SdoClient c = client_for(5);
  TxQueue tx;
  const auto id = c.read(0, kTvObject);
  poll(c, kT0, tx);
  c.on_frame(frame(0x585, {0x41, 0x00, 0x20, 0x01, 0x10, 0, 0, 0}), kT0);
  poll(c, kT0, tx);
  c.on_frame(frame(0x585, {0x01, 1, 2, 3, 4, 5, 6, 7}), kT0);  // last after 7 of 16 bytes
  EXPECT_EQ(poll(c, kT0, tx), (Frames{{0x605, {0x80, 0x00, 0x20, 0x01, 0x13, 0x00, 0x07, 0x06}}}));
  EXPECT_EQ(c.result(id).abort_code, cia402::sdo_abort_code::kTooShort);
}

TEST(SdoClientRequests, CancelWhileQueuedSkipsTheRequest) {
  SdoClient c = client_for(5);
  TxQueue tx;
  const auto a = c.write(0, {0x2001, 0}, 1, 1);
  const auto b = c.write(0, {0x2002, 0}, 2, 1);
  const auto d = c.write(0, {0x2003, 0}, 3, 1);
  c.cancel(b);
  EXPECT_EQ(c.result(b).status, SdoStatus::Unknown);
  EXPECT_EQ(c.pending(0), 2U);
  EXPECT_EQ(poll(c, kT0, tx), (Frames{{0x605, {0x2F, 0x01, 0x20, 0x00, 1, 0, 0, 0}}}));
  c.on_frame(frame(0x585, {0x60, 0x01, 0x20, 0x00, 0, 0, 0, 0}), kT0);
  EXPECT_EQ(poll(c, kT0, tx), (Frames{{0x605, {0x2F, 0x03, 0x20, 0x00, 3, 0, 0, 0}}}));
  c.on_frame(frame(0x585, {0x60, 0x03, 0x20, 0x00, 0, 0, 0, 0}), kT0);
  EXPECT_EQ(c.result(a).status, SdoStatus::Done);
  EXPECT_EQ(c.result(d).status, SdoStatus::Done);
  EXPECT_EQ(c.pending(0), 0U);
}

// Cancelling a transfer in flight into the client's own slot lets it finish on the wire (the drive
// is in the middle of it), forgets its result, and then goes on with the queue.
TEST(SdoClientRequests, CancelInFlightFinishesOnTheWireAndDropsTheResult) {
  SdoClient c = client_for(5);
  TxQueue tx;
  const auto a = c.read(0, kTvObject);
  const auto b = c.read(0, {0x1000, 0});
  EXPECT_EQ(poll(c, kT0, tx), (Frames{{0x605, {0x40, 0x00, 0x20, 0x01, 0, 0, 0, 0}}}));
  c.on_frame(frame(0x585, {0x41, 0x00, 0x20, 0x01, 16, 0, 0, 0}), kT0);
  c.cancel(a);
  EXPECT_EQ(c.result(a).status, SdoStatus::Unknown);
  EXPECT_EQ(poll(c, kT0, tx), (Frames{{0x605, {0x60, 0, 0, 0, 0, 0, 0, 0}}}));
  c.on_frame(frame(0x585, {0x00, 1, 2, 3, 4, 5, 6, 7}), kT0);
  EXPECT_EQ(poll(c, kT0, tx), (Frames{{0x605, {0x70, 0, 0, 0, 0, 0, 0, 0}}}));
  c.on_frame(frame(0x585, {0x10, 8, 9, 10, 11, 12, 13, 14}), kT0);
  EXPECT_EQ(poll(c, kT0, tx), (Frames{{0x605, {0x60, 0, 0, 0, 0, 0, 0, 0}}}));
  c.on_frame(frame(0x585, {0x0B, 15, 16, 0, 0, 0, 0, 0}), kT0);
  EXPECT_EQ(c.result(a).status, SdoStatus::Unknown);
  EXPECT_EQ(poll(c, kT0, tx), (Frames{{0x605, {0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0}}}));
  EXPECT_EQ(c.result(b).status, SdoStatus::InFlight);
  EXPECT_EQ(c.counters().completed, 1U);
}

TEST(SdoClientRequests, ResetChannelDropsEverythingWithoutAnAbort) {
  SdoClient c = client_for(5);
  TxQueue tx;
  const auto a = c.read(0, {0x1000, 0});
  const auto b = c.read(0, {0x1001, 0});
  poll(c, kT0, tx);
  c.reset_channel(0);
  EXPECT_EQ(c.result(a).status, SdoStatus::Unknown);
  EXPECT_EQ(c.result(b).status, SdoStatus::Unknown);
  EXPECT_EQ(c.pending(0), 0U);
  EXPECT_EQ(c.next_deadline(), core::TimePoint::max());
  EXPECT_TRUE(poll(c, kT0 + 1s, tx).empty());
  c.on_frame(frame(0x585, {0x43, 0x00, 0x10, 0x00, 0x92, 0x01, 0x02, 0x00}), kT0 + 1s);
  EXPECT_EQ(c.counters().unexpected, 1U);
  // The channel works again, and old ids do not find the new requests.
  const auto d = c.read(0, {0x1000, 0});
  EXPECT_NE(d, a);
  EXPECT_EQ(poll(c, kT0 + 1s, tx).size(), 1U);
  EXPECT_EQ(c.result(a).status, SdoStatus::Unknown);
}

TEST(SdoClientRequests, ResultsAreHeldUntilTaken) {
  SdoClient c = client_for(5);
  const auto id = c.read(0, kTvObject);
  play_client(c, sd6_tv2(), 0x605, 0x585);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(c.result(id).status, SdoStatus::Done);
  const SdoResult r = c.take(id);
  EXPECT_EQ(r.status, SdoStatus::Done);
  EXPECT_EQ(r.size, 16);
  EXPECT_EQ(c.result(id).status, SdoStatus::Unknown);
  EXPECT_TRUE(c.data(id).empty());
  EXPECT_EQ(c.take(id).status, SdoStatus::Unknown);
}

// Waiting requests are limited to kQueueDepth; finished results that nobody takes fill the
// channel's slots until submit is refused, instead of being overwritten.
TEST(SdoClientRequests, QueueDepthAndUntakenResultsAreBounded) {
  SdoClient c = client_for(5);
  TxQueue tx;
  std::vector<SdoRequestId> ids;
  for (std::size_t i = 0; i < SdoClient::kQueueDepth; ++i) ids.push_back(c.read(0, {0x2000, 0}));
  EXPECT_EQ(c.read(0, {0x2000, 0}), kNoSdoRequest);
  EXPECT_EQ(c.counters().queue_full, 1U);
  poll(c, kT0, tx);  // one leaves the FIFO for the wire, which makes room for one more
  ids.push_back(c.read(0, {0x2000, 0}));
  ASSERT_NE(ids.back(), kNoSdoRequest);

  // Answer one at a time (value = its number); when the channel runs dry, submit another, until
  // the client refuses because every slot holds a result nobody took.
  std::size_t answered = 0;
  for (;;) {
    c.on_frame(frame(0x585, {0x4F, 0x00, 0x20, 0x00, static_cast<std::uint8_t>(answered), 0, 0, 0}), kT0);
    ++answered;
    poll(c, kT0, tx);
    if (c.pending(0) > 0) continue;
    const auto more = c.read(0, {0x2000, 0});
    if (more == kNoSdoRequest) break;
    ids.push_back(more);
    poll(c, kT0, tx);
  }
  EXPECT_EQ(c.counters().queue_full, 2U);
  EXPECT_EQ(ids.size(), answered);
  EXPECT_GT(answered, SdoClient::kQueueDepth);
  for (std::size_t i = 0; i < answered; ++i) {
    EXPECT_EQ(c.result(ids[i]).status, SdoStatus::Done);
    EXPECT_EQ(c.result(ids[i]).value, i);
  }
  c.take(ids[0]);
  EXPECT_NE(c.read(0, {0x2000, 0}), kNoSdoRequest);
}

TEST(SdoClientRequests, InvalidArgumentsAreRefused) {
  SdoClient c = client_for(5);
  const Bytes too_long(SdoClient::kMaxBuffer + 1, 0);
  EXPECT_EQ(c.write(0, {0x2000, 0}, 1, 0), kNoSdoRequest);
  EXPECT_EQ(c.write(0, {0x2000, 0}, 1, 5), kNoSdoRequest);
  EXPECT_EQ(c.write_from(0, {0x2000, 0}, {}), kNoSdoRequest);
  EXPECT_EQ(c.write_from(0, {0x2000, 0}, too_long), kNoSdoRequest);
  EXPECT_EQ(c.read(0, {0x2000, 0}, 5), kNoSdoRequest);
  EXPECT_EQ(c.read(1, {0x2000, 0}), kNoSdoRequest);
  EXPECT_EQ(c.read(-1, {0x2000, 0}), kNoSdoRequest);
  EXPECT_EQ(c.counters().requests, 0U);
  EXPECT_EQ(c.result(kNoSdoRequest).status, SdoStatus::Unknown);
  EXPECT_EQ(c.result(0xFFFFFFFF).status, SdoStatus::Unknown);
  c.cancel(0xFFFFFFFF);
  c.reset_channel(7);
  EXPECT_EQ(c.pending(7), 0U);
}

TEST(SdoClientChannels, ConstructionChecksTheChannelList) {
  const auto make = [](std::vector<SdoChannelConfig> v) { SdoClient c(v, SdoTiming{}); };
  EXPECT_THROW(make({{0, 1, 0, 0}}), std::invalid_argument);
  EXPECT_THROW(make({{128, 1, 0, 0}}), std::invalid_argument);
  EXPECT_THROW(make({{5, 5, 0, 0}}), std::invalid_argument);
  // Derived channel 2 COB-IDs only exist for node-IDs <= 31 (stoeber-sd6-canopen.md §5.3).
  EXPECT_THROW(make({{40, 2, 0, 0}}), std::invalid_argument);
  EXPECT_NO_THROW(make({{40, 2, 0x640, 0x5C0}}));
  EXPECT_THROW(make({{5, 1, 0, 0}, {5, 1, 0, 0}}), std::invalid_argument);
  EXPECT_THROW(make({{5, 1, 0x800, 0x585}}), std::invalid_argument);
  EXPECT_THROW((SdoClient{std::vector<SdoChannelConfig>{{5, 1, 0, 0}}, SdoTiming{0ms, 1}}), std::invalid_argument);
}

// SD6 channel 2 of node 5 uses 625h/5A5h (stoeber-sd6-canopen.md §11.1 TV-8, §11.2 D-14); its
// transfers run beside channel 1's and another node's, each with its own toggle and timeout.
TEST(SdoClientChannels, SeveralChannelsInterleave) {
  const std::vector<SdoChannelConfig> cfg = {{5, 1, 0, 0}, {5, 2, 0, 0}, {7, 1, 0, 0}};
  SdoClient c(cfg, SdoTiming{100ms, 0});
  TxQueue tx;
  ASSERT_EQ(c.channel_of(5, 1), 0);
  ASSERT_EQ(c.channel_of(5, 2), 1);
  ASSERT_EQ(c.channel_of(7), 2);
  EXPECT_EQ(c.channel_of(7, 2), -1);

  const auto up1 = c.read(0, kTvObject);
  const auto up2 = c.read(1, kTvObject);
  const auto n7 = c.read(2, {0x1000, 0});
  const Bytes initiate{0x40, 0x00, 0x20, 0x01, 0, 0, 0, 0};
  EXPECT_EQ(poll(c, kT0, tx),
            (Frames{{0x605, initiate}, {0x625, initiate}, {0x607, {0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0}}}));

  // Play TV-2 on both channels of node 5, with the responses crossing.
  const Conversation tv2 = sd6_tv2();
  for (std::size_t i = 1; i < tv2.size(); i += 2) {
    EXPECT_TRUE(c.on_frame(frame(0x5A5, tv2[i].data), kT0 + 1ms));
    EXPECT_TRUE(c.on_frame(frame(0x585, tv2[i].data), kT0 + 1ms));
    if (i + 1 < tv2.size()) {
      EXPECT_EQ(poll(c, kT0 + 1ms, tx), (Frames{{0x605, tv2[i + 1].data}, {0x625, tv2[i + 1].data}}));
    }
  }
  EXPECT_EQ(c.result(up1).size, 16);
  EXPECT_EQ(c.result(up2).size, 16);
  EXPECT_EQ(c.result(n7).status, SdoStatus::InFlight);
  // Node 7 never answered: only its channel times out.
  EXPECT_EQ(c.next_deadline(), kT0 + 100ms);
  EXPECT_EQ(poll(c, kT0 + 100ms, tx), (Frames{{0x607, {0x80, 0x00, 0x10, 0x00, 0x00, 0x00, 0x04, 0x05}}}));
  EXPECT_EQ(c.result(n7).abort_code, cia402::sdo_abort_code::kTimeout);
  EXPECT_EQ(c.counters().completed, 2U);
}

// poll() with a frame limit sends that many frames; the rest stays due, in each channel's order
// (the timeout's abort before the next request's initiate), and nothing is lost.
TEST(SdoClientChannels, FrameLimitDefersTheRestInOrder) {
  const std::vector<SdoChannelConfig> cfg = {{5, 1, 0, 0}, {7, 1, 0, 0}};
  SdoClient c(cfg, SdoTiming{100ms, 0});
  TxQueue tx;
  const Sent read5{0x605, {0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0}};
  const Sent read7{0x607, {0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0}};
  c.read(0, {0x1000, 0});
  c.read(1, {0x1000, 0});
  c.poll(kT0, tx, 1);
  EXPECT_EQ(drain(tx), Frames{read5});
  EXPECT_EQ(c.next_deadline(), core::TimePoint::min());  // node 7's request is still due
  c.poll(kT0, tx, 0);
  EXPECT_TRUE(drain(tx).empty());
  EXPECT_EQ(poll(c, kT0 + 1ms, tx), Frames{read7});

  // Node 5 times out with a second request queued: its abort, then that request's initiate.
  c.read(0, {0x1018, 1});
  c.poll(kT0 + 100ms, tx, 1);
  EXPECT_EQ(drain(tx), (Frames{{0x605, {0x80, 0x00, 0x10, 0x00, 0x00, 0x00, 0x04, 0x05}}}));
  EXPECT_EQ(c.next_deadline(), core::TimePoint::min());
  c.poll(kT0 + 100ms, tx, 1);
  EXPECT_EQ(drain(tx), (Frames{{0x605, {0x40, 0x18, 0x10, 0x01, 0, 0, 0, 0}}}));
  EXPECT_EQ(c.next_deadline(), kT0 + 101ms);  // node 7's timeout: nothing else is due
  EXPECT_EQ(c.counters().timeouts, 1U);
}

// Bad input of every kind is counted and dropped and leaves the transfer in flight as it was.
TEST(SdoClientBadInput, CountedAndDroppedWithoutTouchingTheTransfer) {
  SdoClient c = client_for(5);
  TxQueue tx;
  // Idle: any response is unexpected.
  EXPECT_TRUE(c.on_frame(frame(0x585, {0x60, 0x00, 0x10, 0x00, 0, 0, 0, 0}), kT0));
  EXPECT_EQ(c.counters().unexpected, 1U);

  const auto id = c.read(0, kTvObject);
  poll(c, kT0, tx);
  const auto with_dlc = [](CanFrame f, std::uint8_t dlc) {
    f.dlc = dlc;
    return f;
  };
  CanFrame rtr = frame(0x585, {});
  rtr.remote = true;
  rtr.dlc = 8;
  struct Junk {
    CanFrame frame;
    bool malformed;
  };
  const std::vector<Junk> junk = {
      {frame(0x585, {0x43, 0x00, 0x20, 0x02, 1, 2, 3, 4}), false},  // response for another object
      {frame(0x585, {0x80, 0x00, 0x20, 0x02, 0, 0, 2, 6}), false},  // abort for another object
      {frame(0x585, {0x60, 0x00, 0x20, 0x01, 0, 0, 0, 0}), false},  // download response to an upload
      {frame(0x585, {0x00, 1, 2, 3, 4, 5, 6, 7}), false},           // a segment before the initiate answer
      {frame(0x585, {0x41, 0x00, 0x20, 0x01, 0x10, 0, 0}), true},   // DLC 7
      {with_dlc(frame(0x585, {0x41, 0x00, 0x20, 0x01, 0x10, 0, 0, 0}), 9), true},  // DLC 9: not a CAN frame
      {frame(0x585, {}), true},                                     // DLC 0
      {frame(0x585, {0xE0, 0x00, 0x20, 0x01, 0, 0, 0, 0}), true},   // unknown specifier (7)
      {frame(0x585, {0xA0, 0x00, 0x20, 0x01, 0, 0, 0, 0}), true},   // block upload response (scs 5)
      {frame(0x585, {0xC1, 0x00, 0x20, 0x01, 0, 0, 0, 0}), true},   // block download response (scs 6)
      {rtr, true},
  };
  std::uint64_t malformed = 0;
  std::uint64_t unexpected = 1;
  for (std::size_t i = 0; i < junk.size(); ++i) {
    SCOPED_TRACE(testing::Message() << "junk " << i);
    EXPECT_TRUE(c.on_frame(junk[i].frame, kT0));
    (junk[i].malformed ? malformed : unexpected) += 1;
    EXPECT_EQ(c.counters().malformed, malformed);
    EXPECT_EQ(c.counters().unexpected, unexpected);
    EXPECT_EQ(c.result(id).status, SdoStatus::InFlight);
    EXPECT_TRUE(poll(c, kT0, tx).empty());
  }
  // Not this client's COB-IDs: not consumed, not counted.
  EXPECT_FALSE(c.on_frame(frame(0x586, {0x43, 0x00, 0x20, 0x01, 1, 2, 3, 4}), kT0));
  EXPECT_FALSE(c.on_frame(frame(0x605, {0x40, 0x00, 0x20, 0x01, 0, 0, 0, 0}), kT0));
  CanFrame extended = frame(0x585, {0x43, 0x00, 0x20, 0x01, 1, 2, 3, 4});
  extended.extended = true;
  EXPECT_FALSE(c.on_frame(extended, kT0));

  // The real conversation still works, and junk during the segments changes nothing either.
  c.on_frame(frame(0x585, {0x41, 0x00, 0x20, 0x01, 0x10, 0, 0, 0}), kT0);
  EXPECT_EQ(poll(c, kT0, tx), (Frames{{0x605, {0x60, 0, 0, 0, 0, 0, 0, 0}}}));
  EXPECT_TRUE(c.on_frame(frame(0x585, {0x43, 0x00, 0x20, 0x01, 1, 2, 3, 4}), kT0));  // initiate answer again
  EXPECT_TRUE(c.on_frame(frame(0x585, {0x00, 1, 2, 3}), kT0));                         // short segment
  EXPECT_TRUE(c.on_frame(frame(0x585, {0xC0, 0, 0, 0, 0, 0, 0, 0}), kT0));             // block
  EXPECT_TRUE(poll(c, kT0, tx).empty());
  const Conversation tv2 = sd6_tv2();
  for (std::size_t i = 3; i < tv2.size(); ++i) {
    if (tv2[i].from_client) {
      EXPECT_EQ(poll(c, kT0, tx), (Frames{{0x605, tv2[i].data}}));
    } else {
      c.on_frame(frame(0x585, tv2[i].data), kT0);
    }
  }
  const auto d = c.data(id);
  EXPECT_EQ(Bytes(d.begin(), d.end()), counting(16));
  EXPECT_EQ(c.counters().failed, 0U);
}

// on_frame, poll, submit, result, take, cancel and next_deadline do not touch the heap.
TEST(SdoClientAllocation, CyclicPathAllocatesNothing) {
  const std::vector<SdoChannelConfig> cfg = {{5, 1, 0, 0}, {5, 2, 0, 0}};
  SdoClient c(cfg, SdoTiming{100ms, 1});
  TxQueue tx;
  const Conversation tv2 = sd6_tv2();
  std::array<CanFrame, 8> responses{};
  for (std::size_t i = 0; i < tv2.size(); ++i) responses[i] = frame(0x585, tv2[i].data);
  const Bytes payload = counting(16);

  SdoResult up{};
  SdoResult timed_out{};
  std::size_t allocations = 0;
  {
    const drivegate::test::AllocationScope scope;
    const auto up_id = c.read(0, kTvObject);
    const auto dn_id = c.write_from(1, kTvObject, payload);
    const auto gone = c.write(0, {0x6040, 0}, 6, 2);
    c.cancel(gone);
    core::TimePoint now = kT0;
    for (std::size_t i = 0; i < tv2.size(); ++i) {
      c.poll(now, tx);
      (void)c.next_deadline();
      if (!tv2[i].from_client) c.on_frame(responses[i], now);
    }
    c.poll(now, tx);
    now += 100ms;
    c.poll(now, tx);
    now += 100ms;
    c.poll(now, tx);  // channel 2 never answered: retry, then abort
    up = c.take(up_id);
    timed_out = c.take(dn_id);
    tx.clear();
    allocations = scope.count();
  }
  EXPECT_EQ(allocations, 0U);
  EXPECT_EQ(up.status, SdoStatus::Done);
  EXPECT_EQ(up.size, 16);
  EXPECT_EQ(timed_out.abort_code, cia402::sdo_abort_code::kTimeout);
}

// Every abort code the digests list has a text (AKD part 1 §10.4, SD6 §6.5).
TEST(SdoAbortText, KnowsEveryCodeOfTheDigests) {
  const std::uint32_t codes[] = {
      0x05030000, 0x05040000, 0x05040001, 0x05040002, 0x05040004, 0x05040005, 0x06010000, 0x06010001,
      0x06010002, 0x06020000, 0x06040041, 0x06040042, 0x06040043, 0x06040047, 0x06060000, 0x06070010,
      0x06070012, 0x06070013, 0x06090011, 0x06090030, 0x06090031, 0x06090032, 0x06090036, 0x08000000,
      0x08000020, 0x08000021, 0x08000022, 0x08000023, 0x08000024,
  };
  for (const auto code : codes) {
    EXPECT_NE(cia402::sdo_abort_text(code), "unknown abort code") << std::hex << code;
  }
  EXPECT_EQ(cia402::sdo_abort_text(0x12345678), "unknown abort code");
}

}  // namespace
}  // namespace drivegate::canopen
