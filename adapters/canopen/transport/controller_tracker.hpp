#pragma once
// The controller's fault confinement state as error reports move it, with the counters that go
// with it. Shared by the SocketCAN transport (kernel error frames) and the in-process bus
// (emulated bus-off), so both count the same way.
#include <atomic>
#include <optional>

#include "adapters/canopen/transport/counter_cells.hpp"
#include "adapters/canopen/transport/transport.hpp"

namespace drivegate::canopen {

// What one error report says: the state the controller is in now (if it says), and whether the
// controller was restarted after bus-off.
struct ErrorFrameEffect {
  std::optional<ControllerState> state;
  bool restarted = false;
};

class ControllerTracker {
 public:
  // Counts the report as an error frame, follows the state, and counts entering bus-off and
  // leaving it (a restart: reported as such, or seen as a state other than bus-off).
  void report(const ErrorFrameEffect& e, CounterCells& counters) noexcept {
    counters.error_frames.add();
    const auto before = state();
    const auto after = e.state.value_or(before);
    if (after == ControllerState::BusOff && before != ControllerState::BusOff) counters.bus_off.add();
    if (e.restarted || (before == ControllerState::BusOff && after != ControllerState::BusOff)) {
      counters.restarts.add();
    }
    state_.store(after, std::memory_order_relaxed);
  }
  // A fresh start (open()): the controller begins error active.
  void reset() noexcept { state_.store(ControllerState::Active, std::memory_order_relaxed); }
  [[nodiscard]] ControllerState state() const noexcept { return state_.load(std::memory_order_relaxed); }

 private:
  std::atomic<ControllerState> state_{ControllerState::Active};
};

}  // namespace drivegate::canopen
