// SII EEPROM parser and builder. The hand-built image follows the SII layout [ETG.1000.6 §5.4: header words,
// category header, strings (Table 20), general (Table 21), FMMU, SyncM, TXPDO/RXPDO, DC], written word by word here without the builder.
#include <gtest/gtest.h>

#include <array>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "adapters/ethercat/wire/registers.hpp"
#include "adapters/ethercat/wire/sii.hpp"

namespace drivegate::ethercat {
namespace {

using Bytes = std::vector<std::uint8_t>;

// CRC-8 of the configuration area, derived independently of sii_crc8() by polynomial long
// division (GF(2)): with init FFh and no reflection the CRC equals the remainder of
// (M(x) with its first byte XOR FFh) · x^8 divided by x^8 + x^2 + x + 1 (107h).
//
// Case A, 14 zero bytes: the first byte becomes FFh; running the division byte by byte the
// remainder after each byte is
//   F3 D7 2B D1 39 AF 44 DB 0F 2D C3 47 D2 30    -> CRC 30h
// (first step by hand: FFh·x^8 mod 107h: FF00 ^ (107 << 7 = 8380) = 7C80; ^ (107 << 6 = 41C0) =
//  3D40; ^ 20E0 = 1DA0; ^ 1070 = 0DD0; ^ 0838 = 05E8; ^ 041C = 01F4; ^ 0107 = 00F3.)
// Case B, words 0-6 = 0005h 0 0 0 1234h 0 0 (bytes 05 00 00 00 00 00 00 00 34 12 00 00 00 00):
//   E8 96 EB 9F D4 22 EE 84 19 31 97 EC 8A BF    -> CRC BFh
constexpr std::uint8_t kCrcZeros = 0x30;
constexpr std::uint8_t kCrcCaseB = 0xBF;

TEST(EcatSii, Crc8AgainstHandDerivation) {
  const std::array<std::uint8_t, 14> zeros{};
  EXPECT_EQ(sii_crc8(zeros), kCrcZeros);
  const std::array<std::uint8_t, 14> b{0x05, 0, 0, 0, 0, 0, 0, 0, 0x34, 0x12, 0, 0, 0, 0};
  EXPECT_EQ(sii_crc8(b), kCrcCaseB);
  // One byte: 00h leaves the register at FFh before the shifts, giving the hand step's F3h; FFh
  // clears it (FFh XOR FFh = 0), and 0 shifted stays 0.
  const std::array<std::uint8_t, 1> zero{0x00};
  EXPECT_EQ(sii_crc8(zero), 0xF3);
  const std::array<std::uint8_t, 1> ff{0xFF};
  EXPECT_EQ(sii_crc8(ff), 0x00);
}

// Writes words little-endian.
class Image {
 public:
  void word(std::uint16_t w) {
    b_.push_back(static_cast<std::uint8_t>(w & 0xFF));
    b_.push_back(static_cast<std::uint8_t>(w >> 8));
  }
  void dword(std::uint32_t d) {
    word(static_cast<std::uint16_t>(d & 0xFFFF));
    word(static_cast<std::uint16_t>(d >> 16));
  }
  void byte(std::uint8_t x) { b_.push_back(x); }
  void bytes(const Bytes& x) { b_.insert(b_.end(), x.begin(), x.end()); }
  void text(const std::string& s) {
    byte(static_cast<std::uint8_t>(s.size()));
    for (char c : s) byte(static_cast<std::uint8_t>(c));
  }
  std::size_t size() const { return b_.size(); }
  Bytes& raw() { return b_; }

