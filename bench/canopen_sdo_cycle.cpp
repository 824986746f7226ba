// SDO throughput while the axes cycle, as drivegated runs a CANopen bus: a real CycleThread and
// BusRunner over a CanopenBus with generic CiA 402 drives, enabled, on the wire-emulating
// in-process bus; the simulated drives answer from a thread of their own on the monotonic clock
// (sim/threaded_wire.hpp), as drives on a cable do. The control plane uploads 5FF0h:00 (a 4 KiB
// DOMAIN) over and over, two requests outstanding, through BusRunner's parameter queue.
//
// Each configuration runs twice: SDO answered once per cycle (the cycle thread only sleeps between
// cycles: how drivegated worked before CanopenBus::serve_until) and SDO answered between cycles.
// Per run: the cycle's lateness without and with the SDO traffic, and the SDO rate against the
// bit-rate limit of a segmented upload, on the whole wire and on what the cyclic traffic leaves.
// Real time: figures vary from run to run and with the machine's load. Nothing is asserted.
#include <algorithm>
#include <charconv>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "adapters/canopen/canopen_bus.hpp"
#include "adapters/canopen/sim/threaded_wire.hpp"
#include "adapters/canopen/wire/bit_timing.hpp"
#include "config/loader.hpp"
#include "core/bus_runner.hpp"
#include "daemon/cycle_thread.hpp"

namespace drivegate::bench {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

constexpr std::size_t kDomainSize = 4096;  // 5FF0h:00 of the simulated drives (sim/slave_node.hpp)
// The ideal for one segmented upload: initiate request and response, then a request and a response
// per 7-byte segment, every SDO frame DLC 8 (wire/sdo_codec.hpp) = frame_bits(8) bits.
constexpr std::uint32_t kSegments = (kDomainSize + 6) / 7;
constexpr std::uint32_t kBitsPerUpload = 2 * (1 + kSegments) * canopen::frame_bits(8);

struct Options {
  int axes = 6;
  int cycle_us = 4000;
  std::vector<std::uint32_t> bitrates{1'000'000};
  double seconds = 3.0;  // per phase
};

std::string plan_yaml(const Options& o, std::uint32_t bitrate) {
  std::string y = "gateway: { name: sdo-bench }\nbuses:\n  - { name: can0, type: canopen, cycle_time: " +
                  std::to_string(o.cycle_us) + "us, options: { transport: sim, bitrate: " + std::to_string(bitrate) +
                  " } }\naxes:\n";
  for (int i = 1; i <= o.axes; ++i)
    y += "  - { name: a" + std::to_string(i) + ", bus: can0, address: " + std::to_string(i) +
         ", device: generic-cia402, mechanics: { encoder_counts_per_rev: 10000 } }\n";
  return y;
}

struct Phase {
  double seconds = 0;
  std::uint64_t cycles = 0;
  std::uint64_t overruns = 0;
  std::int64_t p50_ns = 0;  // lateness over the last status window of the phase
  std::int64_t p99_ns = 0;
  std::int64_t max_ns = 0;
  double wire_load = 0;  // share of time the medium was busy
  std::uint64_t uploads = 0;
  std::uint64_t failed = 0;
  double bytes_per_s = 0;
};

class Rig {
 public:
  Rig(const Options& o, std::uint32_t bitrate, bool serve)
      : plan_(config::load_plan_from_string(plan_yaml(o, bitrate), "sdo-bench.yaml")),
        wire_(plan_.buses.at(0)),
        bus_(plan_.buses.at(0), wire_.gateway()) {
    for (const auto& a : plan_.buses[0].axes) specs_.push_back(a.spec);
    runner_ = std::make_unique<core::BusRunner>(bus_, specs_);
    daemon::CycleThread::Between between;
    if (serve) between = [this](core::TimePoint deadline) { bus_.serve_until(deadline); };
    thread_ = std::make_unique<daemon::CycleThread>(
        daemon::CycleThread::Schedule{.period = plan_.buses[0].cycle_time, .status_window = 1s},
        [this](core::TimePoint now, std::uint64_t) { runner_->cycle(now); }, std::move(between));
  }
  ~Rig() {
    thread_->stop();
    bus_.close();
    wire_.stop();
  }

  // Every link operational and every axis enabled; false (with the reason) when not in time.
  bool bring_up(std::string& why) {
    bus_.open(core::SteadyClock{}.now());
    wire_.start();
    if (!thread_->start()) {
      why = thread_->scheduling_note();
      return false;
    }
    if (!wait([&] { return all(core::AxisState::Unknown, false); }, 10s)) {
      why = "links not operational: " + std::string(bus_.link_detail(0));
      return false;
    }
    for (std::size_t a = 0; a < specs_.size(); ++a) {
      core::Command c;
      c.id = next_id_++;
      c.axis = static_cast<core::AxisIndex>(a);
      c.kind = core::CommandKind::Enable;
      runner_->push_command(c);
    }
    if (!wait([&] { return all(core::AxisState::OperationEnabled, true); }, 10s)) {
      why = "axes not enabled";
      return false;
    }
    return true;
  }

