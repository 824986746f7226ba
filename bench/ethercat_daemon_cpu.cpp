// CPU of the whole drivegated process and of each of its threads with N simulated generic CiA 402
// drives (default 64) on one EtherCAT bus at 1 kHz: the issue's target "64 axes at 1 kHz under 10 %
// of one core for the whole daemon process". The line is `transport: sim`: the simulated slaves
// run inside the daemon's cycle thread (SimLineLink/SimLinePeer), so the figures include the
// simulator's CPU and read high. One bus carries up to 64 slaves (ProcessImage::kMaxSlaves): with
// one LRW per slave, the AL status check and the DC slot, 64 generic drives take three frames a
// cycle (ProcessImage::kMaxFrames is 4); --axes-per-bus spreads N axes over ceil(N / M) buses.
// --transport raw: the real target. The buses are `transport: raw` on end A of a veth pair
// in a network namespace of their own (A), with drivegate-sim serving the lines on end B in
// another (B), so the daemon's process CPU excludes the simulator (whose CPU is shown apart). The
// daemon and its DDS client run in namespace A: DDS stays on A's loopback (the multicast range is
// routed to lo there), never on the machine's interfaces. Needs root (tests/support/netns.hpp).
// Two phases of --seconds each: (a) every axis enabled and still, (b) every axis moving in profile
// position, moves sent by one DDS client.
//
//   bench_ethercat_daemon_cpu [--seconds N (default 10)] [--axes N (default 64)]
//                             [--axes-per-bus M (default 64)] [--transport sim|raw (default sim)]
//                             [--no-dc (the buses with distributed_clocks: false)]
//                             [--priority P (default 0: normal scheduling)]
//
// --priority 1..99 runs the cycle threads (bus priority: P) and, with --transport raw, the
// simulator under SCHED_FIFO P, as a production machine runs its cycle threads: on a machine busy
// with other work a normally scheduled simulator answers frames late enough for the master to take
// its slaves as lost, which measures the machine, not the gateway.
//
// CPU is utime + stime from /proc/PID/stat and /proc/PID/task/TID/stat over wall time, in % of one
// core; threads grouped by name (comm), as bench_daemon_cpu does.
#include <sched.h>
#include <signal.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
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
#include "tests/daemon/daemon_process.hpp"
#include "tests/support/netns.hpp"

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

constexpr auto kCycle = 1ms;
int g_axes_per_bus = 64;  // --axes-per-bus
bool g_no_dc = false;     // --no-dc
int g_priority = 0;       // --priority

// `interfaces` empty: transport sim; else transport raw, bus b on interfaces[b].
std::string config_text(const test::DdsIsolation& dds, int axes, const std::vector<std::string>& interfaces) {
  const char* dc = g_no_dc ? ", distributed_clocks: false" : "";
  const int buses = (axes + g_axes_per_bus - 1) / g_axes_per_bus;
  std::ostringstream y;
  y << "gateway: { name: bench, dds: { domain: " << dds.domain << ", namespace: " << dds.ns << " } }\n"
    << "buses:\n";
  for (int b = 0; b < buses; ++b) {
    y << "  - { name: ec" << b << ", type: ethercat, cycle_time: 1ms, priority: " << g_priority << ", options: { ";
    // Over veth the simulator is a process on a shared machine: a stall of 1.5 ms there (a
    // descheduled vCPU) puts it three cycles behind, and with the default lost_cycles: 3 the whole
    // line is taken as lost. The benchmark measures the master's CPU, not that: it tolerates 20.
    if (interfaces.empty()) y << "transport: sim" << dc << " } }\n";
    else y << "transport: raw, lost_cycles: 20, interface: " << interfaces[static_cast<std::size_t>(b)] << dc << " } }\n";
  }
  y << "axes:\n";
  for (int b = 0, i = 0; b < buses; ++b) {
    const int on_bus = axes / buses + (b < axes % buses ? 1 : 0);
    for (int k = 1; k <= on_bus; ++k, ++i)
      y << "  - { name: a" << i + 1 << ", bus: ec" << b << ", address: " << k
        << ", device: generic-cia402, mechanics: { encoder_counts_per_rev: 10000 },"
           " limits: { max_velocity: 20, max_acceleration: 200 },"
           " defaults: { mode: pp, velocity: 10, acceleration: 100, deceleration: 100 } }\n";
  }
  return y.str();
}

int fail(const std::string& what) {
  std::fprintf(stderr, "bench_ethercat_daemon_cpu: %s\n", what.c_str());
  return 1;
}

