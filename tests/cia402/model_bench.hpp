#pragma once
// Shared test fixture: the master against the simulated drive (profiles/cia402/sim) through
// DirectObjectAccess, with virtual time: begin_cycle(); master.update(); end_cycle(); step(1 ms).
#include <gtest/gtest.h>

#include <array>
#include <span>
#include <utility>

#include "profiles/cia402/sim/direct_access.hpp"
#include "profiles/cia402/sim/drive_model.hpp"
#include "tests/cia402/master_harness.hpp"

namespace drivegate::cia402::test {

inline constexpr std::array kModelMap = {
    obj::kControlword.id,    obj::kStatusword.id,     obj::kModesOfOperation.id, obj::kModesOfOperationDisplay.id,
    obj::kPositionActual.id, obj::kVelocityActual.id, obj::kTorqueActual.id,     obj::kTargetPosition.id,
    obj::kProfileVelocity.id, obj::kTargetVelocity.id, obj::kTargetTorque.id,     obj::kErrorCode.id};

inline sim::DriveModelConfig model_config() {
  sim::DriveModelConfig c;
  c.negative_limit_position = -5000.0;
  c.positive_limit_position = 200000.0;
  return c;
}

struct ModelBench {
  sim::DriveModel model;
  sim::DirectObjectAccess io;
  Cia402Master master;
  RecordingSink sink;
  core::TimePoint now{};

  explicit ModelBench(std::span<const ObjectId> map = kModelMap, sim::DriveModelConfig config = model_config(),
                      MasterSettings settings = MasterSettings{})
      : model(std::move(config)), io(model, map, 2), master(io, settings) {}

  void cycle() {
    io.begin_cycle();
    master.update(now, sink);
    io.end_cycle();
    model.step(1ms);
    now += 1ms;
  }
  void cycles(int n) {
    for (int i = 0; i < n; ++i) cycle();
  }
  // Cycles until `id` completed or failed; false on timeout or failure.
  bool run(core::CommandId id, int max_cycles) {
    for (int i = 0; i < max_cycles; ++i) {
      cycle();
      if (sink.done(id)) return true;
      if (!sink.failure(id).empty()) {
        ADD_FAILURE() << "command " << id << " failed: " << sink.failure(id);
        return false;
      }
    }
    ADD_FAILURE() << "command " << id << " did not finish within " << max_cycles << " cycles";
    return false;
  }
  bool submit(const core::DriveCommand& c) {
    const auto a = master.submit(c, now, sink);
    EXPECT_TRUE(a.accepted) << a.reason.view();
    return a.accepted;
  }
  void boot() { cycles(20); }  // not ready -> switch on disabled
  void enable(core::CommandId id = 1) {
    boot();
    ASSERT_TRUE(submit(command(id, core::CommandKind::Enable)));
    ASSERT_TRUE(run(id, 100));
    ASSERT_EQ(model.state(), sim::DriveState::OperationEnabled);
  }
};

}  // namespace drivegate::cia402::test