  Phase idle(double seconds) {
    return measure(seconds, [&](Clock::time_point end) {
      while (Clock::now() < end) {
        drain_replies();
        std::this_thread::sleep_for(10ms);
      }
    });
  }

  Phase uploading(double seconds) {
    return measure(seconds, [&](Clock::time_point end) {
      int outstanding = 0;
      const auto push = [&] {
        core::ParamRequest r;
        r.id = next_id_++;
        r.axis = 0;
        r.index = 0x5FF0;
        r.type = core::ParamType::Domain;
        if (runner_->push_parameter(r)) ++outstanding;
      };
      const auto start = Clock::now();  // the rate counts from the first request on
      push();
      push();
      Clock::time_point last = start;
      std::uint64_t bytes = 0;
      // After the phase, the uploads still outstanding finish; one that takes longer than two
      // cycles per segment (or 5 s) is given up.
      const auto give_up = end + std::max<Clock::duration>(5s, 2 * (kSegments + 2) * plan_.buses[0].cycle_time);
      while (Clock::now() < end || (outstanding > 0 && Clock::now() < give_up)) {
        core::ParamReply r;
        if (!runner_->pop_parameter_reply(r)) {
          drain_replies();
          std::this_thread::sleep_for(100us);
          continue;
        }
        --outstanding;
        if (r.ok && r.size == kDomainSize) {
          bytes += r.size;
          ++uploads_;
          last = Clock::now();
        } else {
          ++failed_;
        }
        if (Clock::now() < end) push();
      }
      rate_ = last > start ? static_cast<double>(bytes) / std::chrono::duration<double>(last - start).count() : 0.0;
    });
  }

 private:
  template <typename F>
  static bool wait(F done, Clock::duration budget) {
    const auto end = Clock::now() + budget;
    while (!done()) {
      if (Clock::now() > end) return false;
      std::this_thread::sleep_for(1ms);
    }
    return true;
  }
  bool all(core::AxisState state, bool check_state) const {
    for (std::size_t a = 0; a < specs_.size(); ++a) {
      if (bus_.link_state(a) != core::LinkState::Operational) return false;
      const auto s = runner_->snapshot(a).state;
      if (check_state ? s != state : s == core::AxisState::Unknown) return false;
    }
    return true;
  }
  void drain_replies() {
    core::Reply r;
    while (runner_->pop_reply(r)) {
    }
    core::Event e;
    while (runner_->pop_event(e)) {
    }
  }
  // Runs `body` for `seconds` and reports the cycle's timing and the wire load over that time.
  template <typename F>
  Phase measure(double seconds, F body) {
    uploads_ = failed_ = 0;
    rate_ = 0;
    const auto begin = thread_->timing();
    wire_.locked([](canopen::InprocBus& b, canopen::sim::SimNetwork&) { b.start_load_window(core::SteadyClock{}.now()); });
    const auto start = Clock::now();
    body(start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds)));
    Phase p;
    p.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    p.wire_load = wire_.locked([](canopen::InprocBus& b, canopen::sim::SimNetwork&) { return b.load(core::SteadyClock{}.now()); });
    const auto end = thread_->timing();
    p.cycles = end.cycles - begin.cycles;
    p.overruns = end.overruns - begin.overruns;
    p.p50_ns = end.lateness_p50_ns;
    p.p99_ns = end.lateness_p99_ns;
    p.max_ns = end.lateness_max_ns;
    p.uploads = uploads_;
    p.failed = failed_;
    p.bytes_per_s = rate_;
    return p;
  }

  config::Plan plan_;  // first: the bus keeps views into it
  canopen::sim::ThreadedSimWire wire_;
  canopen::CanopenBus bus_;
  std::vector<core::AxisSpec> specs_;
  std::unique_ptr<core::BusRunner> runner_;
  std::unique_ptr<daemon::CycleThread> thread_;
  core::CommandId next_id_ = 1;
  std::uint64_t uploads_ = 0;
  std::uint64_t failed_ = 0;
  double rate_ = 0;
};

template <typename T>
bool parse(std::string_view s, T& out) {
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
  return ec == std::errc{} && end == s.data() + s.size();
}

