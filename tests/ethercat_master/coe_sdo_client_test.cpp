// CoeSdoClient against a fake slave mailbox (fake_line.hpp) and a small scripted SDO server in
// this file: expedited and segmented upload/download, server abort, timeout, lost reply with the
// SM1 repeat procedure, emergency in the mailbox, no allocation while polling. Request bytes are
// checked against ETG.1000.6 §5.6.2 (digest TV-6 for the expedited download layout).
#include <gtest/gtest.h>

#include <deque>
#include <map>
#include <vector>

#include "adapters/ethercat/master/coe_sdo_client.hpp"
#include "profiles/cia402/sdo_abort.hpp"
#include "tests/ethercat_master/fake_line.hpp"
#include "tests/support/alloc_counter.hpp"

namespace drivegate::ethercat {
namespace {

using namespace std::chrono_literals;
using test::FakeEsc;
using test::FakeLine;

constexpr SiiMailbox kMailbox{0x1000, 64, 0x1080, 64};

// SDO server: an object dictionary, segmented transfers, scripted aborts / silence / emergencies.
struct Server {
  std::map<std::pair<std::uint16_t, std::uint8_t>, std::vector<std::uint8_t>> od;
  std::map<std::pair<std::uint16_t, std::uint8_t>, std::uint32_t> aborts;
  int ignore = 0;  // requests left unanswered
  bool emergency_first = false;
  std::uint8_t counter = 0;
  // segmented state
  std::pair<std::uint16_t, std::uint8_t> key{};
  std::vector<std::uint8_t> up;     // remaining upload bytes
  std::vector<std::uint8_t> down;   // download bytes so far
  std::size_t down_total = 0;
  // Replies wait here while SM1 is full (a slave cannot write a full mailbox [ETG.1000.4 §6
  // SyncManager, 1-buffer mode]) or while held back: `delay_next` holds the next reply that many
  // harness cycles (a late reply).
  std::deque<std::vector<std::uint8_t>> outbox;
  int delay_next = 0;
  int delay_left = 0;
  std::uint32_t stated_size = 0;  // normal upload responses state this size instead (0: the real one)
  bool size_unstated = false;     // normal upload responses without the size indicator

  std::uint8_t next() { return counter = next_mailbox_counter(counter); }

  void send(FakeEsc& esc, std::span<const std::uint8_t> reply) {
    if (delay_next > 0) {
      delay_left = delay_next;
      delay_next = 0;
    }
    if (delay_left > 0 || esc.sm1_full || !outbox.empty()) {
      outbox.emplace_back(reply.begin(), reply.end());
    } else {
      esc.reply(reply);
    }
  }
  // Called once per harness cycle: hands a waiting reply to SM1 when it is free.
  void deliver(FakeEsc& esc) {
    if (delay_left > 0) {
      --delay_left;
      return;
    }
    if (!outbox.empty() && !esc.sm1_full) {
      esc.reply(outbox.front());
      outbox.pop_front();
    }
  }

