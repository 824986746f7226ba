// drivegate's side of a PROFINET bus with N simulated Kollmorgen AKDs (telegram 1, update time
// 1 ms x 16) in the same process (adapters/profinet/sim_transport): the bus cycle at 1 kHz on an
// absolute clock_nanosleep schedule (real time), BusRunner::cycle = ProfinetBus::receive -> the
// PROFIdrive master of every axis -> ProfinetBus::transmit.
//
//   time to data exchange: from open() until every device is in data exchange and every axis
//       reports its state (DCP identify window, Set IP, Connect, PrmEnd, ApplicationReady), in
//       real time at 1 ms cycles.
//   bus CPU per cycle: thread CPU time of the cycle minus the simulated devices' own step (the
//       transport's peer, timed apart); frames the bus sends are handed to the devices inside its
//       transmit(), so that part of the devices' work counts as the bus'.
//   lateness: the bus cycle's wake against a bare timer wake half a period later in the same run.
//   allocations inside the measured cycles (expected 0).
// Every axis is enabled and runs in speed mode while measured. Figures only.
//
//   bench_profinet_cycle [--devices 8,32] [--cycles 10000]
#include <time.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "adapters/profinet/profinet_bus.hpp"
#include "adapters/profinet/sim/akd_persona.hpp"
#include "adapters/profinet/sim/pn_sim_network.hpp"
#include "adapters/profinet/sim_transport.hpp"
#include "config/loader.hpp"
#include "core/bus_runner.hpp"
#include "tests/support/alloc_counter.hpp"

namespace {

using namespace drivegate;
using namespace drivegate::profinet;
using namespace std::chrono_literals;

std::int64_t clock_ns(clockid_t c) noexcept {
  timespec ts{};
  clock_gettime(c, &ts);
  return std::int64_t{ts.tv_sec} * 1'000'000'000 + ts.tv_nsec;
}
std::int64_t mono_ns() noexcept { return clock_ns(CLOCK_MONOTONIC); }
std::int64_t thread_cpu_ns() noexcept { return clock_ns(CLOCK_THREAD_CPUTIME_ID); }

void sleep_until_ns(std::int64_t t) noexcept {
  timespec ts{};
  ts.tv_sec = t / 1'000'000'000;
  ts.tv_nsec = t % 1'000'000'000;
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) != 0) {
  }
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const auto rank = static_cast<std::size_t>(std::max(1.0, std::ceil(p / 100.0 * static_cast<double>(v.size()))));
  return v[std::min(rank, v.size()) - 1];
}

constexpr std::int64_t kPeriodNs = 1'000'000;

std::string plan_yaml(int devices) {
  std::string y =
      "gateway: { name: bench }\nbuses:\n  - name: pn0\n    type: profinet\n    cycle_time: 1ms\n"
      "    options: { interface: sim0, reduction_ratio: 16 }\n    devices:\n";
  for (int i = 1; i <= devices; ++i)
    y += "      - { station: akd-" + std::to_string(i) + ", ip: 192.168.0." + std::to_string(10 + i) + " }\n";
  y += "axes:\n";
  for (int i = 1; i <= devices; ++i)
    y += "  - { name: a" + std::to_string(i) + ", bus: pn0, address: " + std::to_string(i) +
         ", device: kollmorgen-akd-profinet, profinet: { station: akd-" + std::to_string(i) + ", telegram: 1 } }\n";
  return y;
}

struct Devices {
  std::vector<std::unique_ptr<AkdPersona>> personas;
  PnSimNetwork net;
};

// The devices' step, timed apart from the bus.
class TimedPeer final : public PnCyclePeer {
 public:
  explicit TimedPeer(std::unique_ptr<PnCyclePeer> inner) : inner_(std::move(inner)) {}
  void step(core::TimePoint now) noexcept override {
    const std::int64_t t0 = thread_cpu_ns();
    inner_->step(now);
    ns += thread_cpu_ns() - t0;
  }
  std::int64_t ns = 0;

 private:
  std::unique_ptr<PnCyclePeer> inner_;
};

struct Row {
  int devices = 0;
  double bring_up_ms = -1;
  std::vector<double> bus_us, sim_us, late_bus_us, late_bare_us;
  std::size_t allocations = 0;
  std::uint64_t lost = 0, errors = 0;
};

