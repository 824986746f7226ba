// drivegate-sim: runs the simulated devices of a drivegate config, so the daemon finds
// real-looking devices on its buses:
// - canopen buses on udp-multicast: one SlaveNode per axis with its device profile's persona, on
//   the virtual CAN bus (python-can sees them too);
// - ethercat buses with transport raw: the line of the bus (adapters/ethercat/sim/line_builder.hpp:
//   a slave per position, drives by their profile's ethercat.persona, io: slaves generic-io) on a
//   network interface, normally the other end of a veth pair from the gateway's `interface`
//   (sim_endpoint.hpp; needs CAP_NET_RAW);
// - profinet buses: a simulated IO device per station of the bus (adapters/profinet/sim/
//   network_builder.hpp: an AKD for a station an axis uses, generic IO for an io: entry), each with
//   its own MAC, its NameOfStation and no IP address until the controller sets one by DCP, on a
//   network interface like an ethercat line (pn_sim_link.hpp; CAP_NET_RAW). The interface must
//   carry the stations' configured addresses (ip addr add), so that the devices can take them.
//
//   drivegate-sim CONFIG [--bus NAME] [--interface [BUS=]IFACE]...
//
// --interface: the interface an ethercat line or profinet network is served on (BUS= for one bus of several); without
// it, the bus' own `interface` (the simulator then runs in another network namespace, whose end of
// the pair carries the gateway's name).
//
// Steps every 1 ms on an absolute CLOCK_MONOTONIC schedule until SIGINT or SIGTERM; EtherCAT frames
// are answered as they come in between. Fault injection comes on stdin, one command a line, each
// answered with one line on stdout (kCommands):
//   CANopen:  power-off NODE | power-on NODE | fault NODE CODE [CAUSE] | clear NODE |
//             silent NODE on|off | abort NODE INDEX[:SUB] CODE | corrupt NODE COUNT [dlc|garbage] |
//             service-write NODE INDEX[:SUB] VALUE SIZE
//   EtherCAT: power-off K | power-on K | break-after K | mend [BUS] | drop N [BUS] |
//             corrupt N [BUS] | stick K STATE CODE | unstick K   (adapters/ethercat/sim/line_console.hpp)
//   PROFINET: power-off STATION | power-on STATION | reboot STATION | abort-ar STATION |
//             lose STATION rx|tx N | drive-fault STATION NUMBER |
//             alarm STATION KIND [SLOT[:SUBSLOT]] [ERROR] | io STATION SLOT[:SUBSLOT] [BYTE...]
//             (adapters/profinet/sim/pn_console.hpp)
//   all:      status
// NODE is a node-ID, K a position on an EtherCAT line (1 = next to the gateway), STATION a
// PROFINET NameOfStation, each BUS:NODE, BUS:K or BUS:STATION when more than one bus has it;
// numbers are decimal or 0x hex. `corrupt` with one number (or a number and a bus name) is
// EtherCAT's, with a node and a count CANopen's; power-off / power-on and io naming a station
// PROFINET's.
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
#include "adapters/ethercat/link/ethercat_link.hpp"
#include "adapters/ethercat/sim/line_builder.hpp"
#include "adapters/ethercat/sim/line_console.hpp"
#include "adapters/ethercat/sim/sim_endpoint.hpp"
#include "adapters/link/raw_socket_link.hpp"
#include "adapters/link/udp_endpoint.hpp"
#include "adapters/profinet/link/profinet_link.hpp"
#include "adapters/profinet/sim/network_builder.hpp"
#include "adapters/profinet/sim/pn_console.hpp"
#include "adapters/profinet/sim/pn_sim_link.hpp"
#include "config/ethercat/plan.hpp"
#include "config/profinet/plan.hpp"
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

// An EtherCAT line served on a network interface.
struct EcatBus {
  std::unique_ptr<ethercat::sim::BuiltLine> line;
  std::unique_ptr<ethercat::RawSocketLink> wire;
  std::unique_ptr<ethercat::sim::SimEndpoint> endpoint;
};

// A PROFINET network served on a network interface.
struct PnBus {
  std::unique_ptr<profinet::BuiltPnNetwork> network;
  std::unique_ptr<link::RawSocketLink> wire;
  std::unique_ptr<profinet::PnSimLinkRunner> runner;
  std::string reported;  // the runner's last port error said on stderr
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
constexpr std::string_view kEthercatCommands =
    "power-off K, power-on K, break-after K, mend [BUS], drop N [BUS], corrupt N [BUS], stick K STATE CODE, unstick K, "
    "drive K, io K [BYTE...], status";

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
  Simulator(std::vector<SimBus> buses, std::vector<EcatBus> ecat, std::vector<PnBus> pn)
      : buses_(std::move(buses)), ecat_(std::move(ecat)), pn_(std::move(pn)) {
    for (auto& e : ecat_) console_.add(*e.line);
    for (auto& p : pn_) pn_console_.add(*p.network);
  }

