// CPU time per cycle of drivegate's side of an EtherCAT bus: BusRunner::cycle, that is
// EthercatBus::receive -> the CiA 402 master of every axis -> EthercatBus::transmit, with N
// generic-cia402 drives (every axis enabled and moving in profile position), at 1 kHz on an
// absolute clock_nanosleep schedule (real time), on two links:
//
//   memory: the bus sends on an in-process link that keeps the frames; after the measured cycle
//           the simulated line (sim::build_line, the personas drivegate-sim uses) answers them and
//           runs its PDI side, measured apart ("sim" columns), so the bus figure is the gateway's
//           alone. The answers are read by the next cycle's receive, as on a real line.
//   veth:   the bus on RawSocketLink at one end of a veth pair (namespace A), the same simulated
//           line behind a SimEndpoint on the other end (namespace B) in a thread of this process;
//           the bus figure includes the system calls (sendmmsg/recvmmsg), the sim thread's CPU is
//           read from its own clock.
//
// Half a period after each bus cycle the same thread wakes once more from an absolute sleep and
// does nothing: that bare timer's lateness, measured in the same run, is the floor the machine
// gives; the bus cycle's own lateness is compared with it.
//
// Counted over the measured cycles: working-counter errors and lost cycles (CyclicExchange), frames
// lost (the bus), heap allocations inside the measured calls (expected 0). Figures only.
#include <pthread.h>
#include <time.h>

#include <algorithm>
#include <atomic>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "adapters/ethercat/bus_type.hpp"
#include "adapters/ethercat/ethercat_bus.hpp"
#include "adapters/ethercat/link/ethercat_link.hpp"
#include "adapters/ethercat/sim/line_builder.hpp"
#include "adapters/ethercat/sim/sim_endpoint.hpp"
#include "config/loader.hpp"
#include "core/bus_runner.hpp"
#include "tests/support/alloc_counter.hpp"
#include "tests/support/netns.hpp"

namespace drivegate::bench {
namespace {

using namespace std::chrono_literals;
using ethercat::FrameBuffer;
using ethercat::FrameView;

struct Options {
  int cycles = 100'000;
  std::vector<int> slaves{1, 8, 64};
  std::vector<std::string> links{"memory", "veth"};
  int period_us = 1000;
  int lost_cycles = 0;  // 0: the bus' default (3)
  bool no_dc = false;   // --no-dc: the bus option distributed_clocks: false (the drives run free)
};

std::optional<int> parse_int(std::string_view s) {
  int value = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (ec != std::errc{} || end != s.data() + s.size()) return std::nullopt;
  return value;
}

std::vector<std::string> split(std::string_view s) {
  std::vector<std::string> out;
  while (!s.empty()) {
    const std::size_t comma = s.find(',');
    out.emplace_back(s.substr(0, comma));
    s = comma == std::string_view::npos ? std::string_view{} : s.substr(comma + 1);
  }
  return out;
}

std::optional<Options> parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg(argv[i]);
    if (arg == "--no-dc") {
      o.no_dc = true;
      continue;
    }
    if (arg == "--help" || arg == "-h" || i + 1 >= argc) return std::nullopt;
    const std::string_view value(argv[++i]);
    if (arg == "--slaves") {
      o.slaves.clear();
      for (const auto& s : split(value)) {
        const auto n = parse_int(s);
        if (!n || *n < 1 || *n > 64) return std::nullopt;
        o.slaves.push_back(*n);
      }
      if (o.slaves.empty()) return std::nullopt;
      continue;
    }
    if (arg == "--links") {
      o.links = split(value);
      for (const auto& l : o.links)
        if (l != "memory" && l != "veth") return std::nullopt;
      continue;
    }
    const auto n = parse_int(value);
    if (!n || *n <= 0) return std::nullopt;
    if (arg == "--cycles") o.cycles = *n;
    else if (arg == "--period-us") o.period_us = *n;
    else if (arg == "--lost-cycles") o.lost_cycles = *n;
    else return std::nullopt;
  }
  return o;
}

std::int64_t cpu_ns(clockid_t clock) noexcept {
  timespec ts{};
  clock_gettime(clock, &ts);
  return std::int64_t{ts.tv_sec} * 1'000'000'000 + ts.tv_nsec;
}
std::int64_t thread_cpu_ns() noexcept { return cpu_ns(CLOCK_THREAD_CPUTIME_ID); }
std::int64_t mono_ns() noexcept { return cpu_ns(CLOCK_MONOTONIC); }

