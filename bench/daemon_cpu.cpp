// CPU of the whole drivegated process and of each of its threads with six simulated generic CiA 402
// drives on a udp-multicast bus (4 ms SYNC, loopback), drivegate-sim in a second process: the
// configuration of the daemon's CPU budget. Two phases of --seconds each: (a) the axes enabled and
// still, (b) six DDS clients (one per axis, each its own participant) jogging the axes as
// `drivegatectl velocity` does: a velocity command, then a set-point every 50 ms.
//
//   bench_daemon_cpu [--seconds N] [--rpdo-refresh D] [--status-keepalive D]
//
// --seconds: per phase (default 10). --rpdo-refresh and --status-keepalive set the bus' and the
// gateway's options of those names (default: the daemon's defaults); 0 for both is how the daemon
// ran before they existed (every RPDO after every SYNC, every axis state at every period).
//
// CPU is utime + stime from /proc/PID/stat and /proc/PID/task/TID/stat over wall time, in % of one
// core; threads are grouped by name (comm). The reference line per phase is what the rest of the
// machine did meanwhile (other processes' share of both cores) and the thread CPU time of a fixed
// loop: a slower loop or a busier machine means the figures of that phase read high.
#include <dirent.h>
#include <signal.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "bench/proc_stat.hpp"
#include "client/client.hpp"
#include "tests/canopen_e2e/sim_process.hpp"
#include "tests/daemon/daemon_process.hpp"

using namespace drivegate;
using bench::machine_ticks;
using bench::print_reference;
using bench::print_usage;
using bench::reference_loop_ms;
using bench::sample;
using bench::usage;
using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

