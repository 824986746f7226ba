#pragma once
// Drives a DriveModel with raw controlwords in virtual time (1 ms steps).
#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <functional>
#include <utility>

#include "profiles/cia402/sim/drive_model.hpp"

namespace drivegate::cia402::sim::test {

inline constexpr core::Duration kStep = std::chrono::milliseconds(1);

// Status patterns for the state bits [AKD digest §1].
inline bool sw_is(std::uint16_t sw, std::uint16_t mask, std::uint16_t value) { return (sw & mask) == value; }

class DriveHarness {
 public:
  explicit DriveHarness(DriveModelConfig config = {}) : drive(std::move(config)) {}

  void set(ObjectDef def, std::int64_t value) {
    ASSERT_EQ(drive.write_object(def.id, value), 0U) << std::hex << def.id.index << ":" << int{def.id.sub};
  }
  [[nodiscard]] std::int64_t get(ObjectDef def) const { return drive.dictionary().get(def.id).value_or(-999999); }
  void cw(std::uint16_t value) { set(obj::kControlword, value); }
  void step(int n = 1) {
    for (int i = 0; i < n; ++i) drive.step(kStep);
  }
  // Steps until pred() holds; returns the number of steps taken or -1 after max_steps.
  int run_until(const std::function<bool()>& pred, int max_steps = 20000) {
    for (int i = 0; i < max_steps; ++i) {
      if (pred()) return i;
      drive.step(kStep);
    }
    return pred() ? max_steps : -1;
  }
  [[nodiscard]] std::uint16_t sw() const { return drive.statusword(); }
  [[nodiscard]] DriveState state() const { return drive.state(); }

  // Boot, select a mode and walk 0x06 -> 0x07 -> 0x0F into Operation enabled.
  void enable(std::int8_t mode) {
    set(obj::kModesOfOperation, mode);
    step();  // Not ready -> Switch on disabled, mode taken
    cw(0x0006);
    step();
    cw(0x0007);
    step();
    cw(0x000F);
    step();
    ASSERT_EQ(state(), DriveState::OperationEnabled);
    ASSERT_EQ(get(obj::kModesOfOperationDisplay), mode);
  }

  DriveModel drive;
};

}  // namespace drivegate::cia402::sim::test
