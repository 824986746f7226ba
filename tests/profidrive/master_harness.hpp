#pragma once
// Test fixture: a ProfidriveMaster over a ScriptedDrive, virtual time in 1 ms cycles, a sink that
// records every reply and event, and command builders in drive units.
#include <chrono>
#include <cstdint>
#include <functional>

#include "profiles/profidrive/profidrive_master.hpp"
#include "tests/profidrive/scripted_drive.hpp"
#include "tests/support/recording_sink.hpp"

namespace drivegate::profidrive::test {

using namespace std::chrono_literals;
using core::CommandKind;
using drivegate::test::RecordingSink;

inline core::DriveCommand command(core::CommandId id, CommandKind kind, core::Mode mode = core::Mode::None) {
  core::DriveCommand c;
  c.id = id;
  c.kind = kind;
  c.mode = mode;
  return c;
}
inline core::DriveCommand velocity(core::CommandId id, std::int32_t v) {
  core::DriveCommand c = command(id, CommandKind::Velocity, core::Mode::ProfileVelocity);
  c.target_velocity = v;
  c.profile_acceleration = 100;
  c.profile_deceleration = 200;
  return c;
}
// 1 rev/s (60 rpm) in the native velocity unit, 2^31 = 12000 rpm (scaling.hpp).
inline constexpr std::int32_t kOneRps = 10737418;
inline core::DriveCommand move(core::CommandId id, std::int32_t target, bool relative = false) {
  core::DriveCommand c = command(id, CommandKind::Move, core::Mode::ProfilePosition);
  c.target_position = target;
  c.profile_velocity = static_cast<std::uint32_t>(kOneRps);
  c.profile_acceleration = 100;
  c.profile_deceleration = 200;
  c.relative = relative;
  return c;
}
inline core::DriveCommand home(core::CommandId id, std::int8_t method = 0, std::int32_t offset = 0) {
  core::DriveCommand c = command(id, CommandKind::Home, core::Mode::Homing);
  c.homing_method = method;
  c.home_offset = offset;
  return c;
}
inline core::DriveCommand run_block(core::CommandId id, std::int32_t block) {
  core::DriveCommand c = command(id, CommandKind::RunBlock, core::Mode::TraversingBlock);
  c.block = block;
  return c;
}

struct Harness {
  ScriptedDrive drive;
  MasterSettings settings;
  ProfidriveMaster master;
  RecordingSink sink;
  core::TimePoint now{};

  explicit Harness(std::uint16_t telegram, MasterSettings s = MasterSettings{})
      : drive(telegram), settings(s), master(drive, drive, drive.layout, settings) {}

  // One cycle: the drive reacts to the last setpoints, then the master runs.
  void cycle() {
    drive.step();
    master.update(now, sink);
    now += 1ms;
  }
  void run(int cycles) {
    for (int i = 0; i < cycles; ++i) cycle();
  }
  // Cycles until `done` holds (true) or `limit` cycles passed (false).
  bool run_until(const std::function<bool()>& done, int limit = 2000) {
    for (int i = 0; i < limit; ++i) {
      if (done()) return true;
      cycle();
    }
    return done();
  }
  bool finished(core::CommandId id) const { return sink.replies(id) > 0; }
  bool wait(core::CommandId id, int limit = 2000) {
    return run_until([&] { return finished(id); }, limit);
  }
  core::Admission submit(const core::DriveCommand& c) { return master.submit(c, now, sink); }
  core::Admission param(const core::ParamRequest& r) { return master.parameter(r, now); }

  // First telegram, then the enable walk (command id 1) to S4.
  void enable() {
    cycle();
    (void)submit(command(1, CommandKind::Enable));
    (void)wait(1);
  }
  // Enable and home (id 2) on a position telegram.
  void enable_and_home() {
    enable();
    (void)submit(home(2));
    (void)wait(2);
  }
};

}  // namespace drivegate::profidrive::test
