// The demo axes as the benchmark's cycle work: config/demo.yaml (or --config FILE) compiled, its
// first bus built and run through a BusRunner exactly as drivegated does, with every axis enabled
// and kept busy: position axes move back and forth, velocity axes jog on streamed set-points.
// Commands and drains happen on the cycle thread itself (it is the only producer and consumer
// here), so the measured cycle includes queue traffic too.
#include <cstring>
#include <memory>
#include <string>

#include "bench/workload.hpp"
#include "config/loader.hpp"
#include "core/bus_runner.hpp"
#include "daemon/bus_factory.hpp"

namespace drivegate::bench {

namespace {
struct DemoAxes {
  config::Plan plan;
  std::vector<core::AxisSpec> specs;
  std::unique_ptr<core::Bus> bus;
  std::unique_ptr<core::BusRunner> runner;
  core::CommandId next_id = 1;

  void command(core::AxisIndex axis, core::CommandKind kind, double value) noexcept {
    core::Command c;
    c.id = next_id++;
    c.axis = axis;
    c.kind = kind;
    c.position = value;
    c.velocity = kind == core::CommandKind::Velocity ? value : 0;
    runner->push_command(c);
  }

  void cycle(core::TimePoint now, std::uint64_t n) noexcept {
    const auto axes = static_cast<core::AxisIndex>(specs.size());
    if (n == 1)
      for (core::AxisIndex a = 0; a < axes; ++a) command(a, core::CommandKind::Enable, 0);
    if (n > 500 && n % 2000 == 0) {
      const double sign = (n / 2000) % 2 == 0 ? 1.0 : -1.0;
      for (core::AxisIndex a = 0; a < axes; ++a) {
        const auto& s = specs[a];
        if (s.default_mode == core::Mode::ProfilePosition)
          command(a, core::CommandKind::Move, sign > 0 ? s.limits.max_position / 4 : 0);
        else if (s.modes.contains(core::Mode::ProfileVelocity))
          command(a, core::CommandKind::Velocity, sign * s.limits.max_velocity / 4);
      }
    }
    for (core::AxisIndex a = 0; a < axes; ++a) {
      if (specs[a].default_mode != core::Mode::ProfileVelocity) continue;
      core::Setpoint sp;
      sp.axis = a;
      sp.velocity = runner->snapshot(a).velocity;  // keep-alive at the present speed
      runner->push_setpoint(sp);
    }
    runner->cycle(now);
    core::Reply r;
    while (runner->pop_reply(r)) {
    }
    core::Event e;
    while (runner->pop_event(e)) {
    }
  }
};
}  // namespace

std::function<void(core::TimePoint, std::uint64_t)> make_workload(int argc, char** argv) {
  std::string path = DRIVEGATE_DEMO_CONFIG;
  for (int i = 1; i + 1 < argc; ++i)
    if (std::strcmp(argv[i], "--config") == 0) path = argv[i + 1];
  auto w = std::make_shared<DemoAxes>();
  w->plan = config::load_plan(path);
  const auto& bus_plan = w->plan.buses.at(0);
  for (const auto& a : bus_plan.axes) w->specs.push_back(a.spec);
  w->bus = daemon::make_bus(bus_plan);
  w->runner = std::make_unique<core::BusRunner>(*w->bus, w->specs);
  w->bus->open(core::SteadyClock{}.now());
  std::printf("workload: bus '%s' (%s) from %s with %zu axes\n", bus_plan.name.c_str(), bus_plan.type.c_str(),
              path.c_str(), w->specs.size());
  return [w](core::TimePoint now, std::uint64_t n) { w->cycle(now, n); };
}

}  // namespace drivegate::bench
