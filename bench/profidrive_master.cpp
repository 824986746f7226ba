// CPU time of ProfidriveMaster::update() per cycle, for telegrams 1 (speed), 7 (program mode), 9
// (MDI) and 353 (MDI with homing signals), the axis enabled and busy: velocity reversing, blocks or
// MDI moves back and forth, a record-47 parameter read every 100 cycles. The drive is the tests'
// scripted drive (tests/profidrive/scripted_drive.hpp), stepped outside the measured region, so the
// figure is the master's work alone. Wall time on CLOCK_MONOTONIC (the vDSO clock, tens of ns to
// read; the thread CPU clock is a system call costing more than update() itself), so other
// processes show in p99 and max on a shared machine: read p50. Heap allocations inside update()
// are counted (expected 0). Figures only; nothing is asserted.
#include <time.h>

#include <algorithm>
#include <charconv>
#include <cstdint>
#include <cstdio>
#include <initializer_list>
#include <string_view>
#include <vector>

#include "profiles/profidrive/profidrive_master.hpp"
#include "tests/profidrive/scripted_drive.hpp"
#include "tests/support/alloc_counter.hpp"

namespace drivegate::bench {
namespace {

using profidrive::test::ScriptedDrive;

struct NullSink final : core::ControllerSink {
  std::size_t replies = 0;
  void completed(core::CommandId) noexcept override { ++replies; }
  void failed(core::CommandId, std::string_view) noexcept override { ++replies; }
  void event(core::EventKind, std::uint32_t, std::string_view) noexcept override {}
  void parameter_done(const core::ParamReply&) noexcept override { ++replies; }
};

std::int64_t clock_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

core::DriveCommand command(core::CommandId id, core::CommandKind kind) {
  core::DriveCommand c;
  c.id = id;
  c.kind = kind;
  return c;
}

// The command that keeps the axis busy, alternating direction with `flip`.
core::DriveCommand busy_command(std::uint16_t telegram, core::CommandId id, bool flip) {
  core::DriveCommand c;
  c.id = id;
  switch (telegram) {
    case 1:
      c.kind = core::CommandKind::Velocity;
      c.target_velocity = flip ? -10737418 : 10737418;  // +-60 rpm
      break;
    case 7:
      c.kind = core::CommandKind::RunBlock;
      c.block = flip ? 0 : 3;
      break;
    default:
      c.kind = core::CommandKind::Move;
      c.target_position = flip ? 0 : 20000;
      c.profile_velocity = 10737418;
      c.profile_acceleration = 100;
      c.profile_deceleration = 100;
      break;
  }
  return c;
}

void run(std::uint16_t telegram, int cycles) {
  ScriptedDrive drive(telegram);
  drive.param_delay = 5;
  profidrive::ProfidriveMaster master(drive, drive, drive.layout, profidrive::MasterSettings{});
  NullSink sink;
  core::TimePoint now{};
  const auto step = [&] {
    drive.step();
    master.update(now, sink);
    now += std::chrono::milliseconds(1);
  };
  step();
  (void)master.submit(command(1, core::CommandKind::Enable), now, sink);
  for (int i = 0; i < 20; ++i) step();
  if (telegram != 1) {
    (void)master.submit(command(2, core::CommandKind::Home), now, sink);
    for (int i = 0; i < 50; ++i) step();
  }
  std::vector<std::int64_t> ns(static_cast<std::size_t>(cycles));
  core::CommandId id = 10;
  std::size_t allocations = 0;
  for (int i = 0; i < cycles; ++i) {
    if (i % 400 == 0) (void)master.submit(busy_command(telegram, id++, (i / 400) % 2 == 1), now, sink);
    if (i % 100 == 0) {
      core::ParamRequest r;
      r.id = id++;
      r.index = 1002;
      (void)master.parameter(r, now);
    }
    drive.step();
    const test::AllocationScope scope;
    const std::int64_t t0 = clock_ns();
    master.update(now, sink);
    const std::int64_t t1 = clock_ns();
    allocations += scope.count();
    ns[static_cast<std::size_t>(i)] = t1 - t0;
    now += std::chrono::milliseconds(1);
  }
  std::sort(ns.begin(), ns.end());
  const auto at = [&](double q) { return ns[static_cast<std::size_t>(q * static_cast<double>(ns.size() - 1))]; };
  std::printf("telegram %3u  cycles %7d  update() ns p50 %6lld  p99 %6lld  max %7lld  allocations %zu  replies %zu  state %s\n",
              static_cast<unsigned>(telegram), cycles, static_cast<long long>(at(0.5)), static_cast<long long>(at(0.99)),
              static_cast<long long>(ns.back()), allocations, sink.replies,
              core::to_string(master.feedback().state).data());
}

}  // namespace
}  // namespace drivegate::bench

int main(int argc, char** argv) {
  int cycles = 200'000;
  for (int i = 1; i + 1 < argc; ++i) {
    if (std::string_view(argv[i]) == "--cycles") {
      const std::string_view v(argv[i + 1]);
      if (std::from_chars(v.data(), v.data() + v.size(), cycles).ec != std::errc{} || cycles <= 0) {
        std::fprintf(stderr, "--cycles takes a positive number\n");
        return 2;
      }
    }
  }
  // What reading the clock twice costs by itself: part of every figure.
  std::vector<std::int64_t> empty(10'000);
  for (auto& e : empty) {
    const std::int64_t t0 = drivegate::bench::clock_ns();
    e = drivegate::bench::clock_ns() - t0;
  }
  std::sort(empty.begin(), empty.end());
  std::printf("clock overhead ns p50 %lld (included in the figures below)\n", static_cast<long long>(empty[empty.size() / 2]));
  for (const std::uint16_t telegram : std::initializer_list<std::uint16_t>{1, 7, 9, 353}) drivegate::bench::run(telegram, cycles);
  return 0;
}
