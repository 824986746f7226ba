#pragma once
// Device control [CiA 402 §6.3; AKD digest §3.1-3.2, §3.7; NORD digest §3.2]: produces controlword
// bits 0..3 and 7 that walk the drive towards a goal, ONE legal transition per cycle, with a timeout
// per step. It decides from the state decoded from the latest statusword and never skips a state.
#include <cstdint>

#include "core/axis_types.hpp"
#include "core/clock.hpp"
#include "core/command.hpp"

namespace drivegate::cia402 {

enum class DeviceGoal : std::uint8_t {
  Hold,        // keep sending the present controlword (no walk in progress)
  Enable,      // to Operation enabled
  Disable,     // to Switch on disabled via Disable voltage (0x0000)
  QuickStop,   // Quick stop (0x0002): transition 11 from Operation enabled, 7/10 otherwise
  FaultReset,  // 0->1 edge on bit 7, bit 7 cleared again once the drive left Fault
};

enum class DeviceProgress : std::uint8_t { Idle, Running, Done, Failed };

class DeviceControl {
 public:
  explicit DeviceControl(core::Duration step_timeout) noexcept : step_timeout_(step_timeout) {}

  // Start walking towards `goal`; a walk in progress is replaced.
  void start(DeviceGoal goal, core::AxisState state, core::TimePoint now) noexcept;
  // One cycle with the freshly decoded drive state. Done/Failed are reported once, then Idle.
  DeviceProgress step(core::AxisState state, core::TimePoint now) noexcept;
  // Stop any walk and hold `controlword` (e.g. 0x0000 after the drive dropped out on its own).
  void hold(std::uint16_t controlword) noexcept;
  // Forget everything (link lost): controlword 0, no walk.
  void reset() noexcept { hold(0); }

  [[nodiscard]] DeviceGoal goal() const noexcept { return goal_; }
  [[nodiscard]] std::uint16_t controlword() const noexcept { return cw_; }
  // Why the last walk failed, in words.
  [[nodiscard]] const core::Text& failure() const noexcept { return failure_; }

 private:
  DeviceProgress step_enable(core::AxisState state, core::TimePoint now) noexcept;
  DeviceProgress step_fault_reset(core::AxisState state, core::TimePoint now) noexcept;
  DeviceProgress finish(std::uint16_t hold_cw) noexcept;
  DeviceProgress fail_timeout(core::AxisState state) noexcept;
  void note_progress(core::AxisState state, core::TimePoint now) noexcept;

  core::Duration step_timeout_;
  DeviceGoal goal_ = DeviceGoal::Hold;
  std::uint16_t cw_ = 0;
  core::AxisState step_state_ = core::AxisState::Unknown;  // state the present step started from
  core::TimePoint step_since_{};
  bool reset_edge_sent_ = false;
  core::Text failure_;
};

}  // namespace drivegate::cia402
