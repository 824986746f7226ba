// Frame and datagram codec. Vectors are derived from the EtherCAT frame layout [ETG.1000.4 §5:
// Ethernet II header with EtherType 88A4h, the 2-byte EtherCAT header (11-bit length, type 1),
// 10-byte datagram headers (cmd, idx, address, length word with C and M bits, IRQ), data, WKC].
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <vector>

#include "adapters/ethercat/wire/frame.hpp"
#include "adapters/ethercat/wire/registers.hpp"

namespace drivegate::ethercat {
namespace {

using Bytes = std::vector<std::uint8_t>;
constexpr MacAddress kSrc{0x02, 0x00, 0x00, 0x00, 0x00, 0x01};

Bytes to_bytes(std::span<const std::uint8_t> s) { return {s.begin(), s.end()}; }

Bytes eth_header() {
  return {0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0x02, 0x00, 0x00, 0x00, 0x00, 0x01, 0x88, 0xA4};
}

// One datagram frame: Ethernet header, EtherCAT header, datagram, zero padding to 60 bytes.
Bytes single_frame(Bytes datagram) {
  Bytes f = eth_header();
  const auto len = static_cast<std::uint16_t>(datagram.size());
  f.push_back(static_cast<std::uint8_t>(len & 0xFF));
  f.push_back(static_cast<std::uint8_t>(0x10 | (len >> 8)));  // type 1 in bits 12-15
  f.insert(f.end(), datagram.begin(), datagram.end());
  if (f.size() < 60) f.resize(60, 0);
  return f;
}

TEST(EcatFrame, CommandNamesAndKinds) {
  // [ETG.1000.4 §5.4]: mnemonic and value of every command.
  const std::array<std::pair<Command, const char*>, 15> all{{
      {Command::NOP, "NOP"},   {Command::APRD, "APRD"}, {Command::APWR, "APWR"}, {Command::APRW, "APRW"},
      {Command::FPRD, "FPRD"}, {Command::FPWR, "FPWR"}, {Command::FPRW, "FPRW"}, {Command::BRD, "BRD"},
      {Command::BWR, "BWR"},   {Command::BRW, "BRW"},   {Command::LRD, "LRD"},   {Command::LWR, "LWR"},
      {Command::LRW, "LRW"},   {Command::ARMW, "ARMW"}, {Command::FRMW, "FRMW"},
  }};
  for (std::size_t i = 0; i < all.size(); ++i) {
    EXPECT_EQ(static_cast<std::size_t>(all[i].first), i);
    EXPECT_EQ(command_name(all[i].first), all[i].second);
    EXPECT_NE(command_description(all[i].first), "unknown command");
  }
  EXPECT_EQ(command_name(static_cast<Command>(15)), "?");
  EXPECT_EQ(command_description(Command::FRMW), "configured address physical read multiple write");
  EXPECT_EQ(addressing_of(Command::LRW), Addressing::Logical);
  EXPECT_EQ(addressing_of(Command::ARMW), Addressing::AutoIncrement);
  EXPECT_EQ(access_of(Command::BRW), Access::ReadWrite);
  EXPECT_FALSE(is_valid_command(15));
}

TEST(EcatFrame, ExpectedWorkingCounter) {
  // [ETG.1000.4 §5.4, working counter of each command]: read +1, write +1, read-write +3 per slave.
  EXPECT_EQ(expected_wkc(Command::APRD, 1), 1);
  EXPECT_EQ(expected_wkc(Command::FPWR, 1), 1);
  EXPECT_EQ(expected_wkc(Command::FPRW, 1), 3);
  EXPECT_EQ(expected_wkc(Command::BRD, 5), 5);
  EXPECT_EQ(expected_wkc(Command::BRW, 4), 12);
  EXPECT_EQ(expected_wkc(Command::ARMW, 8), 8);
  EXPECT_EQ(expected_wkc(Command::NOP, 8), 0);
  // digest "What a master must do" step 6: LRW on a slave with inputs and outputs: +3.
  EXPECT_EQ(expected_logical_wkc(Command::LRW, 1, 1), 3);
  EXPECT_EQ(expected_logical_wkc(Command::LRW, 2, 1), 4);
  EXPECT_EQ(expected_logical_wkc(Command::LRD, 3, 2), 3);
  EXPECT_EQ(expected_logical_wkc(Command::LWR, 3, 2), 2);
  EXPECT_EQ(expected_logical_wkc(Command::APRD, 3, 2), 0);
  EXPECT_EQ(expected_wkc(Command::LRW, 0xFFFF), 0xFFFF);  // saturates
}

TEST(EcatFrame, AutoIncrementAddress) {
  EXPECT_EQ(auto_increment_adp(0), 0x0000);
  EXPECT_EQ(auto_increment_adp(1), 0xFFFF);
  EXPECT_EQ(auto_increment_adp(2), 0xFFFE);
  EXPECT_EQ(physical_address(0x1001, 0x0130), 0x01301001U);
}

// Every command as the only datagram of a frame, byte for byte [ETG.1000.4 §5.4].
TEST(EcatFrame, EveryCommandByteExact) {
  struct Case {
    Command cmd;
    std::uint32_t address;
    std::uint16_t length;
    Bytes address_bytes;
  };
  const std::array<Case, 15> cases{{
      {Command::NOP, 0, 0, {0, 0, 0, 0}},
      {Command::APRD, physical_address(auto_increment_adp(1), reg::kAlStatus), 2, {0xFF, 0xFF, 0x30, 0x01}},
      {Command::APWR, physical_address(auto_increment_adp(2), reg::kStationAddress), 2, {0xFE, 0xFF, 0x10, 0x00}},
      {Command::APRW, physical_address(0, reg::kAlControl), 2, {0x00, 0x00, 0x20, 0x01}},
      {Command::FPRD, physical_address(0x1001, reg::kAlStatus), 6, {0x01, 0x10, 0x30, 0x01}},
      {Command::FPWR, physical_address(0x1001, reg::kAlControl), 2, {0x01, 0x10, 0x20, 0x01}},
      {Command::FPRW, physical_address(0x1002, reg::kSm0), 8, {0x02, 0x10, 0x00, 0x08}},
      {Command::BRD, physical_address(0, reg::kType), 1, {0, 0, 0, 0}},
      {Command::BWR, physical_address(0, reg::kAlControl), 2, {0x00, 0x00, 0x20, 0x01}},
      {Command::BRW, physical_address(0, reg::kDcReceiveTimePort0), 4, {0x00, 0x00, 0x00, 0x09}},
      {Command::LRD, 0x00010000, 4, {0x00, 0x00, 0x01, 0x00}},
      {Command::LWR, 0x00010004, 4, {0x04, 0x00, 0x01, 0x00}},
      {Command::LRW, 0x00010000, 12, {0x00, 0x00, 0x01, 0x00}},
      {Command::ARMW, physical_address(0, reg::kDcSystemTime), 8, {0x00, 0x00, 0x10, 0x09}},
      {Command::FRMW, physical_address(0x1001, reg::kDcSystemTime), 8, {0x01, 0x10, 0x10, 0x09}},
  }};
  for (const Case& c : cases) {
    std::array<std::uint8_t, 1514> buf{};
    FrameBuilder b(buf, kBroadcastMac, kSrc);
    const AddResult r = b.add(c.cmd, 0x2A, c.address, c.length);
    ASSERT_TRUE(r.ok()) << command_name(c.cmd);
    Bytes dg{static_cast<std::uint8_t>(c.cmd), 0x2A};
    dg.insert(dg.end(), c.address_bytes.begin(), c.address_bytes.end());
    dg.push_back(static_cast<std::uint8_t>(c.length & 0xFF));
    dg.push_back(static_cast<std::uint8_t>(c.length >> 8));  // C = 0, M = 0
    dg.push_back(0);
    dg.push_back(0);  // IRQ
    dg.resize(dg.size() + c.length + 2, 0);  // zero data, WKC 0
    EXPECT_EQ(to_bytes(b.finish()), single_frame(dg)) << command_name(c.cmd);
    EXPECT_EQ(r.slot.header_offset, 16U);
    EXPECT_EQ(r.slot.data_offset, 26U);
    EXPECT_EQ(r.slot.wkc_offset, 26U + c.length);
  }
}

// APRD of AL status at position 1, whole frame written out [ETG.1000.4 §5.3, §5.4].
TEST(EcatFrame, AprdAlStatusFrame) {
  std::array<std::uint8_t, 128> buf{};
  FrameBuilder b(buf, kBroadcastMac, kSrc);
  ASSERT_TRUE(b.add(Command::APRD, 0x05, physical_address(auto_increment_adp(1), reg::kAlStatus), 2).ok());
  const Bytes expected = {
      0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0x02, 0x00, 0x00, 0x00, 0x00, 0x01, 0x88, 0xA4,  // Ethernet
      0x0E, 0x10,                                                                            // length 14, type 1
      0x01, 0x05, 0xFF, 0xFF, 0x30, 0x01, 0x02, 0x00, 0x00, 0x00,                            // APRD idx 5
      0x00, 0x00,                                                                            // data
      0x00, 0x00,                                                                            // WKC
      0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,  // padding to 60
      0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0};
  EXPECT_EQ(to_bytes(b.finish()), expected);
}

// Three datagrams: M set on the first two, data copied, offsets usable for reading in place.
TEST(EcatFrame, MultiDatagramFrame) {
  std::array<std::uint8_t, 1514> buf{};
  FrameBuilder b(buf, kBroadcastMac, kSrc);
  const std::array<std::uint8_t, 2> ctl{0x02, 0x00};
  const std::array<std::uint8_t, 4> out{0x0F, 0x00, 0x45, 0x23};
  const auto r1 = b.add(Command::BRD, 0, physical_address(0, reg::kType), 1);
  const auto r2 = b.add(Command::FPWR, 1, physical_address(0x1001, reg::kAlControl), 2, ctl);
  const auto r3 = b.add(Command::LRW, 2, 0x00010000, 6, out);
  ASSERT_TRUE(r1.ok() && r2.ok() && r3.ok());
  EXPECT_EQ(b.datagram_count(), 3U);
  const auto frame = b.finish();
  // 16 + (12+1) + (12+2) + (12+6) = 61 bytes: no padding.
  ASSERT_EQ(frame.size(), 61U);
  const Bytes expected = {
      0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0x02, 0x00, 0x00, 0x00, 0x00, 0x01, 0x88, 0xA4,
      0x2D, 0x10,  // 45 bytes of datagrams, type 1
      0x07, 0x00, 0x00, 0x00, 0x00, 0x00, 0x01, 0x80, 0x00, 0x00, 0x00, 0x00, 0x00,        // BRD, M
      0x05, 0x01, 0x01, 0x10, 0x20, 0x01, 0x02, 0x80, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00,  // FPWR, M
      0x0C, 0x02, 0x00, 0x00, 0x01, 0x00, 0x06, 0x00, 0x00, 0x00,                          // LRW, last
      0x0F, 0x00, 0x45, 0x23, 0x00, 0x00, 0x00, 0x00};
  EXPECT_EQ(to_bytes(frame), expected);

  // The slaves answer in place: emulate a WKC and input data, then parse.
  buf[r1.slot.data_offset] = 0x11;
  buf[r1.slot.wkc_offset] = 3;
  buf[r3.slot.data_offset + 4] = 0xAB;
  buf[r3.slot.wkc_offset] = 3;
  FrameParser p(std::span<const std::uint8_t>(buf.data(), frame.size()));
  ASSERT_EQ(p.error(), FrameError::None);
  Datagram d;
  ASSERT_TRUE(p.next(d));
  EXPECT_EQ(d.header.command, Command::BRD);
  EXPECT_TRUE(d.header.more);
  EXPECT_EQ(d.data.size(), 1U);
  EXPECT_EQ(d.data[0], 0x11);
  EXPECT_EQ(d.wkc, 3);
  ASSERT_TRUE(p.next(d));
  EXPECT_EQ(d.header.command, Command::FPWR);
  EXPECT_EQ(d.header.adp(), 0x1001);
  EXPECT_EQ(d.header.ado(), reg::kAlControl);
  EXPECT_EQ(d.header.index, 1);
  ASSERT_TRUE(p.next(d));
  EXPECT_EQ(d.header.command, Command::LRW);
  EXPECT_FALSE(d.header.more);
  EXPECT_EQ(d.header.address, 0x00010000U);
  EXPECT_EQ(d.data_offset, r3.slot.data_offset);
  EXPECT_EQ(d.data[4], 0xAB);
  EXPECT_EQ(d.wkc, 3);
  EXPECT_FALSE(p.next(d));
  EXPECT_EQ(p.error(), FrameError::None);
  EXPECT_EQ(p.info().ecat_length, 45);
  EXPECT_EQ(p.info().src, kSrc);
}

TEST(EcatFrame, HeaderBitsRoundTrip) {
  DatagramHeader h;
  h.command = Command::FRMW;
  h.index = 0xFE;
  h.address = 0x09101001;
  h.length = 0x7FF;
  h.circulating = true;
  h.more = true;
  h.irq = 0xBEEF;
  std::array<std::uint8_t, 10> b{};
  ASSERT_TRUE(encode_datagram_header(h, b));
  EXPECT_EQ(to_bytes(b), (Bytes{0x0E, 0xFE, 0x01, 0x10, 0x10, 0x09, 0xFF, 0xC7, 0xEF, 0xBE}));
  DatagramHeader d;
  ASSERT_TRUE(decode_datagram_header(b, d));
  EXPECT_EQ(d.command, h.command);
  EXPECT_EQ(d.length, h.length);
  EXPECT_TRUE(d.circulating);
  EXPECT_TRUE(d.more);
  EXPECT_EQ(d.irq, 0xBEEF);
  h.length = 0x800;
  EXPECT_FALSE(encode_datagram_header(h, b));
  EXPECT_FALSE(decode_datagram_header(std::span<const std::uint8_t>(b).first(9), d));
}

TEST(EcatFrame, BuilderLimits) {
  std::array<std::uint8_t, 59> tiny{};
  FrameBuilder t(tiny, kBroadcastMac, kSrc);
  EXPECT_EQ(t.error(), BuildError::BufferTooSmall);
  EXPECT_EQ(t.add(Command::BRD, 0, 0, 1).error, BuildError::BufferTooSmall);
  EXPECT_TRUE(t.finish().empty());

  std::array<std::uint8_t, 2000> buf{};
  FrameBuilder b(buf, kBroadcastMac, kSrc);
  EXPECT_TRUE(b.finish().empty());  // nothing added
  EXPECT_EQ(b.remaining_data(), kMaxDatagramData);
  EXPECT_EQ(kMaxDatagramData, 1486U);
  const std::array<std::uint8_t, 3> three{1, 2, 3};
  EXPECT_EQ(b.add(Command::LWR, 0, 0, 2, three).error, BuildError::DataTooLong);
  EXPECT_EQ(b.add(Command::LWR, 0, 0, 0x800).error, BuildError::DataTooLong);
  EXPECT_EQ(b.add(Command::LRW, 0, 0, 1487).error, BuildError::FrameFull);
  ASSERT_TRUE(b.add(Command::LRW, 0, 0, 1486).ok());
  EXPECT_EQ(b.remaining_data(), 0U);
  EXPECT_EQ(b.add(Command::NOP, 0, 0, 0).error, BuildError::FrameFull);
  const auto f = b.finish();
  EXPECT_EQ(f.size(), 1514U);
  EXPECT_EQ(validate_frame(f), FrameError::None);
  EXPECT_EQ(b.add(Command::NOP, 0, 0, 0).error, BuildError::Finished);

  // A buffer between 60 and 1514 bytes bounds the frame.
  std::array<std::uint8_t, 100> small{};
  FrameBuilder s(small, kBroadcastMac, kSrc);
  EXPECT_EQ(s.remaining_data(), 100U - 16 - 12);
  EXPECT_EQ(s.add(Command::LRD, 0, 0, 73).error, BuildError::FrameFull);
  EXPECT_TRUE(s.add(Command::LRD, 0, 0, 72).ok());
}

TEST(EcatFrame, ParserAcceptsVlanTag) {
  std::array<std::uint8_t, 64> buf{};
  FrameBuilder b(buf, kBroadcastMac, kSrc);
  ASSERT_TRUE(b.add(Command::BRD, 7, 0, 2).ok());
  const auto f = b.finish();
  Bytes tagged(f.begin(), f.begin() + 12);
  for (std::uint8_t x : {std::uint8_t{0x81}, std::uint8_t{0x00}, std::uint8_t{0x20}, std::uint8_t{0x05}}) tagged.push_back(x);  // TPID, PCP 1 VID 5
  tagged.insert(tagged.end(), f.begin() + 12, f.end());
  FrameParser p(tagged);
  ASSERT_EQ(p.error(), FrameError::None);
  EXPECT_TRUE(p.info().vlan);
  EXPECT_EQ(p.info().vlan_tci, 0x2005);
  Datagram d;
  ASSERT_TRUE(p.next(d));
  EXPECT_EQ(d.header.index, 7);
  EXPECT_EQ(d.header_offset, 20U);
  EXPECT_FALSE(p.next(d));
  EXPECT_EQ(p.error(), FrameError::None);
}

// Malformed frames: each is rejected with its own reason and never read past its end.
TEST(EcatFrame, MalformedFrames) {
  std::array<std::uint8_t, 128> buf{};
  FrameBuilder b(buf, kBroadcastMac, kSrc);
  ASSERT_TRUE(b.add(Command::FPRD, 1, physical_address(0x1001, reg::kAlStatus), 2).ok());
  ASSERT_TRUE(b.add(Command::FPRD, 2, physical_address(0x1002, reg::kAlStatus), 2).ok());
  const auto built = b.finish();
  const Bytes good(built.begin(), built.end());  // two datagrams of 14 bytes: ecat length 28
  ASSERT_EQ(validate_frame(good), FrameError::None);

  auto expect = [](const Bytes& f, FrameError e) {
    std::size_t n = 99;
    EXPECT_EQ(validate_frame(f, &n), e) << to_string(e);
  };
  expect(Bytes(good.begin(), good.begin() + 13), FrameError::TruncatedEthernet);
  Bytes vlan_cut(good.begin(), good.begin() + 12);
  vlan_cut.insert(vlan_cut.end(), {0x81, 0x00, 0x00});
  expect(vlan_cut, FrameError::TruncatedEthernet);
  Bytes ip = good;
  ip[12] = 0x08;
  ip[13] = 0x00;
  expect(ip, FrameError::WrongEtherType);
  expect(Bytes(good.begin(), good.begin() + 15), FrameError::TruncatedEcatHeader);
  Bytes type4 = good;
  type4[15] = 0x40;  // type 4 (network variables)
  expect(type4, FrameError::UnsupportedType);
  Bytes too_long = good;
  too_long[14] = 0xFF;
  too_long[15] = 0x17;  // length 0x7FF > 44 bytes left
  expect(too_long, FrameError::EcatLengthBeyondFrame);
  Bytes empty = good;
  empty[14] = 0;
  expect(empty, FrameError::EmptyFrame);
  Bytes short_hdr = good;
  short_hdr[14] = 5;  // 5 bytes: not even one header
  expect(short_hdr, FrameError::TruncatedDatagramHeader);
  Bytes second_cut = good;
  second_cut[14] = 14 + 9;  // second header cut at 9 bytes
  expect(second_cut, FrameError::TruncatedDatagramHeader);
  Bytes data_long = good;
  data_long[16 + 14 + 6] = 0x10;  // second datagram claims 16 data bytes
  expect(data_long, FrameError::DatagramBeyondLength);
  Bytes unknown = good;
  unknown[16] = 0x0F;
  expect(unknown, FrameError::UnknownCommand);
  Bytes m_last = good;
  m_last[16 + 14 + 7] |= 0x80;  // M on the final datagram
  expect(m_last, FrameError::MoreBitWithoutDatagram);
  Bytes m_missing = good;
  m_missing[16 + 7] = static_cast<std::uint8_t>(m_missing[16 + 7] & 0x7F);  // first datagram says it is the last one
  expect(m_missing, FrameError::LengthAfterLastDatagram);
  Bytes longer = good;
  longer[14] = 28 + 4;  // length covers 4 padding bytes after the last datagram
  expect(longer, FrameError::LengthAfterLastDatagram);

  // Counting the reasons.
  FrameErrorCounters c;
  c.count(FrameError::WrongEtherType);
  c.count(FrameError::WrongEtherType);
  EXPECT_EQ(c[FrameError::WrongEtherType], 2U);
  EXPECT_EQ(c[FrameError::EmptyFrame], 0U);
  for (std::size_t i = 0; i < kFrameErrorCount; ++i) EXPECT_NE(to_string(static_cast<FrameError>(i)), "?");
}

}  // namespace
}  // namespace drivegate::ethercat
