#pragma once
// Shared test fixture: a Cia402Master over FakeObjectAccess, virtual time in 1 ms cycles, and a
// sink that records every reply and event (tests/support/recording_sink.hpp).
#include <chrono>
#include <string>
#include <vector>

#include "core/axis_controller.hpp"
#include "profiles/cia402/cia402_master.hpp"
#include "profiles/cia402/objects.hpp"
#include "tests/cia402/fake_object_access.hpp"
#include "tests/support/recording_sink.hpp"

namespace drivegate::cia402::test {

using namespace std::chrono_literals;

using drivegate::test::RecordingSink;

// Statuswords as the AKD digest shows them (bit 9 remote set).
inline constexpr std::uint16_t kSwSwitchOnDisabled = 0x0240;
inline constexpr std::uint16_t kSwReady = 0x0221;
inline constexpr std::uint16_t kSwSwitchedOn = 0x0233;
inline constexpr std::uint16_t kSwEnabled = 0x0237;
inline constexpr std::uint16_t kSwEnabledReached = 0x0637;
inline constexpr std::uint16_t kSwEnabledAck = 0x1237;
inline constexpr std::uint16_t kSwHomed = 0x1637;
inline constexpr std::uint16_t kSwQuickStop = 0x0217;
inline constexpr std::uint16_t kSwFault = 0x0218;

inline core::DriveCommand command(core::CommandId id, core::CommandKind kind, core::Mode mode = core::Mode::None) {
  core::DriveCommand c;
  c.id = id;
  c.kind = kind;
  c.mode = mode;
  return c;
}

struct Harness {
  FakeObjectAccess io;
  MasterSettings settings;
  Cia402Master master;
  RecordingSink sink;
  core::TimePoint now{};

  explicit Harness(MasterSettings s = MasterSettings{}) : settings(s), master(io, settings) {
    for (const ObjectDef* d : {&obj::kControlword, &obj::kStatusword, &obj::kModesOfOperation, &obj::kModesOfOperationDisplay,
                               &obj::kPositionActual, &obj::kVelocityActual, &obj::kTorqueActual, &obj::kTargetPosition,
                               &obj::kProfileVelocity, &obj::kTargetVelocity, &obj::kTargetTorque, &obj::kErrorCode}) {
      io.map(d->id);
    }
    io.set(obj::kModesOfOperationDisplay.id, op_mode::kProfilePosition);
  }

  // One cycle with the drive reporting `sw`; returns the controlword the master sends.
  std::uint16_t cycle(std::uint16_t sw) {
    io.set(obj::kStatusword.id, sw);
    master.update(now, sink);
    now += 1ms;
    return cw();
  }
  [[nodiscard]] std::uint16_t cw() const { return static_cast<std::uint16_t>(io.value(obj::kControlword.id)); }
  core::Admission submit(const core::DriveCommand& c) { return master.submit(c, now, sink); }
  void set_mode_display(std::int8_t m) { io.set(obj::kModesOfOperationDisplay.id, m); }

  // Bring the axis to Operation enabled through the enable walk (command id 1).
  void enable() {
    cycle(kSwSwitchOnDisabled);
    (void)submit(command(1, core::CommandKind::Enable));
    cycle(kSwSwitchOnDisabled);
    cycle(kSwReady);
    cycle(kSwSwitchedOn);
    cycle(kSwEnabled);
  }
};

}  // namespace drivegate::cia402::test
