// The two-axis CiA 402 persona (generic-cia402-2axis) over hand-built frames: axis 1's objects at
// + 800h [ETG.6010 §4], one drive model per axis, both axes in the PDOs (1600h/1601h in 1C12h,
// 1A00h/1A01h in 1C13h), and each axis' own 6007h reaction to the SM watchdog.
#include <gtest/gtest.h>

#include <cmath>

#include "adapters/ethercat/wire/sii.hpp"
#include "core/bytes.hpp"
#include "tests/ethercat_sim/drive_line.hpp"
#include "tests/support/alloc_counter.hpp"

namespace drivegate::ethercat::sim::test {
namespace {

using core::AxisState;
using core::put_u16;

// Per axis 17 output bytes (6040h u16, 6060h i8, 6071h i16, 607Ah i32, 60FFh i32, 60C1h:01 i32)
// and 15 input bytes (6041h u16, 6061h i8, 6077h i16, 603Fh u16, 6064h i32, 606Ch i32).
constexpr std::size_t kOut = 17;
constexpr std::size_t kIn = 15;

void controlword(std::vector<std::uint8_t>& out, std::size_t axis, std::uint16_t cw) {
  put_u16(out, axis * kOut, cw);
}
std::uint16_t statusword(const Reply& in, std::size_t axis) { return in.u16(axis * kIn); }

// PRE-OP, both axes' PDOs on SM2/SM3, SAFE-OP, OP with zero outputs.
void to_op(DriveLine& l, std::vector<std::uint8_t>& out) {
  l.preop();
  l.pd_sms(2 * kOut, 2 * kIn);
  l.bus.fpwr16(l.st, reg::kWatchdogTimeProcessData, 100);  // 10 ms [ETG.1000.4 §6.7.2]
  ASSERT_EQ(l.request(AlState::SafeOp), 0x0004);
  out.assign(2 * kOut, 0);
  l.cycle(out, 2 * kIn);
  ASSERT_EQ(l.request(AlState::Op), 0x0008);
}

// Cycles until axis `axis`' statusword matches; returns the last inputs.
Reply walk(DriveLine& l, std::vector<std::uint8_t>& out, std::size_t axis, std::uint16_t cw, std::uint16_t mask,
           std::uint16_t want) {
  controlword(out, axis, cw);
  Reply in;
  for (int i = 0; i < 500; ++i) {
    in = l.cycle(out, 2 * kIn);
    if ((statusword(in, axis) & mask) == want) return in;
  }
  ADD_FAILURE() << "axis " << axis << " statusword " << std::hex << statusword(in, axis) << " after controlword " << cw;
  return in;
}

TEST(EthercatMultiAxisSlave, AxisOneObjectsSitAtPlus800h) {
  DriveLine l("generic-cia402-2axis");
  ASSERT_EQ(l.app().axes(), 2U);
  l.preop();
  // Both axes' PDOs assigned at power-on.
  EXPECT_EQ(l.upload(0x1C12, 0).value, 2U);
  EXPECT_EQ(l.upload(0x1C12, 2).value, 0x1601U);
  EXPECT_EQ(l.upload(0x1C13, 2).value, 0x1A01U);
  EXPECT_EQ(l.upload(0x1601, 1).value, 0x68400010U);
  EXPECT_EQ(l.upload(0x1A01, 1).value, 0x68410010U);
  EXPECT_EQ(l.app().output_size(), 2 * kOut);
  EXPECT_EQ(l.app().input_size(), 2 * kIn);
  // 6881h is axis 1's profile velocity; 6081h axis 0's.
  const auto axis0 = l.app().drive(0).read_object({0x6081, 0}).value;
  EXPECT_EQ(l.download(0x6881, 0, 555, 4), 0U);
  EXPECT_EQ(l.app().drive(1).read_object({0x6081, 0}).value, 555);
  EXPECT_EQ(l.app().drive(0).read_object({0x6081, 0}).value, axis0);
  EXPECT_EQ(l.upload(0x6881, 0).value, 555U);
  EXPECT_EQ(l.upload(0x6081, 0).value, static_cast<std::uint32_t>(axis0));
  // Each axis its own 6007h: 6807h for axis 1.
  EXPECT_EQ(l.upload(0x6807, 0).value, 1U);
  EXPECT_EQ(l.download(0x6807, 0, 0, 2), 0U);
  EXPECT_EQ(l.app().abort_option(1), 0);
  EXPECT_EQ(l.app().abort_option(0), 1);
  // Axis 1's entries map and have their types; nothing lies beyond the second axis.
  EXPECT_EQ(l.upload(0x6861, 0).size, 1U);
  EXPECT_EQ(l.upload(0x7041, 0).abort, cia402::sdo_abort_code::kNoObject);
  // Axis 1's mapping entries are checked as axis 0's: 6841h (statusword) is no RxPDO object.
  EXPECT_EQ(l.download(0x1601, 0, 0, 1), 0U);
  EXPECT_EQ(l.download(0x1601, 1, 0x68410010, 4), cia402::sdo_abort_code::kNotMappable);
  EXPECT_EQ(l.download(0x1601, 1, 0x68400010, 4), 0U);
  // Its SII says two CiA 402 channels [ETG.2010 general category].
  SiiInfo info;
  parse_sii(l.app().sii(), info);
  ASSERT_TRUE(info.ok());
  EXPECT_EQ(info.general.ds402_channels, 2);
  EXPECT_EQ(info.header.identity.product_code, 0x00020192U);
}

TEST(EthercatMultiAxisSlave, ProcessDataDrivesEachAxisAlone) {
  DriveLine l("generic-cia402-2axis");
  std::vector<std::uint8_t> out;
  to_op(l, out);
  if (HasFatalFailure()) return;
  // Axis 1 enabled through its own controlword; axis 0 stays switch on disabled.
  walk(l, out, 1, 0x0006, 0x006F, 0x0021);
  walk(l, out, 1, 0x0007, 0x006F, 0x0023);
  const Reply in = walk(l, out, 1, 0x000F, 0x006F, 0x0027);
  EXPECT_EQ(statusword(in, 0) & 0x004F, 0x0040);
  EXPECT_EQ(l.app().drive(1).state(), AxisState::OperationEnabled);
  EXPECT_EQ(l.app().drive(0).state(), AxisState::SwitchOnDisabled);
  // Axis 1 in pv (6860h = 3) with 60FFh + 800h: it moves, axis 0 does not.
  out[kOut + 2] = 3;
  core::put_u32(out, kOut + 9, 20000);
  const double p0 = l.app().drive(0).position();
  const double p1 = l.app().drive(1).position();
  for (int i = 0; i < 100; ++i) l.cycle(out, 2 * kIn);
  EXPECT_EQ(l.app().drive(1).active_mode(), 3);
  EXPECT_EQ(l.app().drive(0).active_mode(), 0);
  EXPECT_GT(l.app().drive(1).position() - p1, 100.0);
  EXPECT_EQ(l.app().drive(0).position(), p0);
  // 6864h in the inputs is axis 1's position.
  const Reply now = l.cycle(out, 2 * kIn);
  EXPECT_EQ(static_cast<std::int32_t>(now.u32(kIn + 7)), static_cast<std::int32_t>(std::lround(l.app().drive(1).position())));
}

// The SM watchdog: every axis runs its own 6007h; 6807h = 0 leaves axis 1 running.
TEST(EthercatMultiAxisSlave, WatchdogRunsEachAxisOwnReaction) {
  DriveLine l("generic-cia402-2axis");
  std::vector<std::uint8_t> out;
  l.preop();
  ASSERT_EQ(l.download(0x6807, 0, 0, 2), 0U);
  l.pd_sms(2 * kOut, 2 * kIn);
  l.bus.fpwr16(l.st, reg::kWatchdogTimeProcessData, 100);
  ASSERT_EQ(l.request(AlState::SafeOp), 0x0004);
  out.assign(2 * kOut, 0);
  l.cycle(out, 2 * kIn);
  ASSERT_EQ(l.request(AlState::Op), 0x0008);
  for (std::size_t axis : {0U, 1U}) {
    walk(l, out, axis, 0x0006, 0x006F, 0x0021);
    walk(l, out, axis, 0x0007, 0x006F, 0x0023);
    walk(l, out, axis, 0x000F, 0x006F, 0x0027);
  }
  for (int i = 0; i < 30; ++i) {
    l.set_time(l.now + 1'000'000);
    l.bus.line().advance(l.now);
  }
  EXPECT_EQ(l.esc().state(), AlState::SafeOp);
  EXPECT_EQ(l.al_code(), 0x001B);
  const Reply in = l.cycle({}, 2 * kIn);
  EXPECT_EQ(statusword(in, 0) & 0x004F, 0x0008);  // fault (6007h = 1)
  EXPECT_EQ(in.u16(5), 0x8100);                    // 603Fh
  EXPECT_EQ(statusword(in, 1) & 0x006F, 0x0027);  // 6807h = 0: runs on
  EXPECT_EQ(l.app().counters().comm_losses, 1U);
  l.collect_emergencies();
  ASSERT_EQ(l.emcys.size(), 1U);
}

TEST(EthercatMultiAxisSlave, NoAllocationWhileFramesPass) {
  DriveLine l("generic-cia402-2axis");
  std::vector<std::uint8_t> out;
  to_op(l, out);
  if (HasFatalFailure()) return;
  l.emcys.reserve(8);
  const drivegate::test::AllocationScope scope;
  for (int i = 0; i < 60; ++i) {
    const std::uint16_t cw = i < 10 ? 0x06 : (i < 20 ? 0x07 : 0x0F);
    controlword(out, 0, cw);
    controlword(out, 1, cw);
    l.cycle(out, 2 * kIn);
  }
  EXPECT_EQ(l.upload(0x6864, 0).abort, 0U);
  l.app().inject_fault(0x2310, 1);
  for (int i = 0; i < 10; ++i) l.cycle(out, 2 * kIn);
  l.collect_emergencies();
  EXPECT_EQ(scope.count(), 0U);
  EXPECT_EQ(l.emcys.size(), 1U);
}

}  // namespace
}  // namespace drivegate::ethercat::sim::test
