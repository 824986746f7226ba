// drivegate-sim: runs the simulated drives of a drivegate config's canopen buses on their
// udp-multicast bus, one SlaveNode per axis with its device profile's persona, so the daemon (or
// python-can) finds real-looking drives on the virtual CAN bus.
//
//   drivegate-sim CONFIG [--bus NAME]
//
// Steps every 1 ms on an absolute CLOCK_MONOTONIC schedule until SIGINT or SIGTERM. Fault
// injection comes on stdin, one command a line, each answered with one line on stdout (kCommands):
//   power-off NODE | power-on NODE | fault NODE CODE [CAUSE] | clear NODE | silent NODE on|off |
//   abort NODE INDEX[:SUB] CODE | corrupt NODE COUNT [dlc|garbage] |
//   service-write NODE INDEX[:SUB] VALUE SIZE | status
// NODE is a node-ID, or BUS:NODE when several buses have it; numbers are decimal or 0x hex.
#include <poll.h>
#include <signal.h>
#include <time.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <exception>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "adapters/canopen/canopen_bus.hpp"
#include "adapters/canopen/sim/sim_network.hpp"
#include "adapters/canopen/sim/slave_config.hpp"
#include "config/loader.hpp"

namespace {

using namespace drivegate;
using canopen::sim::FrameDamage;
using canopen::sim::SimNetwork;
using canopen::sim::SlaveNode;

volatile sig_atomic_t g_stop = 0;
extern "C" void on_signal(int) { g_stop = 1; }

constexpr long kPeriodNs = 1'000'000;          // 1 ms
constexpr long kResyncNs = 100 * kPeriodNs;    // behind by more: start the schedule again

struct SimBus {
  std::string name;
  std::unique_ptr<canopen::Transport> transport;
  std::unique_ptr<SimNetwork> network;
};

void say(const std::string& line) {
  std::fputs(line.c_str(), stdout);
  std::fputc('\n', stdout);
  std::fflush(stdout);
}

std::optional<unsigned long> parse_number(std::string_view s) {
  int base = 10;
  if (s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X')) {
    s.remove_prefix(2);
    base = 16;
  }
  unsigned long v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v, base);
  if (ec != std::errc{} || end != s.data() + s.size() || s.empty()) return std::nullopt;
  return v;
}

std::string hex4(unsigned v) {
  std::array<char, 8> b{};
  std::snprintf(b.data(), b.size(), "0x%04X", v);
  return b.data();
}

std::string hex8(std::uint32_t v) {
  std::array<char, 12> b{};
  std::snprintf(b.data(), b.size(), "0x%08X", static_cast<unsigned>(v));
  return b.data();
}

constexpr std::string_view kCommands =
    "power-off NODE, power-on NODE, fault NODE CODE [CAUSE], clear NODE, emcy NODE CODE REGISTER [BYTE3..BYTE7], "
    "silent NODE on|off, "
    "abort NODE INDEX[:SUB] CODE, corrupt NODE COUNT [dlc|garbage], service-write NODE INDEX[:SUB] VALUE SIZE, "
    "status";

std::string usage_of(const std::string& verb) {
  if (verb == "fault") return "NODE CODE [CAUSE]";
  if (verb == "emcy") return "NODE CODE REGISTER [BYTE3..BYTE7] (code 0x0000..0xFFFF, register and bytes 0..255)";
  if (verb == "silent") return "NODE on|off";
  if (verb == "abort") return "NODE INDEX[:SUB] CODE (hex index, e.g. abort 3 0x6081 0x06090031)";
  if (verb == "corrupt") return "NODE COUNT [dlc|garbage]";
  if (verb == "service-write") return "NODE INDEX[:SUB] VALUE SIZE (hex index, SIZE 1, 2 or 4 bytes)";
  return "NODE";
}

class Simulator {
 public:
  explicit Simulator(std::vector<SimBus> buses) : buses_(std::move(buses)) {}

