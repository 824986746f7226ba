// Mailbox and CoE of a simulated slave: SM0/SM1 in mailbox mode, SDO expedited/normal/segmented,
// aborts, SDO information, emergencies, the repeat request and the mailbox counter. Frames and
// mailboxes are built with the wire codecs; expected bytes follow ETG.1000.4 (SM mailbox mode) and
// ETG.1000.6 §5.6 (CoE) as cited per test.
#include <gtest/gtest.h>

#include <string>

#include "adapters/ethercat/sim/coe_server.hpp"
#include "adapters/ethercat/sim/object_dictionary.hpp"
#include "tests/ethercat_sim/coe_line.hpp"

namespace drivegate::ethercat::sim {
namespace {

using test::Bus;
using test::CoeLine;
using test::Reply;
using test::kMbxIn;
using test::kMbxOut;
using test::kMbxSize;

TEST(EthercatSimMailbox, InitToPreOpChecksMailboxSms) {
  CoeLine l;
  // No SM0/SM1 configured: invalid mailbox configuration 0016h [ETG.1000.6 §5.3.2].
  EXPECT_EQ(l.bus.request(l.st, AlState::PreOp), 0x0011);
  EXPECT_EQ(l.bus.fprd(l.st, reg::kAlStatusCode, 2).u16(), 0x0016);
  // SM1 with the wrong length: still refused.
  l.bus.write_sm(l.st, 0, SmEntry{kMbxOut, kMbxSize, sm_control::kMailboxOut, 0, 1, 0});
  l.bus.write_sm(l.st, 1, SmEntry{kMbxIn, 64, sm_control::kMailboxIn, 0, 1, 0});
  EXPECT_EQ(l.bus.request(l.st, AlState::PreOp, true), 0x0011);
  l.mailbox_sms();
  EXPECT_EQ(l.bus.request(l.st, AlState::PreOp, true), 0x0002);
  // In PRE-OP with an empty SM1: reading it is refused (WKC 0), SM0 takes one mailbox and a
  // second write to the full SM0 is refused until the slave has taken it.
  EXPECT_EQ(l.bus.fprd(l.st, kMbxIn, kMbxSize).wkc, 0);
}

TEST(EthercatSimMailbox, ExpeditedUploadAndDownload) {
  CoeLine l;
  l.preop();
  // Upload 1000h: expedited response 43h, 00020192h [ETG.1000.6 §5.6.2.4; CiA 301 SDO].
  std::size_t n = encode_sdo_upload_request(l.req, l.next(), 0x1000, 0);
  SdoView v = l.sdo(std::span(l.req.data(), n));
  ASSERT_EQ(v.error, MailboxError::None);
  EXPECT_EQ(v.sdo.command, SdoCommand::UploadInitiateResponse);
  EXPECT_TRUE(v.sdo.expedited);
  ASSERT_EQ(v.sdo.data.size(), 4U);
  EXPECT_EQ(get_u32(v.sdo.data, 0), 0x00020192U);
  // Raw bytes: mailbox header length 10, type CoE, counter 1; CoE 3000h (SDO response); 43 00 10 00.
  const std::array<std::uint8_t, 16> expect{0x0A, 0x00, 0x00, 0x00, 0x00, 0x13, 0x00, 0x30,
                                            0x43, 0x00, 0x10, 0x00, 0x92, 0x01, 0x02, 0x00};
  EXPECT_TRUE(std::equal(expect.begin(), expect.end(), l.reply.data.begin()));
  // Download 2000h := 5678h, read back.
  n = encode_sdo_download_value(l.req, l.next(), 0x2000, 0, 0x5678, 2);
  v = l.sdo(std::span(l.req.data(), n));
  EXPECT_EQ(v.sdo.command, SdoCommand::DownloadInitiateResponse);
  EXPECT_EQ(get_u16(l.app.od.value(0x2000, 0), 0), 0x5678);
  n = encode_sdo_upload_request(l.req, l.next(), 0x2000, 0);
  v = l.sdo(std::span(l.req.data(), n));
  EXPECT_EQ(get_u16(v.sdo.data, 0), 0x5678);
}

TEST(EthercatSimMailbox, Aborts) {
  CoeLine l;
  l.preop();
  struct Case {
    std::uint16_t index;
    std::uint8_t sub;
    bool write;
    std::size_t size;
    std::uint32_t code;  // CiA 301 §7.2.4.3.17
  };
  const std::array<Case, 5> cases{
      Case{0x3000, 0, false, 0, 0x06020000},  // object does not exist
      Case{0x6040, 7, false, 0, 0x06090011},  // subindex does not exist
      Case{0x1000, 0, true, 4, 0x06010002},   // read only
      Case{0x2000, 0, true, 4, 0x06070012},   // length too high
      Case{0x2000, 0, true, 1, 0x06070013},   // length too low
  };
  for (const Case& c : cases) {
    const std::size_t n = c.write ? encode_sdo_download_value(l.req, l.next(), c.index, c.sub, 1, c.size)
                                  : encode_sdo_upload_request(l.req, l.next(), c.index, c.sub);
    const SdoView v = l.sdo(std::span(l.req.data(), n));
    EXPECT_EQ(v.sdo.command, SdoCommand::Abort) << std::hex << c.index;
    EXPECT_EQ(v.sdo.abort_code, c.code) << std::hex << c.index;
    EXPECT_EQ(v.sdo.index, c.index);
  }
  // A segment with no transfer open: 05040001h.
  const std::size_t n = encode_sdo_upload_segment_request(l.req, l.next(), false);
  EXPECT_EQ(l.sdo(std::span(l.req.data(), n)).sdo.abort_code, 0x05040001U);
}

TEST(EthercatSimMailbox, SegmentedUploadAndDownload) {
  CoeLine l;
  l.preop();
  // Upload 300 bytes through a 128-byte mailbox: the normal response carries 128 - 16 = 112, the
  // segments 128 - 9 = 119, then 69 [ETG.1000.6 §5.6.2.4-§5.6.2.6].
  std::size_t n = encode_sdo_upload_request(l.req, l.next(), 0x2001, 0);
  SdoView v = l.sdo(std::span(l.req.data(), n));
  ASSERT_EQ(v.sdo.command, SdoCommand::UploadInitiateResponse);
  EXPECT_FALSE(v.sdo.expedited);
  EXPECT_EQ(v.sdo.size, 300U);
  std::vector<std::uint8_t> got(v.sdo.data.begin(), v.sdo.data.end());
  EXPECT_EQ(got.size(), 112U);
  bool toggle = false;
  bool last = false;
  std::vector<std::size_t> sizes;
  while (!last) {
    n = encode_sdo_upload_segment_request(l.req, l.next(), toggle);
    v = l.sdo(std::span(l.req.data(), n));
    ASSERT_EQ(v.sdo.command, SdoCommand::UploadSegmentResponse);
    EXPECT_EQ(v.sdo.toggle, toggle);
    got.insert(got.end(), v.sdo.data.begin(), v.sdo.data.end());
    sizes.push_back(v.sdo.data.size());
    last = v.sdo.last;
    toggle = !toggle;
  }
  EXPECT_EQ(sizes, (std::vector<std::size_t>{119, 69}));
  EXPECT_EQ(got, l.app.long_value);

  // Download 300 bytes: initiate with 128 - 16 = 112, then segments.
  std::vector<std::uint8_t> data(300);
  for (std::size_t i = 0; i < data.size(); ++i) data[i] = static_cast<std::uint8_t>(i);
  n = encode_sdo_download_normal(l.req, l.next(), 0x2001, 0, 300, std::span(data.data(), 112));
  v = l.sdo(std::span(l.req.data(), n));
  EXPECT_EQ(v.sdo.command, SdoCommand::DownloadInitiateResponse);
  std::size_t at = 112;
  toggle = false;
  while (at < data.size()) {
    const std::size_t chunk = std::min<std::size_t>(119, data.size() - at);
    n = encode_sdo_download_segment(l.req, l.next(), toggle, at + chunk == data.size(), std::span(data.data() + at, chunk));
    v = l.sdo(std::span(l.req.data(), n));
    EXPECT_EQ(v.sdo.command, SdoCommand::DownloadSegmentResponse);
    EXPECT_EQ(v.sdo.toggle, toggle);
    at += chunk;
    toggle = !toggle;
  }
  const auto stored = l.app.od.value(0x2001, 0);
  EXPECT_TRUE(std::equal(stored.begin(), stored.end(), data.begin(), data.end()));
  // A wrong toggle aborts with 05030000h.
  n = encode_sdo_upload_request(l.req, l.next(), 0x2001, 0);
  l.sdo(std::span(l.req.data(), n));
  n = encode_sdo_upload_segment_request(l.req, l.next(), true);
  EXPECT_EQ(l.sdo(std::span(l.req.data(), n)).sdo.abort_code, 0x05030000U);
}

TEST(EthercatSimMailbox, SdoInformation) {
  CoeLine l;
  l.preop();
  std::size_t n = encode_get_od_list_request(l.req, l.next(), OdListType::All);
  ASSERT_EQ(l.put(std::span(l.req.data(), n)), 1);
  Reply r = l.get();
  SdoInfoView v = decode_sdo_info(r.bytes());
  ASSERT_EQ(v.error, MailboxError::None);
  EXPECT_EQ(v.opcode, SdoInfoOpcode::GetOdListResponse);
  ASSERT_EQ(v.index_count(), 4U);
  EXPECT_EQ(v.index_at(0), 0x1000);
  EXPECT_EQ(v.index_at(3), 0x6040);
  n = encode_get_od_list_request(l.req, l.next(), OdListType::RxPdoMappable);
  l.put(std::span(l.req.data(), n));
  r = l.get();
  v = decode_sdo_info(r.bytes());
  ASSERT_EQ(v.index_count(), 1U);
  EXPECT_EQ(v.index_at(0), 0x6040);

  n = encode_get_object_description_request(l.req, l.next(), 0x6040);
  l.put(std::span(l.req.data(), n));
  r = l.get();
  v = decode_sdo_info(r.bytes());
  EXPECT_EQ(v.opcode, SdoInfoOpcode::GetObjectDescriptionResponse);
  EXPECT_EQ(v.object.max_subindex, 1);
  EXPECT_EQ(v.object.object_code, object_code::kRecord);
  EXPECT_EQ(v.object.name, "Record");

  n = encode_get_entry_description_request(l.req, l.next(), 0x6040, 1, 0);
  l.put(std::span(l.req.data(), n));
  r = l.get();
  v = decode_sdo_info(r.bytes());
  EXPECT_EQ(v.opcode, SdoInfoOpcode::GetEntryDescriptionResponse);
  EXPECT_EQ(v.entry.data_type, data_type::kUnsigned16);
  EXPECT_EQ(v.entry.bit_length, 16);
  EXPECT_EQ(v.entry.name, "Word");

  n = encode_get_object_description_request(l.req, l.next(), 0x5555);
  l.put(std::span(l.req.data(), n));
  r = l.get();
  v = decode_sdo_info(r.bytes());
  EXPECT_EQ(v.opcode, SdoInfoOpcode::Error);
  EXPECT_EQ(v.abort_code, 0x06020000U);
}

TEST(EthercatSimMailbox, OdListInFragments) {
  CoeLine l;
  const std::array<std::uint8_t, 1> v{0};
  for (std::uint16_t i = 0; i < 100; ++i) {
    l.app.od.add_variable(static_cast<std::uint16_t>(0x3000 + i), data_type::kUnsigned8, object_access::kReadPreOp, "x", v);
  }
  l.preop();
  // 104 indexes; a 128-byte mailbox holds (128 - 12) / 2 = 58 u16: the first fragment the list
  // type and 57 indexes, the second 47 [ETG.1000.6 §5.6.3.2 fragments, "fragments left"].
  const std::size_t n = encode_get_od_list_request(l.req, l.next(), OdListType::All);
  ASSERT_EQ(l.put(std::span(l.req.data(), n)), 1);
  Reply r = l.get();
  SdoInfoView f = decode_sdo_info(r.bytes(), true);
  ASSERT_EQ(f.error, MailboxError::None);
  EXPECT_TRUE(f.incomplete);
  EXPECT_EQ(f.fragments_left, 1);
  EXPECT_EQ(f.index_count(), 57U);
  EXPECT_EQ(f.index_at(1), 0x2000);
  r = l.get();
  f = decode_sdo_info(r.bytes(), false);
  ASSERT_EQ(f.error, MailboxError::None);
  EXPECT_FALSE(f.incomplete);
  EXPECT_EQ(f.fragments_left, 0);
  EXPECT_EQ(f.index_count(), 47U);
  EXPECT_EQ(f.index_at(46), 0x6040);
  // List type 0: the five lengths (all, RxPDO, TxPDO, backup, startup).
  const std::size_t m = encode_get_od_list_request(l.req, l.next(), OdListType::Lengths);
  ASSERT_EQ(l.put(std::span(l.req.data(), m)), 1);
  r = l.get();
  f = decode_sdo_info(r.bytes(), true);
  ASSERT_EQ(f.index_count(), 5U);
  EXPECT_EQ(f.index_at(0), 104);
  EXPECT_EQ(f.index_at(1), 1);
  EXPECT_EQ(f.index_at(2), 0);
}

TEST(EthercatSimMailbox, EmergencyRepeatAndCounter) {
  CoeLine l;
  l.preop();
  // The application was attached and saw INIT -> PRE-OP.
  ASSERT_EQ(l.app.esc, &l.esc);
  EXPECT_EQ(l.app.last_from, AlState::Init);
  EXPECT_EQ(l.app.last_to, AlState::PreOp);
  // Emergency queued by the application, delivered when SM1 is read [ETG.1000.6 §5.6.4].
  ASSERT_TRUE(l.app.esc->post_emergency(CoeEmergency{0x8100, 0x11, {1, 2, 3, 4, 5}}));
  Reply r = l.get();
  ASSERT_TRUE(r.returned);
  const EmergencyView e = decode_emergency(r.bytes());
  ASSERT_EQ(e.error, MailboxError::None);
  EXPECT_EQ(e.emergency.error_code, 0x8100);
  const std::uint8_t emcy_counter = e.mailbox.counter;
  EXPECT_EQ(emcy_counter, 1);
  // SM1 is empty again after its last byte was read.
  EXPECT_EQ(l.bus.fprd(l.st, kMbxIn, kMbxSize).wkc, 0);

  // Repeat request: toggle SM1 activate bit 1; the slave puts the same mailbox back and
  // acknowledges in PDI control bit 1 [ETG.1000.4 Table 59].
  const std::array<std::uint8_t, 1> act{static_cast<std::uint8_t>(sm_activate::kEnable | sm_activate::kRepeat)};
  EXPECT_EQ(l.bus.fpwr(l.st, reg::sm_activation(1), act).wkc, 1);
  r = l.get();
  ASSERT_TRUE(r.returned);
  EXPECT_EQ(decode_emergency(r.bytes()).mailbox.counter, emcy_counter);
  EXPECT_EQ(l.bus.fprd(l.st, reg::sm_pdi_control(1), 1).data[0] & sm_pdi_control::kRepeatAck, sm_pdi_control::kRepeatAck);
  EXPECT_EQ(l.esc.mailbox_repeats(), 1U);
  // Repeat while a newer mailbox already waits in SM1: the one read last comes first, the newer
  // one after it (counters 1 and 2).
  ASSERT_TRUE(l.esc.post_emergency(CoeEmergency{0x8200, 0x11, {}}));
  l.bus.brd(reg::kType, 1);  // a frame passes: the PDI loads the new emergency into SM1
  const std::array<std::uint8_t, 1> act2{sm_activate::kEnable};
  EXPECT_EQ(l.bus.fpwr(l.st, reg::sm_activation(1), act2).wkc, 1);
  r = l.get();
  EXPECT_EQ(decode_emergency(r.bytes()).emergency.error_code, 0x8100);
  r = l.get();
  EXPECT_EQ(decode_emergency(r.bytes()).emergency.error_code, 0x8200);
  EXPECT_EQ(decode_emergency(r.bytes()).mailbox.counter, 2);
  EXPECT_EQ(l.bus.fprd(l.st, reg::sm_pdi_control(1), 1).data[0] & sm_pdi_control::kRepeatAck, 0x00);

  // The same request counter twice: the second is a repeat and gets no second answer.
  const std::size_t n = encode_sdo_upload_request(l.req, 3, 0x1000, 0);
  ASSERT_EQ(l.put(std::span(l.req.data(), n)), 1);
  EXPECT_TRUE(l.get().returned);
  ASSERT_EQ(l.put(std::span(l.req.data(), n)), 1);
  EXPECT_FALSE(l.get().returned);
  EXPECT_EQ(l.esc.mailbox_duplicates(), 1U);
  // A non-CoE mailbox (type FoE): mailbox error "unsupported protocol" 0002h.
  std::array<std::uint8_t, 8> foe{};
  encode_mailbox_header(MailboxHeader{2, 0, 0, 0, static_cast<std::uint8_t>(MailboxType::FoE), 4}, foe);
  ASSERT_EQ(l.put(foe), 1);
  r = l.get();
  const MailboxErrorReply me = decode_mailbox_error(r.bytes());
  EXPECT_EQ(me.detail, mailbox_error_code::kUnsupportedProtocol);
}

TEST(EthercatSimMailbox, FullMailboxRefusesWrite) {
  CoeLine l;
  l.preop();
  // Block the PDI: two SM0 writes in one frame; the second finds the mailbox full (WKC 0 for it).
  std::array<std::uint8_t, kMaxFrameSize> tx{};
  std::array<std::uint8_t, kMbxSize> box{};
  encode_sdo_upload_request(box, 1, 0x1000, 0);
  FrameBuilder b(tx, test::kMasterMac, test::kMasterMac);
  const auto s1 = b.add(Command::FPWR, 0, physical_address(l.st, kMbxOut), kMbxSize, box);
  const auto s2 = b.add(Command::FPWR, 1, physical_address(l.st, kMbxOut), kMbxSize, box);
  const auto frame = b.finish();
  l.bus.link().send(FrameView(frame.data(), frame.size()));
  std::array<FrameBuffer, 1> rx;
  ASSERT_EQ(l.bus.link().receive(rx), 1U);
  EXPECT_EQ(get_u16(rx[0].view(), s1.slot.wkc_offset), 1);
  EXPECT_EQ(get_u16(rx[0].view(), s2.slot.wkc_offset), 0);
}

TEST(EthercatSimMailbox, OutboxCountsWhatItCannotQueue) {
  // A full outbox, an encoding that fails and a message dropped from the front are each counted;
  // a queued message takes the next mailbox counter [ETG.1000.6 mailbox header, Cnt].
  MailboxOutbox out(1, kMbxSize);
  const auto error_reply = [](std::span<std::uint8_t> buf) {
    return encode_mailbox_error(buf, 0, mailbox_error_code::kUnsupportedProtocol);
  };
  EXPECT_TRUE(out.emit(error_reply));
  EXPECT_EQ(out.dropped(), 0U);
  ASSERT_FALSE(out.empty());
  EXPECT_EQ(decode_mailbox(out.front()).header.counter, 1);
  EXPECT_FALSE(out.emit(error_reply));  // full
  EXPECT_EQ(out.dropped(), 1U);
  out.pop();
  EXPECT_FALSE(out.emit([](std::span<std::uint8_t>) { return std::size_t{0}; }));  // could not encode
  EXPECT_EQ(out.dropped(), 2U);
  EXPECT_TRUE(out.empty());
  EXPECT_TRUE(out.emit(error_reply));
  EXPECT_EQ(decode_mailbox(out.front()).header.counter, 2);
  out.drop_front();
  EXPECT_EQ(out.dropped(), 3U);
  EXPECT_TRUE(out.empty());
}

}  // namespace
}  // namespace drivegate::ethercat::sim
