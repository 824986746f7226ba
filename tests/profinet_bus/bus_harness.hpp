#pragma once
// A PROFINET bus from a plan on simulated devices in the same process (sim_transport.hpp): two
// Kollmorgen AKDs (telegram 1 and 9) and a generic IO device, each coming up with its name and
// without an IP address (the controller assigns it), run through a BusRunner on virtual time as
// drivegated's cycle thread runs it.
#include <gtest/gtest.h>

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "adapters/profinet/profinet_bus.hpp"
#include "adapters/profinet/sim/akd_persona.hpp"
#include "adapters/profinet/sim/generic_io_persona.hpp"
#include "adapters/profinet/sim/pn_sim_network.hpp"
#include "adapters/profinet/sim_transport.hpp"
#include "config/loader.hpp"
#include "core/bus_runner.hpp"

namespace drivegate::profinet::test {

using namespace std::chrono_literals;

inline constexpr std::uint16_t kVendor = 0x0118;  // [sim]
inline constexpr std::uint16_t kAkdDevice = 0x0501;
inline constexpr std::uint16_t kIoDevice = 0x0042;

inline const char* kNetwork = R"(gateway: { name: pn-test }
buses:
  - name: pn0
    type: profinet
    cycle_time: 1ms
    options: { interface: sim0, reduction_ratio: 16 }
    devices:
      - { station: akd-x, ip: 192.168.0.10 }
      - { station: akd-y, ip: 192.168.0.11 }
      - { station: io-block, ip: 192.168.0.20, vendor_id: 0x0118, device_id: 0x0042 }
    io:
      - name: panel
        station: io-block
        dap_ident: 0x10
        slots:
          - { slot: 1, module_ident: 0x20, submodule_ident: 0x21, inputs: 2 }
          - { slot: 2, module_ident: 0x30, submodule_ident: 0x31, outputs: 4 }
axes:
  - { name: x, bus: pn0, address: 1, device: kollmorgen-akd-profinet, profinet: { station: akd-x, telegram: 1 } }
  - { name: y, bus: pn0, address: 2, device: kollmorgen-akd-profinet, profinet: { station: akd-y, telegram: 9 } }
)";

inline config::LoadOptions load_options() {
  config::LoadOptions o;
  o.device_dirs = {DRIVEGATE_DEVICE_DIR_SOURCE};
  o.bus_types = config::BusTypeRegistry::builtin();
  return o;
}

inline MacAddress sim_mac(std::uint8_t n) { return {0x02, 0x1B, 0x1B, 0x00, 0x0A, n}; }

// The simulated devices; the transport's `keep` holds it.
struct SimDevices {
  SimDevices() {
    akd_x = std::make_unique<AkdPersona>(AkdPersonaConfig{});
    akd_y = std::make_unique<AkdPersona>(AkdPersonaConfig{});
    io = std::make_unique<GenericIoPersona>(GenericIoPersonaConfig{
        {{0, 0, 0x10, {{1, 0x1, 0, 0}}}, {0, 1, 0x20, {{1, 0x21, 2, 0}}}, {0, 2, 0x30, {{1, 0x31, 0, 4}}}}, kVendor, "IO-1",
        "1"});
    x = &net.add(config(1, "akd-x", "AKD", kAkdDevice), *akd_x);
    y = &net.add(config(2, "akd-y", "AKD", kAkdDevice), *akd_y);
    block = &net.add(config(3, "io-block", "IO", kIoDevice), *io);
  }
  static PnDeviceConfig config(std::uint8_t n, std::string name, std::string type, std::uint16_t device) {
    PnDeviceConfig c;
    c.dcp.mac = sim_mac(n);
    c.dcp.type_of_station = std::move(type);
    c.dcp.vendor_id = kVendor;
    c.dcp.device_id = device;
    c.dcp.name_of_station = std::move(name);
    c.activity = {0xA0000000U + n, 0, 0, {1, 2, 3, 4, 5, 6, 7, n}};
    return c;
  }
  std::unique_ptr<AkdPersona> akd_x, akd_y;
  std::unique_ptr<GenericIoPersona> io;
  PnSimNetwork net;
  PnDevice* x = nullptr;
  PnDevice* y = nullptr;
  PnDevice* block = nullptr;
};

struct PnHarness {
  // `wrap` may replace parts of the transport before the bus takes it (recorders).
  explicit PnHarness(const std::string& yaml = kNetwork, const std::function<void(ProfinetTransport&)>& wrap = {})
      : plan(config::load_plan_from_string(yaml, "pn-test.yaml", load_options())) {
    const auto& bp = plan.buses.at(0);
    for (const auto& a : bp.axes) specs.push_back(a.spec);
    auto devices = std::make_shared<SimDevices>();
    sim = devices.get();
    SimControllerAddress address;
    address.ip = 0xC0A80001;  // 192.168.0.1
    ProfinetTransport transport = sim_transport(sim->net, devices, address);
    if (wrap) wrap(transport);
    bus = std::make_unique<ProfinetBus>(bp, std::move(transport));
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
  void run_for(core::Duration d) {
    const auto end = now + d;
    while (now < end) cycle();
  }
  core::AxisSnapshot snap(const std::string& name) const { return runner->snapshot(axis(name)); }
  core::LinkState link(const std::string& name) const { return bus->link_state(axis(name)); }
  bool up(const std::string& name) const {
    return link(name) == core::LinkState::Operational && snap(name).state != core::AxisState::Unknown;
  }
  bool all_up() const {
    if (bus->phase(2) != ProfinetBus::Phase::Running) return false;
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
  std::string details() const {
    std::string s;
    for (std::size_t k = 0; k < bus->device_count(); ++k) s += std::string(bus->device_detail(k)) + "\n";
    return s;
  }

  config::Plan plan;
  std::vector<core::AxisSpec> specs;
  SimDevices* sim = nullptr;  // owned by the bus' transport
  std::unique_ptr<ProfinetBus> bus;
  std::unique_ptr<core::BusRunner> runner;
  core::TimePoint now{};
  core::CommandId next_id = 1;
  std::vector<core::Reply> replies;
  std::vector<core::Event> events;
};

}  // namespace drivegate::profinet::test
