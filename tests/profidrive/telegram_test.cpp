// Telegram codecs against akd-profinet-profidrive.md §4.3, §14, §15.1 and §20.3.
#include "profiles/profidrive/telegram.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <vector>

#include "profiles/profidrive/control_words.hpp"
#include "profiles/profidrive/state_machine.hpp"
#include "tests/support/alloc_counter.hpp"

namespace drivegate::profidrive {
namespace {

using Bytes = std::vector<std::uint8_t>;

TelegramLayout layout(std::uint16_t n) {
  const auto l = standard_layout(n);
  EXPECT_TRUE(l.has_value()) << n;
  return l.value_or(TelegramLayout{});
}

struct SizeRow {
  std::uint16_t telegram;
  std::size_t out_bytes;
  std::size_t in_bytes;
};

TEST(ProfidriveTelegram, SizesMatchTheDigestTable) {
  // §4.3 (from the word tables of §14): output / input bytes.
  for (const SizeRow r : {SizeRow{1, 4, 4}, SizeRow{7, 4, 4}, SizeRow{9, 20, 10}, SizeRow{350, 4, 6},
                          SizeRow{351, 4, 10}, SizeRow{352, 24, 10}, SizeRow{353, 26, 10}, SizeRow{400, 24, 24}}) {
    const auto s = telegram_size(r.telegram);
    ASSERT_TRUE(s.has_value()) << r.telegram;
    EXPECT_EQ(s->setpoint_bytes, r.out_bytes) << r.telegram;
    EXPECT_EQ(s->actual_bytes, r.in_bytes) << r.telegram;
    if (r.telegram != 400) {
      EXPECT_EQ(layout(r.telegram).setpoint_bytes(), r.out_bytes);
      EXPECT_EQ(layout(r.telegram).actual_bytes(), r.in_bytes);
    }
  }
  EXPECT_FALSE(telegram_size(0).has_value());  // set by its module [§13]
  EXPECT_FALSE(standard_layout(400).has_value());
  EXPECT_FALSE(standard_layout(2).has_value());
}

TEST(ProfidriveTelegram, Telegram1RunningFramesOfTheS7Example) {
  // §15.1 step 4 and §20.3: controller -> AKD 04 7F 00 A3, AKD -> controller 02 37 00 9E.
  const TelegramLayout t1 = layout(1);
  Setpoints sp;
  sp.stw1 = 0x047F;
  sp.nsoll_a = 0x00A3;
  std::array<std::uint8_t, 4> out{};
  ASSERT_EQ(encode_setpoints(t1, sp, out), TelegramError::None);
  EXPECT_EQ(out, (std::array<std::uint8_t, 4>{0x04, 0x7F, 0x00, 0xA3}));

  const std::array<std::uint8_t, 4> in{0x02, 0x37, 0x00, 0x9E};
  Actuals a;
  ASSERT_EQ(decode_actuals(t1, in, a), TelegramError::None);
  EXPECT_EQ(a.zsw1, 0x0237);
  EXPECT_EQ(a.nist_a, 158);
}

TEST(ProfidriveTelegram, Telegram1EnableSequenceOnTheWire) {
  // §15.1 output bytes of steps 1..3 (set-point 0).
  const TelegramLayout t1 = layout(1);
  std::array<std::uint8_t, 4> out{};
  const std::array<std::pair<std::uint16_t, std::array<std::uint8_t, 4>>, 3> steps{{
      {0x0470, {0x04, 0x70, 0x00, 0x00}}, {0x0476, {0x04, 0x76, 0x00, 0x00}}, {0x0477, {0x04, 0x77, 0x00, 0x00}}}};
  for (const auto& [stw1, bytes] : steps) {
    Setpoints sp;
    sp.stw1 = stw1;
    ASSERT_EQ(encode_setpoints(t1, sp, out), TelegramError::None);
    EXPECT_EQ(out, bytes);
  }
}

TEST(ProfidriveTelegram, EnableAndRunWithTelegram1) {
  // §15.1 end to end: the enable walk with the ramp bits reads each ZSW1 from the input image and
  // writes STW1 (and, from S4 on, NSOLL_A = 0x00A3) into the output image. The drive's replies are
  // the standard patterns (§9.4), the last one the S7 example's 02 37 00 9E (§20.3).
  const TelegramLayout t1 = layout(1);
  const std::array<std::array<std::uint8_t, 4>, 4> inputs{{{0x02, 0x70, 0x00, 0x00},   // S1
                                                           {0x02, 0x31, 0x00, 0x00},   // S2
                                                           {0x02, 0x33, 0x00, 0x00},   // S3
                                                           {0x02, 0x37, 0x00, 0x9E}}}; // S4, running
  const std::array<std::array<std::uint8_t, 4>, 4> expected{{{0x04, 0x76, 0x00, 0x00},
                                                             {0x04, 0x77, 0x00, 0x00},
                                                             {0x04, 0x7F, 0x00, 0x00},
                                                             {0x04, 0x7F, 0x00, 0xA3}}};
  std::uint16_t last = 0x0470;  // §15.1 step 1
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    Actuals a;
    ASSERT_EQ(decode_actuals(t1, inputs[i], a), TelegramError::None);
    const EnableStep step = enable_step(decode_state(a.zsw1, last), last, stw1::kSpeedRunBits);
    Setpoints sp;
    sp.stw1 = step.stw1;
    sp.nsoll_a = step.done ? std::int16_t{0x00A3} : std::int16_t{0};  // the set-point counts from S4 on
    std::array<std::uint8_t, 4> out{};
    ASSERT_EQ(encode_setpoints(t1, sp, out), TelegramError::None);
    EXPECT_EQ(out, expected[i]) << "step " << i;
    EXPECT_EQ(step.done, i == 3);
    last = step.stw1;
  }
}

TEST(ProfidriveTelegram, NegativeSpeedIsTwosComplement) {
  const TelegramLayout t1 = layout(1);
  Setpoints sp;
  sp.stw1 = 0x047F;
  sp.nsoll_a = -163;
  std::array<std::uint8_t, 4> out{};
  ASSERT_EQ(encode_setpoints(t1, sp, out), TelegramError::None);
  EXPECT_EQ(out, (std::array<std::uint8_t, 4>{0x04, 0x7F, 0xFF, 0x5D}));
  Setpoints back;
  ASSERT_EQ(decode_setpoints(t1, out, back), TelegramError::None);
  EXPECT_EQ(back.nsoll_a, -163);
}

TEST(ProfidriveTelegram, Telegram9MdiWordsHighWordFirst) {
  // §14.4 word order; §16.3 MDI selected by SATZANW bit 15; §17.1 60 rpm = 0x0147AE14.
  const TelegramLayout t9 = layout(9);
  Setpoints sp;
  sp.stw1 = 0x047F;
  sp.satzanw = 0x8000;
  sp.stw2 = 0;
  sp.mdi_tarpos = 0x00012345;
  sp.mdi_velocity = 0x0147AE14;
  sp.mdi_acc = 0x0102;
  sp.mdi_dec = 0x0304;
  sp.mdi_mod = 1;
  sp.nsoll_a = 1234;   // not in telegram 9: ignored
  sp.home_dist = 99;   // not in telegram 9: ignored
  std::array<std::uint8_t, 20> out{};
  ASSERT_EQ(encode_setpoints(t9, sp, out), TelegramError::None);
  EXPECT_EQ(out, (std::array<std::uint8_t, 20>{0x04, 0x7F, 0x80, 0x00, 0x00, 0x00, 0x00, 0x01, 0x23, 0x45,
                                              0x01, 0x47, 0xAE, 0x14, 0x01, 0x02, 0x03, 0x04, 0x00, 0x01}));
  const std::array<std::uint8_t, 10> in{0x02, 0x37, 0x80, 0x00, 0x00, 0x00, 0xFF, 0xFF, 0xFF, 0xFE};
  Actuals a;
  ASSERT_EQ(decode_actuals(t9, in, a), TelegramError::None);
  EXPECT_EQ(a.zsw1, 0x0237);
  EXPECT_EQ(a.aktsatz, 0x8000);
  EXPECT_EQ(a.zsw2, 0);
  EXPECT_EQ(a.xist_a, -2);
}

TEST(ProfidriveTelegram, VendorTelegrams350To353) {
  // §14.5/§14.6: ITIST_GLATT at word 3 (signed, -182 in §17.4), XIST_A at words 4-5.
  Actuals a;
  const std::array<std::uint8_t, 6> in350{0x02, 0x37, 0x00, 0x9E, 0xFF, 0x4A};
  ASSERT_EQ(decode_actuals(layout(350), in350, a), TelegramError::None);
  EXPECT_EQ(a.itist_glatt, -182);
  const std::array<std::uint8_t, 10> in351{0x02, 0x37, 0x00, 0x9E, 0xFF, 0x4A, 0x00, 0x02, 0x80, 0x00};
  ASSERT_EQ(decode_actuals(layout(351), in351, a), TelegramError::None);
  EXPECT_EQ(a.xist_a, 0x00028000);  // 2.5 rev at 65536 counts/rev [§17.2]

  // §14.7/§14.8: HOME_DIST at words 11-12, HOME_MODE at word 13.
  Setpoints sp;
  sp.stw1 = 0x0C0F;
  sp.home_dist = -65536;
  sp.home_mode = 0x0102;
  std::array<std::uint8_t, 24> out352{};
  ASSERT_EQ(encode_setpoints(layout(352), sp, out352), TelegramError::None);
  EXPECT_EQ((std::array<std::uint8_t, 4>{out352[20], out352[21], out352[22], out352[23]}),
            (std::array<std::uint8_t, 4>{0xFF, 0xFF, 0x00, 0x00}));
  std::array<std::uint8_t, 26> out353{};
  ASSERT_EQ(encode_setpoints(layout(353), sp, out353), TelegramError::None);
  EXPECT_EQ(out353[24], 0x01);
  EXPECT_EQ(out353[25], 0x02);
  Setpoints back;
  ASSERT_EQ(decode_setpoints(layout(353), out353, back), TelegramError::None);
  EXPECT_EQ(back.home_dist, -65536);
  EXPECT_EQ(back.home_mode, 0x0102);
  EXPECT_EQ(back.stw1, 0x0C0F);
}

TEST(ProfidriveTelegram, EveryTelegramRoundTripsAndRefusesWrongLengths) {
  Setpoints sp;
  sp.stw1 = 0x047F;
  sp.stw2 = 0x1234;
  sp.nsoll_a = -5;
  sp.satzanw = 0x8003;
  sp.mdi_tarpos = -100000;
  sp.mdi_velocity = 0xDEADBEEF;
  sp.home_dist = -42;
  Actuals ac;
  ac.zsw1 = 0x0237;
  ac.zsw2 = 0x4321;
  ac.nist_a = -7;
  ac.xist_a = -123456;
  ac.itist_glatt = -182;
  for (const std::uint16_t n : std::array<std::uint16_t, 7>{1, 7, 9, 350, 351, 352, 353}) {
    const TelegramLayout l = layout(n);
    Bytes out(l.setpoint_bytes()), in(l.actual_bytes());
    ASSERT_EQ(encode_setpoints(l, sp, out), TelegramError::None);
    ASSERT_EQ(encode_actuals(l, ac, in), TelegramError::None);
    Setpoints sp_back;
    Actuals ac_back;
    ASSERT_EQ(decode_setpoints(l, out, sp_back), TelegramError::None);
    ASSERT_EQ(decode_actuals(l, in, ac_back), TelegramError::None);
    EXPECT_EQ(sp_back.stw1, sp.stw1);
    EXPECT_EQ(ac_back.zsw1, ac.zsw1);
    if (l.carries(Signal::XistA)) {
      EXPECT_EQ(ac_back.xist_a, ac.xist_a);
    }
    if (l.carries(Signal::MdiVelocity)) {
      EXPECT_EQ(sp_back.mdi_velocity, sp.mdi_velocity);
    }
    EXPECT_EQ(l.carries(Signal::Stw2), n == 9 || n == 352 || n == 353) << n;
    EXPECT_EQ(l.carries(Signal::Zsw2), n == 9 || n == 352 || n == 353) << n;

    // One byte short and one byte long are refused, in every direction, and nothing is written.
    Bytes shorter(l.setpoint_bytes() - 1, 0xAA), longer(l.actual_bytes() + 1, 0xAA);
    EXPECT_EQ(encode_setpoints(l, sp, shorter), TelegramError::WrongLength);
    EXPECT_EQ(shorter, Bytes(l.setpoint_bytes() - 1, 0xAA));
    EXPECT_EQ(decode_actuals(l, longer, ac_back), TelegramError::WrongLength);
    EXPECT_EQ(decode_actuals(l, Bytes(l.actual_bytes() - 1), ac_back), TelegramError::WrongLength);
    EXPECT_EQ(decode_setpoints(l, Bytes(), sp_back), TelegramError::WrongLength);
    Bytes two_long(l.actual_bytes() + 2);
    EXPECT_EQ(encode_actuals(l, ac, two_long), TelegramError::WrongLength);
  }
}

TEST(ProfidriveTelegram, FreeTelegram400FromSignalLists) {
  // A telegram-9-like mapping in PNU 915/916 [§13, §14.9]; 32-bit signals written once or twice.
  const std::array<std::uint16_t, 11> p915{1, 32, 3, 34, 34, 35, 0, 36, 37, 38, 101};
  const std::array<std::uint16_t, 6> p916{2, 33, 4, 28, 28, 52};
  const LayoutResult r = free_layout(400, p915, 12, p916, 12);
  ASSERT_EQ(r.error, TelegramError::None) << to_string(r.error) << " at " << r.at;
  EXPECT_EQ(r.layout.setpoint_bytes(), 24U);
  EXPECT_EQ(r.layout.actual_bytes(), 24U);
  Setpoints sp;
  sp.stw1 = 0x047F;
  sp.satzanw = 0x8000;
  sp.mdi_tarpos = 0x01020304;
  sp.mdi_velocity = 0x0A0B0C0D;
  sp.mdi_acc = 0x1111;
  sp.mdi_dec = 0x2222;
  sp.mdi_mod = 1;
  sp.mt_feedrate = 0x3333;
  std::array<std::uint8_t, 24> out{};
  ASSERT_EQ(encode_setpoints(r.layout, sp, out), TelegramError::None);
  EXPECT_EQ(out, (std::array<std::uint8_t, 24>{0x04, 0x7F, 0x80, 0x00, 0x00, 0x00, 0x01, 0x02, 0x03, 0x04,
                                              0x0A, 0x0B, 0x0C, 0x0D, 0x11, 0x11, 0x22, 0x22, 0x00, 0x01,
                                              0x33, 0x33, 0x00, 0x00}));
  const std::array<std::uint8_t, 24> in{0x02, 0x37, 0x80, 0x00, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0xFF, 0x4A};
  Actuals a;
  ASSERT_EQ(decode_actuals(r.layout, in, a), TelegramError::None);
  EXPECT_EQ(a.zsw1, 0x0237);
  EXPECT_EQ(a.xist_a, 65536);
  EXPECT_EQ(a.itist_glatt, -182);
  EXPECT_EQ(decode_actuals(r.layout, std::span(in).first(12), a), TelegramError::WrongLength);
}

TEST(ProfidriveTelegram, FreeTelegram0TakesItsModuleLength) {
  const std::array<std::uint16_t, 2> p915{1, 5};
  const std::array<std::uint16_t, 4> p916{2, 6, 104, 106};
  const LayoutResult r = free_layout(0, p915, 2, p916, 4);
  ASSERT_EQ(r.error, TelegramError::None);
  EXPECT_EQ(r.layout.setpoint_bytes(), 4U);
  EXPECT_EQ(r.layout.actual_bytes(), 8U);
}

TEST(ProfidriveTelegram, BadSignalListsAreRefusedWithTheEntry) {
  const auto check = [](std::span<const std::uint16_t> p915, std::span<const std::uint16_t> p916, TelegramError e,
                        std::size_t at, bool in916) {
    const LayoutResult r = free_layout(400, p915, 12, p916, 12);
    EXPECT_EQ(r.error, e) << to_string(r.error);
    EXPECT_EQ(r.at, at);
    EXPECT_EQ(r.pnu916, in916);
  };
  const std::array<std::uint16_t, 2> ok{2, 6};
  const std::array<std::uint16_t, 3> unknown{1, 107, 5};
  check(unknown, ok, TelegramError::UnknownSignal, 1, false);
  const std::array<std::uint16_t, 2> wrong_dir{1, 6};
  check(wrong_dir, ok, TelegramError::WrongDirection, 1, false);
  const std::array<std::uint16_t, 2> actual_in_915{1, 5};
  const std::array<std::uint16_t, 2> setpoint_in_916{2, 5};
  check(actual_in_915, setpoint_in_916, TelegramError::WrongDirection, 1, true);
  const std::array<std::uint16_t, 3> dup{1, 5, 5};
  check(dup, ok, TelegramError::DuplicateSignal, 2, false);
  const std::array<std::uint16_t, 3> split{1, 34, 35};
  check(split, ok, TelegramError::SplitSignal, 1, false);
  std::array<std::uint16_t, 12> last_word{};
  last_word[0] = 1;
  last_word[11] = 34;  // a 32-bit signal in the image's last word
  check(last_word, ok, TelegramError::SplitSignal, 11, false);
  const std::array<std::uint16_t, 13> too_long{1};
  check(too_long, ok, TelegramError::TooManyWords, 12, false);
  EXPECT_EQ(free_layout(9, ok, 12, ok, 12).error, TelegramError::UnknownTelegram);
  EXPECT_EQ(free_layout(0, ok, kMaxTelegramWords + 1, ok, 2).error, TelegramError::TooManyWords);
}

TEST(ProfidriveTelegram, CodecsDoNotAllocate) {
  const TelegramLayout l = layout(353);
  std::array<std::uint8_t, 26> out{};
  std::array<std::uint8_t, 10> in{};
  Setpoints sp;
  Actuals ac;
  test::AllocationScope scope;
  for (int i = 0; i < 100; ++i) {
    sp.stw1 = static_cast<std::uint16_t>(i);
    ASSERT_EQ(encode_setpoints(l, sp, out), TelegramError::None);
    ASSERT_EQ(decode_actuals(l, in, ac), TelegramError::None);
  }
  const std::array<std::uint16_t, 3> p915{1, 34, 34};
  const std::array<std::uint16_t, 2> p916{2, 28};
  EXPECT_EQ(free_layout(400, p915, 12, p916, 12).error, TelegramError::None);
  EXPECT_EQ(standard_layout(9)->number, 9);
  EXPECT_EQ(scope.count(), 0U);
}

}  // namespace
}  // namespace drivegate::profidrive