  void step(core::TimePoint now) noexcept {
    for (auto& b : buses_) b.network->step(now);
  }

  // EtherCAT frames waiting on the interfaces are answered; the lines' 1 ms PDI ticks run; the
  // PROFINET devices take what arrived and run what is due.
  void serve(core::TimePoint now) {
    for (auto& e : ecat_) e.endpoint->service(now);
    for (auto& p : pn_) {
      p.runner->run_once(now);
      if (p.runner->port_error() != p.reported) {
        p.reported = p.runner->port_error();
        std::fprintf(stderr, "drivegate-sim: %s\n", p.reported.c_str());
      }
    }
  }
  // The descriptors EtherCAT frames and PROFINET frames and datagrams arrive on (the PROFINET
  // devices' UDP ports open when DCP gives them an address).
  void wait_fds(std::vector<pollfd>& out) const {
    out.clear();
    for (const auto& e : ecat_) out.push_back(pollfd{e.endpoint->wait_fd(), POLLIN, 0});
    for (const auto& p : pn_) {
      for (const int fd : p.runner->wait_fds()) out.push_back(pollfd{fd, POLLIN, 0});
    }
  }

  // One command line in, one answer line out.
  std::string command(const std::string& line) {
    std::istringstream in(line);
    std::string verb;
    std::string node_text;
    in >> verb;
    if (verb.empty()) return "error: empty command";
    if (verb == "status") return status();
    if (const auto answer = profinet_command(line)) return *answer;
    if (const auto answer = ethercat_command(line)) return *answer;
    if (verb != "power-off" && verb != "power-on" && verb != "fault" && verb != "clear" && verb != "silent" &&
        verb != "abort" && verb != "corrupt" && verb != "service-write" && verb != "emcy") {
      std::string known;
      for (const auto& [name, commands] : {std::pair{"CANopen", buses_.empty() ? std::string_view{} : kCommands},
                                           std::pair{"EtherCAT", console_.empty() ? std::string_view{} : kEthercatCommands},
                                           std::pair{"PROFINET", pn_console_.empty() ? std::string_view{} : profinet::PnConsole::kCommands}}) {
        if (!commands.empty()) known += (known.empty() ? "" : "; ") + std::string(name) + ": " + std::string(commands);
      }
      return "error: unknown command \"" + verb + "\" (" + known + ")";
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
    if (found.empty()) return "no simulated node " + text + (console_.empty() ? "" : " (nor EtherCAT slave)");
    if (found.size() > 1) return "node " + text + " is on several buses: name it as BUS:NODE";
    out = found.front();
    return std::nullopt;
  }

  // The PROFINET console's answer when the command is one of its own (pn_console.hpp), nullopt
  // otherwise: its own verbs, power-off / power-on naming a simulated station, and io naming one
  // (or naming none when no EtherCAT line is simulated: PROFINET's refusal says why).
  std::optional<std::string> profinet_command(const std::string& line) {
    std::istringstream in(line);
    std::string verb;
    std::string target;
    in >> verb >> target;
    if (!profinet::PnConsole::handles(verb) || verb == "status") return std::nullopt;
    if (verb != "power-off" && verb != "power-on" && verb != "io") {
      if (pn_console_.empty()) return "error: " + verb + " is a PROFINET command and no PROFINET network is simulated";
      return pn_console_.command(line, clock_.now());
    }
    if (pn_console_.matches(target) > 0 || (verb == "io" && console_.empty() && !pn_console_.empty()))
      return pn_console_.command(line, clock_.now());
    return std::nullopt;
  }

  // The EtherCAT console's answer when the command is one of its own (line_console.hpp), nullopt
  // when it is CANopen's. Shared verbs go by their target: power-off/power-on to whichever bus type
  // has the node or position (both: the user names the bus), corrupt by its arguments.
  std::optional<std::string> ethercat_command(const std::string& line) {
    std::istringstream in(line);
    std::string verb;
    in >> verb;
    std::vector<std::string> args;
    for (std::string a; in >> a;) args.push_back(a);
    if (!ethercat::sim::LineConsole::handles(verb) || verb == "status") return std::nullopt;
    const bool shared = verb == "power-off" || verb == "power-on" || verb == "corrupt";
    if (!shared) {
      if (console_.empty()) return "error: " + verb + " is an EtherCAT command and no EtherCAT line is simulated";
      return console_.command(line);
    }
    if (console_.empty()) return std::nullopt;
    if (buses_.empty()) return console_.command(line);
    if (verb == "corrupt") {
      // EtherCAT: corrupt N [BUS]; CANopen: corrupt NODE COUNT [dlc|garbage].
      const bool ecat = args.size() == 1 || (args.size() == 2 && !parse_number(args[1]));
      return ecat ? std::optional<std::string>{console_.command(line)} : std::nullopt;
    }
    if (args.size() != 1) return std::nullopt;
    const auto colon = args[0].find(':');
    const std::string bus = colon == std::string::npos ? std::string{} : args[0].substr(0, colon);
    const auto number = parse_number(colon == std::string::npos ? args[0] : args[0].substr(colon + 1));
    std::size_t canopen_nodes = 0;
    for (auto& b : buses_) {
      if ((bus.empty() || b.name == bus) && number && *number <= 127 &&
          b.network->find(static_cast<canopen::NodeId>(*number)) != nullptr)
        ++canopen_nodes;
    }
    const std::size_t ecat_slaves = console_.matches(args[0]);
    if (ecat_slaves > 0 && canopen_nodes > 0)
      return "error: " + args[0] + " is a CANopen node and an EtherCAT position: name it as BUS:" + args[0];
    if (ecat_slaves > 0) return console_.command(line);
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
    return s + console_.status_items() + pn_console_.status_items();
  }

  std::vector<SimBus> buses_;
  std::vector<EcatBus> ecat_;
  std::vector<PnBus> pn_;
  ethercat::sim::LineConsole console_;
  profinet::PnConsole pn_console_;
  core::SteadyClock clock_;
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
  std::fputs(
      "usage: drivegate-sim CONFIG [--bus NAME] [--interface [BUS=]IFACE]...\n"
      "  simulates the devices of CONFIG's canopen buses on udp-multicast, its ethercat buses with\n"
      "  transport raw and its profinet buses; --interface serves an ethercat line or a profinet\n"
      "  network on IFACE (default: the bus' interface). PROFINET devices start with their\n"
      "  NameOfStation and no IP address; IFACE must carry the stations' configured addresses.\n"
      "  stdin takes commands, one a line, answered with one line each:\n"
      "    CANopen:  power-off NODE, power-on NODE, fault NODE CODE [CAUSE], clear NODE, emcy NODE CODE REGISTER,\n"
      "              silent NODE on|off, abort NODE INDEX[:SUB] CODE, corrupt NODE COUNT [dlc|garbage],\n"
      "              service-write NODE INDEX[:SUB] VALUE SIZE\n"
      "    EtherCAT: power-off K, power-on K, break-after K, mend [BUS], drop N [BUS], corrupt N [BUS],\n"
      "              stick K INIT|PRE-OP|SAFE-OP CODE, unstick K\n"
      "    PROFINET: power-off STATION, power-on STATION, reboot STATION, abort-ar STATION,\n"
      "              lose STATION rx|tx N, drive-fault STATION NUMBER,\n"
      "              alarm STATION process|diagnosis|diagnosis-gone|pull|plug|return [SLOT[:SUBSLOT]] [ERROR]\n"
      "    all:      status\n"
      "  NODE: a node-ID; K: a position on the line (1 = next to the gateway); STATION: a NameOfStation;\n"
      "  BUS:NODE / BUS:K / BUS:STATION when several buses have it\n",
      stderr);
  return 2;
}

// The interface a --interface option names for `bus` ("BUS=IFACE" first, then a bare "IFACE").
std::string interface_for(const std::string& bus, const std::vector<std::string>& options, const std::string& fallback) {
  for (const auto& o : options) {
    if (o.starts_with(bus + "=")) return o.substr(bus.size() + 1);
  }
  for (const auto& o : options) {
    if (o.find('=') == std::string::npos) return o;
  }
  return fallback;
}

int run(int argc, char** argv) {
  std::string file;
  std::string only;
  std::vector<std::string> interfaces;
  for (int i = 1; i < argc; ++i) {
    const std::string_view a = argv[i];
    if (a == "--bus" && i + 1 < argc) {
      only = argv[++i];
    } else if (a == "--interface" && i + 1 < argc) {
      interfaces.emplace_back(argv[++i]);
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
  std::vector<EcatBus> ecat;
  std::vector<std::string> ready;
  for (const auto& bus : plan.buses) {
    if (bus.type != "ethercat" || (!only.empty() && bus.name != only)) continue;
    const auto& options = bus.section<config::EthercatBusOptions>();
    if (options.transport != config::EthercatTransportKind::Raw) {
      if (!only.empty()) {
        std::fprintf(stderr, "drivegate-sim: bus '%s' is not on transport raw (sim runs inside the gateway)\n",
                     bus.name.c_str());
        return 2;
      }
      continue;
    }
    EcatBus b;
    b.line = ethercat::sim::build_line(bus);
    ethercat::RawSocketOptions o;
    o.interface = interface_for(bus.name, interfaces, options.interface);
    b.wire = std::make_unique<ethercat::RawSocketLink>(o);
    b.wire->open();
    b.endpoint = std::make_unique<ethercat::sim::SimEndpoint>(*b.wire, *b.line);
    ready.push_back("drivegate-sim: " + std::to_string(b.line->size()) + " slaves on ethercat " + o.interface +
                    " (bus " + bus.name + ")");
    ecat.push_back(std::move(b));
  }
  std::vector<PnBus> pn;
  std::size_t pn_index = 0;
  for (const auto& bus : plan.buses) {
    if (bus.type != "profinet") continue;
    const std::size_t index = pn_index++;  // the MACs stay the same with --bus
    if (!only.empty() && bus.name != only) continue;
    PnBus b;
    b.network = profinet::build_pn_network(bus, index);
    link::RawSocketOptions o;
    o.interface = interface_for(bus.name, interfaces, bus.section<config::ProfinetBusOptions>().interface);
    b.wire = std::make_unique<link::RawSocketLink>(profinet::kFrameRules, o);
    b.runner = std::make_unique<profinet::PnSimLinkRunner>(
        b.network->network(), *b.wire, [iface = o.interface](const link::Ipv4Endpoint& local) {
          link::UdpOptions u = profinet::rpc_udp_options(iface, local.port);
          u.address = local.address;
          return std::make_unique<link::UdpEndpoint>(u);
        });
    b.runner->open();
    for (std::size_t i = 0; i < b.network->size(); ++i) {
      const profinet::PnSimStation& s = b.network->station(i);
      ready.push_back("drivegate-sim: " + bus.name + " station " + s.name + ": " + s.persona +
                      (s.used_by.empty() ? "" : " (" + s.used_by + ")") + ", MAC " + profinet::mac_text(s.device->mac()).data() +
                      ", no IP address");
    }
    ready.push_back("drivegate-sim: " + std::to_string(b.network->size()) + " devices on profinet " + o.interface +
                    " (bus " + bus.name + ")");
    pn.push_back(std::move(b));
  }
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
  if (buses.empty() && ecat.empty() && pn.empty()) {
    std::fprintf(stderr,
                 "drivegate-sim: %s has no canopen bus on udp-multicast, no ethercat bus on transport raw and no "
                 "profinet bus%s%s\n",
                 file.c_str(), only.empty() ? "" : " named ", only.c_str());
    return 2;
  }

  struct sigaction sa {};
  sa.sa_handler = on_signal;  // no SA_RESTART: the sleep returns at once
  ::sigaction(SIGINT, &sa, nullptr);
  ::sigaction(SIGTERM, &sa, nullptr);

  Simulator sim(std::move(buses), std::move(ecat), std::move(pn));
  CommandReader commands;
  const core::SteadyClock clock;
  // Ready once the drives have booted: a request that follows the ready line is answered.
  sim.step(clock.now());
  sim.serve(clock.now());
  for (const auto& line : ready) say(line);
  std::vector<pollfd> fds;
  timespec next{};
  ::clock_gettime(CLOCK_MONOTONIC, &next);
  while (g_stop == 0) {
    add_ns(next, kPeriodNs);
    sim.wait_fds(fds);
    // Until the next step: EtherCAT frames are answered as they arrive (the master waits for them
    // within its cycle); without EtherCAT lines this is the plain absolute sleep.
    for (;;) {
      timespec now{};
      ::clock_gettime(CLOCK_MONOTONIC, &now);
      const long left = -behind_ns(next, now);
      if (left <= 0 || g_stop != 0) break;
      if (fds.empty()) {
        ::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, nullptr);
        continue;
      }
      const timespec wait{left / 1'000'000'000L, left % 1'000'000'000L};
      if (::ppoll(fds.data(), fds.size(), &wait, nullptr) > 0) sim.serve(clock.now());
    }
    timespec now{};
    ::clock_gettime(CLOCK_MONOTONIC, &now);
    if (behind_ns(next, now) > kResyncNs) next = now;  // a stall (debugger, suspend): no burst of catch-up steps
    commands.poll(sim);
    sim.step(clock.now());
    sim.serve(clock.now());
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