  void step(core::TimePoint now) noexcept {
    for (auto& b : buses_) b.network->step(now);
  }

  // One command line in, one answer line out.
  std::string command(const std::string& line) {
    std::istringstream in(line);
    std::string verb;
    std::string node_text;
    in >> verb;
    if (verb.empty()) return "error: empty command";
    if (verb == "status") return status();
    if (verb != "power-off" && verb != "power-on" && verb != "fault" && verb != "clear" && verb != "silent" &&
        verb != "abort" && verb != "corrupt" && verb != "service-write" && verb != "emcy") {
      return "error: unknown command \"" + verb + "\" (" + std::string(kCommands) + ")";
    }
    in >> node_text;
    SlaveNode* node = nullptr;
    if (const auto error = find(node_text, node)) return "error: " + *error;
    const std::string id = "node " + std::to_string(node->node());
    std::string arg;
    in >> arg;
    if (verb == "power-off" && arg.empty()) {
      node->power_off();
      return "ok power-off " + id;
    }
    if (verb == "power-on" && arg.empty()) {
      node->power_on();
      return "ok power-on " + id;
    }
    if (verb == "clear" && arg.empty()) {
      node->clear_fault_cause();
      return "ok clear " + id;
    }
    if (verb == "silent" && (arg == "on" || arg == "off")) {
      node->set_silent(arg == "on");
      return "ok silent " + id + " " + arg;
    }
    const auto colon = arg.find(':');
    const auto index = parse_number(arg.substr(0, colon));
    const auto sub = colon == std::string::npos ? std::optional<unsigned long>{0} : parse_number(arg.substr(colon + 1));
    if (verb == "service-write" && !arg.empty()) {
      // A write through the drive's own service interface, not the bus: its configuration changes
      // behind the gateway's back.
      std::string value_text;
      std::string size_text;
      in >> value_text >> size_text;
      const auto value = parse_number(value_text);
      const auto size = parse_number(size_text);
      if (!index || *index > 0xFFFF || !sub || *sub > 0xFF || !value || *value > 0xFFFFFFFF || !size ||
          (*size != 1 && *size != 2 && *size != 4))
        return "error: service-write takes " + usage_of(verb);
      const auto code = node->service_write({static_cast<std::uint16_t>(*index), static_cast<std::uint8_t>(*sub)},
                                            static_cast<std::uint32_t>(*value), *size);
      if (code != 0) return "error: service-write refused by the drive: abort code " + hex8(code);
      return "ok service-write " + id;
    }
    if (verb == "abort" && !arg.empty()) {
      // The next SDO request for the object is answered with this abort code.
      std::string code_text;
      in >> code_text;
      const auto code = parse_number(code_text);
      if (!index || *index > 0xFFFF || !sub || *sub > 0xFF || !code || *code == 0 || *code > 0xFFFFFFFF) {
        return "error: abort takes " + usage_of(verb);
      }
      node->inject_sdo_abort({static_cast<std::uint16_t>(*index), static_cast<std::uint8_t>(*sub)},
                             static_cast<std::uint32_t>(*code));
      return "ok abort " + id;
    }
    if (verb == "corrupt" && !arg.empty()) {
      // The next COUNT frames the node sends get a wrong length or garbage data.
      std::string how;
      in >> how;
      const auto count = parse_number(arg);
      if (!count || *count == 0 || *count > 1000 || !(how.empty() || how == "dlc" || how == "garbage")) {
        return "error: corrupt takes " + usage_of(verb) + " with COUNT 1..1000";
      }
      node->damage_next(static_cast<std::uint32_t>(*count), how == "garbage" ? FrameDamage::Garbage : FrameDamage::WrongDlc);
      return "ok corrupt " + id;
    }
    if (verb == "emcy" && !arg.empty()) {
      // An EMCY that changes nothing in the drive: a warning, an error reset / no error (0000h).
      canopen::Emcy e;
      std::string register_text;
      in >> register_text;
      const auto code = parse_number(arg);
      const auto reg = parse_number(register_text);
      bool ok = code && *code <= 0xFFFF && reg && *reg <= 0xFF;
      std::size_t bytes = 0;
      for (std::string b; ok && in >> b; ++bytes) {
        const auto v = parse_number(b);
        ok = bytes < e.vendor.size() && v && *v <= 0xFF;
        if (ok) e.vendor[bytes] = static_cast<std::uint8_t>(*v);
      }
      if (!ok) return "error: emcy takes " + usage_of(verb);
      e.code = static_cast<std::uint16_t>(*code);
      e.error_register = static_cast<std::uint8_t>(*reg);
      if (!node->send_emcy(e)) return "error: " + id + " does not send EMCY now (NMT state, or its queue is full)";
      return "ok emcy " + id + " " + hex4(e.code);
    }
    if (verb == "fault") {
      std::string cause_text;
      in >> cause_text;
      const auto code = parse_number(arg);
      const auto cause = cause_text.empty() ? std::optional<unsigned long>{0} : parse_number(cause_text);
      if (!code || *code == 0 || *code > 0xFFFF || !cause || *cause > 0xFF) {
        return "error: fault needs an error code 0x0001..0xFFFF and an optional cause 0..255";
      }
      node->inject_fault(static_cast<std::uint16_t>(*code), static_cast<std::uint8_t>(*cause));
      return "ok fault " + id + " " + hex4(static_cast<unsigned>(*code));
    }
    return "error: \"" + line + "\": " + verb + " takes " + usage_of(verb);
  }