 private:
  Bytes b_;
};

// Positions (byte offsets) of parts of the hand-built image, for the malformed variants.
struct HandImage {
  Bytes bytes;
  std::size_t strings_at = 0;  // category header of strings
  std::size_t general_at = 0;
  std::size_t txpdo_at = 0;
  std::size_t end_at = 0;
};

HandImage hand_image() {
  HandImage h;
  Image im;
  // Words 0-6: PDI control 0005h, alias 1234h (case B above), CRC BFh in word 7.
  im.word(0x0005);
  im.word(0);
  im.word(0);
  im.word(0);
  im.word(0x1234);
  im.word(0);
  im.word(0);
  im.word(kCrcCaseB);
  im.dword(0x0000000F);  // vendor
  im.dword(0x00001A63);  // product
  im.dword(0x00010002);  // revision
  im.dword(0x12345678);  // serial
  for (int i = 0; i < 4; ++i) im.word(0);
  // Bootstrap mailbox absent, standard mailbox 1000h/128, 1080h/128.
  for (int i = 0; i < 4; ++i) im.word(0);
  im.word(0x1000);
  im.word(128);
  im.word(0x1080);
  im.word(128);
  im.word(mailbox_protocol::kCoE);
  while (im.size() < 2 * 0x3E) im.word(0);
  im.word(15);  // 16 KiBit = 2 KiB
  im.word(1);
  // Strings: "Drives", "TrioDrive", "Statusword", "Controlword" = 1 + 7 + 10 + 11 + 12 = 41 bytes
  // + 1 pad = 21 words.
  h.strings_at = im.size();
  im.word(10);
  im.word(21);
  im.byte(4);
  im.text("Drives");
  im.text("TrioDrive");
  im.text("Statusword");
  im.text("Controlword");
  im.byte(0);
  // General: group "Drives" (1), image 0, order/name "TrioDrive" (2), CoE SDO + SDO info + PDO
  // assign + PDO config (0Fh), ports MII/MII (0011h).
  h.general_at = im.size();
  im.word(30);
  im.word(16);
  im.bytes({1, 0, 2, 2, 0, 0x0F, 0, 0, 0, 1, 0, 0x01});
  im.word(0);       // current on E-bus
  im.bytes({1, 0});  // group duplicate, reserved
  im.word(0x0011);  // physical ports
  im.word(0);       // physical memory address
  for (int i = 0; i < 6; ++i) im.word(0);
  // FMMU: outputs, inputs, SyncM status, unused.
  im.word(40);
  im.word(2);
  im.bytes({0x01, 0x02, 0x03, 0xFF});
  // SyncM: SM0 mailbox out, SM1 mailbox in, SM2 outputs, SM3 inputs.
  im.word(41);
  im.word(16);
  im.bytes({0x00, 0x10, 0x80, 0x00, 0x26, 0x00, 0x01, 0x01});
  im.bytes({0x80, 0x10, 0x80, 0x00, 0x22, 0x00, 0x01, 0x02});
  im.bytes({0x00, 0x11, 0x02, 0x00, 0x64, 0x00, 0x01, 0x03});
  im.bytes({0x80, 0x11, 0x02, 0x00, 0x20, 0x00, 0x01, 0x04});
  // TXPDO 1A00h: 1 entry, SM3, entry 6041h:00 "Statusword" UNSIGNED16 16 bits.
  h.txpdo_at = im.size();
  im.word(50);
  im.word(8);
  im.bytes({0x00, 0x1A, 0x01, 0x03, 0x00, 0x00, 0x00, 0x00});
  im.bytes({0x41, 0x60, 0x00, 0x03, 0x06, 0x10, 0x00, 0x00});
  // RXPDO 1600h: 1 entry, SM2, entry 6040h:00 "Controlword".
  im.word(51);
  im.word(8);
  im.bytes({0x00, 0x16, 0x01, 0x02, 0x00, 0x00, 0x00, 0x00});
  im.bytes({0x40, 0x60, 0x00, 0x04, 0x06, 0x10, 0x00, 0x00});
  // DC: one entry, 1 ms SYNC0, assign-activate 0300h.
  im.word(60);
  im.word(12);
  im.dword(1000000);
  im.dword(0);
  im.dword(0);
  im.word(0);
  im.word(0x0300);
  im.word(1);
  im.bytes({0, 0, 0, 0, 0, 0});
  h.end_at = im.size();
  im.word(0xFFFF);
  while (im.size() < 2048) im.byte(0xFF);
  h.bytes = im.raw();
  return h;
}

// The result's string views point into `b`: callers keep the image alive while they use it.
std::unique_ptr<SiiInfo> parse(std::span<const std::uint8_t> b) {
  auto info = std::make_unique<SiiInfo>();
  parse_sii(b, *info);
  return info;
}

TEST(EcatSii, ParseHandBuiltImage) {
  const HandImage h = hand_image();
  const auto s = parse(h.bytes);
  EXPECT_TRUE(s->ok());
  EXPECT_EQ(s->issue_count, 0U);
  EXPECT_TRUE(s->header_valid);
  EXPECT_EQ(s->header.pdi_control, 0x0005);
  EXPECT_EQ(s->header.station_alias, 0x1234);
  EXPECT_TRUE(s->checksum_ok());
  EXPECT_EQ(s->header.identity, (SiiIdentity{0x0F, 0x1A63, 0x00010002, 0x12345678}));
  EXPECT_EQ(s->header.standard_mailbox, (SiiMailbox{0x1000, 128, 0x1080, 128}));
  EXPECT_FALSE(s->header.bootstrap_mailbox.present());
  EXPECT_EQ(s->header.mailbox_protocols, mailbox_protocol::kCoE);
  EXPECT_EQ(s->eeprom_bytes(), 2048U);
  EXPECT_EQ(s->version, 1);
  ASSERT_EQ(s->string_count, 4U);
  EXPECT_EQ(s->string(1), "Drives");
  EXPECT_EQ(s->string(4), "Controlword");
  EXPECT_EQ(s->string(0), "");
  EXPECT_EQ(s->string(5), "");
  ASSERT_TRUE(s->has_general);
  EXPECT_EQ(s->string(s->general.name_index), "TrioDrive");
  EXPECT_EQ(s->general.coe_details, coe_details::kSdo | coe_details::kSdoInfo | coe_details::kPdoAssign | coe_details::kPdoConfig);
  EXPECT_EQ(s->general.ds402_channels, 1);
  EXPECT_EQ(s->general.physical_ports, 0x0011);
  ASSERT_EQ(s->fmmu_count, 4U);
  EXPECT_EQ(s->fmmus[2], sii_fmmu_usage::kSyncMStatus);
  ASSERT_EQ(s->sync_manager_count, 4U);
  EXPECT_EQ(s->sync_managers[0], (SiiSyncManager{0x1000, 128, sm_control::kMailboxOut, 0, 1, sii_sm_type::kMailboxOut}));
  EXPECT_EQ(s->sync_managers[2].control, sm_control::kOutputs);
  EXPECT_EQ(s->sync_managers[3].type, sii_sm_type::kInputs);
  ASSERT_EQ(s->pdo_count, 2U);
  EXPECT_TRUE(s->pdos[0].tx);
  EXPECT_EQ(s->pdos[0].index, 0x1A00);
  EXPECT_EQ(s->pdos[0].sm, 3);
  const auto tx = s->entries_of(s->pdos[0]);
  ASSERT_EQ(tx.size(), 1U);
  EXPECT_EQ(tx[0], (SiiPdoEntry{0x6041, 0, 3, 0x06, 16, 0}));
  EXPECT_EQ(s->string(tx[0].name_index), "Statusword");
  EXPECT_FALSE(s->pdos[1].tx);
  EXPECT_EQ(s->entries_of(s->pdos[1])[0].index, 0x6040);
  ASSERT_EQ(s->dc_count, 1U);
  EXPECT_EQ(s->dcs[0].cycle_time0, 1000000U);
  EXPECT_EQ(s->dcs[0].assign_activate, 0x0300);
  EXPECT_EQ(s->dcs[0].sync0_cycle_factor, 1);
  EXPECT_TRUE(s->end_seen);
}

TEST(EcatSii, ChecksumMismatchIsAWarning) {
  HandImage h = hand_image();
  h.bytes[14] ^= 0x01;
  const auto s = parse(h.bytes);
  EXPECT_TRUE(s->has(SiiProblem::ChecksumMismatch));
  EXPECT_TRUE(s->ok());  // a warning: the data is still read
  EXPECT_EQ(s->checksum, kCrcCaseB ^ 0x01);
  EXPECT_EQ(s->checksum_computed, kCrcCaseB);
  EXPECT_EQ(s->header.identity.vendor_id, 0x0FU);
}

// Impossible lengths: reported as errors, nothing read outside the image (ASan checks it).
TEST(EcatSii, MalformedImages) {
  const HandImage h = hand_image();
  {
    const auto s = parse(std::span<const std::uint8_t>(h.bytes).first(127));
    EXPECT_TRUE(s->has(SiiProblem::ImageTooShort));
    EXPECT_FALSE(s->ok());
    EXPECT_FALSE(s->header_valid);
  }
  {  // strings category claiming 0x7FFF words
    Bytes b = h.bytes;
    b[h.strings_at + 2] = 0xFF;
    b[h.strings_at + 3] = 0x7F;
    const auto s = parse(b);
    EXPECT_TRUE(s->has(SiiProblem::CategoryBeyondImage));
    EXPECT_FALSE(s->ok());
  }
  {  // the last string's length runs past its category
    Bytes b = h.bytes;
    b[h.strings_at + 4 + 1 + 7 + 10 + 11] = 40;
    const auto s = parse(b);
    EXPECT_TRUE(s->has(SiiProblem::StringBeyondCategory));
    EXPECT_EQ(s->string_count, 3U);  // the three before it are kept
    EXPECT_FALSE(s->ok());
  }
  {  // more strings announced than present
    Bytes b = h.bytes;
    b[h.strings_at + 4] = 200;
    EXPECT_TRUE(parse(b)->has(SiiProblem::StringBeyondCategory));
  }
  {  // PDO with 5 entries in a category that holds one
    Bytes b = h.bytes;
    b[h.txpdo_at + 4 + 2] = 5;
    const auto s = parse(b);
    EXPECT_TRUE(s->has(SiiProblem::PdoEntriesBeyondCategory));
    EXPECT_FALSE(s->ok());
    EXPECT_EQ(s->entries_of(s->pdos[0]).size(), 0U);
  }
  {  // PDO category of 6 words: header plus 4 stray bytes
    Bytes b = h.bytes;
    b[h.txpdo_at + 2] = 6;
    b[h.txpdo_at + 4 + 2] = 0;  // no entries: the 4 bytes after the header are a cut-off header
    const auto s = parse(b);
    EXPECT_TRUE(s->has(SiiProblem::PdoHeaderTruncated));
  }
  {  // general category of 8 words
    Bytes b = h.bytes;
    b[h.general_at + 2] = 8;
    const auto s = parse(b);
    EXPECT_TRUE(s->has(SiiProblem::GeneralTooShort));
    EXPECT_FALSE(s->has_general);
  }
  {  // image ends right after the DC category: no end marker
    const auto s = parse(std::span<const std::uint8_t>(h.bytes).first(h.end_at));
    EXPECT_TRUE(s->has(SiiProblem::NoEndCategory));
    EXPECT_TRUE(s->ok());
    EXPECT_EQ(s->pdo_count, 2U);
  }
  {  // image ends inside a category header (one word of it)
    const auto s = parse(std::span<const std::uint8_t>(h.bytes).first(h.txpdo_at + 2));
    EXPECT_TRUE(s->has(SiiProblem::NoEndCategory));
  }
  {  // a PDO entry naming string 9 of 4
    Bytes b = h.bytes;
    b[h.txpdo_at + 4 + 8 + 3] = 9;
    const auto s = parse(b);
    EXPECT_TRUE(s->has(SiiProblem::StringIndexOutOfRange));
    EXPECT_EQ(s->string(9), "");
  }
  {  // odd-length image: the last byte is not half a word
    Bytes b(h.bytes.begin(), h.bytes.begin() + 129);
    const auto s = parse(b);
    EXPECT_TRUE(s->header_valid);
    EXPECT_TRUE(s->has(SiiProblem::CategoryBeyondImage) || s->has(SiiProblem::NoEndCategory));
  }
  for (int p = 0; p <= static_cast<int>(SiiProblem::TooManyDcs); ++p) {
    EXPECT_NE(to_string(static_cast<SiiProblem>(p)), "?");
  }
}

// The profile the simulator would write for an ESR/Dunker drive (digest §7.1 defaults and the
// TV-6 IP-mode PDOs), built, then parsed back.
TEST(EcatSii, BuilderRoundTrip) {
  const std::array<SiiBuildEntry, 2> rx1{{{0x6040, 0, "Controlword", 0x06, 16, 0}, {0x60C1, 1, "IP target", 0x04, 32, 0}}};
  const std::array<SiiBuildEntry, 2> rx2{{{0x6040, 0, "Controlword", 0x06, 16, 0}, {0x6060, 0, "Modes of operation", 0x03, 16, 0}}};
  const std::array<SiiBuildEntry, 2> tx1{{{0x6041, 0, "Statusword", 0x06, 16, 0}, {0x6063, 0, "Position internal", 0x04, 32, 0}}};
  const std::array<SiiBuildPdo, 2> rx{{{0x1600, 2, 0, "RPDO1", 0, rx1}, {0x1601, 2, 0, "RPDO2", 0, rx2}}};
  const std::array<SiiBuildPdo, 1> tx{{{0x1A00, 3, 0, "TPDO1", 0, tx1}}};
  const std::array<SiiSyncManager, 4> sms{{
      {0x1000, 128, sm_control::kMailboxOut, 0, 1, sii_sm_type::kMailboxOut},
      {0x1080, 128, sm_control::kMailboxIn, 0, 1, sii_sm_type::kMailboxIn},
      {0x1100, 6, sm_control::kOutputs, 0, 1, sii_sm_type::kOutputs},
      {0x1180, 6, sm_control::kInputs, 0, 1, sii_sm_type::kInputs},
  }};
  const std::array<std::uint8_t, 3> fmmus{sii_fmmu_usage::kOutputs, sii_fmmu_usage::kInputs, sii_fmmu_usage::kSyncMStatus};
  SiiBuildDc dc;
  dc.dc.cycle_time0 = 2000000;
  dc.dc.assign_activate = 0x0300;
  dc.name = "SYNC0";
  const std::array<SiiBuildDc, 1> dcs{dc};

  SiiProfile p;
  p.header.pdi_control = 0x0C08;
  p.header.station_alias = 0;
  p.header.identity = {0x0000000F, 0x00001A63, 0x00000001, 42};
  p.header.standard_mailbox = {0x1000, 128, 0x1080, 128};
  p.header.mailbox_protocols = mailbox_protocol::kCoE;
  p.group = "Drives";
  p.order = "TrioDrive D/ES";
  p.name = "TrioDrive D/ES";  // the same text: stored once
  p.general.coe_details = coe_details::kSdo | coe_details::kPdoAssign | coe_details::kPdoConfig;
  p.general.physical_ports = 0x0011;
  p.fmmus = fmmus;
  p.sync_managers = sms;
  p.tx_pdos = tx;
  p.rx_pdos = rx;
  p.dcs = dcs;

  std::array<std::uint8_t, 2048> img{};
  const SiiBuildResult r = build_sii(p, img);
  ASSERT_TRUE(r.ok()) << to_string(r.error);
  EXPECT_EQ(r.size, 2048U);
  const auto s = parse(img);
  EXPECT_TRUE(s->ok());
  EXPECT_EQ(s->issue_count, 0U) << to_string(s->issues[0].problem);
  EXPECT_TRUE(s->checksum_ok());
  EXPECT_EQ(s->header.pdi_control, 0x0C08);
  EXPECT_EQ(s->header.identity, p.header.identity);
  EXPECT_EQ(s->header.standard_mailbox, p.header.standard_mailbox);
  EXPECT_EQ(s->eeprom_size, 15);
  EXPECT_EQ(s->version, 1);
  // Strings: Drives, TrioDrive D/ES, TPDO1, Statusword, Position internal, RPDO1, Controlword,
  // IP target, RPDO2, Modes of operation, SYNC0 = 11 distinct.
  EXPECT_EQ(s->string_count, 11U);
  EXPECT_EQ(s->string(s->general.group_index), "Drives");
  EXPECT_EQ(s->general.order_index, s->general.name_index);
  EXPECT_EQ(s->string(s->general.name_index), "TrioDrive D/ES");
  EXPECT_EQ(s->general.image_index, 0);
  EXPECT_EQ(s->general.coe_details, p.general.coe_details);
  ASSERT_EQ(s->fmmu_count, 4U);  // three plus the pad byte (unused)
  EXPECT_EQ(s->fmmus[3], sii_fmmu_usage::kUnused);
  ASSERT_EQ(s->sync_manager_count, 4U);
  for (std::size_t i = 0; i < 4; ++i) EXPECT_EQ(s->sync_managers[i], sms[i]);
  ASSERT_EQ(s->pdo_count, 3U);
  EXPECT_TRUE(s->pdos[0].tx);
  EXPECT_EQ(s->string(s->pdos[0].name_index), "TPDO1");
  EXPECT_EQ(s->pdos[1].index, 0x1600);
  EXPECT_EQ(s->pdos[2].index, 0x1601);
  EXPECT_FALSE(s->pdos[2].tx);
  const auto e = s->entries_of(s->pdos[2]);
  ASSERT_EQ(e.size(), 2U);
  EXPECT_EQ(e[1].index, 0x6060);
  EXPECT_EQ(e[1].bit_length, 16);  // ESR/Dunker quirk 1: 16-bit modes of operation
  EXPECT_EQ(s->string(e[1].name_index), "Modes of operation");
  EXPECT_EQ(s->string(s->entries_of(s->pdos[1])[0].name_index), "Controlword");
  ASSERT_EQ(s->dc_count, 1U);
  EXPECT_EQ(s->dcs[0].cycle_time0, 2000000U);
  EXPECT_EQ(s->string(s->dcs[0].name_index), "SYNC0");
  EXPECT_TRUE(s->end_seen);
  // Unused EEPROM after the end marker reads FFh.
  EXPECT_EQ(img[2047], 0xFF);
  // The checksum word: CRC in the low byte, 0 in the high byte.
  EXPECT_EQ(img[14], sii_crc8(std::span<const std::uint8_t>(img).first(14)));
  EXPECT_EQ(img[15], 0);
}

TEST(EcatSii, BuilderErrors) {
  SiiProfile p;
  std::array<std::uint8_t, 4096> img{};
  p.eeprom_bytes = 100;
  EXPECT_EQ(build_sii(p, img).error, SiiBuildError::InvalidEepromSize);
  p.eeprom_bytes = 0;
  EXPECT_EQ(build_sii(p, img).error, SiiBuildError::InvalidEepromSize);
  p.eeprom_bytes = 8192;
  EXPECT_EQ(build_sii(p, img).error, SiiBuildError::OutputTooSmall);
  p.eeprom_bytes = 256;  // header (128) + general (36) fit; a 200-byte name does not
  EXPECT_TRUE(build_sii(p, img).ok());
  const std::string long_name(200, 'x');
  p.name = long_name;
  EXPECT_EQ(build_sii(p, img).error, SiiBuildError::ContentTooLarge);
  const std::string too_long(256, 'y');
  p.name = too_long;
  EXPECT_EQ(build_sii(p, img).error, SiiBuildError::StringTooLong);
  // An empty profile still parses: header, general, end.
  SiiProfile empty;
  empty.eeprom_bytes = 128 * 2;
  ASSERT_TRUE(build_sii(empty, img).ok());
  const auto s = parse(std::span<const std::uint8_t>(img).first(256));
  EXPECT_TRUE(s->ok());
  EXPECT_TRUE(s->has_general);
  EXPECT_EQ(s->string_count, 0U);
  EXPECT_EQ(s->eeprom_bytes(), 256U);
  EXPECT_NE(to_string(SiiBuildError::TooManyEntries), "?");
}

}  // namespace
}  // namespace drivegate::ethercat