Row run(int n, int cycles) {
  Row row;
  row.devices = n;
  config::LoadOptions lo;
  lo.bus_types = config::BusTypeRegistry::builtin();
  const config::Plan plan = config::load_plan_from_string(plan_yaml(n), "bench.yaml", lo);
  const auto& bp = plan.buses.at(0);
  std::vector<core::AxisSpec> specs;
  for (const auto& a : bp.axes) specs.push_back(a.spec);
  auto devices = std::make_shared<Devices>();
  for (int i = 1; i <= n; ++i) {
    devices->personas.push_back(std::make_unique<AkdPersona>(AkdPersonaConfig{}));
    PnDeviceConfig c;
    c.dcp.mac = {0x02, 0x1B, 0x1B, 0x00, 0x0B, static_cast<std::uint8_t>(i)};
    c.dcp.type_of_station = "AKD";
    c.dcp.vendor_id = 0x0118;
    c.dcp.device_id = 0x0501;
    c.dcp.name_of_station = "akd-" + std::to_string(i);
    c.activity = {0xA0000000U + static_cast<std::uint32_t>(i), 0, 0, {1, 2, 3, 4, 5, 6, 7, static_cast<std::uint8_t>(i)}};
    devices->net.add(c, *devices->personas.back());
  }
  SimControllerAddress address;
  address.ip = 0xC0A80001;
  ProfinetTransport t = sim_transport(devices->net, devices, address);
  auto timed = std::make_unique<TimedPeer>(std::move(t.peer));
  TimedPeer* peer = timed.get();
  t.peer = std::move(timed);
  ProfinetBus bus(bp, std::move(t));
  core::BusRunner runner(bus, specs);

  std::int64_t next = mono_ns() + kPeriodNs;
  core::CommandId id = 1;
  const auto push = [&](std::size_t axis, core::CommandKind kind, core::Mode mode = core::Mode::None, double v = 0) {
    core::Command c;
    c.id = id++;
    c.axis = static_cast<core::AxisIndex>(axis);
    c.kind = kind;
    c.mode = mode;
    c.velocity = v;
    (void)runner.push_command(c);
  };
  const auto drain = [&] {
    core::Reply r;
    while (runner.pop_reply(r)) {
    }
    core::Event e;
    while (runner.pop_event(e)) {
    }
  };
  const auto all_up = [&] {
    for (std::size_t k = 0; k < bus.device_count(); ++k)
      if (bus.phase(k) != ProfinetBus::Phase::Running) return false;
    for (std::size_t a = 0; a < specs.size(); ++a)
      if (runner.snapshot(static_cast<core::AxisIndex>(a)).state == core::AxisState::Unknown) return false;
    return true;
  };
  const std::int64_t opened = mono_ns();
  bus.open(core::TimePoint{core::Duration(opened)});
  // Bring-up, then enable every axis and run it in speed mode; then the measured cycles.
  int phase = 0;
  int measured = 0;
  int settle = 0;
  while (measured < cycles) {
    sleep_until_ns(next);
    const std::int64_t woke = mono_ns();
    const std::int64_t c0 = thread_cpu_ns();
    const std::int64_t sim0 = peer->ns;
    std::size_t allocs = 0;
    {
      const drivegate::test::AllocationScope scope;
      runner.cycle(core::TimePoint{core::Duration(woke)});
      allocs = scope.count();
    }
    const std::int64_t c1 = thread_cpu_ns();
    const std::int64_t sim = peer->ns - sim0;
    drain();
    sleep_until_ns(next + kPeriodNs / 2);
    const std::int64_t bare = mono_ns();
    // One command per cycle (the runner's queues are bounded): enable, speed mode, 1 rev/s.
    const auto each = [&](int from) { return settle >= from && settle < from + n ? static_cast<std::size_t>(settle - from) : specs.size(); };
    if (phase == 0 && all_up()) {
      row.bring_up_ms = static_cast<double>(woke - opened) / 1e6;
      phase = 1;
    } else if (phase == 1) {
      if (const std::size_t a = each(0); a < specs.size()) push(a, core::CommandKind::Enable);
      if (const std::size_t a = each(500); a < specs.size()) push(a, core::CommandKind::SetMode, core::Mode::ProfileVelocity);
      if (const std::size_t a = each(700); a < specs.size()) push(a, core::CommandKind::Velocity, core::Mode::None, 1.0);
      if (++settle == 1200) phase = 2;
    } else if (phase == 0 && woke - opened > 30'000'000'000) {
      std::fprintf(stderr, "%d devices: not all in data exchange after 30 s\n", n);
      return row;
    } else if (phase == 2) {
      row.bus_us.push_back(static_cast<double>(c1 - c0 - sim) / 1000.0);
      row.sim_us.push_back(static_cast<double>(sim) / 1000.0);
      row.late_bus_us.push_back(static_cast<double>(woke - next) / 1000.0);
      row.late_bare_us.push_back(static_cast<double>(bare - (next + kPeriodNs / 2)) / 1000.0);
      row.allocations += allocs;
      ++measured;
    }
    next += kPeriodNs;
    const std::int64_t now = mono_ns();
    if (next < now) next += ((now - next) / kPeriodNs + 1) * kPeriodNs;
  }
  std::size_t enabled = 0;
  for (std::size_t a = 0; a < specs.size(); ++a)
    if (runner.snapshot(static_cast<core::AxisIndex>(a)).state == core::AxisState::OperationEnabled) ++enabled;
  if (enabled != specs.size()) std::fprintf(stderr, "%d devices: only %zu axes enabled\n", n, enabled);
  row.lost = bus.counters().frames_lost;
  row.errors = bus.counters().errors;
  bus.close();
  return row;
}