// Why axes stopped being enabled, from the daemon's log (level info logs every event; events come
// on changes only): the lines of each kind that takes an axis out of operation enabled, counted,
// with the first of each. A moment without an answer from the whole line (the simulator stalled
// for more than lost_cycles) shows as every axis' link going lost at once.
void print_what_disabled_axes(const std::string& log) {
  struct Kind {
    const char* label;
    const char* needle;
  };
  constexpr std::array<Kind, 5> kKinds{{{"link lost", " -> lost"},
                                        {"drive fault", ": fault 0x"},
                                        {"control lost", ": control_lost: "},
                                        {"command timeout", ": command_timeout: "},
                                        {"cycle schedule missed", "stopped keeping its schedule"}}};
  std::array<int, kKinds.size()> count{};
  std::array<std::string, kKinds.size()> first;
  std::istringstream in(log);
  for (std::string line; std::getline(in, line);) {
    for (std::size_t k = 0; k < kKinds.size(); ++k) {
      if (line.find(kKinds[k].needle) == std::string::npos) continue;
      if (count[k]++ == 0) first[k] = line;
    }
  }
  std::printf("  in the daemon's log, what takes axes out of operation enabled:\n");
  for (std::size_t k = 0; k < kKinds.size(); ++k) {
    std::printf("    %-22s %4d%s%s\n", kKinds[k].label, count[k], count[k] > 0 ? "   first: " : "", first[k].c_str());
  }
}

// The raw transport's rig: namespaces A (daemon, client) and B (drivegate-sim), a veth pair per
// bus between them, and drivegate-sim serving every bus' line on its end B.
struct RawRig {
  explicit RawRig(int buses) {
    if (const std::string& why = test::netns_unavailable(); !why.empty()) throw std::runtime_error("--transport raw: " + why);
    // DDS discovery is multicast: route the range to A's loopback so it stays there.
    const test::RunResult route = ns_a.ip({"route", "add", "224.0.0.0/4", "dev", "lo"});
    if (!route.ok()) throw std::runtime_error("ip route add 224.0.0.0/4 dev lo: " + route.output);
    for (int b = 0; b < buses; ++b) {
      pairs.push_back(std::make_unique<test::VethPair>(&ns_a, &ns_b));
      interfaces.push_back(pairs.back()->a());
    }
  }
  // drivegate-sim CONFIG --interface ecN=END_B... in namespace B; returns once it said it serves
  // every line.
  void start_sim(const std::string& config) {
    std::vector<std::string> args{DRIVEGATE_SIM_EXE, config};
    for (std::size_t i = 0; i < pairs.size(); ++i) {
      args.emplace_back("--interface");
      args.push_back("ec" + std::to_string(i) + "=" + pairs[i]->b());
    }
    sim = std::make_unique<test::ChildProcess>(&ns_b, [args](int out) {
      // The console reads stdin until its end: a pipe whose write end the simulator holds itself.
      int in[2];
      if (::pipe(in) != 0) return 125;
      ::dup2(in[0], STDIN_FILENO);
      ::dup2(out, STDOUT_FILENO);
      ::dup2(out, STDERR_FILENO);
      std::vector<char*> argv;
      for (const auto& x : args) argv.push_back(const_cast<char*>(x.c_str()));
      argv.push_back(nullptr);
      if (g_priority > 0) {
        sched_param sp{};
        sp.sched_priority = g_priority;
        if (::sched_setscheduler(0, SCHED_FIFO, &sp) != 0) return 126;
      }
      ::execv(argv[0], argv.data());
      return 127;
    });
    for (std::size_t served = 0; served < pairs.size();) {
      const auto line = sim->read_line(30s);
      if (!line) throw std::runtime_error("drivegate-sim did not start");
      if (line->find(" slaves on ethercat ") != std::string::npos) ++served;
      else std::fprintf(stderr, "%s\n", line->c_str());
    }
  }
  test::NetNamespace ns_a;
  test::NetNamespace ns_b;
  std::vector<std::unique_ptr<test::VethPair>> pairs;
  std::vector<std::string> interfaces;
  std::unique_ptr<test::ChildProcess> sim;
};

int run(int argc, char** argv);

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    return fail(e.what());
  }
}

namespace {

int run(int argc, char** argv) {
  double seconds = 10;
  int axes = 64;
  bool raw = false;
  for (int i = 1; i + 1 < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--seconds") seconds = std::max(1.0, std::atof(argv[i + 1]));
    if (a == "--axes") axes = std::clamp(std::atoi(argv[i + 1]), 1, 512);
    if (a == "--axes-per-bus") g_axes_per_bus = std::clamp(std::atoi(argv[i + 1]), 1, 64);
    if (a == "--transport") raw = std::string(argv[i + 1]) == "raw";
    if (a == "--priority") g_priority = std::clamp(std::atoi(argv[i + 1]), 0, 99);
  }
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--no-dc") g_no_dc = true;
  }
  const int buses = (axes + g_axes_per_bus - 1) / g_axes_per_bus;
  const auto dds = test::unique_dds("bench_ecat_cpu");
  std::unique_ptr<RawRig> rig;
  std::optional<test::NetnsScope> in_a;
  if (raw) {
    rig = std::make_unique<RawRig>(buses);
    // From here on this thread, the daemon it forks and the DDS client live in namespace A.
    in_a.emplace(rig->ns_a);
  }
  const auto config =
      test::write_config_text("bench-ethercat-daemon-cpu", config_text(dds, axes, rig ? rig->interfaces : std::vector<std::string>{}));
  if (rig) rig->start_sim(config);
  test::NotifySocket notify;
  test::DaemonProcess daemon(config, notify.path(), "info");  // events: print_what_disabled_axes()
  if (!notify.wait_for("READY=1", 30s)) return fail("drivegated did not start:\n" + daemon.log());

