// ESC register map, FMMU/SM entries, AL state and AL status codes. Vectors derived from the ESC
// register layout [ETG.1000.4 Table 56 FMMU, Table 59 SyncManager] and the AL status code table
// [ETG.1000.6 §5.3.2 Table 11].
#include <gtest/gtest.h>

#include <vector>

#include "adapters/ethercat/wire/al_status.hpp"
#include "adapters/ethercat/wire/registers.hpp"

namespace drivegate::ethercat {
namespace {

using Bytes = std::vector<std::uint8_t>;
template <std::size_t N>
Bytes v(const std::array<std::uint8_t, N>& a) {
  return {a.begin(), a.end()};
}

TEST(EcatRegisters, Addresses) {
  // The addresses the brief and the digest (§5 "AL register background", §8.2) name.
  EXPECT_EQ(reg::kStationAddress, 0x0010);
  EXPECT_EQ(reg::kStationAlias, 0x0012);
  EXPECT_EQ(reg::kDlControl, 0x0100);
  EXPECT_EQ(reg::kDlStatus, 0x0110);
  EXPECT_EQ(reg::kAlControl, 0x0120);
  EXPECT_EQ(reg::kAlStatus, 0x0130);
  EXPECT_EQ(reg::kAlStatusCode, 0x0134);
  EXPECT_EQ(reg::kPdiControl, 0x0140);
  EXPECT_EQ(reg::kWatchdogDivider, 0x0400);
  EXPECT_EQ(reg::kWatchdogTimePdi, 0x0410);
  EXPECT_EQ(reg::kWatchdogTimeProcessData, 0x0420);
  EXPECT_EQ(reg::kWatchdogStatusProcessData, 0x0440);
  EXPECT_EQ(reg::kSiiControl, 0x0502);
  EXPECT_EQ(reg::fmmu(0), 0x0600);
  EXPECT_EQ(reg::fmmu(2), 0x0620);
  EXPECT_EQ(reg::sm(0), 0x0800);
  EXPECT_EQ(reg::sm(3), 0x0818);
  EXPECT_EQ(reg::kDcSystemTime, 0x0910);
  EXPECT_EQ(reg::kDcReceiveTimeProcessingUnit, 0x0918);
  EXPECT_EQ(reg::kDcSystemTimeOffset, 0x0920);
  EXPECT_EQ(reg::kDcSystemTimeDelay, 0x0928);
  EXPECT_EQ(reg::kDcSystemTimeDifference, 0x092C);
  EXPECT_EQ(reg::kDcSpeedCounterStart, 0x0930);
  EXPECT_EQ(reg::kDcCyclicUnitControl, 0x0980);
  EXPECT_EQ(reg::kDcActivation, 0x0981);
  EXPECT_EQ(reg::kDcSync0StartTime, 0x0990);
  EXPECT_EQ(reg::kDcSync0CycleTime, 0x09A0);
  EXPECT_EQ(reg::kDcSync1CycleTime, 0x09A4);
}

// FMMU 0 mapping 6 output bytes at logical 0x00010000 onto SM2 at 0x1100, bits 0..7, write.
TEST(EcatRegisters, FmmuEntryBytes) {
  FmmuEntry f;
  f.logical_start = 0x00010000;
  f.length = 6;
  f.logical_start_bit = 0;
  f.logical_stop_bit = 7;
  f.physical_start = 0x1100;
  f.physical_start_bit = 0;
  f.type = fmmu_type::kWrite;
  f.active = true;
  const Bytes expected{0x00, 0x00, 0x01, 0x00, 0x06, 0x00, 0x00, 0x07, 0x00, 0x11, 0x00, 0x02, 0x01, 0x00, 0x00, 0x00};
  EXPECT_EQ(v(encode_fmmu(f)), expected);
  const auto d = decode_fmmu(expected);
  ASSERT_TRUE(d.has_value());
  EXPECT_EQ(*d, f);
  EXPECT_FALSE(decode_fmmu(std::span<const std::uint8_t>(expected).first(15)).has_value());
  // Reserved bits are masked, not trusted.
  Bytes noisy = expected;
  noisy[6] = 0xF8;
  noisy[12] = 0xFE;
  const auto n = decode_fmmu(noisy);
  ASSERT_TRUE(n.has_value());
  EXPECT_EQ(n->logical_start_bit, 0);
  EXPECT_FALSE(n->active);
}

// SM2 outputs at 0x1100, 6 bytes, control 64h (buffered, ECAT writes, AL event, watchdog), enabled: the
// digest §8.2 "typical 0x64".
TEST(EcatRegisters, SmEntryBytes) {
  SmEntry s;
  s.physical_start = 0x1100;
  s.length = 6;
  s.control = sm_control::kOutputs;
  s.activate = sm_activate::kEnable;
  const Bytes expected{0x00, 0x11, 0x06, 0x00, 0x64, 0x00, 0x01, 0x00};
  EXPECT_EQ(v(encode_sm(s)), expected);
  const auto d = decode_sm(expected);
  ASSERT_TRUE(d.has_value());
  EXPECT_EQ(*d, s);
  EXPECT_TRUE(d->enabled());
  EXPECT_EQ(sm_control::kOutputs, sm_control::kModeBuffered | sm_control::kDirectionWrite | sm_control::kAlEventIrq |
                                      sm_control::kWatchdogTrigger);
  EXPECT_EQ(sm_control::kMailboxOut, sm_control::kModeMailbox | sm_control::kDirectionWrite | sm_control::kAlEventIrq);
  EXPECT_FALSE(decode_sm(std::span<const std::uint8_t>(expected).first(7)).has_value());
}

TEST(EcatRegisters, AlStates) {
  EXPECT_EQ(to_string(AlState::Init), "INIT");
  EXPECT_EQ(to_string(AlState::PreOp), "PRE-OP");
  EXPECT_EQ(to_string(AlState::Boot), "BOOT");
  EXPECT_EQ(to_string(AlState::SafeOp), "SAFE-OP");
  EXPECT_EQ(to_string(AlState::Op), "OP");
  EXPECT_EQ(to_string(static_cast<AlState>(5)), "unknown");
  // AL status 0x0014: SAFE-OP with the error indicator (digest §5 "0x0130 bit 4").
  const AlStatus s = decode_al_status(0x0014);
  EXPECT_EQ(s.state(), AlState::SafeOp);
  EXPECT_TRUE(s.error);
  EXPECT_FALSE(s.identification);
  EXPECT_EQ(decode_al_status(0x0028).state(), AlState::Op);
  EXPECT_TRUE(decode_al_status(0x0028).identification);
  EXPECT_EQ(decode_al_status(0x0007).state(), AlState::None);
  EXPECT_EQ(decode_al_status(0x0007).raw_state, 7);
  // AL control: request PRE-OP and acknowledge the error: 0x12.
  EXPECT_EQ(al_control(AlState::PreOp, true), 0x0012);
  EXPECT_EQ(al_control(AlState::Op), 0x0008);
}

TEST(EcatRegisters, SystemTimeDifference) {
  EXPECT_EQ(decode_system_time_difference(0x00000010), 16);
  EXPECT_EQ(decode_system_time_difference(0x80000010), -16);
  EXPECT_EQ(decode_system_time_difference(0x7FFFFFFF), 0x7FFFFFFF);
}

// Texts of the AL status code table [ETG.1000.6 Table 11].
TEST(EcatAlStatus, Texts) {
  EXPECT_EQ(al_status_text(0x0000), "no error");
  EXPECT_EQ(al_status_text(0x0011), "invalid requested state change");
  EXPECT_EQ(al_status_text(0x0017), "invalid sync manager configuration");
  EXPECT_EQ(al_status_text(0x001B), "sync manager watchdog");
  EXPECT_EQ(al_status_text(0x001D), "invalid output configuration");
  EXPECT_EQ(al_status_text(0x001E), "invalid input configuration");
  EXPECT_EQ(al_status_text(0x0035), "invalid sync cycle time");
  EXPECT_EQ(al_status_text(0x0030), "invalid DC SYNC configuration");
  EXPECT_EQ(al_status_text(0x0051), "EEPROM error");
  EXPECT_EQ(al_status_text(0x00F0), "application controller available");
  EXPECT_EQ(al_status_text(0x8000), "vendor specific");
  EXPECT_EQ(al_status_text(0xFFFF), "vendor specific");
  EXPECT_EQ(al_status_text(0x0008), "reserved");
  EXPECT_EQ(al_status_text(0x7FFF), "reserved");
  // 002Eh as the ETG slave stack code defines it now; 0080h..0083h are in its table; 0005h is not.
  EXPECT_EQ(al_status_text(0x002E), "cycle time smaller than the minimum cycle time the slave supports");
  EXPECT_EQ(al_status_text(0x0083), "temperature too high");
  EXPECT_FALSE(al_status_known(0x0005));
  EXPECT_TRUE(al_status_known(0x001B));
  EXPECT_FALSE(al_status_known(0x8001));
  // Every code from 0x0000 to 0x0070 has a text (table, or "reserved").
  for (std::uint16_t c = 0; c <= 0x70; ++c) EXPECT_FALSE(al_status_text(c).empty());
}

}  // namespace
}  // namespace drivegate::ethercat
