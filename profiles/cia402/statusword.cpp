#include "profiles/cia402/statusword.hpp"

namespace drivegate::cia402 {

// Bits 6, 5, 3, 2, 1, 0 select the state; two masks are needed because bit 5 (quick stop) is
// "don't care" in some states [AKD digest §1 table "Statusword decoding"].
core::AxisState decode_state(std::uint16_t statusword) noexcept {
  using core::AxisState;
  switch (statusword & 0x4FU) {
    case 0x00: return AxisState::NotReadyToSwitchOn;
    case 0x40: return AxisState::SwitchOnDisabled;
    case 0x0F: return AxisState::FaultReactionActive;
    case 0x08: return AxisState::Fault;
    default: break;
  }
  switch (statusword & 0x6FU) {
    case 0x21: return AxisState::ReadyToSwitchOn;
    case 0x23: return AxisState::SwitchedOn;
    case 0x27: return AxisState::OperationEnabled;
    case 0x07: return AxisState::QuickStopActive;
    default: break;
  }
  // A pattern the standard does not define: say so rather than guess a state.
  return AxisState::Unknown;
}

StatusFlags decode_flags(std::uint16_t statusword) noexcept {
  const auto has = [statusword](std::uint16_t bit) { return (statusword & bit) != 0; };
  StatusFlags f;
  f.voltage_enabled = has(sw::kVoltageEnabled);
  f.warning = has(sw::kWarning);
  f.remote = has(sw::kRemote);
  f.target_reached = has(sw::kTargetReached);
  f.internal_limit = has(sw::kInternalLimit);
  f.bit12 = has(sw::kModeBit12);
  f.bit13 = has(sw::kModeBit13);
  return f;
}

}  // namespace drivegate::cia402
