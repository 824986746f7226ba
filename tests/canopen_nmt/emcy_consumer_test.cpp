// EmcyConsumer: SD6 and AKD EMCY vectors decoded into reports with text and vendor fields, the
// cleared-state rules, the per-node active fault, the report ring and bad input.
#include "adapters/canopen/master/emcy_consumer.hpp"

#include <gtest/gtest.h>

#include <array>
#include <stdexcept>
#include <string>
#include <vector>

#include "tests/canopen_nmt/nmt_test_support.hpp"

namespace drivegate::canopen::test {
namespace {

// What a device profile would hold: SD6 Tab. 17 names (stoeber-sd6-canopen.md §6.9) and the AKD
// code table (AKD part 1 §9.4).
constexpr std::array kSd6Texts{cia402::FaultText{0x7500, "communication"},
                               cia402::FaultText{0x4310, "motor overtemperature (sensor)"}};
constexpr std::array kSd6Fields{EmcyField{3, "event"}, EmcyField{4, "cause"}};
constexpr std::array kAkdTexts{cia402::FaultText{0xFF01, "F702 fieldbus communication lost"},
                               cia402::FaultText{0x8130, "F129 life guard or heartbeat error"}};
constexpr std::array kAkdFields{EmcyField{3, "category"}};

constexpr NodeId kSd6 = 5;
constexpr NodeId kAkd = 1;
constexpr NodeId kPlain = 7;  // no vendor table, no fields, 0000h always clears

std::array<EmcyNodeConfig, 3> node_table() {
  EmcyNodeConfig sd6{kSd6, kSd6Texts, kSd6Fields, true};
  EmcyNodeConfig akd{kAkd, kAkdTexts, kAkdFields, true};
  EmcyNodeConfig plain{kPlain, {}, {}, false};
  return {sd6, akd, plain};
}

std::vector<EmcyReport> reports(EmcyConsumer& c) {
  std::vector<EmcyReport> out;
  EmcyReport r;
  while (c.next_report(r)) out.push_back(r);
  return out;
}

class EmcyConsumerTest : public ::testing::Test {
 protected:
  std::array<EmcyNodeConfig, 3> table_ = node_table();
  EmcyConsumer c_{table_};