 private:
  // The node a NODE or BUS:NODE names; the error text otherwise.
  std::optional<std::string> find(const std::string& text, SlaveNode*& out) {
    const auto colon = text.find(':');
    const std::string bus = colon == std::string::npos ? std::string{} : text.substr(0, colon);
    const auto number = parse_number(colon == std::string::npos ? text : text.substr(colon + 1));
    if (!number || *number < 1 || *number > 127) return "\"" + text + "\" is not a node-ID 1..127 (or BUS:NODE)";
    std::vector<SlaveNode*> found;
    for (auto& b : buses_) {
      if (!bus.empty() && b.name != bus) continue;
      if (auto* n = b.network->find(static_cast<canopen::NodeId>(*number))) found.push_back(n);
    }
    if (found.empty()) return "no simulated node " + text;
    if (found.size() > 1) return "node " + text + " is on several buses: name it as BUS:NODE";
    out = found.front();
    return std::nullopt;
  }

  std::string status() {
    std::string s = "status:";
    for (auto& b : buses_) {
      for (std::size_t i = 0; i < b.network->size(); ++i) {
        const auto& n = b.network->node(i);
        s += " " + b.name + ":" + std::to_string(n.node()) + " " + std::string(n.persona().name);
        if (!n.powered()) {
          s += " off;";
          continue;
        }
        s += " nmt=" + std::string(canopen::to_string(n.nmt_state()));
        s += " state=" + std::string(core::to_string(n.drive().state()));
        s += " fault=" + hex4(n.fault_code());
        s += n.silent() ? " silent;" : ";";
      }
    }
    return s;
  }

  std::vector<SimBus> buses_;
};

// Reads stdin without blocking the cycle; complete lines go to the simulator.
class CommandReader {
 public:
  void poll(Simulator& sim) {
    if (closed_) return;
    pollfd p{STDIN_FILENO, POLLIN, 0};
    if (::poll(&p, 1, 0) <= 0) return;
    std::array<char, 512> chunk{};
    const ssize_t n = ::read(STDIN_FILENO, chunk.data(), chunk.size());
    if (n <= 0) {
      if (n == 0 || (errno != EINTR && errno != EAGAIN)) closed_ = true;  // no more commands; keep running
      return;
    }
    pending_.append(chunk.data(), static_cast<std::size_t>(n));
    for (auto nl = pending_.find('\n'); nl != std::string::npos; nl = pending_.find('\n')) {
      std::string line = pending_.substr(0, nl);
      pending_.erase(0, nl + 1);
      if (!line.empty() && line.back() == '\r') line.pop_back();
      if (!line.empty()) say(sim.command(line));
    }
  }

