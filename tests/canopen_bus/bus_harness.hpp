#pragma once
// A CANopen bus with simulated drives on the wire-emulating in-process bus, run through a
// BusRunner on virtual time as drivegated's cycle thread runs it.
#include <gtest/gtest.h>

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "adapters/canopen/canopen_bus.hpp"
#include "adapters/canopen/sim/sim_network.hpp"
#include "config/loader.hpp"
#include "core/bus_runner.hpp"
#include "tests/support/param_request.hpp"

namespace drivegate::canopen::test {

using namespace std::chrono_literals;

// AKD on node 1, NORD SK 500P on node 2, STÖBER SD6 on node 3, 4 ms SYNC at 1 Mbit/s.
inline const char* kThreeDrives = R"(gateway: { name: bus-test }
buses:
  - { name: can0, type: canopen, cycle_time: 4ms, options: { transport: sim, bitrate: 1000000 } }
axes:
  - { name: akd, bus: can0, address: 1, device: kollmorgen-akd, unit: mm, mechanics: { feed: 5 },
      defaults: { velocity: 50, acceleration: 500, deceleration: 500 }, homing: { method: 35 } }
  - { name: nord, bus: can0, address: 2, device: nord-sk500p,
      defaults: { velocity: 10, acceleration: 100, deceleration: 100 }, homing: { method: 35 } }
  - { name: sd6, bus: can0, address: 3, device: stoeber-sd6, mechanics: { encoder_counts_per_rev: 10000 },
      defaults: { velocity: 10, acceleration: 100, deceleration: 100 }, homing: { method: 35 } }
)";

struct BusHarness {
  explicit BusHarness(const std::string& yaml = kThreeDrives)
      : plan(config::load_plan_from_string(yaml, "bus-test.yaml")) {
    const auto& bp = plan.buses.at(0);
    for (const auto& a : bp.axes) specs.push_back(a.spec);
    auto wiring = sim::SimPeer::wire(bp);
    peer = wiring.peer.get();
    bus = std::make_unique<CanopenBus>(bp, std::move(wiring.gateway), std::move(wiring.peer));
    runner = std::make_unique<core::BusRunner>(*bus, specs);
    bus->open(now);
    replies.reserve(4096);
    events.reserve(4096);
  }

  core::AxisIndex axis(const std::string& name) const {
    for (std::size_t i = 0; i < specs.size(); ++i)
      if (specs[i].name == name) return static_cast<core::AxisIndex>(i);
    throw std::runtime_error("no axis " + name);
  }
  sim::SlaveNode& drive(const std::string& name) {
    return *peer->network().find(static_cast<NodeId>(plan.buses[0].axes[axis(name)].address));
  }

  void cycle() {
    now += plan.buses[0].cycle_time;
    runner->cycle(now);
    core::Reply r;
    while (runner->pop_reply(r)) replies.push_back(r);
    core::Event e;
    while (runner->pop_event(e)) events.push_back(e);
  }
  // Cycles until `done` or the virtual time budget runs out; true when done.
  bool run_until(const std::function<bool()>& done, core::Duration budget) {
    const auto end = now + budget;
    while (now < end) {
      if (done()) return true;
      cycle();
    }
    return done();
  }
  core::AxisSnapshot snap(const std::string& name) const { return runner->snapshot(axis(name)); }
  bool all_operational() const {
    for (std::size_t i = 0; i < specs.size(); ++i)
      if (bus->link_state(i) != core::LinkState::Operational) return false;
    return true;
  }
  // Every link operational and every drive's state known: commands are accepted.
  bool all_up() const {
    if (!all_operational()) return false;
    for (const auto& s : specs)
      if (snap(s.name).state == core::AxisState::Unknown) return false;
    return true;
  }

  core::CommandId push(const std::string& name, core::CommandKind kind, double position = 0, double velocity = 0) {
    core::Command c;
    c.id = next_id++;
    c.axis = axis(name);
    c.kind = kind;
    c.position = position;
    c.velocity = velocity;
    EXPECT_TRUE(runner->push_command(c));
    return c.id;
  }
  // The final status of command `id` (Accepted when it did not finish within the budget).
  core::ReplyStatus wait_final(core::CommandId id, core::Duration budget) {
    core::ReplyStatus status = core::ReplyStatus::Accepted;
    run_until([&] {
      for (const auto& r : replies)
        if (r.id == id && r.status != core::ReplyStatus::Accepted) {
          status = r.status;
          return true;
        }
      return false;
    }, budget);
    return status;
  }
  // A parameter request through the runner, cycled until its reply arrives (2 s of virtual time).
  core::ParamReply param(const std::string& name, bool write, std::uint16_t index, std::uint8_t sub,
                         core::ParamType type, std::string_view value = {}) {
    core::ParamRequest r = write ? drivegate::test::param_write(next_id++, index, sub, type, value)
                                 : drivegate::test::param_read(next_id++, index, sub, type);
    r.axis = axis(name);
    EXPECT_TRUE(runner->push_parameter(r));
    core::ParamReply reply;
    EXPECT_TRUE(run_until([&] { return runner->pop_parameter_reply(reply); }, 2s)) << name << " " << index;
    return reply;
  }
  std::string reason(core::CommandId id) const {
    for (const auto& r : replies)
      if (r.id == id && r.status != core::ReplyStatus::Accepted) return std::string(r.reason.view());
    return {};
  }
  std::string events_text() const {
    std::string s;
    for (const auto& e : events) s += std::string(core::to_string(e.kind)) + ": " + std::string(e.text.view()) + "\n";
    return s;
  }

  config::Plan plan;
  std::vector<core::AxisSpec> specs;
  sim::SimPeer* peer = nullptr;
  std::unique_ptr<CanopenBus> bus;
  std::unique_ptr<core::BusRunner> runner;
  core::TimePoint now{};
  core::CommandId next_id = 1;
  std::vector<core::Reply> replies;
  std::vector<core::Event> events;
};

}  // namespace drivegate::canopen::test