void sleep_until_ns(std::int64_t t) noexcept {
  timespec ts{};
  ts.tv_sec = t / 1'000'000'000;
  ts.tv_nsec = t % 1'000'000'000;
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) != 0) {
  }
}

std::int64_t timer_overhead_ns() {
  std::vector<std::int64_t> d(10'001);
  for (auto& x : d) {
    const std::int64_t t0 = thread_cpu_ns();
    x = thread_cpu_ns() - t0;
  }
  std::nth_element(d.begin(), d.begin() + 5'000, d.end());
  return d[5'000];
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const auto rank = static_cast<std::size_t>(std::max(1.0, std::ceil(p / 100.0 * static_cast<double>(v.size()))));
  return v[std::min(rank, v.size()) - 1];
}

config::LoadOptions load_options() {
  config::LoadOptions o;
  o.bus_types = config::BusTypeRegistry::builtin();
  return o;
}

std::string plan_yaml(const Options& o, int slaves, const std::string& interface) {
  std::string y = "gateway: { name: bench }\nbuses:\n  - name: ec0\n    type: ethercat\n    cycle_time: " +
                  std::to_string(o.period_us) + "us\n";
  std::string lost = o.lost_cycles > 0 ? ", lost_cycles: " + std::to_string(o.lost_cycles) : "";
  if (o.no_dc) lost += ", distributed_clocks: false";
  y += interface.empty() ? "    options: { transport: sim" + lost + " }\n"
                         : "    options: { transport: raw, interface: " + interface + lost + " }\n";
  y += "axes:\n";
  for (int i = 1; i <= slaves; ++i)
    y += "  - { name: a" + std::to_string(i) + ", bus: ec0, address: " + std::to_string(i) +
         ", device: generic-cia402, mechanics: { encoder_counts_per_rev: 10000 },"
         " limits: { max_velocity: 20, max_acceleration: 200 },"
         " defaults: { mode: pp, velocity: 10, acceleration: 100, deceleration: 100 } }\n";
  return y;
}

// The in-process wire with the answers deferred: send() copies the frames (as a socket would),
// flush() passes them through the simulated line outside the measured region.
class DeferredLink final : public ethercat::Link {
 public:
  explicit DeferredLink(std::shared_ptr<ethercat::sim::BuiltLine> line) : line_(std::move(line)) {}
  void open() override { line_->open(); }
  void close() noexcept override { line_->link().close(); }
  [[nodiscard]] bool is_open() const noexcept override { return line_->link().is_open(); }
  using Link::send;
  ethercat::SendResult send(std::span<const FrameView> frames) noexcept override {
    ethercat::SendResult r;
    for (const FrameView f : frames) {
      if (count_ == held_.size()) {
        ++r.unsent;
        r.status = ethercat::SendStatus::Busy;
        continue;
      }
      std::copy(f.begin(), f.end(), held_[count_].bytes.begin());
      held_[count_++].size = f.size();
      ++r.sent;
    }
    return r;
  }
  std::size_t receive(std::span<FrameBuffer> out) noexcept override { return line_->link().receive(out); }
  [[nodiscard]] int wait_fd() const noexcept override { return -1; }
  ethercat::LinkState poll_state(core::TimePoint now) noexcept override { return line_->link().poll_state(now); }
  [[nodiscard]] ethercat::LinkState state() const noexcept override { return line_->link().state(); }
  [[nodiscard]] ethercat::LinkCounters counters() const noexcept override { return line_->link().counters(); }
  [[nodiscard]] std::string describe() const override { return "deferred memory link"; }

  // The line answers the frames sent since the last flush and runs its PDI side at `now_ns`.
  void flush(std::uint64_t now_ns) noexcept {
    for (std::size_t i = 0; i < count_; ++i) line_->pass(held_[i].view(), now_ns);
    count_ = 0;
    line_->tick(now_ns);
  }

 private:
  std::shared_ptr<ethercat::sim::BuiltLine> line_;
  std::array<FrameBuffer, 16> held_{};
  std::size_t count_ = 0;
};

constexpr double kMoveEnd = 10.0;

struct Row {
  std::string link;
  int slaves = 0;
  std::string refused;  // the plan or the bus refused the line
  std::vector<double> bus_us, sim_us, late_bus_us, late_bare_us;
  double sim_thread_us_per_cycle = -1;  // veth: the endpoint thread's CPU over the measured cycles
  std::uint64_t wkc_errors = 0, lost_cycles = 0, frames_lost = 0, frames_sent = 0, good = 0, moves = 0;
  std::size_t allocations = 0;
  std::size_t not_enabled = 0;
};

class Rig {
 public:
  Rig(const Options& o, int slaves, bool veth) : o_(o), veth_(veth) {
    if (veth_) {
      ns_a_ = std::make_unique<test::NetNamespace>();
      ns_b_ = std::make_unique<test::NetNamespace>();
      pair_ = std::make_unique<test::VethPair>(ns_a_.get(), ns_b_.get());
    }
    {
      // A raw transport's interface is looked at from namespace A, where it is.
      std::optional<test::NetnsScope> in;
      if (veth_) in.emplace(*ns_a_);
      plan_ = config::load_plan_from_string(plan_yaml(o, slaves, veth_ ? pair_->a() : ""), "bench.yaml", load_options());
    }
    const auto& bp = plan_.buses.at(0);
    for (const auto& a : bp.axes) specs_.push_back(a.spec);
    line_ = ethercat::sim::build_line(bp);
    if (veth_) {
      // The line behind a SimEndpoint on end b, serviced by a thread in namespace B.
      std::atomic<int> ready{0};
      sim_thread_ = std::thread([this, &ready] {
        try {
          const test::NetnsScope in(*ns_b_);
          wire_ = std::make_unique<ethercat::RawSocketLink>(ethercat::RawSocketOptions{.interface = pair_->b()});
          wire_->open();
        } catch (const std::exception& e) {
          std::fprintf(stderr, "sim endpoint: %s\n", e.what());
          ready = -1;
          return;
        }
        ethercat::sim::SimEndpoint endpoint(*wire_, *line_);
        pthread_getcpuclockid(pthread_self(), &sim_clock_);
        ready = 1;
        ethercat::sim::run_endpoint(endpoint, stop_);
      });
      while (ready == 0) std::this_thread::sleep_for(1ms);
      if (ready < 0) throw std::runtime_error("the simulated line's endpoint did not open");
      bus_ = std::make_unique<ethercat::EthercatBus>(
          bp, std::make_unique<ethercat::RawSocketLink>(ethercat::RawSocketOptions{.interface = pair_->a()}));
    } else {
      auto link = std::make_unique<DeferredLink>(line_);
      deferred_ = link.get();
      bus_ = std::make_unique<ethercat::EthercatBus>(bp, std::move(link));
    }
    runner_ = std::make_unique<core::BusRunner>(*bus_, specs_);
    pending_.assign(specs_.size(), 0);
    target_.assign(specs_.size(), 0.0);
    const std::int64_t t = mono_ns();
    if (veth_) {
      const test::NetnsScope in(*ns_a_);
      bus_->open(core::TimePoint(core::Duration(t)));
    } else {
      bus_->open(core::TimePoint(core::Duration(t)));
    }
    next_ = t + period_ns();
  }
  ~Rig() {
    runner_.reset();
    if (bus_) bus_->close();
    stop_ = true;
    if (sim_thread_.joinable()) sim_thread_.join();
  }
  Rig(const Rig&) = delete;
  Rig& operator=(const Rig&) = delete;

  std::int64_t period_ns() const { return std::int64_t{o_.period_us} * 1000; }

  // One period: the bus cycle at its slot (measured when `row`), the line (memory), the control
  // plane, then the bare timer wake half a period later.
  void period(Row* row, std::int64_t overhead_ns) {
    sleep_until_ns(next_);
    const std::int64_t woke = mono_ns();
    const core::TimePoint now{core::Duration(woke)};
    const std::int64_t c0 = thread_cpu_ns();
    std::size_t allocs = 0;
    {
      const test::AllocationScope scope;
      runner_->cycle(now);
      allocs = scope.count();
    }
    const std::int64_t c1 = thread_cpu_ns();
    if (deferred_ != nullptr) deferred_->flush(static_cast<std::uint64_t>(woke));
    const std::int64_t c2 = thread_cpu_ns();
    control();
    sleep_until_ns(next_ + period_ns() / 2);
    const std::int64_t bare = mono_ns();
    if (row != nullptr) {
      const auto us = [overhead_ns](std::int64_t ns) {
        return static_cast<double>(std::max<std::int64_t>(0, ns - overhead_ns)) / 1000.0;
      };
      row->bus_us.push_back(us(c1 - c0));
      if (deferred_ != nullptr) row->sim_us.push_back(us(c2 - c1));
      row->late_bus_us.push_back(static_cast<double>(woke - next_) / 1000.0);
      row->late_bare_us.push_back(static_cast<double>(bare - (next_ + period_ns() / 2)) / 1000.0);
      row->allocations += allocs;
    }
    next_ += period_ns();
    // After an overrun the schedule resumes at the next slot (missed slots are not made up).
    const std::int64_t t = mono_ns();
    if (next_ < t) next_ += ((t - next_) / period_ns() + 1) * period_ns();
  }

  bool bring_up() {
    if (!run_until([&] { return all_up(); }, 60s)) {
      std::fprintf(stderr, "the axes did not come up: %s\n", std::string(bus_->slave_detail(0)).c_str());
      return false;
    }
    for (std::size_t a = 0; a < specs_.size(); ++a) pending_[a] = push(a, core::CommandKind::Enable, 0.0);
    if (!run_until([&] { return idle(); }, 10s) || failures_ > 0) {
      std::fprintf(stderr, "enabling failed (%s)\n", first_failure_.c_str());
      return false;
    }
    moving_ = true;
    for (std::size_t a = 0; a < specs_.size(); ++a) {
      target_[a] = kMoveEnd;
      move(a);
    }
    return true;
  }

  void measure(Row& row, int cycles, std::int64_t overhead_ns) {
    row.bus_us.reserve(static_cast<std::size_t>(cycles));
    row.sim_us.reserve(static_cast<std::size_t>(cycles));
    row.late_bus_us.reserve(static_cast<std::size_t>(cycles));
    row.late_bare_us.reserve(static_cast<std::size_t>(cycles));
    const ethercat::CyclicExchange* cx = bus_->exchange();
    if (cx == nullptr) return;  // no image: bring_up() failed first
    const auto cx0 = cx->counters();
    const auto bc0 = bus_->counters();
    const std::uint64_t moves0 = moves_;
    const std::int64_t sim0 = veth_ ? cpu_ns(sim_clock_) : 0;
    for (int i = 0; i < cycles; ++i) period(&row, overhead_ns);
    if (veth_) row.sim_thread_us_per_cycle = static_cast<double>(cpu_ns(sim_clock_) - sim0) / 1000.0 / cycles;
    const auto cx1 = cx->counters();
    const auto bc1 = bus_->counters();
    row.wkc_errors = cx1.wkc_errors - cx0.wkc_errors;
    row.lost_cycles = cx1.lost - cx0.lost;
    row.good = cx1.good - cx0.good;
    row.frames_lost = bc1.frames_lost - bc0.frames_lost;
    row.frames_sent = bc1.frames_sent - bc0.frames_sent;
    row.moves = moves_ - moves0;
    for (std::size_t a = 0; a < specs_.size(); ++a)
      if (runner_->snapshot(a).state != core::AxisState::OperationEnabled) ++row.not_enabled;
  }

 private:
  template <typename Done>
  bool run_until(Done done, core::Duration budget) {
    const auto cycles = budget / std::chrono::microseconds(o_.period_us);
    for (std::int64_t i = 0; i < cycles; ++i) {
      if (done()) return true;
      period(nullptr, 0);
    }
    return done();
  }
  bool all_up() const {
    for (std::size_t a = 0; a < specs_.size(); ++a)
      if (bus_->link_state(a) != core::LinkState::Operational || runner_->snapshot(a).state == core::AxisState::Unknown)
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
  void control() {
    core::Reply r;
    while (runner_->pop_reply(r)) {
      if (r.axis >= pending_.size() || r.id != pending_[r.axis] || r.status == core::ReplyStatus::Accepted) continue;
      pending_[r.axis] = 0;
      if (r.status != core::ReplyStatus::Completed) {
        if (failures_++ == 0) first_failure_ = "axis " + std::to_string(r.axis + 1) + ": " + std::string(r.reason.view());
        continue;
      }
      if (!moving_) continue;
      ++moves_;
      target_[r.axis] = target_[r.axis] == 0.0 ? kMoveEnd : 0.0;
      move(r.axis);
    }
    core::Event e;
    while (runner_->pop_event(e)) {
    }
  }

  const Options& o_;
  bool veth_;
  std::unique_ptr<test::NetNamespace> ns_a_, ns_b_;
  std::unique_ptr<test::VethPair> pair_;
  config::Plan plan_;
  std::vector<core::AxisSpec> specs_;
  std::shared_ptr<ethercat::sim::BuiltLine> line_;
  std::unique_ptr<ethercat::RawSocketLink> wire_;  // the endpoint's end (namespace B)
  std::thread sim_thread_;
  std::atomic<bool> stop_{false};
  clockid_t sim_clock_{};
  DeferredLink* deferred_ = nullptr;
  std::unique_ptr<ethercat::EthercatBus> bus_;
  std::unique_ptr<core::BusRunner> runner_;
  std::int64_t next_ = 0;
  core::CommandId next_id_ = 1;
  std::vector<core::CommandId> pending_;
  std::vector<double> target_;
  bool moving_ = false;
  std::uint64_t moves_ = 0;
  std::uint64_t failures_ = 0;
  std::string first_failure_;
};

int run(const Options& o) {
  const std::int64_t overhead = timer_overhead_ns();
  std::printf("bench_ethercat_cycle: CPU per cycle of BusRunner::cycle (EthercatBus receive -> CiA 402 masters -> transmit)\n"
              "  generic-cia402 drives, every axis enabled and moving in profile position; %d us period on an absolute\n"
              "  clock_nanosleep schedule; %d measured cycles per row; thread CPU time, clock overhead (p50 %.3f us)\n"
              "  subtracted; 'sim' = the simulated line's CPU per cycle (memory: measured apart in the same thread;\n"
              "  veth: the endpoint thread's CPU / cycles); lateness of the bus cycle's wake vs a bare timer wake half a\n"
              "  period later in the same run\n\n",
              o.period_us, o.cycles, static_cast<double>(overhead) / 1000.0);
  if (o.no_dc) {
    std::printf("  --no-dc: WITHOUT distributed clocks (bus option distributed_clocks: false): no DC set-up, no FRMW,\n"
                "  the drives run free (not SYNC0-synchronized)\n\n");
  }
  std::vector<Row> rows;
  for (const auto& link : o.links) {
    if (link == "veth" && !test::netns_unavailable().empty()) {
      std::printf("veth: skipped (%s)\n", test::netns_unavailable().c_str());
      continue;
    }
    for (const int n : o.slaves) {
      Row row;
      row.link = link;
      row.slaves = n;
      try {
        Rig rig(o, n, link == "veth");
        if (!rig.bring_up()) {
          row.refused = "did not come up";
        } else {
          rig.measure(row, o.cycles, overhead);
        }
      } catch (const std::exception& e) {
        row.refused = e.what();
      }
      rows.push_back(std::move(row));
      std::fflush(stdout);
    }
  }
  std::printf("link   slaves  bus p50  bus p99  bus max p50/slave  sim p50 | late bus p50/p99/max   bare p50/p99/max  "
              "p99 ratio | wkc err lost cyc frames lost allocs moves\n");
  int status = 0;
  for (const auto& r : rows) {
    if (!r.refused.empty()) {
      std::printf("%-6s %6d  refused: %s\n", r.link.c_str(), r.slaves, r.refused.c_str());
      continue;
    }
    const double p50 = percentile(r.bus_us, 50);
    const double sim = r.sim_thread_us_per_cycle >= 0 ? r.sim_thread_us_per_cycle : percentile(r.sim_us, 50);
    const double lb99 = percentile(r.late_bus_us, 99), la99 = percentile(r.late_bare_us, 99);
    std::printf("%-6s %6d %8.2f %8.2f %8.1f %9.3f %8.2f%s| %6.1f %6.1f %8.1f %6.1f %6.1f %8.1f %6.2f | %7llu %8llu %11llu %6zu %5llu\n",
                r.link.c_str(), r.slaves, p50, percentile(r.bus_us, 99), percentile(r.bus_us, 100), p50 / r.slaves, sim,
                r.sim_thread_us_per_cycle >= 0 ? "*" : " ", percentile(r.late_bus_us, 50), lb99,
                percentile(r.late_bus_us, 100), percentile(r.late_bare_us, 50), la99, percentile(r.late_bare_us, 100),
                la99 > 0 ? lb99 / la99 : 0.0, static_cast<unsigned long long>(r.wkc_errors),
                static_cast<unsigned long long>(r.lost_cycles), static_cast<unsigned long long>(r.frames_lost),
                r.allocations, static_cast<unsigned long long>(r.moves));
    if (r.not_enabled > 0) {
      std::printf("       %zu axes were not enabled at the end\n", r.not_enabled);
      status = 1;
    }
  }
  std::printf("(* = mean of the endpoint thread's CPU per cycle; all figures in microseconds)\n");
  return status;
}

}  // namespace
}  // namespace drivegate::bench

int main(int argc, char** argv) {
  const auto o = drivegate::bench::parse(argc, argv);
  if (!o) {
    std::fprintf(stderr,
                 "usage: bench_ethercat_cycle [--cycles N (default 100000)] [--slaves LIST (default 1,8,64)]\n"
                 "                            [--links memory,veth] [--period-us N (default 1000)]\n"
                 "                            [--lost-cycles N (default: the bus' 3)] [--no-dc]\n");
    return 2;
  }
  return drivegate::bench::run(*o);
}