  void handle(FakeEsc& esc, std::span<const std::uint8_t> req) {
    if (ignore > 0) {
      --ignore;
      return;
    }
    if (const CoeView c = decode_coe(req);
        c.error == MailboxError::None && c.service == static_cast<std::uint8_t>(CoeService::SdoInformation)) {
      // SDO Information: the scripted replies, in order (fragments follow as SM1 empties).
      info_requests.emplace_back(req.begin(), req.end());
      for (auto& r : info_replies) {
        r[5] = static_cast<std::uint8_t>((r[5] & 0x0F) | (next() << 4));
        send(esc, r);
      }
      info_replies.clear();
      return;
    }
    std::array<std::uint8_t, 64> out{};
    if (emergency_first) {
      emergency_first = false;
      // Dunker 8100h communication error (digest §8.1 / TV-4), error register 11h.
      const std::size_t n = encode_emergency(out, next(), CoeEmergency{0x8100, 0x11, {}});
      esc.reply(std::span<const std::uint8_t>(out.data(), n));
      // The SDO reply follows once the master has read the emergency: keep the request.
      pending.assign(req.begin(), req.end());
      return;
    }
    const SdoView v = decode_sdo_request(req);
    ASSERT_EQ(v.error, MailboxError::None);
    const CoeSdo& s = v.sdo;
    std::size_t n = 0;
    if (s.command == SdoCommand::UploadInitiateRequest || s.command == SdoCommand::DownloadInitiateRequest) {
      key = {s.index, s.subindex};
      if (auto a = aborts.find(key); a != aborts.end()) {
        n = encode_sdo_abort(out, next(), s.index, s.subindex, a->second);
        send(esc, std::span<const std::uint8_t>(out.data(), n));
        return;
      }
    }
    switch (s.command) {
      case SdoCommand::UploadInitiateRequest: {
        const auto& value = od.at(key);
        if (value.size() <= 4) {
          n = encode_sdo_upload_expedited_response(out, next(), s.index, s.subindex, value);
        } else {
          const std::size_t first = std::min<std::size_t>(value.size(), 64 - 16);
          n = encode_sdo_upload_normal_response(
              out, next(), s.index, s.subindex,
              stated_size != 0 ? stated_size : static_cast<std::uint32_t>(value.size()),
              std::span<const std::uint8_t>(value).first(first));
          if (size_unstated) {  // s = 0, size field 0 [ETG.1000.6 §5.6.2.4, CiA 301 §7.2.4.3.5]
            out[8] = static_cast<std::uint8_t>(out[8] & ~0x01U);
            core::put_u32(out, 12, 0);
          }
          up.assign(value.begin() + static_cast<std::ptrdiff_t>(first), value.end());
        }
        break;
      }
      case SdoCommand::UploadSegmentRequest: {
        const std::size_t chunk = std::min<std::size_t>(up.size(), 64 - 9);
        const bool last = chunk == up.size();
        n = encode_sdo_upload_segment_response(out, next(), s.toggle, last, std::span<const std::uint8_t>(up).first(chunk));
        up.erase(up.begin(), up.begin() + static_cast<std::ptrdiff_t>(chunk));
        break;
      }
      case SdoCommand::DownloadInitiateRequest:
        down.assign(s.data.begin(), s.data.end());
        down_total = s.expedited ? s.data.size() : s.size;
        if (down.size() >= down_total) od[key] = down;
        n = encode_sdo_download_response(out, next(), s.index, s.subindex);
        break;
      case SdoCommand::DownloadSegmentRequest:
        down.insert(down.end(), s.data.begin(), s.data.end());
        if (s.last) od[key] = down;
        n = encode_sdo_download_segment_response(out, next(), s.toggle);
        break;
      default:
        FAIL() << "unexpected command";
    }
    send(esc, std::span<const std::uint8_t>(out.data(), n));
  }
  std::vector<std::uint8_t> pending;
  std::vector<std::vector<std::uint8_t>> info_replies;  // sent (counter stamped) on the next info request
  std::vector<std::vector<std::uint8_t>> info_requests;
};

// One SDO Information message as a slave sends it [ETG.1000.6 §5.6.3.2]: mailbox header (type
// CoE), CoE header service 8, opcode with the incomplete bit, fragments left, `data`.
std::vector<std::uint8_t> info_message(SdoInfoOpcode op, bool incomplete, std::uint16_t left,
                                       std::vector<std::uint8_t> data) {
  // Sized once and copied into (GCC 12 warns falsely about vector::insert here).
  std::vector<std::uint8_t> m(6 + 2 + 4 + data.size());
  std::copy(data.begin(), data.end(), m.begin() + 12);
  put_u16(m, 0, static_cast<std::uint16_t>(2 + 4 + data.size()));
  m[5] = 0x03;           // CoE; counter stamped when sent
  m[7] = 0x80;           // CoE service 8: SDO Information
  m[8] = static_cast<std::uint8_t>(static_cast<std::uint8_t>(op) | (incomplete ? 0x80 : 0x00));
  put_u16(m, 10, left);
  return m;
}
std::vector<std::uint8_t> le16s(std::initializer_list<std::uint16_t> v) {
  std::vector<std::uint8_t> b;
  for (const auto x : v) {
    b.push_back(static_cast<std::uint8_t>(x & 0xFF));
    b.push_back(static_cast<std::uint8_t>(x >> 8));
  }
  return b;
}

struct Emergencies final : EmergencySink {
  std::vector<std::pair<std::uint16_t, CoeEmergency>> got;
  void on_emergency(std::uint16_t station, const CoeEmergency& e) noexcept override { got.emplace_back(station, e); }
};

struct Harness {
  FakeLine line;
  Server server;
  Transactions tx;
  Emergencies emcy;
  CoeSdoClient client;
  core::TimePoint now{};
  bool drop_next_sm1_read = false;
  std::vector<core::TimePoint> status_reads;  // when the client read SM1 status (080Dh)

  explicit Harness(CoeSdoTiming timing = {}, bool sink = true)
      : client(0x1001, kMailbox, timing, sink ? &emcy : nullptr) {
    FakeEsc esc;
    put_u16(esc.mem, reg::kStationAddress, 0x1001);
    const auto sm0 = encode_sm(SmEntry{0x1000, 64, 0x26, 0, 1, 0});
    const auto sm1 = encode_sm(SmEntry{0x1080, 64, 0x22, 0, 1, 0});
    std::copy(sm0.begin(), sm0.end(), esc.mem.begin() + 0x0800);
    std::copy(sm1.begin(), sm1.end(), esc.mem.begin() + 0x0808);
    esc.on_mailbox = [this](FakeEsc& e, std::span<const std::uint8_t> req) { server.handle(e, req); };
    line.slaves.push_back(std::move(esc));
  }

