#include "profiles/cia402/statusword.hpp"

#include <gtest/gtest.h>

#include "profiles/cia402/controlword.hpp"

namespace drivegate::cia402 {
namespace {

using core::AxisState;

struct Row {
  std::uint16_t sw;
  AxisState state;
};

TEST(Statusword, DecodesTheManualsExamplesAndEveryState) {
  // AKD digest §1 / §12.2 / §12.7 / §12.8 example values, then one synthetic word per state.
  const Row rows[] = {
      {0x0240, AxisState::SwitchOnDisabled}, {0x0221, AxisState::ReadyToSwitchOn},
      {0x0231, AxisState::ReadyToSwitchOn},  {0x0233, AxisState::SwitchedOn},
      {0x0237, AxisState::OperationEnabled}, {0x0637, AxisState::OperationEnabled},
      {0x1237, AxisState::OperationEnabled}, {0x1637, AxisState::OperationEnabled},
      {0x0000, AxisState::NotReadyToSwitchOn}, {0x0020, AxisState::NotReadyToSwitchOn},
      {0x0060, AxisState::SwitchOnDisabled}, {0x0007, AxisState::QuickStopActive},
      {0x0217, AxisState::QuickStopActive},  {0x000F, AxisState::FaultReactionActive},
      {0x002F, AxisState::FaultReactionActive}, {0x0008, AxisState::Fault},
      {0x0228, AxisState::Fault},
  };
  for (const auto& r : rows) {
    EXPECT_EQ(decode_state(r.sw), r.state) << "statusword 0x" << std::hex << r.sw;
  }
}

TEST(Statusword, UndefinedPatternsAreUnknownNotAGuess) {
  EXPECT_EQ(decode_state(0x0001), AxisState::Unknown);  // ready bit without quick-stop bit
  EXPECT_EQ(decode_state(0x0048), AxisState::Unknown);  // switch on disabled and fault together
  EXPECT_EQ(decode_state(0x0003), AxisState::Unknown);
}

TEST(Statusword, Flags) {
  const StatusFlags f = decode_flags(0x3E97);
  EXPECT_TRUE(f.voltage_enabled);
  EXPECT_TRUE(f.warning);
  EXPECT_TRUE(f.remote);
  EXPECT_TRUE(f.target_reached);
  EXPECT_TRUE(f.internal_limit);
  EXPECT_TRUE(f.bit12);
  EXPECT_TRUE(f.bit13);
  const StatusFlags none = decode_flags(0x0027);
  EXPECT_FALSE(none.voltage_enabled || none.warning || none.remote || none.target_reached || none.internal_limit ||
               none.bit12 || none.bit13);
}

TEST(Controlword, CommandValuesMatchTheManual) {
  // AKD digest §1 controlword table.
  EXPECT_EQ(cw::kShutdown, 0x0006);
  EXPECT_EQ(cw::kSwitchOn, 0x0007);
  EXPECT_EQ(cw::kEnableOperation, 0x000F);
  EXPECT_EQ(cw::kDisableVoltage, 0x0000);
  EXPECT_EQ(cw::kQuickStop, 0x0002);
  EXPECT_EQ(cw::kFaultReset, 0x0080);
  EXPECT_EQ(cw::kEnableOperation | cw::kHalt, 0x010F);
  EXPECT_EQ(cw::kEnableOperation | cw::kNewSetpoint, 0x001F);
  EXPECT_EQ(cw::kEnableOperation | cw::kVlRunBits, 0x007F);  // NORD vl [NORD digest §5.2]
  EXPECT_EQ(cw::with(0x000F, cw::kHalt, true), 0x010F);
  EXPECT_EQ(cw::with(0x010F, cw::kHalt, false), 0x000F);
}

}  // namespace
}  // namespace drivegate::cia402