 private:
  bool closed_ = false;
  std::string pending_;
};

void add_ns(timespec& t, long ns) {
  t.tv_nsec += ns;
  while (t.tv_nsec >= 1'000'000'000) {
    t.tv_nsec -= 1'000'000'000;
    ++t.tv_sec;
  }
}

long behind_ns(const timespec& deadline, const timespec& now) {
  return (now.tv_sec - deadline.tv_sec) * 1'000'000'000L + (now.tv_nsec - deadline.tv_nsec);
}

int usage() {
  std::fputs("usage: drivegate-sim CONFIG [--bus NAME]\n", stderr);
  return 2;
}

int run(int argc, char** argv) {
  std::string file;
  std::string only;
  for (int i = 1; i < argc; ++i) {
    const std::string_view a = argv[i];
    if (a == "--bus" && i + 1 < argc) {
      only = argv[++i];
    } else if (a == "-h" || a == "--help") {
      usage();
      return 0;
    } else if (file.empty() && !a.starts_with("-")) {
      file = a;
    } else {
      return usage();
    }
  }
  if (file.empty()) return usage();

  const config::Plan plan = config::load_plan(file);
  std::vector<SimBus> buses;
  std::vector<std::string> ready;
  for (const auto& bus : plan.buses) {
    if (bus.type != "canopen" || (!only.empty() && bus.name != only)) continue;
    const auto& options = bus.section<config::CanopenBusOptions>();
    if (options.transport != config::CanTransportKind::UdpMulticast) {
      if (!only.empty()) {
        std::fprintf(stderr, "drivegate-sim: bus '%s' is not on udp-multicast\n", bus.name.c_str());
        return 2;
      }
      continue;
    }
    SimBus b{bus.name, canopen::make_transport(bus), nullptr};
    b.transport->open();
    b.network = std::make_unique<SimNetwork>(*b.transport);
    for (const auto& axis : bus.axes) b.network->add(canopen::sim::slave_config_for(axis));
    ready.push_back("drivegate-sim: " + std::to_string(bus.axes.size()) + " nodes on udp-multicast " +
                    options.group + ":" + std::to_string(options.port));
    buses.push_back(std::move(b));
  }
  if (buses.empty()) {
    std::fprintf(stderr, "drivegate-sim: %s has no canopen bus on udp-multicast%s%s\n", file.c_str(),
                 only.empty() ? "" : " named ", only.c_str());
    return 2;
  }

  struct sigaction sa {};
  sa.sa_handler = on_signal;  // no SA_RESTART: the sleep returns at once
  ::sigaction(SIGINT, &sa, nullptr);
  ::sigaction(SIGTERM, &sa, nullptr);

  Simulator sim(std::move(buses));
  CommandReader commands;
  const core::SteadyClock clock;
  // Ready once the drives have booted: a request that follows the ready line is answered.
  sim.step(clock.now());
  for (const auto& line : ready) say(line);
  timespec next{};
  ::clock_gettime(CLOCK_MONOTONIC, &next);
  while (g_stop == 0) {
    add_ns(next, kPeriodNs);
    while (::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, nullptr) == EINTR && g_stop == 0) {
    }
    timespec now{};
    ::clock_gettime(CLOCK_MONOTONIC, &now);
    if (behind_ns(next, now) > kResyncNs) next = now;  // a stall (debugger, suspend): no burst of catch-up steps
    commands.poll(sim);
    sim.step(clock.now());
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "drivegate-sim: %s\n", e.what());
    return 1;
  }
}