  void cycle() {
    client.poll(now, tx);
    std::vector<std::vector<std::uint8_t>> out;
    for (const auto& f : tx.take_frames(now + 1ms)) out.emplace_back(f.begin(), f.end());
    for (auto& f : out) {
      const bool reads_sm1 = f.size() > 20 && f[16] == static_cast<std::uint8_t>(Command::FPRD) &&
                             get_u16(f, 20) == kMailbox.tx_offset;
      if (f.size() > 20 && f[16] == static_cast<std::uint8_t>(Command::FPRD) && get_u16(f, 20) == reg::sm_status(1)) {
        status_reads.push_back(now);
      }
      line.process(f);
      if (reads_sm1 && drop_next_sm1_read) {
        drop_next_sm1_read = false;
        continue;
      }
      tx.on_frame(f);
    }
    // An emergency read: now the SDO reply the server held back.
    FakeEsc& esc = line.slaves[0];
    server.deliver(esc);
    if (!server.pending.empty() && !esc.sm1_full) {
      const auto req = server.pending;
      server.pending.clear();
      server.handle(esc, req);
    }
    now += 1ms;
    tx.expire(now);
  }
  CoeSdoResult run(CoeSdoId id, int max = 5000) {
    for (int i = 0; i < max; ++i) {
      const auto r = client.result(id);
      if (r.status == CoeSdoStatus::Done || r.status == CoeSdoStatus::Failed) return r;
      cycle();
    }
    return client.result(id);
  }
};

TEST(EthercatCoeSdo, ExpeditedDownloadWritesTheWholeSm0Buffer) {
  Harness h;
  const CoeSdoId id = h.client.download_value(0x6060, 0x00, 7, 2);  // 6060h is 16 bits (quirk 1)
  ASSERT_NE(id, 0U);
  const auto r = h.run(id);
  EXPECT_EQ(r.status, CoeSdoStatus::Done);
  ASSERT_EQ(h.line.slaves[0].requests.size(), 1U);
  const auto& req = h.line.slaves[0].requests[0];
  ASSERT_EQ(req.size(), 64U);  // the whole SM0 length, so the SyncManager sees the buffer complete
  // Mailbox header: length 10, address 0, channel/priority 0, type 3 (CoE) counter 1 -> 13h;
  // CoE header 2000h (SDO request); SDO 2Bh (expedited, size indicated, 2 bytes), 6060h:00, 07 00.
  EXPECT_EQ(std::vector<std::uint8_t>(req.begin(), req.begin() + 16),
            (std::vector<std::uint8_t>{0x0A, 0x00, 0x00, 0x00, 0x00, 0x13, 0x00, 0x20, 0x2B, 0x60, 0x60, 0x00, 0x07,
                                       0x00, 0x00, 0x00}));
  EXPECT_EQ(h.server.od.at({0x6060, 0}), (std::vector<std::uint8_t>{0x07, 0x00}));
}

TEST(EthercatCoeSdo, ExpeditedUploadAndCounterRunsOneToSeven) {
  Harness h;
  h.server.od[{0x1000, 0}] = {0x92, 0x01, 0x02, 0x00};  // digest TV-2: device type 00020192h
  for (int i = 0; i < 8; ++i) {
    const CoeSdoId id = h.client.upload_value(0x1000, 0);
    const auto r = h.run(id);
    ASSERT_EQ(r.status, CoeSdoStatus::Done);
    EXPECT_EQ(r.value, 0x00020192U);
    EXPECT_EQ(r.size, 4U);
    (void)h.client.take(id);
  }
  std::vector<std::uint8_t> counters;
  for (const auto& q : h.line.slaves[0].requests) counters.push_back(static_cast<std::uint8_t>(q[5] >> 4));
  EXPECT_EQ(counters, (std::vector<std::uint8_t>{1, 2, 3, 4, 5, 6, 7, 1}));
}

TEST(EthercatCoeSdo, SegmentedUploadAndDownload) {
  Harness h;
  std::vector<std::uint8_t> name(150);
  for (std::size_t i = 0; i < name.size(); ++i) name[i] = static_cast<std::uint8_t>('A' + i % 26);
  h.server.od[{0x1008, 0}] = name;
  std::array<std::uint8_t, 200> into{};
  const CoeSdoId up = h.client.upload(0x1008, 0, into);
  const auto r = h.run(up);
  ASSERT_EQ(r.status, CoeSdoStatus::Done) << std::hex << r.abort_code;
  EXPECT_EQ(r.size, 150U);
  const auto got = h.client.data(up);
  EXPECT_EQ(std::vector<std::uint8_t>(got.begin(), got.end()), name);
  // 48 bytes in the initiate response, then segments of up to 55 bytes: 2 segment requests.
  EXPECT_EQ(h.line.slaves[0].requests.size(), 3U);

  std::vector<std::uint8_t> blob(130);
  for (std::size_t i = 0; i < blob.size(); ++i) blob[i] = static_cast<std::uint8_t>(i);
  const CoeSdoId down = h.client.download(0x2000, 1, blob);
  ASSERT_EQ(h.run(down).status, CoeSdoStatus::Done);
  EXPECT_EQ(h.server.od.at({0x2000, 1}), blob);
  // Toggle bits of the two download segments (bit 4 of the command byte): 0 then 1.
  const auto& q = h.line.slaves[0].requests;
  // 48 bytes in the initiate request, then 55 + 27 in two segments.
  ASSERT_EQ(q.size(), 6U);
  EXPECT_EQ(q[4][8] & 0x11, 0x00);
  EXPECT_EQ(q[5][8] & 0x11, 0x11);  // toggle 1, c = 1: last segment
}

TEST(EthercatCoeSdo, ServerAbortFailsWithItsCode) {
  Harness h;
  h.server.aborts[{0x60C2, 2}] = 0x06010002;  // attempt to write a read-only object
  const CoeSdoId id = h.client.download_value(0x60C2, 2, 0xFD, 1);
  const auto r = h.run(id);
  EXPECT_EQ(r.status, CoeSdoStatus::Failed);
  EXPECT_EQ(r.abort_code, 0x06010002U);
  EXPECT_FALSE(cia402::sdo_abort_text(r.abort_code).empty());
  EXPECT_EQ(h.client.counters().aborts, 1U);
}

TEST(EthercatCoeSdo, SilentServerTimesOutAndTheQueueMovesOn) {
  CoeSdoTiming t;
  t.timeout = 20ms;
  Harness h(t);
  h.server.ignore = 1;
  h.server.od[{0x1000, 0}] = {1, 2, 3, 4};
  const CoeSdoId first = h.client.upload_value(0x1000, 0);
  const CoeSdoId second = h.client.upload_value(0x1000, 0);
  EXPECT_EQ(h.client.result(second).status, CoeSdoStatus::Queued);
  const auto t0 = h.now;
  const auto r = h.run(first);
  EXPECT_EQ(r.status, CoeSdoStatus::Failed);
  EXPECT_EQ(r.abort_code, 0x05040000U);
  EXPECT_GE(h.now - t0, 20ms);
  EXPECT_LT(h.now - t0, 30ms);
  EXPECT_EQ(h.run(second).status, CoeSdoStatus::Done);
}

TEST(EthercatCoeSdo, LateReplyIsNotTakenAsTheAnswerToTheNextRequest) {
  // The reply to the first upload comes after its timeout and sits in SM1; the next upload of the
  // same object must get the value the slave has now, not the old reply (ETG.1000.6 §5.6: the
  // mailbox counter of a slave's reply says nothing about the request it answers).
  CoeSdoTiming t;
  t.timeout = 20ms;
  Harness h(t, false);  // no emergency sink: nothing reads SM1 while idle
  h.server.od[{0x2100, 0}] = {1, 0, 0, 0};
  h.server.delay_next = 30;
  const auto r1 = h.run(h.client.upload_value(0x2100, 0));
  EXPECT_EQ(r1.status, CoeSdoStatus::Failed);
  EXPECT_EQ(r1.abort_code, 0x05040000U);
  h.server.od[{0x2100, 0}] = {2, 0, 0, 0};
  for (int i = 0; i < 100 && !h.line.slaves[0].sm1_full; ++i) h.cycle();
  ASSERT_TRUE(h.line.slaves[0].sm1_full);  // the late reply is in SM1 now
  const auto r2 = h.run(h.client.upload_value(0x2100, 0));
  ASSERT_EQ(r2.status, CoeSdoStatus::Done);
  EXPECT_EQ(r2.value, 2U);
  EXPECT_EQ(h.client.counters().stale_replies, 1U);
  EXPECT_EQ(h.line.slaves[0].requests.size(), 2U);
}

TEST(EthercatCoeSdo, EmergencyFoundWhenEmptyingSm1StillGoesToTheSink) {
  Harness h;
  h.server.od[{0x1001, 0}] = {0x22};
  // An emergency already in SM1 when the request starts [digest §8.1: 8100h, error register 11h].
  std::array<std::uint8_t, 64> emcy{};
  const std::size_t n = encode_emergency(emcy, 3, CoeEmergency{0x8100, 0x11, {}});
  h.line.slaves[0].reply(std::span<const std::uint8_t>(emcy.data(), n));
  const auto r = h.run(h.client.upload_value(0x1001, 0));
  ASSERT_EQ(r.status, CoeSdoStatus::Done);
  EXPECT_EQ(r.value, 0x22U);
  ASSERT_EQ(h.emcy.got.size(), 1U);
  EXPECT_EQ(h.emcy.got[0].second.error_code, 0x8100);
  EXPECT_EQ(h.client.counters().stale_replies, 0U);
}

TEST(EthercatCoeSdo, IdleClientReadsSm1ForEmergenciesOnItsStationsGrid) {
  // Nothing asked: SM1 status is read every idle_poll_interval (10 ms), at the station's offset
  // (0x1001 x 1 ms mod 10 ms = 7 ms), not every cycle; an emergency is still delivered.
  Harness h;
  for (int i = 0; i < 100; ++i) h.cycle();
  ASSERT_EQ(h.status_reads.size(), 11U);  // at once, then 7, 17, ..., 97 ms
  EXPECT_EQ(h.status_reads[0], core::TimePoint{});
  for (std::size_t k = 1; k < h.status_reads.size(); ++k) {
    EXPECT_EQ(h.status_reads[k].time_since_epoch(), 7ms + (k - 1) * 10ms) << "read " << k;
  }
  std::array<std::uint8_t, 64> emcy{};
  const std::size_t n = encode_emergency(emcy, 3, CoeEmergency{0x8100, 0x11, {}});
  h.line.slaves[0].reply(std::span<const std::uint8_t>(emcy.data(), n));
  const auto placed = h.now;
  while (h.emcy.got.empty() && h.now - placed < 50ms) h.cycle();
  ASSERT_EQ(h.emcy.got.size(), 1U);
  EXPECT_LE(h.now - placed, 11ms);
  EXPECT_EQ(h.emcy.got[0].second.error_code, 0x8100);
}

TEST(EthercatCoeSdo, IdlePollingEveryCycleWhenAskedFor) {
  CoeSdoTiming t;
  t.idle_poll_interval = 1ms;
  Harness h(t);
  for (int i = 0; i < 20; ++i) h.cycle();
  EXPECT_EQ(h.status_reads.size(), 20U);
}

TEST(EthercatCoeSdo, LostReplyIsFetchedAgainWithTheRepeatBit) {
  Harness h;
  h.server.od[{0x1018, 1}] = {0x0F, 0, 0, 0};
  h.drop_next_sm1_read = true;
  const CoeSdoId id = h.client.upload_value(0x1018, 1);
  const auto r = h.run(id);
  ASSERT_EQ(r.status, CoeSdoStatus::Done);
  EXPECT_EQ(r.value, 0x0FU);
  EXPECT_EQ(h.client.counters().repeats, 1U);
  EXPECT_EQ(h.line.slaves[0].requests.size(), 1U);  // not asked again: the slave repeated its reply
  EXPECT_EQ(h.line.slaves[0].sm1_reads, 2);
  EXPECT_EQ(h.line.slaves[0].mem[0x080E] & 0x02, 0x02);  // repeat request toggled
  EXPECT_EQ(h.line.slaves[0].mem[0x080F] & 0x02, 0x02);  // and acknowledged
}

TEST(EthercatCoeSdo, RepeatRequestInvertsTheBitTheSlaveHas) {
  // A previous master left SM1's repeat request set (and acknowledged); the activate byte also has
  // another bit set. The repeat must invert the slave's bit and keep the others
  // [ETG.1000.4 Table 59: 080Eh activate bit 1 repeat, 080Fh PDI control bit 1 repeat ack].
  Harness h;
  h.server.od[{0x1018, 2}] = {0x34, 0x12, 0, 0};
  FakeEsc& esc = h.line.slaves[0];
  esc.mem[0x080E] = 0x43;  // enable | repeat | DC event 0 bus
  esc.mem[0x080F] = 0x02;  // repeat acknowledged
  h.drop_next_sm1_read = true;
  const auto r = h.run(h.client.upload_value(0x1018, 2));
  ASSERT_EQ(r.status, CoeSdoStatus::Done) << std::hex << r.abort_code;
  EXPECT_EQ(r.value, 0x1234U);
  EXPECT_EQ(h.client.counters().repeats, 1U);
  EXPECT_EQ(esc.requests.size(), 1U);
  EXPECT_EQ(esc.sm1_reads, 2);
  EXPECT_EQ(esc.mem[0x080E], 0x41);  // repeat inverted, the rest as it was
  EXPECT_EQ(esc.mem[0x080F], 0x00);  // acknowledged
}

TEST(EthercatCoeSdo, EmergencyInTheMailboxGoesToTheSink) {
  Harness h;
  h.server.od[{0x1001, 0}] = {0x11};
  h.server.emergency_first = true;
  const CoeSdoId id = h.client.upload_value(0x1001, 0);
  const auto r = h.run(id);
  ASSERT_EQ(r.status, CoeSdoStatus::Done);
  EXPECT_EQ(r.value, 0x11U);
  ASSERT_EQ(h.emcy.got.size(), 1U);
  EXPECT_EQ(h.emcy.got[0].first, 0x1001);
  EXPECT_EQ(h.emcy.got[0].second.error_code, 0x8100);
  EXPECT_EQ(h.emcy.got[0].second.error_register, 0x11);
}

TEST(EthercatCoeSdo, UploadLongerThanTheBufferFails) {
  Harness h;
  h.server.od[{0x1008, 0}] = std::vector<std::uint8_t>(40, 'x');
  std::array<std::uint8_t, 10> small{};
  const auto r = h.run(h.client.upload(0x1008, 0, small));
  EXPECT_EQ(r.status, CoeSdoStatus::Failed);
  EXPECT_EQ(r.abort_code, 0x05040005U);
}

TEST(EthercatCoeSdo, UploadShorterThanItsStatedSizeFails) {
  Harness h;
  h.server.od[{0x1008, 0}] = std::vector<std::uint8_t>(150, 'y');
  h.server.stated_size = 200;  // segments end after 150 bytes
  std::array<std::uint8_t, 256> into{};
  const auto r = h.run(h.client.upload(0x1008, 0, into));
  EXPECT_EQ(r.status, CoeSdoStatus::Failed);
  EXPECT_EQ(r.abort_code, 0x06070013U);  // length of service parameter too low
}

TEST(EthercatCoeSdo, NormalUploadWithoutStatedSizeFails) {
  Harness h;
  h.server.od[{0x1008, 0}] = std::vector<std::uint8_t>(10, 'z');
  h.server.size_unstated = true;
  std::array<std::uint8_t, 64> into{};
  const auto r = h.run(h.client.upload(0x1008, 0, into));
  EXPECT_EQ(r.status, CoeSdoStatus::Failed);
  EXPECT_EQ(r.abort_code, 0x05040001U);
}

TEST(EthercatCoeSdo, ResetFailsQueuedRequestsAndForgetsTheReplyCounter) {
  Harness h;
  h.server.od[{0x1000, 0}] = {0x92, 0x01, 0x02, 0x00};
  const CoeSdoId first = h.client.upload_value(0x1000, 0);
  ASSERT_EQ(h.run(first).status, CoeSdoStatus::Done);  // the slave's reply carried counter 1
  const CoeSdoId a = h.client.upload_value(0x1000, 0);
  const CoeSdoId b = h.client.upload_value(0x1000, 0);
  h.cycle();
  EXPECT_EQ(h.client.result(a).status, CoeSdoStatus::InFlight);
  // The slave is re-initialised: its SMs are cleared and it numbers its replies from 1 again.
  FakeEsc& esc = h.line.slaves[0];
  esc.sm1_full = false;
  esc.last_reply.clear();
  h.server.outbox.clear();
  h.server.counter = 0;
  h.client.reset();
  EXPECT_TRUE(h.client.idle());
  EXPECT_EQ(h.client.result(a).status, CoeSdoStatus::Failed);
  EXPECT_EQ(h.client.result(a).abort_code, 0x08000022U);
  EXPECT_EQ(h.client.result(b).status, CoeSdoStatus::Failed);
  EXPECT_EQ(h.client.result(b).abort_code, 0x08000022U);
  EXPECT_EQ(h.client.result(first).status, CoeSdoStatus::Done);  // finished results stay
  const auto r = h.run(h.client.upload_value(0x1000, 0));
  ASSERT_EQ(r.status, CoeSdoStatus::Done) << std::hex << r.abort_code;  // its reply has counter 1 again
  EXPECT_EQ(r.value, 0x00020192U);
}

// SDO Information through the fake slave: request layout, fragments joined (an index split across
// two of them), a gap in the fragments, an SDO Info Error, malformed replies survived.
TEST(EthercatCoeSdoInfo, OdListRequestLayoutAndFragmentsJoined) {
  Harness h;
  // List type 1 and 1000h, 1018h, 6040h; then 6041h split over two fragments; then 607Ah.
  auto a = le16s({0x0001, 0x1000, 0x1018, 0x6040});
  a.push_back(0x41);
  h.server.info_replies.push_back(info_message(SdoInfoOpcode::GetOdListResponse, true, 2, a));
  h.server.info_replies.push_back(info_message(SdoInfoOpcode::GetOdListResponse, true, 1, {0x60}));
  h.server.info_replies.push_back(info_message(SdoInfoOpcode::GetOdListResponse, false, 0, le16s({0x607A})));
  std::array<std::uint16_t, 16> list{};
  const CoeSdoId id = h.client.od_list(OdListType::All, list);
  ASSERT_NE(id, 0U);
  const auto r = h.run(id);
  ASSERT_EQ(r.status, CoeSdoStatus::Done) << std::hex << r.abort_code;
  ASSERT_EQ(r.size, 5U);
  EXPECT_EQ(std::vector<std::uint16_t>(list.begin(), list.begin() + 5),
            (std::vector<std::uint16_t>{0x1000, 0x1018, 0x6040, 0x6041, 0x607A}));
  // Get OD List request: length 8, CoE 8000h, opcode 01h, fragments 0, list type 0001h.
  ASSERT_EQ(h.server.info_requests.size(), 1U);
  const auto& q = h.server.info_requests[0];
  ASSERT_EQ(q.size(), 64U);  // the whole SM0
  EXPECT_EQ(std::vector<std::uint8_t>(q.begin(), q.begin() + 14),
            (std::vector<std::uint8_t>{0x08, 0x00, 0x00, 0x00, 0x00, 0x13, 0x00, 0x80, 0x01, 0x00, 0x00, 0x00, 0x01,
                                       0x00}));
}

TEST(EthercatCoeSdoInfo, MissingFragmentFailsAndTheNextRequestWorks) {
  Harness h;
  h.server.info_replies.push_back(info_message(SdoInfoOpcode::GetOdListResponse, true, 2, le16s({1, 0x1000})));
  h.server.info_replies.push_back(info_message(SdoInfoOpcode::GetOdListResponse, false, 0, le16s({0x6040})));
  std::array<std::uint16_t, 16> list{};
  auto r = h.run(h.client.od_list(OdListType::All, list));
  EXPECT_EQ(r.status, CoeSdoStatus::Failed);
  EXPECT_EQ(r.abort_code, 0x08000000U);
  h.server.od[{0x1000, 0}] = {0x92, 0x01, 0x02, 0x00};
  r = h.run(h.client.upload_value(0x1000, 0));
  EXPECT_EQ(r.status, CoeSdoStatus::Done);
  EXPECT_EQ(r.value, 0x00020192U);
}

TEST(EthercatCoeSdoInfo, ListLongerThanTheArrayFails) {
  Harness h;
  h.server.info_replies.push_back(
      info_message(SdoInfoOpcode::GetOdListResponse, true, 1, le16s({1, 0x1000, 0x1001, 0x1008, 0x1009})));
  h.server.info_replies.push_back(info_message(SdoInfoOpcode::GetOdListResponse, false, 0, le16s({0x6040})));
  std::array<std::uint16_t, 3> list{};
  const auto r = h.run(h.client.od_list(OdListType::All, list));
  EXPECT_EQ(r.status, CoeSdoStatus::Failed);
  EXPECT_EQ(r.abort_code, 0x05040005U);
  // The second fragment came after the request ended: dropped as stale, not taken for another.
  h.server.od[{0x1000, 0}] = {0x92, 0x01, 0x02, 0x00};
  EXPECT_EQ(h.run(h.client.upload_value(0x1000, 0)).status, CoeSdoStatus::Done);
  EXPECT_GE(h.client.counters().stale_replies, 1U);
}

TEST(EthercatCoeSdoInfo, DescriptionsWithNamesErrorAndTruncation) {
  Harness h;
  // Object description 6040h: data type 0006h, max sub-index 0, object code 7, "Controlword".
  std::vector<std::uint8_t> od{0x40, 0x60, 0x06, 0x00, 0x00, 0x07};
  for (const char c : std::string_view("Controlword")) od.push_back(static_cast<std::uint8_t>(c));
  h.server.info_replies.push_back(info_message(SdoInfoOpcode::GetObjectDescriptionResponse, false, 0, od));
  std::array<char, 32> name{};
  auto r = h.run(h.client.object_description(0x6040, name));
  ASSERT_EQ(r.status, CoeSdoStatus::Done) << std::hex << r.abort_code;
  EXPECT_EQ(std::string_view(name.data(), r.size), "Controlword");
  EXPECT_EQ(r.info.data_type, 0x0006);
  EXPECT_EQ(r.info.object_code, 7);
  EXPECT_FALSE(r.info.name_truncated);
  ASSERT_EQ(h.server.info_requests.size(), 1U);
  EXPECT_EQ(h.server.info_requests[0][8], 0x03);  // Get Object Description request
  EXPECT_EQ(get_u16(h.server.info_requests[0], 12), 0x6040);

  // Entry description 6041h:00 with the unit type, its name in two fragments, cut at 8 bytes.
  std::vector<std::uint8_t> e{0x41, 0x60, 0x00, value_info::kUnitType, 0x06, 0x00, 16, 0x00, 0x07, 0x00,
                              0x00, 0x00, 0x01, 0x00};
  for (const char c : std::string_view("Status")) e.push_back(static_cast<std::uint8_t>(c));
  h.server.info_replies.push_back(info_message(SdoInfoOpcode::GetEntryDescriptionResponse, true, 1, e));
  h.server.info_replies.push_back(info_message(SdoInfoOpcode::GetEntryDescriptionResponse, false, 0,
                                               {'w', 'o', 'r', 'd'}));
  std::array<char, 8> shortname{};
  r = h.run(h.client.entry_description(0x6041, 0, shortname, value_info::kUnitType));
  ASSERT_EQ(r.status, CoeSdoStatus::Done) << std::hex << r.abort_code;
  EXPECT_EQ(std::string_view(shortname.data(), r.size), "Statuswo");
  EXPECT_TRUE(r.info.name_truncated);
  EXPECT_EQ(r.info.bit_length, 16);
  EXPECT_EQ(r.info.object_access, 0x0007);
  EXPECT_EQ(r.info.unit_type, 0x00010000U);
  EXPECT_EQ(h.server.info_requests[1][8], 0x05);  // Get Entry Description request
  EXPECT_EQ(h.server.info_requests[1][15], value_info::kUnitType);

  // SDO Info Error request: the abort code [ETG.1000.6 §5.6.3.7].
  h.server.info_replies.push_back(info_message(SdoInfoOpcode::Error, false, 0, {0x00, 0x00, 0x02, 0x06}));
  r = h.run(h.client.object_description(0x5555, name));
  EXPECT_EQ(r.status, CoeSdoStatus::Failed);
  EXPECT_EQ(r.abort_code, 0x06020000U);
}

TEST(EthercatCoeSdoInfo, MalformedAndForeignRepliesAreCountedAndSurvived) {
  CoeSdoTiming timing;
  timing.timeout = 50ms;
  Harness h(timing);
  // Cut in the info header; then the description of another object; then an SDO response.
  h.server.info_replies.push_back({0x04, 0x00, 0x00, 0x00, 0x00, 0x03, 0x00, 0x80, 0x04, 0x00});
  h.server.info_replies.push_back(
      info_message(SdoInfoOpcode::GetObjectDescriptionResponse, false, 0, {0x41, 0x60, 0x06, 0x00, 0x00, 0x07}));
  std::array<char, 16> name{};
  const auto r = h.run(h.client.object_description(0x6040, name));
  EXPECT_EQ(r.status, CoeSdoStatus::Failed);
  EXPECT_EQ(r.abort_code, 0x05040000U);  // nothing fitting came: timed out
  EXPECT_EQ(h.client.counters().malformed, 1U);
  EXPECT_EQ(h.client.counters().unexpected, 1U);
  h.server.od[{0x1000, 0}] = {0x92, 0x01, 0x02, 0x00};
  EXPECT_EQ(h.run(h.client.upload_value(0x1000, 0)).status, CoeSdoStatus::Done);
}

TEST(EthercatCoeSdo, QueueHasAFixedSize) {
  Harness h;
  for (std::size_t i = 0; i < CoeSdoClient::kQueueDepth; ++i) EXPECT_NE(h.client.upload_value(0x1000, 0), 0U);
  EXPECT_EQ(h.client.upload_value(0x1000, 0), 0U);
  EXPECT_EQ(h.client.counters().queue_full, 1U);
  EXPECT_FALSE(CoeSdoClient(0x1001, SiiMailbox{0x1000, 8, 0x1080, 8}).valid());
}

TEST(EthercatCoeSdo, PollingDoesNotAllocate) {
  // Client and transactions alone, the slave's answers written by hand: the fake allocates.
  Transactions tx;
  CoeSdoClient client(0x1001, kMailbox);
  const CoeSdoId id = client.upload_value(0x1000, 0);
  std::array<std::uint8_t, kMaxFrameSize> echo{};
  core::TimePoint now{};
  drivegate::test::AllocationScope scope;
  for (int i = 0; i < 50; ++i) {
    client.poll(now, tx);
    for (const auto& f : tx.take_frames(now + 1ms)) {
      std::copy(f.begin(), f.end(), echo.begin());
      put_u16(echo, 16 + 10 + (get_u16(echo, 22) & 0x7FFU), 1);  // one datagram per frame: WKC 1
      (void)tx.on_frame(std::span<const std::uint8_t>(echo.data(), f.size()));
    }
    now += 1ms;
    tx.expire(now);
  }
  EXPECT_EQ(scope.count(), 0U);
  EXPECT_EQ(client.result(id).status, CoeSdoStatus::InFlight);
}

}  // namespace
}  // namespace drivegate::ethercat