std::optional<Options> parse_options(int argc, char** argv) {
  Options o;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string_view k(argv[i]);
    const std::string_view v(argv[i + 1]);
    if (k == "--axes") {
      if (!parse(v, o.axes) || o.axes < 1 || o.axes > 32) return std::nullopt;
    } else if (k == "--cycle-us") {
      if (!parse(v, o.cycle_us) || o.cycle_us < 500) return std::nullopt;
    } else if (k == "--seconds") {
      int s = 0;
      if (!parse(v, s) || s < 1) return std::nullopt;
      o.seconds = s;
    } else if (k == "--bitrates") {
      o.bitrates.clear();
      for (std::string_view rest = v; !rest.empty();) {
        const auto comma = rest.find(',');
        std::uint32_t b = 0;
        if (!parse(rest.substr(0, comma), b) || b < 10'000 || b > 1'000'000) return std::nullopt;
        o.bitrates.push_back(b);
        rest = comma == std::string_view::npos ? std::string_view{} : rest.substr(comma + 1);
      }
    } else {
      return std::nullopt;
    }
  }
  if (argc % 2 == 0) return std::nullopt;
  return o;
}

double us(std::int64_t ns) { return static_cast<double>(ns) / 1000.0; }

int run(int argc, char** argv) {
  const auto options = parse_options(argc, argv);
  if (!options) {
    std::fprintf(stderr,
                 "usage: bench_canopen_sdo_cycle [--axes N (6)] [--cycle-us N (4000)] [--bitrates B,B,... (1000000)]\n"
                 "                               [--seconds N per phase (3)]\n");
    return 2;
  }
  const Options& o = *options;
  std::printf("bench_canopen_sdo_cycle: %d generic-cia402 axes enabled, SYNC every %d us, drives in their own thread\n"
              "  on the wire-emulating in-process bus; the control plane uploads 5FF0h:00 (%zu B) back to back,\n"
              "  two requests outstanding; %.0f s idle, then %.0f s uploading, per row; real time\n",
              o.axes, o.cycle_us, kDomainSize, o.seconds, o.seconds);
  std::printf("  limit      = %zu B x bitrate / (%u frames x %u bits): one initiate and %u segment exchanges, every\n"
              "               SDO frame DLC 8 = frame_bits(8) bits (wire/bit_timing.hpp, worst-case stuffing)\n"
              "  free limit = limit x (1 - wire load idle): what the wire left by the cyclic traffic allows\n"
              "  lateness   = cycle start - planned start (p50/p99/max of the last 1 s window of the phase)\n\n",
              kDomainSize, 2 * (1 + kSegments), canopen::frame_bits(8), kSegments);
  std::printf("%7s  %-15s %8s %8s %7s %8s %8s %7s %6s | %-22s %5s | %-22s %5s %5s\n", "kbit/s", "SDO answered",
              "kB/s", "limit", "of lim", "load", "free lim", "of free", "ms/up", "lateness idle [us]", "ovr",
              "lateness SDO [us]", "ovr", "fail");
  int status = 0;
  for (const std::uint32_t bitrate : o.bitrates) {
    const double limit = static_cast<double>(kDomainSize) * bitrate / kBitsPerUpload;
    for (const bool serve : {false, true}) {
      Rig rig(o, bitrate, serve);
      std::string why;
      if (!rig.bring_up(why)) {
        std::printf("%7u  %-15s not measured: %s\n", bitrate / 1000, serve ? "between cycles" : "once per cycle",
                    why.c_str());
        status = 1;
        continue;
      }
      const Phase idle = rig.idle(o.seconds);
      const Phase sdo = rig.uploading(o.seconds);
      const double free_limit = limit * (1.0 - idle.wire_load);
      const double per_upload = sdo.bytes_per_s > 0 ? 1000.0 * kDomainSize / sdo.bytes_per_s : 0.0;
      std::printf("%7u  %-15s %8.2f %8.2f %6.1f%% %7.1f%% %8.2f %6.1f%% %6.1f | %6.0f %6.0f %8.0f %5llu | %6.0f %6.0f "
                  "%8.0f %5llu %5llu\n",
                  bitrate / 1000, serve ? "between cycles" : "once per cycle", sdo.bytes_per_s / 1000.0,
                  limit / 1000.0, 100.0 * sdo.bytes_per_s / limit, 100.0 * idle.wire_load, free_limit / 1000.0,
                  free_limit > 0 ? 100.0 * sdo.bytes_per_s / free_limit : 0.0, per_upload, us(idle.p50_ns),
                  us(idle.p99_ns), us(idle.max_ns), static_cast<unsigned long long>(idle.overruns), us(sdo.p50_ns),
                  us(sdo.p99_ns), us(sdo.max_ns), static_cast<unsigned long long>(sdo.overruns),
                  static_cast<unsigned long long>(sdo.failed));
      if (sdo.failed > 0 || sdo.uploads == 0) status = 1;
    }
  }
  return status;
}

}  // namespace
}  // namespace drivegate::bench

int main(int argc, char** argv) { return drivegate::bench::run(argc, argv); }
