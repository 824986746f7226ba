// CPU time per SYNC cycle of drivegate's side of a CANopen bus: BusRunner::cycle, that is
// CanopenBus::receive -> the CiA 402 master of every axis -> CanopenBus::transmit, for 1, 8 and
// 32 nodes with every axis enabled and moving in profile position and the TPDOs flowing. Side by
// side in the same run: the same axes on the in-process `sim` bus (adapters/sim), so the ratio
// reads as "what the CANopen master costs over the simplest bus".
//
// The simulated drives live on the same wire-emulating in-process bus as the gateway. The bus is
// built without its CyclePeer and the drives are stepped before each cycle, outside the measured
// region, so the canopen figure is the gateway's CPU only. The sim bus cannot be split like that:
// its cycle includes its drive models, so the ratio understates what CANopen adds over the sim
// bus' own master work.
//
// Thread CPU time (CLOCK_THREAD_CPUTIME_ID) leaves out the time another process held the CPU, and
// the two bus types alternate in blocks of cycles so both see the same drift in machine load.
// Heap allocations inside the measured calls are counted (expected 0). Figures only; nothing is
// asserted.
#include <time.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "adapters/canopen/canopen_bus.hpp"
#include "adapters/canopen/plan_load.hpp"
#include "adapters/canopen/sim/sim_network.hpp"
#include "adapters/sim/sim_bus.hpp"
#include "config/loader.hpp"
#include "core/bus_runner.hpp"
#include "tests/support/alloc_counter.hpp"

namespace drivegate::bench {
namespace {

struct Options {
  int cycles = 10'000;  // measured cycles per bus type and node count
  int block = 500;      // cycles per slice; the bus types alternate slice by slice
  std::vector<int> nodes{1, 8, 32};
  std::string device = "generic-cia402";
  int bitrate = 1'000'000;
  // 32 generic drives map 5 PDOs each: about 19 700 bits per cycle with SYNC and heartbeats, which
  // the config's load check accepts without a warning (<= 70 %) at 1 Mbit/s from about 29 ms on.
  int cycle_us = 30'000;
  // The sim bus steps its drive models once per cycle by the whole cycle time, and a 16 ms step
  // already ends a profile-position move in a following error; its CPU per cycle does not depend on
  // the cycle time, so the reference runs at the 1 ms of config/demo.yaml.
  int sim_cycle_us = 1'000;
};

std::optional<int> parse_int(std::string_view s) {
  int value = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (ec != std::errc{} || end != s.data() + s.size()) return std::nullopt;
  return value;
}

std::optional<std::vector<int>> parse_list(std::string_view s) {
  std::vector<int> out;
  while (!s.empty()) {
    const std::size_t comma = s.find(',');
    const auto v = parse_int(s.substr(0, comma));
    if (!v || *v < 1 || *v > 127) return std::nullopt;
    out.push_back(*v);
    s = comma == std::string_view::npos ? std::string_view{} : s.substr(comma + 1);
  }
  if (out.empty()) return std::nullopt;
  return out;
}

void usage() {
  std::fprintf(stderr,
               "usage: bench_canopen_cycle [--cycles N (default 10000)] [--block N (default 500)]\n"
               "                           [--nodes LIST (default 1,8,32)] [--device NAME (default generic-cia402)]\n"
               "                           [--bitrate BIT/S (default 1000000)] [--cycle-us N (default 30000)]\n"
               "                           [--sim-cycle-us N (default 1000)]\n");
}

std::optional<Options> parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg(argv[i]);
    if (arg == "--help" || arg == "-h" || i + 1 >= argc) return std::nullopt;
    const std::string_view value(argv[++i]);
    std::optional<int> n = parse_int(value);
    if (arg == "--nodes") {
      auto list = parse_list(value);
      if (!list) return std::nullopt;
      o.nodes = std::move(*list);
      continue;
    }
    if (arg == "--device") {
      o.device = value;
      continue;
    }
    int* target = nullptr;
    if (arg == "--cycles") target = &o.cycles;
    if (arg == "--block") target = &o.block;
    if (arg == "--bitrate") target = &o.bitrate;
    if (arg == "--cycle-us") target = &o.cycle_us;
    if (arg == "--sim-cycle-us") target = &o.sim_cycle_us;
    if (target == nullptr || !n || *n <= 0) return std::nullopt;
    *target = *n;
  }
  return o;
}

std::int64_t thread_cpu_ns() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return std::int64_t{ts.tv_sec} * 1'000'000'000 + ts.tv_nsec;
}