namespace {

constexpr int kAxes = 6;
constexpr auto kCycle = 4ms;
constexpr auto kKeepAlivePeriod = 50ms;  // drivegatectl's (client/drivegatectl.cpp)
constexpr double kJogVelocity = 2;       // rev/s (10000 counts per revolution)

// Options left empty take the daemon's defaults.
struct Tuning {
  std::string rpdo_refresh;
  std::string status_keepalive;
};

std::string config_text(const test::DdsIsolation& dds, const std::string& group, std::uint16_t port,
                        const Tuning& tuning) {
  std::ostringstream y;
  y << "gateway: { name: bench, dds: { domain: " << dds.domain << ", namespace: " << dds.ns << " }"
    << (tuning.status_keepalive.empty() ? "" : ", status_keepalive: " + tuning.status_keepalive) << " }\n"
    << "buses:\n"
    << "  - name: can0\n"
    << "    type: canopen\n"
    << "    cycle_time: 4ms\n"
    << "    options: { transport: udp-multicast, interface: 127.0.0.1, group: " << group << ", port: " << port
    << ", bitrate: 1000000"
    << (tuning.rpdo_refresh.empty() ? "" : ", rpdo_refresh: " + tuning.rpdo_refresh) << " }\n"
    << "axes:\n";
  for (int i = 1; i <= kAxes; ++i) {
    y << "  - { name: a" << i << ", bus: can0, address: " << i
      << ", device: generic-cia402, mechanics: { encoder_counts_per_rev: 10000 } }\n";
  }
  return y.str();
}

int fail(const std::string& what) {
  std::fprintf(stderr, "bench_daemon_cpu: %s\n", what.c_str());
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  double seconds = 10;
  Tuning tuning;
  for (int i = 1; i + 1 < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--seconds") seconds = std::max(1.0, std::atof(argv[i + 1]));
    if (a == "--rpdo-refresh") tuning.rpdo_refresh = argv[i + 1];
    if (a == "--status-keepalive") tuning.status_keepalive = argv[i + 1];
  }

  const auto dds = test::unique_dds("bench_cpu");
  const test::BusAddress bus = test::unique_bus_address(0);
  const std::string& group = bus.group;
  const std::uint16_t port = bus.port;
  const auto config = test::write_config_text("bench-daemon-cpu", config_text(dds, group, port, tuning));

  test::SimProcess sim(config);
  if (!sim.wait_ready(20s)) return fail("drivegate-sim did not start:\n" + sim.log());
  test::NotifySocket notify;
  test::DaemonProcess daemon(config, notify.path(), "warn");
  if (!notify.wait_for("READY=1", 30s)) return fail("drivegated did not start:\n" + daemon.log());

  std::vector<std::unique_ptr<client::Client>> clients;
  for (int i = 0; i < kAxes; ++i)
    clients.push_back(std::make_unique<client::Client>(client::options_for(dds.domain, dds.ns, "bench-" + std::to_string(i))));
  const auto axis = [](int i) { return "a" + std::to_string(i + 1); };
  auto& c0 = *clients[0];
  const bool up = c0.wait_until([&] {
    for (int i = 0; i < kAxes; ++i) {
      const auto s = c0.state(axis(i));
      if (!s || s->link != "operational" || s->state != "switch_on_disabled") return false;
    }
    return true;
  }, 60s);
  if (!up) return fail("the axes did not come up\n" + daemon.log());
  for (int i = 0; i < kAxes; ++i) {
    client::CommandRequest en;
    en.axis = axis(i);
    en.kind = "enable";
    const auto r = clients[static_cast<std::size_t>(i)]->send(en, true, 20s);
    if (r.outcome != client::Outcome::Completed) return fail("enable " + axis(i) + ": " + r.reason);
  }

  std::printf("bench_daemon_cpu: drivegated and drivegate-sim, %d generic-cia402 drives on udp-multicast %s:%u "
              "(loopback), SYNC every 4 ms; %.0f s per phase; %% of one core from /proc (utime + stime)\n",
              kAxes, group.c_str(), port, seconds);
  std::printf("drivegated pid %d, drivegate-sim pid %d (for top -H -p PID while it runs)\n", static_cast<int>(daemon.pid()),
              static_cast<int>(sim.pid()));
  std::fflush(stdout);
  const auto measure = [&](const char* phase) {
    const auto m0 = machine_ticks();
    const auto d0 = sample(daemon.pid());
    const auto s0 = sample(sim.pid());
    const auto t0 = Clock::now();
    std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
    const auto d1 = sample(daemon.pid());
    const auto s1 = sample(sim.pid());
    const auto m1 = machine_ticks();
    const double wall = std::chrono::duration<double>(Clock::now() - t0).count();
    const double ref = reference_loop_ms();
    const auto du = usage(d0, d1, wall);
    const auto su = usage(s0, s1, wall);
    std::printf("\n(%s) %.1f s\n", phase, wall);
    print_usage("drivegated", du, wall, kCycle);
    print_usage("drivegate-sim", su, wall, kCycle);
    print_reference(m0, m1, du.process_pct + su.process_pct, "these two", ref);
    std::fflush(stdout);
  };

  measure("a: axes enabled and still");

  std::atomic<bool> stop{false};
  std::atomic<int> errors{0};
  std::vector<std::thread> joggers;
  for (int i = 0; i < kAxes; ++i) {
    joggers.emplace_back([&, i] {
      auto& c = *clients[static_cast<std::size_t>(i)];
      client::CommandRequest v;
      v.axis = axis(i);
      v.kind = "velocity";
      v.velocity = (i % 2 == 0 ? 1 : -1) * kJogVelocity;
      const auto started = c.send(v, false, 10s);
      if (!started.ok()) {
        std::fprintf(stderr, "bench_daemon_cpu: velocity %s: %s\n", v.axis.c_str(), started.reason.c_str());
        ++errors;
        return;
      }
      for (auto next = Clock::now(); !stop; next += kKeepAlivePeriod) {
        if (!c.stream_setpoint(v.axis, started.gateway, 0, v.velocity, 0).empty()) ++errors;
        std::this_thread::sleep_until(next + kKeepAlivePeriod);
      }
      client::CommandRequest s = v;
      s.kind = "stop";
      s.gateway = started.gateway;
      if (!c.send(s, true, 10s).ok()) ++errors;
    });
  }
  // The axes at speed before the window opens.
  const bool moving = c0.wait_until([&] {
    for (int i = 0; i < kAxes; ++i) {
      const auto s = c0.state(axis(i));
      if (!s || std::abs(s->velocity) < kJogVelocity / 2) return false;
    }
    return true;
  }, 10s);
  if (moving) measure("b: six clients jogging the axes");
  stop = true;
  for (auto& t : joggers) t.join();
  if (!moving || errors > 0) return fail("the jog phase did not run as intended (axes at speed: " +
                                         std::string(moving ? "yes" : "no") + ", errors " + std::to_string(errors) + ")");
  clients.clear();
  daemon.terminate(SIGTERM, 20s);
  for (const char* suffix : {"", ".log", ".sim.log"}) std::filesystem::remove(config + suffix);
  return 0;
}