  client::Client c0(client::options_for(dds.domain, dds.ns, "bench-0"));
  const auto axis = [](int i) { return "a" + std::to_string(i + 1); };
  // Up = enabled. The client does not wait for the axes' states: the keyed depth-1 topics
  // (axis_state, axis_link, setpoint) keep Fast DDS' default of 10 instances per reader and writer
  // (idl/dds_node.cpp), so the states of axes beyond the tenth never arrive. Commands are unkeyed
  // and name the gateway, so they reach every axis: enable is sent again until it completes.
  const auto deadline = Clock::now() + 180s;
  for (int i = 0; i < axes; ++i) {
    client::CommandRequest en;
    en.gateway = "bench";
    en.axis = axis(i);
    en.kind = "enable";
    for (;;) {
      const auto r = c0.send(en, true, 20s);
      if (r.outcome == client::Outcome::Completed) break;
      if (Clock::now() > deadline) return fail("enable " + axis(i) + ": " + r.reason + "\n" + daemon.log());
      std::this_thread::sleep_for(200ms);
    }
  }

  std::printf("bench_ethercat_daemon_cpu: drivegated with %d generic-cia402 drives on %d EtherCAT bus(es) at 1 kHz, "
              "%s; %.0f s per phase; %% of one core from /proc (utime + stime)\n",
              axes, buses,
              raw ? "transport raw over veth (drivegate-sim in its own network namespace, measured apart)"
                  : "transport sim (the simulated slaves run in the cycle threads)",
              seconds);
  if (g_no_dc) {
    std::printf("--no-dc: WITHOUT distributed clocks (bus option distributed_clocks: false): no DC set-up, no FRMW, "
                "the drives run free (not SYNC0-synchronized)\n");
  }
  if (g_priority > 0) {
    std::printf("--priority %d: cycle threads%s under SCHED_FIFO %d\n", g_priority, raw ? " and drivegate-sim" : "",
                g_priority);
  }
  std::printf("drivegated pid %d (for top -H -p PID while it runs)\n", static_cast<int>(daemon.pid()));
  std::fflush(stdout);
  const auto measure = [&](const char* phase) {
    const auto m0 = machine_ticks();
    const auto d0 = sample(daemon.pid());
    const auto s0 = rig ? sample(rig->sim->pid()) : bench::Sample{};
    const auto t0 = Clock::now();
    std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
    const auto d1 = sample(daemon.pid());
    const auto s1 = rig ? sample(rig->sim->pid()) : bench::Sample{};
    const auto m1 = machine_ticks();
    const double wall = std::chrono::duration<double>(Clock::now() - t0).count();
    const double ref = reference_loop_ms();
    const auto du = usage(d0, d1, wall);
    const auto su = rig ? usage(s0, s1, wall) : bench::Usage{};
    std::printf("\n(%s) %.1f s\n", phase, wall);
    print_usage("drivegated", du, wall, kCycle);
    if (rig) print_usage("drivegate-sim", su, wall, kCycle);
    print_reference(m0, m1, du.process_pct + su.process_pct, rig ? "drivegated and drivegate-sim" : "drivegated", ref);
    std::fflush(stdout);
  };

  measure("a: axes enabled and still");

  // (b) every axis moving back and forth between 0 and 10 rev in profile position (1.1 s per move
  // at 10 rev/s and 100 rev/s^2); the moves are sent again every 1.5 s, alternately to either end.
  std::atomic<bool> stop{false};
  std::atomic<int> errors{0};
  std::atomic<int> moves{0};
  std::string first_refusal;  // written by the mover only, read after join()
  std::thread mover([&] {
    for (int round = 0; !stop; ++round) {
      const auto next = Clock::now() + 1500ms;
      for (int i = 0; i < axes && !stop; ++i) {
        client::CommandRequest m;
        m.gateway = "bench";
        m.axis = axis(i);
        m.kind = "move";
        m.position = round % 2 == 0 ? 10.0 : 0.0;
        const auto r = c0.send(m, false, 10s);
        if (r.ok()) {
          ++moves;
        } else if (errors++ == 0) {
          first_refusal = m.axis + ": " + r.reason;
        }
      }
      std::this_thread::sleep_until(next);
    }
  });
  std::this_thread::sleep_for(2s);
  measure("b: every axis moving (profile position, 0 <-> 10 rev)");
  stop = true;
  mover.join();
  std::printf("  moves sent %d, refused %d\n", moves.load(), errors.load());
  if (errors > 0) {
    print_what_disabled_axes(daemon.log());
    return fail("some moves were refused, the first: " + first_refusal);
  }
  daemon.terminate(SIGTERM, 20s);
  for (const char* suffix : {"", ".log"}) std::filesystem::remove(config + suffix);
  return 0;
}

}  // namespace
