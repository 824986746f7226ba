// ExpectedSubmoduleBlockReq and ModuleDiffBlock against byte-exact vectors written from
// IEC 61158-6-10 §5.2.2.4 / §5.2.2.5 (big-endian), the per-slot report text, and malformed input.
#include <gtest/gtest.h>

#include <array>
#include <string>
#include <vector>

#include "adapters/profinet/wire/blocks_submodule.hpp"
#include "tests/profinet_rpc/hex.hpp"
#include "tests/profinet_rpc/scenario.hpp"

namespace drivegate::profinet {
namespace {

using test::hex;
using Bytes = std::vector<std::uint8_t>;

// Slot 1 of scenario.hpp: API 3A00h, module 101h, one input-output submodule (SubmoduleProperties
// type 3) with an input and an output DataDescription of 4 bytes, LengthIOCS 1, LengthIOPS 1.
const Bytes kExpectedSlot1 = hex(
    "01 04 | 00 26 | 01 00 | 00 01"
    "00 00 3A 00 | 00 01 | 00 00 01 01 | 00 00 | 00 01"
    "00 01 | 00 00 00 01 | 00 03 | 00 01 00 04 01 01 | 00 02 00 04 01 01");
// Slot 0: the DAP's NO_IO submodule carries one input DataDescription of length 0.
const Bytes kExpectedSlot0 = hex(
    "01 04 | 00 20 | 01 00 | 00 01"
    "00 00 00 00 | 00 00 | 00 00 00 01 | 00 00 | 00 01"
    "00 01 | 00 00 00 01 | 00 00 | 00 01 00 00 01 01");

// API 3A00h: slot 1 wrong module 102h with subslot 1 wrong submodule 2 (SubmoduleState 9000h:
// FormatIndicator, IdentInfo 2 = Wrong), slot 2 no module.
const Bytes kModuleDiff = hex(
    "81 04 | 00 26 | 01 00 | 00 01 | 00 00 3A 00 | 00 02"
    "00 01 | 00 00 01 02 | 00 01 | 00 01 | 00 01 | 00 00 00 02 | 90 00"
    "00 02 | 00 00 00 00 | 00 00 | 00 00");

Bytes encode_slots(std::span<const ExpectedSlot> slots) {
  std::array<std::uint8_t, 512> buf{};
  const std::size_t n = encode_expected_submodule_block(slots, buf);
  return Bytes(buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n));
}

TEST(PnExpected, Bytes) {
  const test::Scenario s;
  EXPECT_EQ(encode_slots(std::span(s.expected).subspan(1, 1)), kExpectedSlot1);
  EXPECT_EQ(encode_slots(std::span(s.expected).first(1)), kExpectedSlot0);
}

TEST(PnExpected, DecodesFlat) {
  const test::Scenario s;
  const Bytes both = encode_slots(s.expected);
  const ExpectedSubmoduleBlockView v = decode_expected_submodule_block(both);
  ASSERT_EQ(v.error, WireError::None) << to_string(v.error);
  EXPECT_EQ(v.api_count, 2);
  ExpectedSubmoduleReader r(v);
  ExpectedEntry e;
  ASSERT_TRUE(r.next(e));
  EXPECT_EQ(e.slot, 0);
  EXPECT_EQ(e.module_ident, test::kDapModule);
  ASSERT_TRUE(e.has_submodule);
  EXPECT_EQ(e.submodule.type(), SubmoduleType::NoIo);
  EXPECT_EQ(e.submodule.input, (DataDescription{0, 1, 1}));
  ASSERT_TRUE(r.next(e));
  EXPECT_EQ(e.api, test::kProfidriveApi);
  EXPECT_EQ(e.slot, 1);
  EXPECT_EQ(e.submodule, s.tg_subs[0]);
  EXPECT_FALSE(r.next(e));
}

TEST(PnExpected, Malformed) {
  for (std::size_t n = 0; n < kExpectedSlot1.size(); ++n) {
    EXPECT_NE(decode_expected_submodule_block(std::span(kExpectedSlot1).first(n)).error, WireError::None) << n;
  }
  Bytes b = kExpectedSlot1;
  b[7] = 2;  // NumberOfAPIs 2, one present
  EXPECT_EQ(decode_expected_submodule_block(b).error, WireError::CountBeyondData);
  b = kExpectedSlot1;
  b[21] = 2;  // NumberOfSubmodules 2, one present
  EXPECT_EQ(decode_expected_submodule_block(b).error, WireError::CountBeyondData);
  b = kExpectedSlot1;
  b[29] = 1;  // type input: the output description is left over
  EXPECT_EQ(decode_expected_submodule_block(b).error, WireError::BlockLengthMismatch);
  b = kExpectedSlot1;
  b[31] = 2;  // first description says output where the input-output type wants input first
  EXPECT_EQ(decode_expected_submodule_block(b).error, WireError::BadDataDescription);
  b = kExpectedSlot1;
  b[31] = 7;
  EXPECT_EQ(decode_expected_submodule_block(b).error, WireError::BadDataDescription);
  b = kExpectedSlot1;
  b[0] = 0x81;
  EXPECT_EQ(decode_expected_submodule_block(b).error, WireError::WrongBlockType);
  b = kExpectedSlot1;
  b.push_back(0);
  b[3] = 0x27;
  EXPECT_EQ(decode_expected_submodule_block(b).error, WireError::BlockLengthMismatch);
}

TEST(PnModuleDiff, BytesAndEntries) {
  const std::array<ModuleDiffSubmodule, 1> subs{{{1, 2, 0x9000}}};
  const std::array<ModuleDiffModule, 2> mods{{{1, 0x102, ModuleState::WrongModule, subs}, {2, 0, ModuleState::NoModule, {}}}};
  const std::array<ModuleDiffApi, 1> apis{{{test::kProfidriveApi, mods}}};
  std::array<std::uint8_t, 256> buf{};
  const std::size_t n = encode_module_diff_block(apis, buf);
  EXPECT_EQ(Bytes(buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n)), kModuleDiff);

