// CPU per cycle of the simulated AKD PROFIdrive drive (profiles/profidrive/sim), as the PROFINET
// simulated device will run it: DriveModel::step on a setpoint image, for a drive idle in S1, running
// in speed mode (telegram 1) and running MDI tasks back and forth (telegram 9), and the cost of one
// record-47 exchange (a PNU 947 read of 64 entries; a PNU 930 change). Heap allocations in the
// measured regions are counted (they must be 0). Thread CPU time, median of 15 blocks.
//
//   bench_profidrive_sim_step [STEPS_PER_BLOCK]   (default 20000)
#include <time.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <vector>

#include "profiles/profidrive/control_words.hpp"
#include "profiles/profidrive/scaling.hpp"
#include "profiles/profidrive/sim/drive_model.hpp"
#include "profiles/profidrive/telegram.hpp"
#include "tests/support/alloc_counter.hpp"

namespace {

using namespace drivegate::profidrive;
using namespace drivegate::profidrive::sim;
using namespace std::chrono_literals;

double thread_ns() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e9 + static_cast<double>(ts.tv_nsec);
}

struct Figure {
  double ns_per_op = 0;
  std::size_t allocations = 0;
};

// Median over blocks of `ops` calls of `op`.
Figure measure(int ops, const std::function<void()>& op) {
  std::vector<double> blocks;
  blocks.reserve(15);
  std::size_t allocations = 0;
  for (int b = 0; b < 15; ++b) {
    const drivegate::test::AllocationScope scope;
    const double t0 = thread_ns();
    for (int i = 0; i < ops; ++i) op();
    const double t1 = thread_ns();
    allocations += scope.count();
    blocks.push_back((t1 - t0) / ops);
  }
  std::nth_element(blocks.begin(), blocks.begin() + 7, blocks.end());
  return {blocks[7], allocations};
}

class Drive {
 public:
  explicit Drive(std::uint16_t telegram) : drive_(config(telegram)) {}
  void step(const Setpoints& sp) {
    (void)encode_setpoints(drive_.layout(), sp, std::span(out_).first(drive_.layout().setpoint_bytes()));
    drive_.step(16ms, std::span(out_).first(drive_.layout().setpoint_bytes()),
                std::span(in_).first(drive_.layout().actual_bytes()));
  }
  DriveModel& model() { return drive_; }

 private:
  static DriveModelConfig config(std::uint16_t telegram) {
    DriveModelConfig c;
    c.telegram = telegram;
    return c;
  }
  DriveModel drive_;
  std::array<std::uint8_t, 64> out_{};
  std::array<std::uint8_t, 64> in_{};
};

void print(const char* what, const Figure& f) {
  std::printf("%-44s %10.0f ns %12zu allocations\n", what, f.ns_per_op, f.allocations);
}

}  // namespace

int main(int argc, char** argv) {
  const int steps = argc > 1 ? std::max(1, std::atoi(argv[1])) : 20000;
  std::printf("simulated AKD PROFIdrive drive, 16 ms cycles, %d steps per block, median of 15 blocks\n", steps);

  Drive idle(1);
  Setpoints off;
  off.stw1 = stw1_word::kIdle;
  print("step, telegram 1, S1", measure(steps, [&] { idle.step(off); }));

  Drive speed(1);
  Setpoints run;
  for (const std::uint16_t w : {stw1_word::kIdle, stw1_word::kShutdown, stw1_word::kSwitchOn, stw1_word::kSpeedRun}) {
    run.stw1 = w;
    speed.step(run);
  }
  run.nsoll_a = nsoll_from_rpm(3000.0).value_or(0);
  print("step, telegram 1, S4 at 3000 rpm", measure(steps, [&] { speed.step(run); }));

  // MDI between 0 and 4 revolutions, a new task on every edge of bit 6 (every 64 cycles).
  Drive mdi(9);
  Setpoints sp;
  for (const std::uint16_t w : {stw1_word::kIdle, stw1_word::kShutdown, stw1_word::kSwitchOn,
                                stw1_word::kEnableOperation, stw1_word::kHoming, stw1_word::kHoming,
                                stw1_word::kEnableOperation}) {
    sp.stw1 = w;
    mdi.step(sp);
  }
  sp.satzanw = 0x8000;
  sp.mdi_velocity = mdi_velocity_from_rpm(1200.0).value_or(0);
  sp.mdi_acc = sp.mdi_dec = mdi_acc_from_rpm_per_s(20000.0).value_or(0);
  sp.mdi_mod = 1;
  std::uint32_t n = 0;
  print("step, telegram 9, S4 running MDI tasks", measure(steps, [&] {
          const std::uint32_t phase = n++ % 64;
          sp.stw1 = phase < 32 ? stw1_word::kTaskActivate : stw1_word::kTaskReady;
          sp.mdi_tarpos = (n / 64) % 2 == 0 ? 4 * 65536 : 0;
          mdi.step(sp);
        }));
  if (!mdi.model().homed()) std::printf("  (the MDI drive did not home: figure not meaningful)\n");

  const std::array<std::uint8_t, 10> read947{0x08, 0x01, 0x00, 0x01, 0x10, 0x40, 0x03, 0xB3, 0x00, 0x00};
  const std::array<std::uint8_t, 14> write930{0x05, 0x02, 0x00, 0x01, 0x10, 0x01, 0x03, 0xA2, 0x00, 0x00, 0x42, 0x01, 0x00, 0x02};
  std::array<std::uint8_t, kMaxParamRecord> response{};
  DriveModel& model = idle.model();
  print("record 47: PNU 947 x 64 read, write + read", measure(steps, [&] {
          (void)model.write_parameter_record(read947);
          (void)model.read_parameter_record(response);
        }));
  print("record 47: PNU 930 change, write + read", measure(steps, [&] {
          (void)model.write_parameter_record(write930);
          (void)model.read_parameter_record(response);
        }));
  return 0;
}
