#pragma once
// An EtherCAT bus from a plan on a MemoryLink with a SimLine of simulated slaves (ESR TrioDrive,
// a generic I/O slave, a generic CiA 402 drive), run through a BusRunner on virtual time as
// drivegated's cycle thread runs it.
#include <gtest/gtest.h>

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "adapters/ethercat/bus_type.hpp"
#include "adapters/ethercat/ethercat_bus.hpp"
#include "adapters/ethercat/link/ethercat_link.hpp"
#include "adapters/ethercat/sim/cia402_slave.hpp"
#include "adapters/ethercat/sim/generic_io.hpp"
#include "adapters/ethercat/sim/sim_line.hpp"
#include "config/loader.hpp"
#include "core/bus_runner.hpp"
#include "tests/support/param_request.hpp"

namespace drivegate::ethercat::test {

using namespace std::chrono_literals;

inline constexpr SiiIdentity kPanelId{0x00000099, 0x00001000, 1, 0};

// ESR at position 1, a 2-in/2-out I/O slave at 2, a generic CiA 402 drive at 3; 1 ms cycle.
inline const char* kLine = R"(gateway: { name: ecat-test }
buses:
  - name: ec0
    type: ethercat
    cycle_time: 1ms
    options: { transport: sim, lost_cycles: 3, boot_retry: 200ms, boot_retry_max: 1s }
    io:
      - { name: panel, position: 2, vendor_id: 0x99, product_code: 0x1000, inputs: 2, outputs: 2 }
axes:
  - { name: esr, bus: ec0, address: 1, device: esr-triodrive, mechanics: { encoder_counts_per_rev: 4096 } }
  - { name: gen, bus: ec0, address: 3, device: generic-cia402, mechanics: { encoder_counts_per_rev: 4096 } }
)";

inline config::LoadOptions load_options() {
  config::LoadOptions o;
  o.device_dirs = {DRIVEGATE_DEVICE_DIR_SOURCE};
  // The build's registry: it holds ethercat::bus_type() (daemon/bus_types.cpp).
  o.bus_types = config::BusTypeRegistry::builtin();
  return o;
}

// Steps the simulated line's PDI (watchdogs) with the cycle's time.
class LinePeer final : public CyclePeer {
 public:
  explicit LinePeer(sim::SimLine& line) : line_(line) {}
  void step(core::TimePoint now) noexcept override { line_.advance(static_cast<std::uint64_t>(core::to_ns(now))); }

 private:
  sim::SimLine& line_;
};

struct EcatHarness {
  explicit EcatHarness(const std::string& yaml = kLine, bool build = true)
      : plan(config::load_plan_from_string(yaml, "ecat-test.yaml", load_options())) {
    if (build) make();
  }

  // The line as kLine has it (or `with_generic_at_3 = false`: an I/O slave at position 3 instead).
  void make(bool swap_generic_for_esr = false) {
    const auto& bp = plan.buses.at(0);
    for (const auto& a : bp.axes) specs.push_back(a.spec);
    auto memory = std::make_unique<MemoryLink>(64);
    link = memory.get();
    line = std::make_unique<sim::SimLine>(*link);
    esr = sim::make_cia402_device(swap_generic_for_esr ? "generic-cia402" : "esr-triodrive");
    panel = std::make_unique<sim::GenericIoSlave>(2, 2, kPanelId);
    panel_esc = std::make_unique<sim::EscSlave>(sim::EscConfig{}, panel->sii(), panel.get());
    gen = sim::make_cia402_device("generic-cia402");
    line->add(*esr.esc);
    line->add(*panel_esc);
    line->add(*gen.esc);
    bus = std::make_unique<EthercatBus>(bp, std::move(memory), std::make_unique<LinePeer>(*line));
    runner = std::make_unique<core::BusRunner>(*bus, specs);
    bus->open(now);
    replies.reserve(4096);
    events.reserve(4096);
  }