// The median cost of reading the clock twice: what every sample carries on top of the work.
std::int64_t timer_overhead_ns() {
  std::vector<std::int64_t> d(10'001);
  for (auto& x : d) {
    const std::int64_t t0 = thread_cpu_ns();
    x = thread_cpu_ns() - t0;
  }
  std::nth_element(d.begin(), d.begin() + 5'000, d.end());
  return d[5'000];
}

// Nearest-rank percentile (p in (0, 100]) of the samples.
double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const auto rank = static_cast<std::size_t>(std::max(1.0, std::ceil(p / 100.0 * static_cast<double>(v.size()))));
  return v[std::min(rank, v.size()) - 1];
}

// The same axes for either bus type. Positions in revolutions; a move 0 <-> 10 rev at 10 rev/s
// takes about a second, so most measured cycles have every axis in motion.
std::string plan_yaml(const Options& o, int nodes, bool canopen) {
  const std::string cycle = std::to_string(canopen ? o.cycle_us : o.sim_cycle_us) + "us";
  std::string y = "gateway: { name: bench }\nbuses:\n";
  if (canopen)
    y += "  - { name: b0, type: canopen, cycle_time: " + cycle + ", options: { transport: sim, bitrate: " +
         std::to_string(o.bitrate) + " } }\n";
  else
    y += "  - { name: b0, type: sim, cycle_time: " + cycle + " }\n";
  y += "axes:\n";
  for (int i = 1; i <= nodes; ++i)
    y += "  - { name: a" + std::to_string(i) + ", bus: b0, address: " + std::to_string(i) + ", device: " + o.device +
         ", mechanics: { encoder_counts_per_rev: 10000 }, limits: { max_velocity: 20, max_acceleration: 200 },"
         " defaults: { mode: pp, velocity: 10, acceleration: 100, deceleration: 100 } }\n";
  return y;
}

constexpr double kMoveEnd = 10.0;

// One bus with its runner on virtual time, and the control plane's part: enable every axis, then
// send each axis to the other end whenever its move completes.
class Rig {
 public:
  Rig(const Options& o, int nodes, bool canopen_bus)
      : plan_(config::load_plan_from_string(plan_yaml(o, nodes, canopen_bus), "bench.yaml")) {
    const auto& bp = plan_.buses.at(0);
    for (const auto& a : bp.axes) specs_.push_back(a.spec);
    if (canopen_bus) {
      // Wired like SimPeer::wire() (sim/sim_network.cpp), with transmit queues that hold a whole
      // cycle. SimPeer keeps InprocBus' default of 64 frames per endpoint, while the gateway queues
      // SYNC + 3 RPDOs per generic node at one instant and the drives 2 TPDOs per node plus their
      // heartbeats: with 64, sends are refused from 18 generic nodes on and links lost from 20
      // (measured with this program). 1024 is TxQueue's capacity (master/tx_queue.hpp).
      wire_ = std::make_unique<canopen::InprocBus>(
          static_cast<std::uint32_t>(bp.section<config::CanopenBusOptions>().bitrate),
          canopen::InprocBusOptions{.max_endpoints = 2, .tx_queue_capacity = 1024, .rx_queue_capacity = 4096});
      drives_end_ = wire_->connect();
      drives_end_->open();
      drives_ = std::make_unique<canopen::sim::SimNetwork>(*drives_end_);
      for (const auto& a : bp.axes) drives_->add(canopen::sim::slave_config_for(a));
      // No CyclePeer: the drives are stepped by step_drives(), outside the measured region.
      auto bus = std::make_unique<canopen::CanopenBus>(bp, wire_->connect());
      canopen_ = bus.get();
      bus_ = std::move(bus);
    } else {
      bus_ = std::make_unique<sim::SimBus>(bp);
    }
    runner_ = std::make_unique<core::BusRunner>(*bus_, specs_);
    pending_.assign(specs_.size(), 0);
    target_.assign(specs_.size(), 0.0);
    bus_->open(now_);
  }

  const config::BusPlan& bus_plan() const { return plan_.buses.at(0); }
  canopen::CanopenBus* canopen() const { return canopen_; }
  canopen::sim::SimNetwork* drives() const { return drives_.get(); }
  canopen::InprocBus& wire() const { return *wire_; }
  core::BusRunner& runner() { return *runner_; }
  core::TimePoint now() const { return now_; }
  std::uint64_t moves_completed() const { return moves_completed_; }
  std::uint64_t command_failures() const { return failures_; }
  const std::string& first_failure() const { return first_failure_; }

  void advance() { now_ += bus_plan().cycle_time; }
  // What SimPeer::step() does when CanopenBus::receive() calls it first thing.
  void step_drives() {
    if (!drives_) return;
    wire_->advance(now_);
    drives_->step(now_);
    wire_->advance(now_);
  }
  void control() {
    core::Reply r;
    while (runner_->pop_reply(r)) {
      if (r.axis >= pending_.size() || r.id != pending_[r.axis] || r.status == core::ReplyStatus::Accepted) continue;
      pending_[r.axis] = 0;
      if (r.status != core::ReplyStatus::Completed) {
        if (failures_++ == 0) first_failure_ = "axis " + std::to_string(r.axis + 1) + ": " + std::string(r.reason.view());
        continue;
      }
      if (!moving_) continue;  // an enable finished
      ++moves_completed_;
      target_[r.axis] = target_[r.axis] == 0.0 ? kMoveEnd : 0.0;
      move(r.axis);
    }
    core::Event e;
    while (runner_->pop_event(e)) {
    }
  }
  void cycle() {
    advance();
    step_drives();
    runner_->cycle(now_);
    control();
  }

  // Links up, every axis enabled and moving; false (with the reason printed) when that fails.
  bool bring_up(const char* what) {
    if (!run_until([&] { return all_up(); }, std::chrono::seconds(30))) {
      std::fprintf(stderr, "%s: the axes did not come up\n", what);
      return false;
    }
    for (std::size_t a = 0; a < specs_.size(); ++a) pending_[a] = push(a, core::CommandKind::Enable, 0.0);
    if (!run_until([&] { return idle(); }, std::chrono::seconds(10)) || failures_ > 0) {
      std::fprintf(stderr, "%s: enabling failed (%s)\n", what, first_failure_.c_str());
      return false;
    }
    moving_ = true;
    for (std::size_t a = 0; a < specs_.size(); ++a) {
      target_[a] = kMoveEnd;
      move(a);
    }
    return true;
  }

  std::size_t axes_not_enabled() const {
    std::size_t n = 0;
    for (std::size_t a = 0; a < specs_.size(); ++a)
      if (runner_->snapshot(a).state != core::AxisState::OperationEnabled) ++n;
    return n;
  }

 private:
  template <typename Done>
  bool run_until(Done done, core::Duration budget) {
    const auto end = now_ + budget;
    while (now_ < end) {
      if (done()) return true;
      cycle();
    }
    return done();
  }
  bool all_up() const {
    for (std::size_t a = 0; a < specs_.size(); ++a)
      if (bus_->link_state(a) != core::LinkState::Operational ||
          runner_->snapshot(a).state == core::AxisState::Unknown)
        return false;
    return true;
  }
  bool idle() const {
    return std::all_of(pending_.begin(), pending_.end(), [](core::CommandId id) { return id == 0; });
  }
  core::CommandId push(std::size_t axis, core::CommandKind kind, double position) {
    core::Command c;
    c.id = next_id_++;
    c.axis = static_cast<core::AxisIndex>(axis);
    c.kind = kind;
    c.position = position;
    if (!runner_->push_command(c) && failures_++ == 0) first_failure_ = "the command queue is full";
    return c.id;
  }
  void move(std::size_t axis) { pending_[axis] = push(axis, core::CommandKind::Move, target_[axis]); }

  config::Plan plan_;  // first: the buses keep views into it
  std::vector<core::AxisSpec> specs_;
  std::unique_ptr<canopen::InprocBus> wire_;  // outlives both of its endpoints
  std::unique_ptr<canopen::InprocEndpoint> drives_end_;
  std::unique_ptr<canopen::sim::SimNetwork> drives_;
  std::unique_ptr<core::Bus> bus_;
  canopen::CanopenBus* canopen_ = nullptr;
  std::unique_ptr<core::BusRunner> runner_;
  core::TimePoint now_{};
  core::CommandId next_id_ = 1;
  std::vector<core::CommandId> pending_;  // per axis: the command waiting for its final reply
  std::vector<double> target_;
  bool moving_ = false;
  std::uint64_t moves_completed_ = 0;
  std::uint64_t failures_ = 0;
  std::string first_failure_;
};

struct Samples {
  std::vector<double> us;         // gateway CPU per cycle
  std::vector<double> drives_us;  // the simulated drives' CPU per cycle (canopen only)
  std::vector<double> block_p50;  // median of each block: how much the machine drifted
  std::size_t allocations = 0;

  explicit Samples(std::size_t cycles) {
    us.reserve(cycles);
    drives_us.reserve(cycles);
  }
};

// `n` measured cycles. Only BusRunner::cycle is inside the measured region (and the allocation
// scope); the drives and the control plane are outside.
void measure_block(Rig& rig, int n, std::int64_t overhead_ns, Samples& s) {
  const auto us = [overhead_ns](std::int64_t ns) {
    return static_cast<double>(std::max<std::int64_t>(0, ns - overhead_ns)) / 1000.0;
  };
  const std::size_t first = s.us.size();
  for (int i = 0; i < n; ++i) {
    rig.advance();
    if (rig.drives() != nullptr) {
      const std::int64_t d0 = thread_cpu_ns();
      rig.step_drives();
      s.drives_us.push_back(us(thread_cpu_ns() - d0));
    }
    const drivegate::test::AllocationScope scope;
    const std::int64_t t0 = thread_cpu_ns();
    rig.runner().cycle(rig.now());
    const std::int64_t t1 = thread_cpu_ns();
    s.allocations += scope.count();
    s.us.push_back(us(t1 - t0));
    rig.control();
  }
  s.block_p50.push_back(
      percentile(std::vector<double>(s.us.begin() + static_cast<std::ptrdiff_t>(first), s.us.end()), 50.0));
}

// What the canopen rig's wire and engines did during the measurement: proof the cycles measured
// had TPDOs flowing and axes moving.
struct BusCheck {
  std::uint64_t tpdos = 0;
  std::uint64_t frames = 0;
  std::uint64_t unexpected = 0;
  std::uint64_t missed = 0;
  std::uint64_t refused = 0;  // sends the wire refused (queue full, bus-off) on either side

  static BusCheck of(const Rig& rig) {
    BusCheck c;
    const canopen::CanopenBus& bus = *rig.canopen();
    for (std::size_t a = 0; a < bus.axis_count(); ++a) {
      c.tpdos += bus.pdos(a).counters().tpdos_received;
      c.missed += bus.pdos(a).counters().missed;
    }
    c.frames = rig.wire().stats().frames;
    c.unexpected = bus.unexpected_frames();
    c.refused = rig.canopen()->transport().counters().tx_overflows + rig.drives()->counters().send_failed;
    return c;
  }
};

struct Row {
  int nodes = 0;
  double load_estimate = 0;
  std::string load_text;
  std::unique_ptr<Samples> canopen;
  std::unique_ptr<Samples> sim;
  double wire_load = 0;
  double frames_per_cycle = 0;
  double tpdos_per_cycle = 0;
  std::uint64_t unexpected = 0;
  std::uint64_t missed = 0;
  std::uint64_t refused = 0;
  std::uint64_t moves_canopen = 0;
  std::uint64_t moves_sim = 0;
  std::size_t not_enabled = 0;
  std::uint64_t failures = 0;
  std::string first_failure;
};

std::optional<Row> run_node_count(const Options& o, int nodes, std::int64_t overhead_ns) {
  Rig co(o, nodes, true);
  Rig si(o, nodes, false);
  Row row;
  row.nodes = nodes;
  const auto load = canopen::plan_cycle_load(co.bus_plan());
  row.load_estimate = load.fraction;
  row.load_text = canopen::describe_cycle_load(co.bus_plan(), load);
  if (!co.bring_up("canopen") || !si.bring_up("sim")) return std::nullopt;
  for (int i = 0; i < 50; ++i) {  // past the first moves' start
    co.cycle();
    si.cycle();
  }

  const auto cycles = static_cast<std::size_t>(o.cycles);
  row.canopen = std::make_unique<Samples>(cycles);
  row.sim = std::make_unique<Samples>(cycles);
  const BusCheck before = BusCheck::of(co);
  const std::uint64_t moves_co = co.moves_completed();
  const std::uint64_t moves_si = si.moves_completed();
  co.wire().start_load_window(co.now());
  for (int done = 0; done < o.cycles; done += o.block) {
    const int n = std::min(o.block, o.cycles - done);
    measure_block(co, n, overhead_ns, *row.canopen);
    measure_block(si, n, overhead_ns, *row.sim);
  }
  const BusCheck after = BusCheck::of(co);
  row.wire_load = co.wire().load(co.now());
  row.frames_per_cycle = static_cast<double>(after.frames - before.frames) / o.cycles;
  row.tpdos_per_cycle = static_cast<double>(after.tpdos - before.tpdos) / o.cycles;
  row.unexpected = after.unexpected - before.unexpected;
  row.missed = after.missed - before.missed;
  row.refused = after.refused - before.refused;
  row.moves_canopen = co.moves_completed() - moves_co;
  row.moves_sim = si.moves_completed() - moves_si;
  row.not_enabled = co.axes_not_enabled() + si.axes_not_enabled();
  row.failures = co.command_failures() + si.command_failures();
  row.first_failure = co.command_failures() > 0 ? "canopen " + co.first_failure() : "sim " + si.first_failure();
  return row;
}

void print_samples(int nodes, const char* bus, const Samples& s) {
  const double p50 = percentile(s.us, 50.0);
  const auto [lo, hi] = std::minmax_element(s.block_p50.begin(), s.block_p50.end());
  std::printf("%5d  %-11s %9.2f %9.2f %9.2f %13.3f %12.2f..%-8.2f %11zu\n", nodes, bus, p50, percentile(s.us, 99.0),
              percentile(s.us, 100.0), p50 / nodes, *lo, *hi, s.allocations);
}

int run(int argc, char** argv) {
  const std::optional<Options> options = parse(argc, argv);
  if (!options) {
    usage();
    return 2;
  }
  const Options& o = *options;
  const std::int64_t overhead_ns = timer_overhead_ns();

  std::vector<Row> rows;
  for (int nodes : o.nodes) {
    try {
      auto row = run_node_count(o, nodes, overhead_ns);
      if (!row) return 1;
      rows.push_back(std::move(*row));
    } catch (const std::exception& e) {
      std::fprintf(stderr, "%d nodes: %s\n", nodes, e.what());
      return 1;
    }
  }

  std::printf("bench_canopen_cycle: CPU per cycle of BusRunner::cycle (bus receive -> CiA 402 masters -> bus transmit)\n");
  std::printf("  canopen: %s drives on the in-process wire at %d kbit/s, SYNC every %.3g ms; the drives are\n"
              "           stepped outside the measured region (their CPU is the 'drives' column below)\n",
              o.device.c_str(), o.bitrate / 1000, o.cycle_us / 1000.0);
  std::printf("  sim:     the same axes on the in-process sim bus (adapters/sim), cycle %.3g ms; its cycle includes\n"
              "           its drive models\n",
              o.sim_cycle_us / 1000.0);
  std::printf("  every axis enabled and moving in profile position (0 <-> %.0f rev); %d measured cycles per bus\n"
              "  and node count, the bus types alternating in blocks of %d; thread CPU time, clock overhead\n"
              "  (p50 %.3f us) subtracted from every sample; allocations = heap allocations in the measured calls\n",
              kMoveEnd, o.cycles, o.block, static_cast<double>(overhead_ns) / 1000.0);
  std::printf("\n%5s  %-11s %9s %9s %9s %13s %22s %11s\n", "nodes", "bus", "p50 [us]", "p99 [us]", "max [us]",
              "p50/node [us]", "block p50 min..max", "allocations");
  for (const Row& r : rows) {
    print_samples(r.nodes, "canopen", *r.canopen);
    print_samples(r.nodes, "sim", *r.sim);
    const auto ratio = [&](double p) {
      const double s = percentile(r.sim->us, p);
      return s > 0.0 ? percentile(r.canopen->us, p) / s : 0.0;
    };
    std::printf("%5d  %-11s %9.2f %9.2f %9.2f\n", r.nodes, "canopen/sim", ratio(50.0), ratio(99.0), ratio(100.0));
  }

  std::printf("\nwhat the measured cycles carried (canopen bus):\n");
  int width = 0;
  for (const Row& r : rows) width = std::max(width, static_cast<int>(r.load_text.size()));
  std::printf("%5s  %-*s %9s %12s %11s %10s %7s %7s %6s %11s %15s\n", "nodes", width, "load estimate (--check-config)",
              "wire load", "frames/cycle", "TPDOs/cycle", "unexpected", "missed", "refused", "moves", "moves (sim)",
              "drives p50 [us]");
  const auto u = [](std::uint64_t v) { return static_cast<unsigned long long>(v); };
  for (const Row& r : rows)
    std::printf("%5d  %-*s %8.0f%% %12.1f %11.1f %10llu %7llu %7llu %6llu %11llu %15.2f\n", r.nodes, width,
                r.load_text.c_str(), r.wire_load * 100.0, r.frames_per_cycle, r.tpdos_per_cycle, u(r.unexpected),
                u(r.missed), u(r.refused), u(r.moves_canopen), u(r.moves_sim), percentile(r.canopen->drives_us, 50.0));
  bool healthy = true;
  for (const Row& r : rows) {
    if (r.not_enabled == 0 && r.failures == 0) continue;
    healthy = false;
    std::printf("%d nodes: %zu axes not enabled at the end, %llu commands failed (%s): the figures are not representative\n",
                r.nodes, r.not_enabled, static_cast<unsigned long long>(r.failures), r.first_failure.c_str());
  }
  return healthy ? 0 : 1;
}

}  // namespace
}  // namespace drivegate::bench

int main(int argc, char** argv) { return drivegate::bench::run(argc, argv); }
