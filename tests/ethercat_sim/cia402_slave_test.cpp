// The simulated EtherCAT CiA 402 drives (adapters/ethercat/sim/cia402_slave.hpp) with their
// personas, over a SimLine with hand-built frames (drive_line.hpp) and through the master's
// LineBoot and CoeSdoClient. Vectors: dunker-ethercat-coe.md TV-n where a test names one, else
// derived from ETG.1000.6 / CiA 301 as the comment says.
#include <gtest/gtest.h>

#include <cstdlib>
#include <memory>
#include <stdexcept>
#include <string>
#include <tuple>

#include "adapters/ethercat/master/coe_sdo_client.hpp"
#include "adapters/ethercat/master/line_boot.hpp"
#include "adapters/ethercat/wire/sii.hpp"
#include "core/clock.hpp"
#include "tests/ethercat_sim/drive_line.hpp"
#include "tests/support/alloc_counter.hpp"
#include "tests/ethercat_sim/line_exchange.hpp"

namespace drivegate::ethercat::sim {
namespace {

using test::DriveLine;
using test::Reply;

constexpr std::uint32_t kNotMappable = 0x06040041;
constexpr std::uint32_t kNoObject = 0x06020000;
constexpr std::uint32_t kNoSubIndex = 0x06090011;
constexpr std::uint32_t kValueRange = 0x06090030;
constexpr std::uint32_t kValueTooHigh = 0x06090031;
constexpr std::uint32_t kValueTooLow = 0x06090032;
constexpr std::uint32_t kTypeMismatch = 0x06070010;
constexpr std::uint32_t kDeviceState = 0x08000022;

// ---- Identity and SII -----------------------------------------------------------------------

TEST(EthercatCia402Slave, EsrSiiIdentityAndLayout) {
  const auto app = make_cia402_slave("esr-triodrive");
  const auto image = app->sii();
  // Words 8..0Bh: vendor ID 0000000Fh, product code 00006755h little-endian [ETG.1000.6 §5.4;
  // dunker §10, the profile's first identity].
  ASSERT_GE(image.size(), 24U);
  const std::array<std::uint8_t, 8> identity{0x0F, 0x00, 0x00, 0x00, 0x55, 0x67, 0x00, 0x00};
  EXPECT_TRUE(std::equal(identity.begin(), identity.end(), image.begin() + 16));
  auto info = std::make_unique<SiiInfo>();
  parse_sii(image, *info);
  ASSERT_TRUE(info->ok());
  EXPECT_EQ(info->header.identity.vendor_id, 0x0FU);
  EXPECT_EQ(info->header.identity.product_code, 0x6755U);
  EXPECT_EQ(info->header.standard_mailbox, (SiiMailbox{0x1000, 128, 0x1080, 128}));
  EXPECT_EQ(info->header.mailbox_protocols & mailbox_protocol::kCoE, mailbox_protocol::kCoE);
  EXPECT_EQ(info->string(info->general.name_index), "TrioDrive D/ES");
  // Power-on mapping 2 bytes each way (dunker §7.1): SM2 and SM3 of 2 bytes, one PDO each.
  ASSERT_EQ(info->sync_manager_count, 4U);
  EXPECT_EQ(info->sync_managers[2].length, 2);
  EXPECT_EQ(info->sync_managers[3].length, 2);
  EXPECT_EQ(info->pdo_count, 2U);
  EXPECT_EQ(info->dc_count, 0U);  // quirk 9
  EXPECT_FALSE(app->esc_config().dc_supported);
  EXPECT_EQ(app->output_size(), 2U);
  EXPECT_EQ(app->input_size(), 2U);
}

TEST(EthercatCia402Slave, GenericSiiIdentityAndLayout) {
  const auto app = make_cia402_slave("generic-cia402");
  auto info = std::make_unique<SiiInfo>();
  parse_sii(app->sii(), *info);
  ASSERT_TRUE(info->ok());
  EXPECT_EQ(info->header.identity.product_code, 0x0192U);
  // The device profile's maps: 17 output bytes, 15 input bytes (generic-cia402.yaml).
  EXPECT_EQ(info->sync_managers[2].length, 17);
  EXPECT_EQ(info->sync_managers[3].length, 15);
  EXPECT_EQ(info->dc_count, 2U);
  EXPECT_EQ(info->dcs[1].assign_activate, 0x0300);
  EXPECT_TRUE(app->esc_config().dc_supported);
}

TEST(EthercatCia402Slave, FactoryRefusesUnknownPersona) {
  try {
    (void)make_cia402_slave("akd");
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("\"akd\""), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("esr-triodrive, generic-cia402"), std::string::npos);
  }
  EXPECT_EQ(find_ethercat_persona("nope"), nullptr);
}

TEST(EthercatCia402Slave, EscFeaturesFollowPersona) {
  DriveLine esr("esr-triodrive");
  EXPECT_EQ(esr.bus.fprd(esr.st, reg::kEscFeatures, 2).u16() & 0x0004, 0);  // no DC unit
  DriveLine gen("generic-cia402");
  EXPECT_EQ(gen.bus.fprd(gen.st, reg::kEscFeatures, 2).u16() & 0x0004, 0x0004);
}

TEST(EthercatCia402Slave, IdentityObjectsOverSdo) {
  DriveLine l("esr-triodrive");
  l.preop();
  EXPECT_EQ(l.upload(0x1000, 0).value, 0x00020192U);  // TV-2
  EXPECT_EQ(l.upload(0x1018, 1).value, 0x0000000FU);
  EXPECT_EQ(l.upload(0x1018, 2).value, 0x00006755U);
  // 1C00h: SM types 1, 2, 3, 4 [dunker §11.2].
  EXPECT_EQ(l.upload(0x1C00, 0).value, 4U);
  for (std::uint8_t s = 1; s <= 4; ++s) EXPECT_EQ(l.upload(0x1C00, s).value, s);
  // TV-5: 1C12h = 1 x 1600h, 1C13h = 1 x 1A00h.
  EXPECT_EQ(l.upload(0x1C12, 0).value, 1U);
  EXPECT_EQ(l.upload(0x1C12, 1).value, 0x1600U);
  EXPECT_EQ(l.upload(0x1C13, 1).value, 0x1A00U);
  EXPECT_EQ(l.upload(0x1600, 1).value, 0x60400010U);  // TV-1
  EXPECT_EQ(l.upload(0x1A01, 2).value, 0x60610010U);  // erratum 2 corrected
  // 1008h "TrioDrive D/ES" (14 bytes: a normal upload).
  const std::size_t n = encode_sdo_upload_request(l.req, l.next(), 0x1008, 0);
  const SdoView v = l.sdo(std::span(l.req.data(), n));
  ASSERT_EQ(v.sdo.command, SdoCommand::UploadInitiateResponse);
  EXPECT_EQ(std::string(v.sdo.data.begin(), v.sdo.data.end()), "TrioDrive D/ES");
}

// ---- PDO mapping rules ----------------------------------------------------------------------

TEST(EthercatCia402Slave, EsrMappingFollowsCountZeroRuleAndWhitelist) {
  // TV-6 step 3 with mailbox counter 1, byte for byte.
  std::array<std::uint8_t, 16> step3{};
  ASSERT_EQ(encode_sdo_download_value(step3, 1, 0x1600, 1, 0x60400010, 4), 16U);
  const std::array<std::uint8_t, 16> tv6{0x0A, 0x00, 0x00, 0x00, 0x00, 0x13, 0x00, 0x20,
                                         0x23, 0x00, 0x16, 0x01, 0x10, 0x00, 0x40, 0x60};
  EXPECT_EQ(step3, tv6);

  DriveLine l("esr-triodrive");
  l.preop();
  // An entry while :00 != 0: 06010003h [ETG.1000.6 SDO abort codes].
  EXPECT_EQ(l.download(0x1600, 1, 0x60400010, 4), cia402::sdo_abort_code::kSubindexZeroFirst);
  // TV-6 steps 1..7.
  EXPECT_EQ(l.download(0x1C12, 0, 0, 1), 0U);
  EXPECT_EQ(l.download(0x1600, 0, 0, 1), 0U);
  EXPECT_EQ(l.download(0x1600, 1, 0x60400010, 4), 0U);
  EXPECT_EQ(l.download(0x1600, 2, 0x60C10120, 4), 0U);
  // Not in the whitelist (§7.3): 60FFh (also absent), 6077h (the model has it), 6041h (TPDO only).
  EXPECT_EQ(l.download(0x1600, 3, 0x60FF0020, 4), kNotMappable);
  EXPECT_EQ(l.download(0x1600, 3, 0x60770010, 4), kNotMappable);
  EXPECT_EQ(l.download(0x1600, 3, 0x60410010, 4), kNotMappable);
  // 6060h is 16 bits here (quirk 1): the CiA 402 8-bit entry is refused.
  EXPECT_EQ(l.download(0x1600, 3, 0x60600008, 4), kNotMappable);
  EXPECT_EQ(l.download(0x1600, 3, 0x60600010, 4), 0U);
  EXPECT_EQ(l.download(0x1600, 3, 0, 4), 0U);  // cleared again
  // At most 8 entries (§7.2): there is no sub-index 9, and a count of 9 is too high.
  EXPECT_EQ(l.download(0x1600, 9, 0x60400010, 4), kNoSubIndex);
  EXPECT_EQ(l.download(0x1600, 0, 9, 1), kValueTooHigh);
  // A count over an empty entry: not mappable.
  EXPECT_EQ(l.download(0x1600, 0, 3, 1), kNotMappable);
  EXPECT_EQ(l.download(0x1600, 0, 2, 1), 0U);
  EXPECT_EQ(l.download(0x1C12, 1, 0x1600, 2), 0U);
  EXPECT_EQ(l.download(0x1C12, 0, 1, 1), 0U);
  EXPECT_EQ(l.app().output_size(), 6U);  // TV-6: SM2 = 6 bytes
  // 1602h does not exist (quirk 3): no object, and the assignment refuses it.
  EXPECT_EQ(l.upload(0x1602, 0).abort, kNoObject);
  EXPECT_EQ(l.upload(0x1614, 0).abort, kNoObject);
  EXPECT_EQ(l.download(0x1C12, 0, 0, 1), 0U);
  EXPECT_EQ(l.download(0x1C12, 2, 0x1602, 2), kValueRange);
  // A TxPDO mapping object in the RxPDO assignment: refused.
  EXPECT_EQ(l.download(0x1C12, 2, 0x1A00, 2), kValueRange);
  // The printed default 1C12h:03 = 1602h (§11.2): a count covering it is refused.
  EXPECT_EQ(l.download(0x1C12, 0, 3, 1), kValueRange);
  EXPECT_EQ(l.download(0x1C12, 0, 1, 1), 0U);
  // TxPDO: 1A00h := 6041h/16 + 6063h/32 (TV-6 steps 8..14); 6040h is RPDO only.
  EXPECT_EQ(l.download(0x1A00, 0, 0, 1), 0U);
  EXPECT_EQ(l.download(0x1A00, 1, 0x60400010, 4), kNotMappable);
  EXPECT_EQ(l.download(0x1A00, 1, 0x60410010, 4), 0U);
  EXPECT_EQ(l.download(0x1A00, 2, 0x60630020, 4), 0U);
  EXPECT_EQ(l.download(0x1A00, 0, 2, 1), 0U);
  EXPECT_EQ(l.app().input_size(), 6U);
  // The sub-index 0 is one byte (TV-6 uses 2Fh): a 2-byte write is a length mismatch.
  EXPECT_EQ(l.download(0x1A00, 0, 2, 2), kTypeMismatch);

  // SAFE-OP: TxPDO mapping and assignment locked; RxPDO mapping still writable (quirk 4).
  l.pd_sms(6, 6);
  ASSERT_EQ(l.request(AlState::SafeOp), 0x0004);
  EXPECT_EQ(l.download(0x1A00, 0, 2, 1), kDeviceState);
  EXPECT_EQ(l.download(0x1C12, 0, 1, 1), kDeviceState);
  EXPECT_EQ(l.download(0x1600, 0, 2, 1), 0U);
}

TEST(EthercatCia402Slave, GenericMappingIsStrictCia402) {
  DriveLine l("generic-cia402");
  l.preop();
  EXPECT_EQ(l.download(0x1601, 1, 0x60600008, 4), 0U);  // 6060h INTEGER8
  EXPECT_EQ(l.download(0x1601, 2, 0x60600010, 4), kNotMappable);
  EXPECT_EQ(l.download(0x1601, 2, 0x60FF0020, 4), 0U);  // any writable profile object
  EXPECT_EQ(l.download(0x1601, 3, 0x10000020, 4), kNotMappable);  // not process data
  EXPECT_EQ(l.download(0x1601, 0, 2, 1), 0U);
  EXPECT_EQ(l.upload(0x1603, 0).value, 0U);  // 1600h..1603h exist
  EXPECT_EQ(l.upload(0x1604, 0).abort, kNoObject);
  EXPECT_EQ(l.download(0x1C12, 0, 0, 1), 0U);
  EXPECT_EQ(l.download(0x1C12, 2, 0x1601, 2), 0U);
  EXPECT_EQ(l.download(0x1C12, 0, 2, 1), 0U);
  EXPECT_EQ(l.app().output_size(), 17U + 5U);
  // SAFE-OP: every mapping object locked.
  l.pd_sms(22, 15);
  ASSERT_EQ(l.request(AlState::SafeOp), 0x0004);
  EXPECT_EQ(l.download(0x1601, 0, 2, 1), kDeviceState);
}

// ---- Object quirks --------------------------------------------------------------------------

TEST(EthercatCia402Slave, EsrObjectQuirks) {
  DriveLine l("esr-triodrive");
  l.preop();
  // Quirk 1: 6060h/6061h INTEGER16.
  EXPECT_EQ(l.download(0x6060, 0, 7, 1), kTypeMismatch);
  EXPECT_EQ(l.download(0x6060, 0, 7, 2), 0U);
  const test::Upload mode = l.upload(0x6060, 0);
  EXPECT_EQ(mode.size, 2U);
  EXPECT_EQ(mode.value, 7U);
  EXPECT_EQ(l.download(0x6060, 0, 0x0100, 2), kValueRange);  // beyond the drive's modes
  EXPECT_EQ(l.download(0x6060, 0, 8, 2), kValueRange);       // no csp on this drive (quirk 9)
  l.set_time(l.now + 5'000'000);
  l.bus.line().advance(l.now);
  EXPECT_EQ(l.upload(0x6061, 0).size, 2U);
  EXPECT_EQ(l.upload(0x6061, 0).value, 7U);
  // Quirk 8: writes accepted and ignored; read back unchanged.
  EXPECT_EQ(l.download(0x60C0, 0, 1, 2), 0U);
  EXPECT_EQ(l.upload(0x60C0, 0).value, 0U);
  EXPECT_EQ(l.download(0x60C2, 2, 0xFE, 1), 0U);
  EXPECT_EQ(l.upload(0x60C2, 2).value, 0xFDU);  // -3: ms (TV-3)
  EXPECT_EQ(l.download(0x60C3, 1, 5, 1), 0U);
  EXPECT_EQ(l.upload(0x60C3, 1).value, 0U);
  EXPECT_EQ(l.download(0x60C4, 1, 4, 4), 0U);
  EXPECT_EQ(l.upload(0x60C4, 1).value, 1U);
  // 60C2h:01 2..10 ms, default 4 (TV-3).
  EXPECT_EQ(l.upload(0x60C2, 1).value, 4U);
  EXPECT_EQ(l.download(0x60C2, 1, 1, 1), kValueTooLow);
  EXPECT_EQ(l.download(0x60C2, 1, 11, 1), kValueTooHigh);
  EXPECT_EQ(l.download(0x60C2, 1, 2, 1), 0U);
  EXPECT_EQ(l.upload(0x60C2, 1).value, 2U);
  // 6007h I16: 0 (default, quirk 6) or 1 only; TV-6 step 15 bytes 2B 07 60 00 01 00.
  EXPECT_EQ(l.upload(0x6007, 0).value, 0U);
  EXPECT_EQ(l.download(0x6007, 0, 2, 2), kValueRange);
  EXPECT_EQ(l.download(0x6007, 0, 1, 2), 0U);
  EXPECT_EQ(l.app().abort_option(), 1);
  // No 1010h (quirk 10), no 1C32h/1C33h (quirk 9), no 60FFh (quirk 2).
  EXPECT_EQ(l.upload(0x1010, 1).abort, kNoObject);
  EXPECT_EQ(l.upload(0x1C32, 1).abort, kNoObject);
  EXPECT_EQ(l.upload(0x60FF, 0).abort, kNoObject);
  // Whitelisted manufacturer objects exist with their types (§7.3).
  EXPECT_EQ(l.upload(0x6079, 0).size, 2U);
  EXPECT_EQ(l.upload(0x5EF4, 0).size, 4U);
}

TEST(EthercatCia402Slave, GenericObjects) {
  DriveLine l("generic-cia402");
  l.preop();
  EXPECT_EQ(l.download(0x6060, 0, 8, 1), 0U);
  EXPECT_EQ(l.download(0x6060, 0, 8, 2), kTypeMismatch);
  EXPECT_EQ(l.upload(0x1010, 1).value, 1U);
  EXPECT_EQ(l.download(0x1010, 1, 0x65766173, 4), 0U);  // "save" [CiA 301 §7.5.2.13]
  EXPECT_EQ(l.download(0x1010, 1, 0x12345678, 4), 0x08000020U);
  EXPECT_EQ(l.upload(0x6007, 0).value, 1U);
  EXPECT_EQ(l.download(0x6007, 0, 3, 2), 0U);
  EXPECT_EQ(l.download(0x6007, 0, 4, 2), kValueRange);
  EXPECT_EQ(l.upload(0x1C32, 0).value, 0x20U);
  EXPECT_EQ(l.upload(0x1C32, 4).value, 0x0007U);
  EXPECT_EQ(l.download(0x1C32, 1, 5, 2), kValueRange);
  EXPECT_EQ(l.download(0x1C32, 4, 1, 2), 0x06010002U);  // read-only
}

// ---- State machine --------------------------------------------------------------------------

// TV-4: EMCY in SM1 = mailbox header (length 0Ah, CoE, counter in bits 4..6), CoE 1000h, then
// code, error register, five zero bytes.
void expect_emcy(const Reply& r, std::uint16_t code, std::uint8_t error_register) {
  ASSERT_TRUE(r.returned);
  const std::array<std::uint8_t, 5> head{0x0A, 0x00, 0x00, 0x00, 0x00};
  EXPECT_TRUE(std::equal(head.begin(), head.end(), r.data.begin()));
  EXPECT_EQ(r.data[5] & 0x0F, 0x03);
  const std::array<std::uint8_t, 10> body{0x00, 0x10, static_cast<std::uint8_t>(code), static_cast<std::uint8_t>(code >> 8),
                                          error_register, 0, 0, 0, 0, 0};
  EXPECT_TRUE(std::equal(body.begin(), body.end(), r.data.begin() + 6));
}

TEST(EthercatCia402Slave, EsrSmLengthMismatchRefusedWithA000) {
  DriveLine l("esr-triodrive");
  l.preop();
  // TV-6 mapping: 6 bytes each way.
  EXPECT_EQ(l.download(0x1600, 0, 0, 1), 0U);
  EXPECT_EQ(l.download(0x1600, 2, 0x60C10120, 4), 0U);
  EXPECT_EQ(l.download(0x1600, 0, 2, 1), 0U);
  EXPECT_EQ(l.download(0x1A00, 0, 0, 1), 0U);
  EXPECT_EQ(l.download(0x1A00, 2, 0x60630020, 4), 0U);
  EXPECT_EQ(l.download(0x1A00, 0, 2, 1), 0U);
  // SM2 still at the default 2 bytes: 001Dh, and EMCY A000h (dunker §5, App. C).
  l.pd_sms(2, 6);
  EXPECT_EQ(l.request(AlState::SafeOp), 0x0012);
  EXPECT_EQ(l.al_code(), 0x001D);
  l.collect_emergencies();
  ASSERT_EQ(l.emcys.size(), 1U);
  expect_emcy(l.emcys[0], 0xA000, 0x01);
  // SM3 wrong: 001Eh, another A000h.
  EXPECT_EQ(l.request(AlState::PreOp, true), 0x0002);
  l.pd_sms(6, 2);
  EXPECT_EQ(l.request(AlState::SafeOp), 0x0012);
  EXPECT_EQ(l.al_code(), 0x001E);
  l.collect_emergencies();
  ASSERT_EQ(l.emcys.size(), 2U);
  expect_emcy(l.emcys[1], 0xA000, 0x01);
  // Both right: SAFE-OP.
  EXPECT_EQ(l.request(AlState::PreOp, true), 0x0002);
  l.pd_sms(6, 6);
  EXPECT_EQ(l.request(AlState::SafeOp), 0x0004);
}

TEST(EthercatCia402Slave, GenericRefusesOpWithoutSync0InDcMode) {
  DriveLine l("generic-cia402");
  l.preop();
  EXPECT_EQ(l.download(0x1C32, 1, 2, 2), 0U);  // DC SYNC0
  EXPECT_EQ(l.upload(0x1C32, 1).value, 2U);
  l.pd_sms(17, 15);
  ASSERT_EQ(l.request(AlState::SafeOp), 0x0004);
  EXPECT_EQ(l.download(0x1C32, 1, 0, 2), kDeviceState);
  // 0981h = 0: SYNC0 off -> 0030h "invalid DC SYNC configuration" [ETG.1000.6 AL status codes].
  EXPECT_EQ(l.request(AlState::Op), 0x0014);
  EXPECT_EQ(l.al_code(), 0x0030);
  // SYNC0 on (0981h = 03h: cyclic operation + SYNC0 [ETG.1000.4 DC activation]): OP.
  EXPECT_EQ(l.request(AlState::SafeOp, true), 0x0004);
  const std::array<std::uint8_t, 1> act{0x03};
  EXPECT_EQ(l.bus.fpwr(l.st, reg::kDcActivation, act).wkc, 1);
  EXPECT_EQ(l.request(AlState::Op), 0x0008);
}

TEST(EthercatCia402Slave, GenericFreeRunGoesToOp) {
  DriveLine l("generic-cia402");
  l.preop();
  EXPECT_EQ(l.upload(0x1C32, 1).value, 0U);
  l.pd_sms(17, 15);
  ASSERT_EQ(l.request(AlState::SafeOp), 0x0004);
  EXPECT_EQ(l.request(AlState::Op), 0x0008);
}

// ---- Process data ---------------------------------------------------------------------------

// The enable walk of TV-8 over process data: returns the statusword once it matches.
std::uint16_t walk(DriveLine& l, std::vector<std::uint8_t>& out, std::uint16_t in_len, std::uint16_t cw,
                   std::uint16_t mask, std::uint16_t want) {
  out[0] = static_cast<std::uint8_t>(cw);
  out[1] = static_cast<std::uint8_t>(cw >> 8);
  std::uint16_t sw = 0;
  for (int i = 0; i < 500; ++i) {
    sw = l.cycle(out, in_len).u16(0);
    if ((sw & mask) == want) return sw;
  }
  ADD_FAILURE() << "statusword " << std::hex << sw << " after controlword " << cw;
  return sw;
}

TEST(EthercatCia402Slave, EsrEnablesAndFollowsIpSetpoints) {
  DriveLine l("esr-triodrive");
  l.preop();
  // TV-6: 1600h = 6040h + 60C1h:01, 1A00h = 6041h + 6063h, 6007h := 1, 60C2h:01 := 4; mode 7 by SDO.
  for (const auto& [i, s, v, n] : std::array<std::tuple<std::uint16_t, std::uint8_t, std::uint32_t, std::size_t>, 9>{{
           {0x1600, 0, 0, 1}, {0x1600, 2, 0x60C10120, 4}, {0x1600, 0, 2, 1},
           {0x1A00, 0, 0, 1}, {0x1A00, 2, 0x60630020, 4}, {0x1A00, 0, 2, 1},
           {0x6007, 0, 1, 2}, {0x60C2, 1, 4, 1}, {0x6060, 0, 7, 2}}}) {
    ASSERT_EQ(l.download(i, s, v, n), 0U) << std::hex << i << ":" << int(s);
  }
  l.pd_sms(6, 6);
  ASSERT_EQ(l.request(AlState::SafeOp), 0x0004);
  std::vector<std::uint8_t> out(6, 0);
  l.cycle(out, 6);
  ASSERT_EQ(l.request(AlState::Op), 0x0008);
  walk(l, out, 6, 0x0006, 0x006F, 0x0021);
  walk(l, out, 6, 0x0007, 0x006F, 0x0023);
  const std::uint16_t sw = walk(l, out, 6, 0x000F, 0x006F, 0x0027);
  EXPECT_EQ(sw & 0x1000, 0);
  // Enable interpolation (rising edge of bit 4) and send one target per 4 ms period, ramping to
  // 74565 (TV-7: outputs 1F 00 45 23 01 00).
  std::int32_t target = 0;
  Reply in;
  for (int period = 0; period < 200; ++period) {
    target = std::min(target + 500, 74565);
    out = {0x1F, 0x00, static_cast<std::uint8_t>(target), static_cast<std::uint8_t>(target >> 8),
           static_cast<std::uint8_t>(target >> 16), static_cast<std::uint8_t>(target >> 24)};
    for (int ms = 0; ms < 4; ++ms) in = l.cycle(out, 6);
  }
  EXPECT_EQ(out, (std::vector<std::uint8_t>{0x1F, 0x00, 0x45, 0x23, 0x01, 0x00}));
  const auto actual = static_cast<std::int32_t>(in.u32(2));
  EXPECT_LT(std::abs(actual - 74565), 50) << actual;
  EXPECT_EQ(in.u16(0) & 0x006F, 0x0027);  // still enabled: no following error
  EXPECT_EQ(in.u16(0) & 0x1000, 0);       // no "ip mode active" bit (quirk 7)
  EXPECT_EQ(l.app().counters().refused_pdo_values, 0U);
}

TEST(EthercatCia402Slave, GenericEnablesAndFollowsCsp) {
  DriveLine l("generic-cia402");
  l.preop();
  l.pd_sms(17, 15);
  ASSERT_EQ(l.request(AlState::SafeOp), 0x0004);
  // Outputs: 6040 u16, 6060 i8, 6071 i16, 607A i32, 60FF i32, 60C1:1 i32; mode 8 (csp).
  std::vector<std::uint8_t> out(17, 0);
  out[2] = 8;
  l.cycle(out, 15);
  ASSERT_EQ(l.request(AlState::Op), 0x0008);
  walk(l, out, 15, 0x0006, 0x006F, 0x0021);
  walk(l, out, 15, 0x0007, 0x006F, 0x0023);
  walk(l, out, 15, 0x000F, 0x006F, 0x0027);
  // One set-point per 1 ms cycle, 20 counts each, to 4000.
  Reply in;
  std::int32_t target = 0;
  for (int i = 0; i < 260; ++i) {
    target = std::min(target + 20, 4000);
    put_u32(out, 5, static_cast<std::uint32_t>(target));
    in = l.cycle(out, 15);
  }
  // Inputs: 6041 u16, 6061 i8, 6077 i16, 603F u16, 6064 i32, 606C i32.
  EXPECT_EQ(in.u16(0) & 0x006F, 0x0027);
  EXPECT_EQ(in.data[2], 8);
  EXPECT_EQ(in.u16(5), 0);
  EXPECT_LT(std::abs(static_cast<std::int32_t>(in.u32(7)) - 4000), 20);
}

// pp on the ESR: controlword bit 6 = 1 is an absolute move (quirk 14 [EXT]; CiA 402: relative).
// Two moves to 607Ah = 5000 with bit 6 set end at 5000, not 10000.
TEST(EthercatCia402Slave, EsrControlwordBit6MeansAbsolute) {
  DriveLine l("esr-triodrive");
  l.preop();
  ASSERT_EQ(l.download(0x6060, 0, 1, 2), 0U);
  ASSERT_EQ(l.download(0x607A, 0, 5000, 4), 0U);
  l.pd_sms(2, 2);
  ASSERT_EQ(l.request(AlState::SafeOp), 0x0004);
  std::vector<std::uint8_t> out(2, 0);
  l.cycle(out, 2);
  ASSERT_EQ(l.request(AlState::Op), 0x0008);
  walk(l, out, 2, 0x0006, 0x006F, 0x0021);
  walk(l, out, 2, 0x0007, 0x006F, 0x0023);
  walk(l, out, 2, 0x000F, 0x006F, 0x0027);
  for (int move = 0; move < 2; ++move) {
    walk(l, out, 2, 0x005F, 0x1000, 0x1000);  // new set-point, absolute: wait for the acknowledge
    walk(l, out, 2, 0x004F, 0x1400, 0x0400);  // bit 4 back; wait for target reached
  }
  const auto pos = l.upload(0x6064, 0);
  EXPECT_EQ(pos.abort, 0U);
  EXPECT_LT(std::abs(static_cast<std::int32_t>(pos.value) - 5000), 20);
  // Read back as the master wrote it, bit 6 included.
  EXPECT_EQ(l.upload(0x6040, 0).value, 0x004FU);
}

// ---- SM watchdog and 6007h ------------------------------------------------------------------

// Enabled in OP (pp mode, default mapping: controlword/statusword), then the master stops.
void enabled_then_silent(DriveLine& l, std::uint32_t abort_option) {
  l.preop();
  ASSERT_EQ(l.download(0x6007, 0, abort_option, 2), 0U);
  l.pd_sms(2, 2);
  // Watchdog 100 ticks of 100 µs = 10 ms [digest §8.2].
  l.bus.fpwr16(l.st, reg::kWatchdogTimeProcessData, 100);
  ASSERT_EQ(l.request(AlState::SafeOp), 0x0004);
  std::vector<std::uint8_t> out(2, 0);
  l.cycle(out, 2);
  ASSERT_EQ(l.request(AlState::Op), 0x0008);
  walk(l, out, 2, 0x0006, 0x006F, 0x0021);
  walk(l, out, 2, 0x0007, 0x006F, 0x0023);
  walk(l, out, 2, 0x000F, 0x006F, 0x0027);
  l.collect_emergencies();
  l.emcys.clear();
  // No more outputs for 30 ms.
  for (int i = 0; i < 30; ++i) {
    l.set_time(l.now + 1'000'000);
    l.bus.line().advance(l.now);
  }
  EXPECT_EQ(l.esc().state(), AlState::SafeOp);
  EXPECT_EQ(l.al_code(), 0x001B);
}

TEST(EthercatCia402Slave, EsrWatchdogWithAbortOption1Faults8100) {
  DriveLine l("esr-triodrive");
  enabled_then_silent(l, 1);
  l.collect_emergencies();
  // One EMCY: 8100h, error register 11h (generic + communication, CiA 301), bytes 3..7 zero (TV-4).
  ASSERT_EQ(l.emcys.size(), 1U);
  expect_emcy(l.emcys[0], 0x8100, 0x11);
  // Statusword Fault; the inputs still come in SAFE-OP.
  EXPECT_EQ(l.cycle({}, 2).u16(0) & 0x004F, 0x0008);
  EXPECT_EQ(l.upload(0x603F, 0).value, 0x8100U);
  EXPECT_EQ(l.app().counters().comm_losses, 1U);
  // A requested OP -> SAFE-OP runs no reaction on this drive (§8.2: the watchdog only).
}

TEST(EthercatCia402Slave, EsrWatchdogWithAbortOption0DoesNothing) {
  DriveLine l("esr-triodrive");
  enabled_then_silent(l, 0);
  l.collect_emergencies();
  EXPECT_TRUE(l.emcys.empty());
  // Quirk 6: the drive runs on, enabled, with its last set-points.
  EXPECT_EQ(l.cycle({}, 2).u16(0) & 0x006F, 0x0027);
  EXPECT_EQ(l.app().drive().state(), core::AxisState::OperationEnabled);
}

TEST(EthercatCia402Slave, GenericRequestedLeaveOfOpRunsAbortOption) {
  DriveLine l("generic-cia402");
  l.preop();
  l.pd_sms(17, 15);
  ASSERT_EQ(l.request(AlState::SafeOp), 0x0004);
  std::vector<std::uint8_t> out(17, 0);
  out[2] = 8;
  l.cycle(out, 15);
  ASSERT_EQ(l.request(AlState::Op), 0x0008);
  walk(l, out, 15, 0x0006, 0x006F, 0x0021);
  walk(l, out, 15, 0x0007, 0x006F, 0x0023);
  walk(l, out, 15, 0x000F, 0x006F, 0x0027);
  l.collect_emergencies();
  l.emcys.clear();
  // Disabled first (0007h), then SAFE-OP: no reaction.
  walk(l, out, 15, 0x0007, 0x006F, 0x0023);
  EXPECT_EQ(l.request(AlState::SafeOp), 0x0004);
  for (int i = 0; i < 10; ++i) EXPECT_EQ(l.cycle({}, 15).u16(0) & 0x006F, 0x0023);
  l.collect_emergencies();
  EXPECT_TRUE(l.emcys.empty());
  EXPECT_EQ(l.app().counters().comm_losses, 0U);
  // Enabled, then SAFE-OP on request: 6007h = 1 (the default) faults the drive.
  EXPECT_EQ(l.request(AlState::Op), 0x0008);
  walk(l, out, 15, 0x000F, 0x006F, 0x0027);
  EXPECT_EQ(l.request(AlState::SafeOp), 0x0004);
  std::uint16_t sw = 0;
  for (int i = 0; i < 50 && (sw & 0x004F) != 0x0008; ++i) sw = l.cycle({}, 15).u16(0);
  EXPECT_EQ(sw & 0x004F, 0x0008);
  l.collect_emergencies();
  ASSERT_GE(l.emcys.size(), 1U);
  expect_emcy(l.emcys[0], 0x8100, 0x11);
}

TEST(EthercatCia402Slave, NoAllocationWhileFramesPass) {
  // The cyclic path (outputs -> objects, model steps, inputs), SDO traffic, a fault with its EMCY
  // and the ESR fine interpolator: nothing allocates once the slave is built.
  DriveLine l("esr-triodrive");
  l.preop();
  ASSERT_EQ(l.download(0x1600, 0, 0, 1), 0U);
  ASSERT_EQ(l.download(0x1600, 2, 0x60C10120, 4), 0U);
  ASSERT_EQ(l.download(0x1600, 0, 2, 1), 0U);
  ASSERT_EQ(l.download(0x6060, 0, 7, 2), 0U);
  l.pd_sms(6, 2);
  ASSERT_EQ(l.request(AlState::SafeOp), 0x0004);
  std::vector<std::uint8_t> out(6, 0);
  l.cycle(out, 2);
  ASSERT_EQ(l.request(AlState::Op), 0x0008);
  l.emcys.reserve(8);
  const drivegate::test::AllocationScope scope;
  for (int i = 0; i < 100; ++i) {
    out[0] = static_cast<std::uint8_t>(i < 10 ? 0x06 : (i < 20 ? 0x07 : (i < 30 ? 0x0F : 0x1F)));
    put_u32(out, 2, static_cast<std::uint32_t>(i * 10));
    l.cycle(out, 2);
  }
  EXPECT_EQ(l.upload(0x6064, 0).abort, 0U);
  EXPECT_EQ(l.download(0x6081, 0, 1000, 4), 0U);
  l.app().inject_fault(0x2310);
  for (int i = 0; i < 10; ++i) l.cycle(out, 2);
  l.collect_emergencies();
  EXPECT_EQ(scope.count(), 0U);
  EXPECT_EQ(l.emcys.size(), 1U);
}

// ---- Through the master's engines -----------------------------------------------------------

TEST(EthercatCia402Slave, LineBootFindsBothPersonasAndReadsIdentity) {
  using namespace std::chrono_literals;
  MemoryLink link(16);
  link.open();
  SimLine line(link);
  Cia402Device esr = make_cia402_device("esr-triodrive", Cia402SlaveOptions{.serial = 42, .station_alias = 0, .drive = {}, .more_drives = {}});
  Cia402Device gen = make_cia402_device("generic-cia402");
  line.add(*esr.esc);
  line.add(*gen.esc);
  const std::vector<ExpectedSlave> expected{{0x0F, 0x6755, 0, "ESR TrioDrive D/ES"}, {0x00, 0x0192, 0, "generic"}};
  Transactions tx;
  LineBoot boot(expected, LineBootConfig{});
  core::TimePoint now{};
  std::unique_ptr<CoeSdoClient> client;
  auto cycle = [&] {
    boot.poll(now, tx);
    if (client) client->poll(now, tx);
    drivegate::ethercat::test::exchange_over_line(tx, link, line, now);
  };
  boot.start(now);
  for (int i = 0; i < 20000 && boot.status() == LineStatus::Running; ++i) cycle();
  ASSERT_EQ(boot.status(), LineStatus::Done) << boot.line_text();
  EXPECT_TRUE(boot.ok());
  EXPECT_EQ(esr.esc->state(), AlState::PreOp);
  EXPECT_EQ(gen.esc->state(), AlState::PreOp);
  // 1018h:04 over the SDO client: the serial given in the options; 6060h two bytes on the ESR.
  client = std::make_unique<CoeSdoClient>(0x1001, SiiMailbox{0x1000, 128, 0x1080, 128});
  ASSERT_TRUE(client->valid());
  const CoeSdoId serial = client->upload_value(0x1018, 4);
  const CoeSdoId mode = client->upload_value(0x6060, 0);
  for (int i = 0; i < 2000 && !(client->idle() && client->result(mode).status >= CoeSdoStatus::Done); ++i) cycle();
  EXPECT_EQ(client->result(serial).status, CoeSdoStatus::Done);
  EXPECT_EQ(client->result(serial).value, 42U);
  EXPECT_EQ(client->result(mode).status, CoeSdoStatus::Done);
  EXPECT_EQ(client->result(mode).size, 2U);
}

}  // namespace
}  // namespace drivegate::ethercat::sim