std::optional<int> parse_int(std::string_view s) {
  int v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc{} || end != s.data() + s.size() || v <= 0) return std::nullopt;
  return v;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<int> counts{8, 32};
  int cycles = 10000;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string_view arg(argv[i]), value(argv[i + 1]);
    if (arg == "--cycles" && parse_int(value)) {
      cycles = *parse_int(value);
    } else if (arg == "--devices") {
      counts.clear();
      std::string_view v = value;
      while (!v.empty()) {
        const auto comma = v.find(',');
        const auto n = parse_int(v.substr(0, comma));
        if (!n || *n > 200) return std::fprintf(stderr, "--devices: 1..200, comma separated\n"), 2;
        counts.push_back(*n);
        v = comma == std::string_view::npos ? std::string_view{} : v.substr(comma + 1);
      }
    } else {
      return std::fprintf(stderr, "usage: bench_profinet_cycle [--devices 8,32] [--cycles 10000]\n"), 2;
    }
  }
  if (argc % 2 == 0) return std::fprintf(stderr, "usage: bench_profinet_cycle [--devices 8,32] [--cycles 10000]\n"), 2;
  std::printf("PROFINET bus, simulated AKDs in process, 1 ms cycle, update time 16 ms, %d measured cycles, every axis "
              "enabled in speed mode\n",
              cycles);
  std::printf("devices  to data exchange  bus us p50/p99/max  bus p50/device  sim us p50 | late bus p50/p99/max  "
              "bare p50/p99/max  p99 ratio  allocs  lost errors\n");
  for (const int n : counts) {
    const Row r = run(n, cycles);
    if (r.bus_us.empty()) continue;
    const double lb = percentile(r.late_bus_us, 99), la = percentile(r.late_bare_us, 99);
    std::printf("%7d  %14.0f ms  %6.1f/%6.1f/%6.1f  %14.2f  %10.1f | %6.1f/%6.1f/%7.1f  %5.1f/%6.1f/%7.1f  %9.2f  %6zu  %4llu %6llu\n",
                n, r.bring_up_ms, percentile(r.bus_us, 50), percentile(r.bus_us, 99), percentile(r.bus_us, 100),
                percentile(r.bus_us, 50) / n, percentile(r.sim_us, 50), percentile(r.late_bus_us, 50), lb,
                percentile(r.late_bus_us, 100), percentile(r.late_bare_us, 50), la, percentile(r.late_bare_us, 100),
                la > 0 ? lb / la : 0.0, r.allocations, static_cast<unsigned long long>(r.lost),
                static_cast<unsigned long long>(r.errors));
  }
  return 0;
}