  EmcyReport one(const CanFrame& f, std::int64_t t_ms = 0) {
    EXPECT_TRUE(c_.on_frame(f, at_ms(t_ms)));
    auto r = reports(c_);
    EXPECT_EQ(r.size(), 1U);
    return r.empty() ? EmcyReport{} : r.front();
  }
};

TEST_F(EmcyConsumerTest, Sd6LifeGuardingD7) {
  const auto r = one(make_frame(0x085, {0x00, 0x75, 0x10, 0x34, 0x01, 0x00, 0x00, 0x00}), 12);
  EXPECT_EQ(r.node, kSd6);
  EXPECT_EQ(r.emcy.code, 0x7500);
  EXPECT_EQ(r.emcy.error_register, 0x10);
  EXPECT_EQ(r.emcy.vendor[0], 52);
  EXPECT_EQ(r.emcy.vendor[1], 1);
  EXPECT_FALSE(r.cleared);
  EXPECT_EQ(r.time, at_ms(12));
  EXPECT_EQ(r.text.view(), "0x7500 communication (event 52, cause 1)");
  const EmcyReport* a = c_.active(kSd6);
  ASSERT_NE(a, nullptr);
  EXPECT_EQ(a->text.view(), r.text.view());
}

TEST_F(EmcyConsumerTest, Sd6BusOffD8) {
  const auto r = one(make_frame(0x085, {0x00, 0x75, 0x10, 0x34, 0x03, 0x00, 0x00, 0x00}));
  EXPECT_EQ(r.text.view(), "0x7500 communication (event 52, cause 3)");
}

TEST_F(EmcyConsumerTest, Sd6MotorOvertemperatureD9) {
  const auto r = one(make_frame(0x085, {0x10, 0x43, 0x08, 0x29, 0x00, 0x00, 0x00, 0x00}));
  EXPECT_EQ(r.emcy.code, 0x4310);
  EXPECT_EQ(r.emcy.error_register, 0x08);  // temperature bit without the generic bit (SD6 §6.9 notes)
  EXPECT_EQ(r.text.view(), "0x4310 motor overtemperature (sensor) (event 41, cause 0)");
}

TEST_F(EmcyConsumerTest, Sd6LeavingFaultTv5ClearsTheActiveFault) {
  one(make_frame(0x085, {0x00, 0x75, 0x10, 0x34, 0x01, 0x00, 0x00, 0x00}));
  ASSERT_NE(c_.active(kSd6), nullptr);
  const auto r = one(make_frame(0x085, {0x00, 0x00, 0x00, 0x1E, 0x00, 0x00, 0x00, 0x00}));
  EXPECT_TRUE(r.cleared);
  EXPECT_EQ(r.text.view(), "0x0000 error reset / no error (event 30, cause 0)");  // E82 = 30 "inactive"
  EXPECT_EQ(c_.active(kSd6), nullptr);
}

TEST_F(EmcyConsumerTest, AkdZeroWithRegisterKeepsTheFault) {
  // AKD part 1 §14 vectors 32 and 33, with ER = 81h and category 2.
  const auto fault = one(make_frame(0x081, {0x01, 0xFF, 0x81, 0x02, 0x00, 0x00, 0x00, 0x00}));
  EXPECT_EQ(fault.text.view(), "0xFF01 F702 fieldbus communication lost (category 2)");

  const auto update = one(make_frame(0x081, {0x00, 0x00, 0x81, 0x02, 0x00, 0x00, 0x00, 0x00}));
  EXPECT_FALSE(update.cleared);  // quirk 4: 0000h is a state update, byte 2 says errors remain
  EXPECT_EQ(update.text.view(), "0x0000 error state update, errors pending (register 0x81) (category 2)");
  const EmcyReport* a = c_.active(kAkd);
  ASSERT_NE(a, nullptr);
  EXPECT_EQ(a->emcy.code, 0xFF01);

  // A second fault replaces the first as the active one.
  one(make_frame(0x081, {0x30, 0x81, 0x81, 0x00, 0x00, 0x00, 0x00, 0x00}));
  ASSERT_NE(c_.active(kAkd), nullptr);
  EXPECT_EQ(c_.active(kAkd)->text.view(), "0x8130 F129 life guard or heartbeat error (category 0)");

  const auto clear = one(make_frame(0x081, {0x00, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00, 0x00}));
  EXPECT_TRUE(clear.cleared);
  EXPECT_EQ(c_.active(kAkd), nullptr);
}

TEST_F(EmcyConsumerTest, UpdateWithErrorsPendingAndNoKnownFaultBecomesActive) {
  // The consumer started after the fault EMCY: the update alone says something is wrong.
  one(make_frame(0x081, {0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00}));
  const EmcyReport* a = c_.active(kAkd);
  ASSERT_NE(a, nullptr);
  EXPECT_EQ(a->emcy.error_register, 0x01);
}

TEST_F(EmcyConsumerTest, ZeroClearsRegardlessOfRegisterWhenConfigured) {
  one(make_frame(0x087, {0x10, 0x43, 0x08, 0x00, 0x00, 0x00, 0x00, 0x00}));
  ASSERT_NE(c_.active(kPlain), nullptr);
  const auto r = one(make_frame(0x087, {0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00}));
  EXPECT_TRUE(r.cleared);
  EXPECT_EQ(c_.active(kPlain), nullptr);
}

TEST_F(EmcyConsumerTest, StandardTextsWithoutVendorTable) {
  EXPECT_EQ(one(make_frame(0x087, {0x30, 0x81, 0x11, 0, 0, 0, 0, 0})).text.view(),
            "0x8130 life guard or heartbeat error");
  // Not in any table: the class text (first two hex digits).
  EXPECT_EQ(one(make_frame(0x087, {0x99, 0x42, 0x09, 0, 0, 0, 0, 0})).text.view(), "0x4299 device temperature");
  // A vendor table entry wins over the standard text of the same code.
  EXPECT_EQ(one(make_frame(0x081, {0x30, 0x81, 0x11, 0, 0, 0, 0, 0})).text.view(),
            "0x8130 F129 life guard or heartbeat error (category 0)");
}

TEST_F(EmcyConsumerTest, ShortFramesHoldingCodeAndRegisterAreAccepted) {
  const auto r = one(make_frame(0x085, {0x00, 0x75, 0x10, 0x34, 0x01, 0x00, 0x00}));  // 7 bytes
  EXPECT_EQ(r.text.view(), "0x7500 communication (event 52, cause 1)");
  const auto r3 = one(make_frame(0x085, {0x10, 0x43, 0x08}));
  EXPECT_EQ(r3.text.view(), "0x4310 motor overtemperature (sensor) (event 0, cause 0)");
}

TEST_F(EmcyConsumerTest, ResetForgetsTheActiveFault) {
  one(make_frame(0x085, {0x00, 0x75, 0x10, 0x34, 0x01, 0x00, 0x00, 0x00}));
  c_.reset(kSd6);
  EXPECT_EQ(c_.active(kSd6), nullptr);
  c_.reset(99);  // not registered: nothing happens
  c_.reset(200);
  EXPECT_EQ(c_.active(99), nullptr);
  EXPECT_EQ(c_.active(200), nullptr);
}

TEST_F(EmcyConsumerTest, BadInputIsCountedAndDropped) {
  EXPECT_FALSE(c_.on_frame(make_frame(0x080, {}), at_ms(0)));  // SYNC
  EXPECT_FALSE(c_.on_frame(make_frame(0x185, {1, 2, 3}), at_ms(0)));
  EXPECT_FALSE(c_.on_frame(make_frame(0x705, {0x05}), at_ms(0)));
  CanFrame ext = make_frame(0x085, {0, 0x75, 0x10});
  ext.extended = true;
  EXPECT_FALSE(c_.on_frame(ext, at_ms(0)));
  EXPECT_EQ(c_.counters().received, 0U);

  EXPECT_TRUE(c_.on_frame(make_frame(0x0A0, {0x00, 0x75, 0x10, 0, 0, 0, 0, 0}), at_ms(0)));  // node 32
  EXPECT_EQ(c_.counters().unexpected, 1U);

  EXPECT_TRUE(c_.on_frame(make_frame(0x085, {0x00, 0x75}), at_ms(0)));  // no register
  EXPECT_TRUE(c_.on_frame(make_frame(0x085, {}), at_ms(0)));
  EXPECT_TRUE(c_.on_frame(rtr(0x085, 8), at_ms(0)));
  CanFrame dlc9 = make_frame(0x085, {0x00, 0x75, 0x10, 0x34, 0x01, 0x00, 0x00, 0x00});
  dlc9.dlc = 9;
  EXPECT_TRUE(c_.on_frame(dlc9, at_ms(0)));
  EXPECT_EQ(c_.counters().malformed, 4U);
  EXPECT_EQ(c_.counters().received, 5U);

  EXPECT_TRUE(reports(c_).empty());
  EXPECT_EQ(c_.active(kSd6), nullptr);
}

TEST_F(EmcyConsumerTest, ReportRingOverflowIsCounted) {
  for (std::size_t k = 0; k < EmcyConsumer::kReportCapacity + 6; ++k) {
    c_.on_frame(make_frame(0x085, {static_cast<std::uint8_t>(k), 0x75, 0x10, 0x34, 0x01, 0, 0, 0}), at_ms(0));
  }
  EXPECT_EQ(c_.counters().reports_dropped, 6U);
  const auto r = reports(c_);
  ASSERT_EQ(r.size(), EmcyConsumer::kReportCapacity);
  EXPECT_EQ(r.front().emcy.code, 0x7500);  // the oldest are kept
  // The active fault still follows the newest frame, reported or not.
  ASSERT_NE(c_.active(kSd6), nullptr);
  EXPECT_EQ(c_.active(kSd6)->emcy.code, 0x7500 + EmcyConsumer::kReportCapacity + 5);
}

TEST(EmcyText, LongVendorTextIsCutVisibly) {
  static const std::string long_text(300, 'x');
  const std::array texts{cia402::FaultText{0x1000, long_text}};
  const std::array fields{EmcyField{3, "event"}};
  const std::array table{EmcyNodeConfig{5, texts, fields, true}};
  EmcyConsumer c(table);
  ASSERT_TRUE(c.on_frame(make_frame(0x085, {0x00, 0x10, 0x01, 0x30, 0, 0, 0, 0}), at_ms(0)));
  EmcyReport r;
  ASSERT_TRUE(c.next_report(r));
  EXPECT_EQ(r.text.size(), decltype(r.text)::capacity());
  EXPECT_TRUE(r.text.view().starts_with("0x1000 xxx"));
  EXPECT_TRUE(r.text.view().ends_with("..."));
}

TEST(EmcyConstruction, RejectsBadTables) {
  const std::array bad_byte{EmcyField{2, "register"}};
  const std::array t1{EmcyNodeConfig{5, {}, bad_byte, true}};
  EXPECT_THROW(EmcyConsumer{t1}, std::invalid_argument);
  const std::array bad_byte8{EmcyField{8, "beyond"}};
  const std::array t2{EmcyNodeConfig{5, {}, bad_byte8, true}};
  EXPECT_THROW(EmcyConsumer{t2}, std::invalid_argument);
  const std::array t3{EmcyNodeConfig{0, {}, {}, true}};
  EXPECT_THROW(EmcyConsumer{t3}, std::invalid_argument);
  const std::array t4{EmcyNodeConfig{5, {}, {}, true}, EmcyNodeConfig{5, {}, {}, true}};
  EXPECT_THROW(EmcyConsumer{t4}, std::invalid_argument);
}

}  // namespace
}  // namespace drivegate::canopen::test