  const ModuleDiffBlockView v = decode_module_diff_block(kModuleDiff);
  ASSERT_EQ(v.error, WireError::None) << to_string(v.error);
  ModuleDiffReader r(v);
  ModuleDiffEntry e;
  ASSERT_TRUE(r.next(e));
  EXPECT_EQ(e.api, test::kProfidriveApi);
  EXPECT_EQ(e.slot, 1);
  EXPECT_EQ(e.module_ident, 0x102U);
  EXPECT_EQ(e.module_state, 1);
  ASSERT_TRUE(e.has_submodule);
  EXPECT_EQ(e.submodule, subs[0]);
  ASSERT_TRUE(r.next(e));
  EXPECT_EQ(e.api, test::kProfidriveApi);
  EXPECT_EQ(e.slot, 2);
  EXPECT_EQ(e.module_state, 0);
  EXPECT_FALSE(e.has_submodule);
  EXPECT_FALSE(r.next(e));
}

TEST(PnModuleDiff, ReportNamesTheSlots) {
  const test::Scenario s;
  std::array<char, 512> text{};
  const ModuleDiffBlockView v = decode_module_diff_block(kModuleDiff);
  EXPECT_EQ(std::string(module_diff_report(v, s.expected, text)),
            "slot 1 (API 0x00003A00): wrong module (ident 0x00000102, expected 0x00000101)\n"
            "slot 1 subslot 1 (API 0x00003A00): wrong submodule (ident 0x00000002, expected 0x00000001)\n"
            "slot 2 (API 0x00003A00): no module");
  // Without the expectation the idents are still named.
  EXPECT_EQ(std::string(module_diff_report(v, {}, text)).substr(0, 64),
            "slot 1 (API 0x00003A00): wrong module (ident 0x00000102)\nslot 1 ");
}

TEST(PnModuleDiff, ReportStates) {
  // The DAP in API 0: proper module, its submodule waiting for ApplicationReady (ARInfo 1), a
  // second one substituted with diagnosis (IdentInfo 1, DiagInfo), a third locked by another
  // controller (ARInfo 3), one in the old format.
  const std::array<ModuleDiffSubmodule, 4> subs{{{1, 1, 0x8080}, {0x8000, 5, 0x8840}, {0x8001, 6, 0x8180}, {0x8002, 7, 0x0001}}};
  const std::array<ModuleDiffModule, 1> mods{{{0, 1, ModuleState::ProperModule, subs}}};
  const std::array<ModuleDiffApi, 1> apis{{{0, mods}}};
  std::array<std::uint8_t, 256> buf{};
  const std::size_t n = encode_module_diff_block(apis, buf);
  ASSERT_NE(n, 0U);
  const ModuleDiffBlockView v = decode_module_diff_block(std::span(buf).first(n));
  ASSERT_EQ(v.error, WireError::None);
  std::array<char, 512> text{};
  EXPECT_EQ(std::string(module_diff_report(v, {}, text)),
            "slot 0 subslot 1: application ready pending\n"
            "slot 0 subslot 32768: substitute submodule (ident 0x00000005)\n"
            "slot 0 subslot 32768: diagnosis available\n"
            "slot 0 subslot 32769: locked by another IO controller\n"
            "slot 0 subslot 32770: submodule state 0x0001 (old format)");
  // A short buffer cuts, never overruns.
  std::array<char, 10> small{};
  EXPECT_EQ(module_diff_report(v, {}, small), "slot 0 sub");
}

TEST(PnModuleDiff, Malformed) {
  for (std::size_t n = 0; n < kModuleDiff.size(); ++n) {
    EXPECT_NE(decode_module_diff_block(std::span(kModuleDiff).first(n)).error, WireError::None) << n;
  }
  Bytes b = kModuleDiff;
  b[13] = 3;  // NumberOfModules 3, two present
  EXPECT_EQ(decode_module_diff_block(b).error, WireError::CountBeyondData);
  b = kModuleDiff;
  b[23] = 2;  // NumberOfSubmodules 2 in slot 1: the rest of the block is too short
  EXPECT_EQ(decode_module_diff_block(b).error, WireError::CountBeyondData);
  b = kModuleDiff;
  b[7] = 0;  // NumberOfAPIs 0: everything after is left over
  EXPECT_EQ(decode_module_diff_block(b).error, WireError::BlockLengthMismatch);
  std::array<char, 128> text{};
  EXPECT_EQ(std::string(module_diff_report(decode_module_diff_block(b), {}, text)),
            "ModuleDiffBlock unreadable: block fields do not end where BlockLength says");
}

}  // namespace
}  // namespace drivegate::profinet
