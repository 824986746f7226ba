// CPU of the simulated PROFINET IO devices (adapters/profinet/sim) per cycle, as drivegate-sim will
// run them: N AKD devices (telegram 1, 16 ms) on one PnSimNetwork, each in data exchange with the
// controller engines of tests/profinet_sim (connected on virtual time first). Measured per cycle:
// the N output frames handed to the network and its poll(), which steps every drive model and
// writes every input frame. Thread CPU time per device and cycle, median of 15 blocks; heap
// allocations in the measured regions (they must be 0).
//
//   bench_profinet_sim_device [CYCLES_PER_BLOCK]   (default 2000)
#include <time.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <vector>

#include "tests/profinet_sim/sim_bench.hpp"
#include "tests/support/alloc_counter.hpp"

namespace {

using namespace drivegate;
using namespace drivegate::profinet;
using namespace drivegate::profinet::test;

double thread_ns() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e9 + static_cast<double>(ts.tv_nsec);
}

// Counts what the devices send; keeps nothing.
class CountingWire final : public PnSimWire {
 public:
  void send_frame(std::span<const std::uint8_t>) noexcept override { ++frames; }
  void send_datagram(const UdpEndpoint&, const UdpEndpoint&, std::span<const std::uint8_t>) noexcept override {}
  std::uint64_t frames = 0;
};

struct Result {
  double ns = 0;
  std::size_t allocations = 0;
  std::uint64_t frames = 0;
  std::size_t in_data_exchange = 0;
};

Result run(std::size_t devices, int cycles) {
  SimBench bench;
  std::vector<std::unique_ptr<AkdPersona>> personas;
  std::vector<std::unique_ptr<ArPlan>> plans;
  for (std::size_t i = 0; i < devices; ++i) {
    const auto n = static_cast<std::uint8_t>(i + 1);
    personas.push_back(std::make_unique<AkdPersona>(AkdPersonaConfig{}));
    bench.net.add(device_config(n, "drive-" + std::to_string(n), suite(static_cast<std::uint8_t>(10 + n))), *personas.back());
    plans.push_back(std::make_unique<ArPlan>(akd_plan(1, 4, 4), ip_of(static_cast<std::uint8_t>(10 + n)), device_mac(n),
                                             static_cast<std::uint16_t>(i)));
    bench.start(bench.add_ar(*plans.back()));
  }
  bench.run_until([&] {
    return std::all_of(bench.ars.begin(), bench.ars.end(),
                       [](const SimBench::Ar& a) { return a.cm->state() == CmClientState::DataExchange; });
  });
  Result r;
  for (const SimBench::Ar& a : bench.ars) r.in_data_exchange += a.cm->state() == CmClientState::DataExchange ? 1U : 0U;
  for (auto& p : plans) p->provider->stop();  // the bench sends the output frames itself
  std::vector<std::array<std::uint8_t, kMaxFrameSize>> frames(devices);
  std::vector<std::size_t> sizes(devices);
  CountingWire wire;
  std::vector<double> blocks;
  core::TimePoint t = bench.now;
  for (auto& p : plans) p->provider->start(t);
  for (int b = 0; b < 15; ++b) {
    double spent = 0;
    std::size_t allocations = 0;
    for (int c = 0; c < cycles; ++c) {
      t += std::chrono::milliseconds(16);
      for (std::size_t i = 0; i < devices; ++i) sizes[i] = plans[i]->provider->poll(t, frames[i]);
      const drivegate::test::AllocationScope scope;
      const double t0 = thread_ns();
      for (std::size_t i = 0; i < devices; ++i) {
        bench.net.on_frame(std::span<const std::uint8_t>(frames[i]).first(sizes[i]), t);
      }
      bench.net.poll(t, wire);
      spent += thread_ns() - t0;
      allocations += scope.count();
    }
    r.allocations += allocations;
    blocks.push_back(spent / (static_cast<double>(cycles) * static_cast<double>(devices)));
  }
  std::nth_element(blocks.begin(), blocks.begin() + 7, blocks.end());
  r.ns = blocks[7];
  r.frames = wire.frames;
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  const int cycles = argc > 1 ? std::atoi(argv[1]) : 2000;
  if (cycles <= 0) {
    std::fprintf(stderr, "usage: bench_profinet_sim_device [CYCLES_PER_BLOCK]\n");
    return 2;
  }
  std::printf("%-8s %-18s %-14s %-12s %s\n", "devices", "in data exchange", "ns/device/cycle", "allocations",
              "input frames sent");
  for (const std::size_t n : {std::size_t{1}, std::size_t{16}, std::size_t{64}}) {
    const Result r = run(n, cycles);
    std::printf("%-8zu %-18zu %-14.0f %-12zu %llu\n", n, r.in_data_exchange, r.ns, r.allocations,
                static_cast<unsigned long long>(r.frames));
  }
  return 0;
}