  // The bus as the daemon makes it: the type's make_bus (transport sim: the line from the
  // profiles' personas, inside the bus).
  void make_from_factory() {
    const auto& bp = plan.buses.at(0);
    for (const auto& a : bp.axes) specs.push_back(a.spec);
    std::unique_ptr<core::Bus> made = bp.type_info->make_bus(bp);
    bus.reset(dynamic_cast<EthercatBus*>(made.release()));
    runner = std::make_unique<core::BusRunner>(*bus, specs);
    bus->open(now);
  }

  core::AxisIndex axis(const std::string& name) const {
    for (std::size_t i = 0; i < specs.size(); ++i)
      if (specs[i].name == name) return static_cast<core::AxisIndex>(i);
    throw std::runtime_error("no axis " + name);
  }
  void cycle() {
    now += plan.buses[0].cycle_time;
    runner->cycle(now);
    core::Reply r;
    while (runner->pop_reply(r)) replies.push_back(r);
    core::Event e;
    while (runner->pop_event(e)) events.push_back(e);
  }
  bool run_until(const std::function<bool()>& done, core::Duration budget) {
    const auto end = now + budget;
    while (now < end) {
      if (done()) return true;
      cycle();
    }
    return done();
  }
  core::AxisSnapshot snap(const std::string& name) const { return runner->snapshot(axis(name)); }
  bool up(const std::string& name) const {
    return bus->link_state(axis(name)) == core::LinkState::Operational && snap(name).state != core::AxisState::Unknown;
  }
  bool all_up() const {
    for (const auto& s : specs)
      if (!up(s.name)) return false;
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
  core::CommandId set_mode(const std::string& name, core::Mode m) {
    core::Command c;
    c.id = next_id++;
    c.axis = axis(name);
    c.kind = core::CommandKind::SetMode;
    c.mode = m;
    EXPECT_TRUE(runner->push_command(c));
    return c.id;
  }
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
  core::ParamReply param(const std::string& name, bool write, std::uint16_t index, std::uint8_t sub,
                         core::ParamType type, std::string_view value = {}) {
    core::ParamRequest r = write ? drivegate::test::param_write(next_id++, index, sub, type, value)
                                 : drivegate::test::param_read(next_id++, index, sub, type);
    r.axis = axis(name);
    EXPECT_TRUE(runner->push_parameter(r));
    core::ParamReply reply;
    EXPECT_TRUE(run_until([&] { return runner->pop_parameter_reply(reply); }, 3s)) << name << " " << index;
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
  const CyclicExchange& cx() const {
    const CyclicExchange* p = bus->exchange();
    if (p == nullptr) throw std::runtime_error("the bus has no process image yet");
    return *p;
  }
  std::string details() const {
    std::string s;
    for (std::size_t k = 0; k < bus->slave_count(); ++k) s += std::string(bus->slave_detail(k)) + "\n";
    return s;
  }

  config::Plan plan;
  std::vector<core::AxisSpec> specs;
  // Destroyed in reverse: the runner, the line (it refers to the bus' link), then the bus and the
  // simulated slaves.
  sim::Cia402Device esr;
  std::unique_ptr<sim::GenericIoSlave> panel;
  std::unique_ptr<sim::EscSlave> panel_esc;
  sim::Cia402Device gen;
  std::unique_ptr<EthercatBus> bus;
  MemoryLink* link = nullptr;
  std::unique_ptr<sim::SimLine> line;
  std::unique_ptr<core::BusRunner> runner;
  core::TimePoint now{};
  core::CommandId next_id = 1;
  std::vector<core::Reply> replies;
  std::vector<core::Event> events;
};

// The value of the n-th "label:" row of a --check-config printout.
inline std::string row(const std::string& out, const std::string& label, int n = 0) {
  std::size_t at = 0;
  for (;;) {
    at = out.find("  " + label + ": ", at);
    if (at == std::string::npos) return "(no row " + label + ")";
    if (n-- == 0) break;
    ++at;
  }
  const std::size_t start = out.find_first_not_of(' ', at + label.size() + 3);
  return out.substr(start, out.find('\n', start) - start);
}

}  // namespace drivegate::ethercat::test
