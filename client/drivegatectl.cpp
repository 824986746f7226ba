// drivegatectl: command-line client of drivegated (see --help).
#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <iostream>
#include <string>
#include <thread>

#include "client/cli_args.hpp"
#include "client/client.hpp"
#include "client/discovery.hpp"
#include "client/interrupt.hpp"
#include "client/json_writer.hpp"
#include "client/node_ids.hpp"
#include "client/status_table.hpp"
#include "core/device_identity.hpp"
#include "core/record_address.hpp"

namespace {

using namespace drivegate::client;
namespace core = drivegate::core;
using SteadyClock = std::chrono::steady_clock;
using StringSet = std::set<std::string, std::less<>>;

struct CommandHelp {
  const char* name;
  const char* usage;
  const char* text;
  std::size_t min_words = 0;  // positional words after the command name, checked before discovery
  std::size_t max_words = 0;
};
constexpr std::size_t kAny = 64;

constexpr CommandHelp kCommands[] = {
    {"list", "list", "gateways and their axes (bus, address, device, unit, modes)", 0, 0},
    {"status", "status [AXIS...] [--watch]",
     "axis table; with AXIS also why each one's link is in its state and since when; --watch redraws\n"
     "      the table at 10 Hz until Ctrl-C",
     0, kAny},
    {"enable", "enable AXIS", "walk the axis to operation enabled", 1, 1},
    {"disable", "disable AXIS", "disable the drive (power stage off)", 1, 1},
    {"stop", "stop AXIS", "bring the axis to standstill, keep it enabled", 1, 1},
    {"quick-stop", "quick-stop AXIS", "quick stop (fast ramp, then disabled)", 1, 1},
    {"halt", "halt AXIS", "halt the running motion", 1, 1},
    {"resume", "resume AXIS", "resume after halt", 1, 1},
    {"reset", "reset AXIS", "acknowledge a drive fault", 1, 1},
    {"mode", "mode AXIS MODE", "select the mode (pp, pv, vl, tq, hm, ip, csp, csv, cst, tb or long names)", 2, 2},
    {"move", "move AXIS POS [--relative] [--velocity V] [--accel A] [--decel D] [--queued] [--no-wait]",
     "profile position move; waits for target reached unless --no-wait", 2, 2},
    {"velocity", "velocity AXIS V [--accel A] [--for SECONDS]",
     "jog at V, streaming keep-alive set-points until --for elapses or Ctrl-C, then stop", 2, 2},
    {"torque", "torque AXIS T [--for SECONDS]", "torque T, kept alive like velocity, then stop", 2, 2},
    {"home", "home AXIS [--method M] [--offset O]", "run homing and wait until it is attained", 1, 1},
    {"events", "events [--follow] [AXIS]", "recent events (faults, warnings, state changes); --follow keeps printing",
     0, 1},
    {"param",
     "param get AXIS OBJECT [--type TYPE]\n"
     "  param set AXIS OBJECT VALUE [--type TYPE]\n"
     "  OBJECT is INDEX[:SUB] in hex (6060, 0x6099:1, 6060h) or a name: an EDS ParameterName or a\n"
     "  vendor parameter such as A83. The type comes from the axis' EDS, the device profile or CiA\n"
     "  301/402; --type names it otherwise: u8 u16 u24 u32 u40 u48 u56 u64, i8 .. i64, r32 r64, bool,\n"
     "  string, unicode, octets, domain (VALUE: decimal or 0x hex, a real, text, hex bytes \"01 02 0a\")\n"
     "  PROFIdrive: OBJECT is a PNU: p930, p930[1] (subindex 1), r947[0]\n"
     "  PROFINET: OBJECT rec:SLOT:SUBSLOT:INDEX[@API] (decimal or 0x hex) reads or writes a record of the\n"
     "  axis' device (IODReadReq/IODWriteReq), e.g. rec:0:1:0xAFF0 for I&M0; its bytes unless --type\n"
     "  names a value (big-endian in the record); @API defaults to the configured submodule's",
     "read/write a drive object; INDEX is hex (0x optional), SUB decimal or 0x-hex", 3, 4},
    {"buses", "buses", "bus status: cycle timing, lateness, frame counters", 0, 0},
    {"io",
     "io [NAME] [--bus BUS]\n"
     "  io NAME write OFFSET BYTES... [--bus BUS]\n"
     "  BYTES are hex bytes (\"01 ff\", 0x01, or 01ff); OFFSET is the first output byte (decimal or 0x hex)",
     "generic I/O slaves (EtherCAT io:): their input and output bytes; write output bytes", 0, kAny},
};

void print_usage(std::ostream& os) {
  os << "usage: drivegatectl [--domain N] [--namespace NS] [--gateway G] [--identity DIR] [--interfaces LIST] "
        "[--json] [--timeout S] <command> ...\n\n"
        "commands:\n";
  for (const auto& c : kCommands) os << "  " << c.usage << "\n      " << c.text << "\n";
  os << "\n--domain N      DDS domain id (default 0)\n"
        "--namespace NS  topic namespace (default drivegate)\n"
        "--identity DIR  DDS Security identity (scripts/make-pki.sh makes one per role); default: the\n"
        "                DRIVEGATE_IDENTITY environment variable, else no security\n"
        "--interfaces L  DDS over these interfaces only (comma-separated names or IPv4 addresses);\n"
        "                default: DRIVEGATE_INTERFACES, else every interface\n"
        "--gateway G     address gateway G (needed when several gateways claim an axis)\n"
        "--json          one JSON object per result on stdout\n"
        "--timeout S     seconds to wait for discovery and replies (default 5)\n"
        "exit status: 0 success, 1 rejected/failed/timed out/no gateway, 2 usage error\n";
}

void print_command_usage(std::string_view name) {
  for (const auto& c : kCommands)
    if (name == c.name) {
      std::cout << "usage: drivegatectl [global options] " << c.usage << "\n  " << c.text << "\n";
      return;
    }
  print_usage(std::cout);
}

struct Context {
  Client& client;
  const Args& args;
  bool json = false;
  Millis timeout{5000};
  std::string gateway;
  std::vector<std::string> words;  // positional words after the command name
};

const std::string& word(const Context& ctx, std::size_t i, const char* what) {
  if (i >= ctx.words.size()) throw UsageError(std::string("missing ") + what);
  return ctx.words[i];
}

void expect_words(const Context& ctx, std::size_t n) {
  if (ctx.words.size() > n) throw UsageError("unexpected argument '" + ctx.words[n] + "'");
}

std::vector<std::string> split_commas(const std::string& text) {
  std::vector<std::string> out;
  std::size_t at = 0;
  while (at < text.size()) {
    const auto comma = text.find(',', at);
    const auto end = comma == std::string::npos ? text.size() : comma;
    if (end > at) out.push_back(text.substr(at, end - at));
    at = end + 1;
  }
  return out;
}

int fail(const std::string& message) {
  std::cerr << "drivegatectl: " << message << "\n";
  return 1;
}

int require_gateways(const Context& ctx) {
  if (discover_gateways(ctx.client, ctx.gateway, ctx.timeout)) return 0;
  return fail(ctx.gateway.empty() ? "no gateway answered on this domain/namespace"
                                  : "gateway '" + ctx.gateway + "' did not answer");
}

int report(const Context& ctx, std::string_view command, const CommandResult& r) {
  if (ctx.json) {
    JsonWriter w;
    w.begin_object()
        .field("command", command)
        .field("axis", std::string_view(r.axis))
        .field("gateway", std::string_view(r.gateway))
        .field("id", r.id)
        .field("status", to_string(r.outcome))
        .field("ok", r.ok())
        .field("reason", std::string_view(r.reason))
        .end_object();
    std::cout << w.str() << std::endl;
  } else if (r.ok()) {
    std::cout << command << " " << r.axis << " (" << r.gateway << "): " << to_string(r.outcome)
              << (r.reason.empty() ? "" : ": " + r.reason) << std::endl;
  }
  if (r.ok()) return 0;
  return fail(std::string(command) + " " + r.axis + ": " + std::string(to_string(r.outcome)) +
              (r.reason.empty() ? "" : ": " + r.reason));
}

CommandRequest request(const Context& ctx, std::string kind) {
  CommandRequest req;
  req.axis = word(ctx, 0, "AXIS");
  req.gateway = ctx.gateway;
  req.kind = std::move(kind);
  return req;
}

// Waits (within the timeout) until the link of every axis of `names` (gateway, axis) arrived; not
// when some gateway publishes no links or this identity may not read them (they would never come).
void wait_links(const Context& ctx, const std::vector<std::pair<std::string, std::string>>& names) {
  if (ctx.client.link_writers() < ctx.client.gateways().size()) return;
  ctx.client.wait_until(
      [&] {
        return std::all_of(names.begin(), names.end(),
                           [&](const auto& n) { return ctx.client.link(n.second, n.first).has_value(); });
      },
      ctx.timeout);
}

int cmd_list(Context& ctx) {
  expect_words(ctx, 0);
  std::vector<std::pair<std::string, std::string>> names;
  for (const auto& g : ctx.client.gateways())
    if (ctx.gateway.empty() || g.name == ctx.gateway)
      for (const auto& a : g.axes) names.emplace_back(g.name, a.name);
  wait_links(ctx, names);
  for (const auto& g : ctx.client.gateways()) {
    if (!ctx.gateway.empty() && g.name != ctx.gateway) continue;
    if (ctx.json) {
      JsonWriter w;
      w.begin_object().field("gateway", std::string_view(g.name)).field("host", std::string_view(g.host));
      w.field("pid", static_cast<std::uint64_t>(g.pid)).key("axes").begin_array();
      for (const auto& a : g.axes) {
        w.begin_object().field("name", std::string_view(a.name)).field("bus", std::string_view(a.bus));
        const auto l = ctx.client.link(a.name, g.name);
        if (l) w.field("bus_type", std::string_view(l->bus_type)).field("address", static_cast<std::uint64_t>(l->address));
        if (const auto id = l ? core::identity_in_link_detail(l->detail) : std::nullopt) {
          w.key("identity")
              .begin_object()
              .field("order_id", std::string_view(id->order_id))
              .field("serial_number", std::string_view(id->serial_number))
              .field("hardware_revision", std::string_view(id->hardware_revision))
              .field("software_revision", std::string_view(id->software_revision))
              .end_object();
        }
        w.field("device", std::string_view(a.device))
            .field("unit", std::string_view(a.unit))
            .key("modes")
            .begin_array();
        for (const auto& m : a.modes) w.value(std::string_view(m));
        w.end_array().end_object();
      }
      w.end_array().end_object();
      std::cout << w.str() << "\n";
      continue;
    }
    std::cout << "gateway " << g.name << " (" << g.host << ", pid " << g.pid << ")\n";
    for (const auto& a : g.axes) {
      std::string modes;
      for (const auto& m : a.modes) modes += (modes.empty() ? "" : ",") + m;
      const auto l = ctx.client.link(a.name, g.name);
      std::cout << "  " << a.name << "  bus=" << a.bus
                << (l ? "  address=" + format_address(l->bus_type, l->address) : std::string{})
                << "  device=" << a.device << "  unit=" << a.unit << "  modes=" << modes << "\n";
      // The device's identity where the bus names it (PROFINET: I&M0 read at connect).
      if (const auto id = l ? core::identity_in_link_detail(l->detail) : std::nullopt)
        std::cout << "      order " << id->order_id << "  serial " << id->serial_number << "  hw "
                  << id->hardware_revision << "  sw " << id->software_revision << "\n";
    }
  }
  return 0;
}

std::vector<AxisState> selected_states(const Context& ctx) {
  auto states = ctx.client.states();
  std::erase_if(states, [&](const AxisState& s) {
    if (!ctx.gateway.empty() && s.gateway != ctx.gateway) return true;
    return !ctx.words.empty() && std::find(ctx.words.begin(), ctx.words.end(), s.axis) == ctx.words.end();
  });
  return states;
}

// Seconds from `since_ns` to `stamp_ns` (gateway monotonic time), as text with 0.1 s.
std::string seconds_between(std::int64_t since_ns, std::int64_t stamp_ns) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f s", static_cast<double>(std::max<std::int64_t>(0, stamp_ns - since_ns)) / 1e9);
  return buf;
}

void print_state_json(const AxisState& s, const std::optional<AxisLink>& l) {
  JsonWriter w;
  w.begin_object()
      .field("gateway", std::string_view(s.gateway))
      .field("axis", std::string_view(s.axis))
      .field("state", std::string_view(s.state))
      .field("link", std::string_view(s.link));
  if (l) {
    w.field("bus", std::string_view(l->bus))
        .field("bus_type", std::string_view(l->bus_type))
        .field("address", static_cast<std::uint64_t>(l->address))
        .field("link_detail", std::string_view(l->detail))
        .field("link_since_ns", l->since_ns);
  }
  w.field("mode", std::string_view(s.mode))
      .field("position", s.position)
      .field("velocity", s.velocity)
      .field("torque", s.torque)
      .field("unit", std::string_view(s.unit))
      .field("fault_code", static_cast<std::uint64_t>(s.fault_code))
      .field("fault_text", std::string_view(s.fault_text))
      .field("target_reached", s.target_reached)
      .field("homed", s.homed)
      .field("warning", s.warning)
      .field("stopping", s.stopping)
      .field("statusword", static_cast<std::uint64_t>(s.statusword))
      .field("stamp_ns", s.stamp_ns)
      .end_object();
  std::cout << w.str() << "\n";
}

// `status AXIS`: why the link is in its state and since when, under the table.
//   x: link offline for 2.4 s (since 14:03:07)
//     node 35 (0x23): identity: 1018h:01 reads 0x0000006A, expected 0x00000059; ...
void print_link_detail(const AxisState& s, const std::optional<AxisLink>& l) {
  std::cout << "\n" << s.axis << ": link " << s.link;
  if (!l) {
    std::cout << " (the gateway publishes no link detail)\n";
    return;
  }
  if (l->since_ns > 0 && l->link == s.link) {
    // The state's stamp is the gateway's "now" (to within its status period).
    const auto age = std::chrono::nanoseconds(std::max<std::int64_t>(0, s.stamp_ns - l->since_ns));
    const auto since = std::chrono::system_clock::to_time_t(
        std::chrono::system_clock::now() - std::chrono::duration_cast<std::chrono::system_clock::duration>(age));
    char clock[16] = "";
    std::tm local{};
    if (::localtime_r(&since, &local) != nullptr) std::strftime(clock, sizeof clock, "%H:%M:%S", &local);
    std::cout << " for " << seconds_between(l->since_ns, s.stamp_ns) << " (since " << clock << ")";
  }
  std::cout << "\n";
  if (!l->detail.empty())
    std::cout << "  " << (l->bus_type == "canopen" ? annotate_node_ids(l->detail) : l->detail) << "\n";
}

int cmd_status(Context& ctx) {
  // Wait until every requested axis (or every discovered one) has reported its state.
  const auto wanted = [&] {
    std::size_t n = 0;
    for (const auto& g : ctx.client.gateways()) {
      if (!ctx.gateway.empty() && g.name != ctx.gateway) continue;
      for (const auto& a : g.axes)
        if (ctx.words.empty() || std::find(ctx.words.begin(), ctx.words.end(), a.name) != ctx.words.end()) ++n;
    }
    return n;
  };
  ctx.client.wait_until([&] { return selected_states(ctx).size() >= wanted(); }, ctx.timeout);
  if (ctx.args.flag("watch")) {
    while (!interrupted()) {
      const auto states = selected_states(ctx);
      std::cout << kAnsiClearHome << format_status_table(states, ctx.client.links(), SteadyClock::now())
                << "\n(refreshing at 10 Hz, Ctrl-C to quit)" << std::flush;
      std::this_thread::sleep_for(Millis(100));  // display pacing, not synchronisation
    }
    std::cout << "\n";
    return 0;
  }
  std::vector<std::pair<std::string, std::string>> names;
  for (const auto& s : selected_states(ctx)) names.emplace_back(s.gateway, s.axis);
  wait_links(ctx, names);
  const auto states = selected_states(ctx);
  for (const auto& name : ctx.words)
    if (std::none_of(states.begin(), states.end(), [&](const AxisState& s) { return s.axis == name; }))
      return fail("no state for axis '" + name + "'");
  if (ctx.json) {
    for (const auto& s : states) print_state_json(s, ctx.client.link(s.axis, s.gateway));
  } else {
    std::cout << format_status_table(states, ctx.client.links(), SteadyClock::now());
    if (!ctx.words.empty())
      for (const auto& s : states) print_link_detail(s, ctx.client.link(s.axis, s.gateway));
  }
  return 0;
}

int cmd_simple(Context& ctx, std::string_view command, const char* kind) {
  expect_words(ctx, 1);
  return report(ctx, command, ctx.client.send(request(ctx, kind), true, ctx.timeout));
}

int cmd_mode(Context& ctx) {
  expect_words(ctx, 2);
  auto req = request(ctx, "set_mode");
  req.mode = word(ctx, 1, "MODE");
  return report(ctx, "mode", ctx.client.send(req, true, ctx.timeout));
}

int cmd_move(Context& ctx) {
  expect_words(ctx, 2);
  auto req = request(ctx, "move");
  req.position = parse_number("POS", word(ctx, 1, "POS"));
  req.relative = ctx.args.flag("relative");
  req.immediate = !ctx.args.flag("queued");
  req.velocity = ctx.args.number("velocity").value_or(0);
  req.acceleration = ctx.args.number("accel").value_or(0);
  req.deceleration = ctx.args.number("decel").value_or(0);
  return report(ctx, "move", ctx.client.send(req, !ctx.args.flag("no-wait"), ctx.timeout));
}

// Set-points keep a velocity/torque command alive: the gateway stops an axis whose source is silent
// for longer than its command timeout (DESIGN.md §4), typically a few hundred ms; 20 Hz is several
// times faster than that needs.
constexpr Millis kKeepAlivePeriod{50};

int cmd_stream(Context& ctx, bool torque) {
  expect_words(ctx, 2);
  auto req = request(ctx, torque ? "torque" : "velocity");
  const double value = parse_number(torque ? "T" : "V", word(ctx, 1, torque ? "T" : "V"));
  if (torque) {
    req.torque = value;
  } else {
    req.velocity = value;
    req.acceleration = ctx.args.number("accel").value_or(0);
  }
  const auto duration = ctx.args.number("for");
  if (duration && *duration <= 0) throw UsageError("--for must be positive");
  const CommandResult started = ctx.client.send(req, false, ctx.timeout);
  if (int rc = report(ctx, req.kind, started)) return rc;

  const auto until = duration ? SteadyClock::now() + std::chrono::duration_cast<SteadyClock::duration>(
                                                         std::chrono::duration<double>(*duration))
                              : SteadyClock::time_point::max();
  auto next = SteadyClock::now();
  std::string error;
  while (!interrupted() && SteadyClock::now() < until) {
    error = ctx.client.stream_setpoint(req.axis, started.gateway, 0, torque ? 0 : value, torque ? value : 0);
    if (!error.empty()) break;
    next += kKeepAlivePeriod;
    std::this_thread::sleep_until(std::min(next, until));
  }
  CommandRequest stop = req;
  stop.kind = "stop";
  stop.gateway = started.gateway;
  const int rc = report(ctx, "stop", ctx.client.send(stop, true, ctx.timeout));
  if (!error.empty()) return fail("set-point stream: " + error);
  return rc;
}

int cmd_home(Context& ctx) {
  expect_words(ctx, 1);
  auto req = request(ctx, "home");
  if (const auto m = ctx.args.option("method"))
    req.homing_method = static_cast<std::int16_t>(parse_integer("--method", *m, -128, 127));
  req.home_offset = ctx.args.number("offset").value_or(0);
  return report(ctx, "home", ctx.client.send(req, true, ctx.timeout));
}

// Whether the event comes from a canopen bus (its texts name nodes): by its axis' link, else by
// its bus' status.
bool on_canopen(const Context& ctx, const AxisEvent& e) {
  if (!e.axis.empty()) {
    const auto l = ctx.client.link(e.axis, e.gateway);
    return l && l->bus_type == "canopen";
  }
  const auto buses = ctx.client.buses();
  return std::any_of(buses.begin(), buses.end(), [&](const BusStatus& b) {
    return b.gateway == e.gateway && b.bus == e.bus && b.type == "canopen";
  });
}

void print_event(const Context& ctx, const AxisEvent& e) {
  if (ctx.json) {
    JsonWriter w;
    w.begin_object()
        .field("gateway", std::string_view(e.gateway))
        .field("axis", std::string_view(e.axis))
        .field("bus", std::string_view(e.bus))
        .field("kind", std::string_view(e.kind))
        .field("state", std::string_view(e.state))
        .field("code", static_cast<std::uint64_t>(e.code))
        .field("text", std::string_view(e.text))
        .field("stamp_ns", e.stamp_ns)
        .end_object();
    std::cout << w.str() << std::endl;
    return;
  }
  char code[16] = "";
  if (e.code != 0) std::snprintf(code, sizeof code, " 0x%04X", e.code);
  std::cout << e.gateway << "/" << (e.axis.empty() ? "bus:" + e.bus : e.axis) << "  " << e.kind << code << "  "
            << (on_canopen(ctx, e) ? annotate_node_ids(e.text) : e.text)
            << (e.state.empty() || e.state == "unknown" ? "" : "  [" + e.state + "]") << std::endl;
}

int cmd_events(Context& ctx) {
  expect_words(ctx, 1);
  const std::string axis = ctx.words.empty() ? "" : ctx.words[0];
  // Text output looks up each event's bus type (links, bus statuses): subscribe to them now, not
  // in the middle of the stream at the first event.
  if (!ctx.json) {
    (void)ctx.client.links();
    (void)ctx.client.buses();
  }
  std::uint64_t seen = 0;  // the first events_since() waits for the gateways' event history
  do {
    for (const auto& e : ctx.client.events_since(seen)) {
      if (!axis.empty() && e.axis != axis) continue;
      if (!ctx.gateway.empty() && e.gateway != ctx.gateway) continue;
      print_event(ctx, e);
    }
    if (!ctx.args.flag("follow")) break;
    std::uint64_t probe = seen;
    ctx.client.wait_until([&] { return interrupted() || !ctx.client.events_since(probe).empty(); }, Millis(200));
  } while (!interrupted());
  return 0;
}

struct ObjectAddress {
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
};

ObjectAddress parse_address(std::string_view text) {
  ObjectAddress a;
  const auto colon = text.find(':');
  std::string index(text.substr(0, colon));
  if (index.size() > 2 && (index.substr(0, 2) == "0x" || index.substr(0, 2) == "0X")) index = index.substr(2);
  if (!index.empty() && (index.back() == 'h' || index.back() == 'H')) index.pop_back();
  a.index = static_cast<std::uint16_t>(parse_integer("INDEX", "0x" + index, 0, 0xFFFF));
  if (colon != std::string_view::npos)
    a.sub = static_cast<std::uint8_t>(parse_integer("SUB", text.substr(colon + 1), 0, 0xFF));
  return a;
}

// An object is an index (hex, "6060", "0x6060:1", "6060h") or a name ("A83", an EDS ParameterName).
// A word that starts with a letter is a name unless it has the 0x prefix or the h suffix.
bool is_object_name(std::string_view text) {
  const std::string_view index = text.substr(0, text.find(':'));
  if (index.empty() || !std::isalpha(static_cast<unsigned char>(index.front()))) return false;
  return !(index.back() == 'h' || index.back() == 'H');
}

// How a parameter value reads: "0x00020192 (131474)" for objects read in hex, quoted text for
// strings, a hex dump for long byte strings, and the type named.
std::string describe_value(const ParamResult& r) {
  const std::string cia(core::param_type_cia_name(r.type));
  const std::string size = std::to_string(r.data.size()) + (r.data.size() == 1 ? " byte" : " bytes");
  if (r.type == core::ParamType::Unknown)
    return core::hex_bytes(r.data) + " (" + size + "; type not known: give --type to decode)";
  if (const auto error = core::param_size_error(r.type, r.data.size()); !error.empty())
    return core::hex_bytes(r.data) + " (" + error + ")";
  const std::string text = r.text();
  if (r.type == core::ParamType::VisibleString || r.type == core::ParamType::UnicodeString)
    return "\"" + text + "\" (" + cia + ", " + size + ")";
  if (const auto hex = core::format_param_hex(r.type, r.data)) {
    if (core::param_reads_as_hex(r.index, r.subindex)) return *hex + " (" + text + ", " + cia + ")";
    return text + " (" + *hex + ", " + cia + ")";
  }
  if (r.data.size() <= 16) return text + " (" + cia + ")";
  std::string dump = "(" + cia + ", " + size + ")";
  for (std::size_t at = 0; at < r.data.size(); at += 16) {
    char offset[32];
    std::snprintf(offset, sizeof offset, "\n  %04zx: ", at);
    dump += offset;
    dump += core::hex_bytes(std::span<const std::uint8_t>(r.data).subspan(at, std::min<std::size_t>(16, r.data.size() - at)));
  }
  return dump;
}

void json_value(JsonWriter& w, const ParamResult& r) {
  const bool fits = core::param_size_error(r.type, r.data.size()).empty();
  w.field("type", core::param_type_name(r.type));
  w.field("size", static_cast<std::uint64_t>(r.data.size()));
  w.field("bytes", std::string_view(core::hex_bytes(r.data)));
  if (!fits || r.type == core::ParamType::Unknown) return;
  if (r.type == core::ParamType::Bool && r.data[0] <= 1) {
    w.field("value", r.data[0] != 0);
  } else if (core::param_type_is_signed(r.type)) {
    w.field("value", *core::param_as_signed(r.type, r.data));
  } else if (core::param_type_is_integer(r.type)) {
    w.field("value", *core::param_as_unsigned(r.type, r.data));
  } else if (core::param_type_is_real(r.type)) {
    w.field("value", *core::param_as_real(r.type, r.data));
  } else {
    w.field("value", std::string_view(r.text()));
  }
  if (const auto hex = core::format_param_hex(r.type, r.data)) w.field("hex", std::string_view(*hex));
}

int cmd_param(Context& ctx) {
  const std::string& op = word(ctx, 0, "get|set");
  if (op != "get" && op != "set") throw UsageError("param: expected 'get' or 'set', got '" + op + "'");
  const bool write = op == "set";
  expect_words(ctx, write ? 4 : 3);
  ParamRequest req;
  req.axis = word(ctx, 1, "AXIS");
  req.gateway = ctx.gateway;
  const std::string& object = word(ctx, 2, "OBJECT");
  const bool record = core::is_record_address(object);  // its syntax was checked before discovery
  if (record || is_object_name(object)) {
    req.name = object;
  } else {
    const ObjectAddress addr = parse_address(object);
    req.index = addr.index;
    req.subindex = addr.sub;
  }
  req.write = write;
  req.type = ctx.args.option_or("type", "");
  if (!req.type.empty() && !core::param_type_from_name(req.type))
    throw UsageError("--type: unknown type '" + req.type +
                     "'; use u8, u16, u24, u32, u40, u48, u56, u64, i8 .. i64, r32, r64, bool, string, unicode, "
                     "octets, domain, time_of_day or time_difference");
  if (write) req.value = word(ctx, 3, "VALUE");
  const ParamResult r = ctx.client.param(req, ctx.timeout);
  char where[96];
  if (req.name.empty())
    std::snprintf(where, sizeof where, "%04Xh:%02X", req.index, static_cast<unsigned>(req.subindex));
  else if (r.ok && !record)
    std::snprintf(where, sizeof where, "%.60s (%04Xh:%02X)", req.name.c_str(), r.index,
                  static_cast<unsigned>(r.subindex));
  else
    std::snprintf(where, sizeof where, "%.60s", req.name.c_str());
  if (ctx.json) {
    JsonWriter w;
    w.begin_object()
        .field("axis", std::string_view(req.axis))
        .field("gateway", std::string_view(r.gateway))
        .field("object", std::string_view(where))
        .field("index", static_cast<std::uint64_t>(r.index))
        .field("subindex", static_cast<std::uint64_t>(r.subindex))
        .field("write", write)
        .field("ok", r.ok);
    if (r.ok) json_value(w, r);
    w.field("error_code", static_cast<std::uint64_t>(r.error_code)).field("error", std::string_view(r.error)).end_object();
    std::cout << w.str() << std::endl;
  } else if (r.ok) {
    std::cout << req.axis << " " << where << " = " << describe_value(r) << (write ? " written" : "") << "\n";
  }
  if (r.ok) return 0;
  char code[24] = "";
  if (r.error_code != 0) std::snprintf(code, sizeof code, " (0x%08X)", r.error_code);
  if (r.error.find(code + 2, 0, 10) != std::string::npos) code[0] = '\0';  // the text already names it
  return fail("param " + op + " " + req.axis + " " + where + ": " + r.error + code);
}

int cmd_buses(Context& ctx) {
  expect_words(ctx, 0);
  // The first read waits for every known gateway's bus statuses (client.hpp).
  ctx.client.wait_until([&] { return !ctx.client.buses().empty(); }, std::min(ctx.timeout, Millis(1500)));
  for (const auto& b : ctx.client.buses()) {
    if (!ctx.gateway.empty() && b.gateway != ctx.gateway) continue;
    if (ctx.json) {
      JsonWriter w;
      w.begin_object()
          .field("gateway", std::string_view(b.gateway))
          .field("bus", std::string_view(b.bus))
          .field("type", std::string_view(b.type))
          .field("running", b.running)
          .field("healthy", b.healthy)
          .field("period_ns", b.period_ns)
          .field("achieved_period_ns", b.achieved_period_ns)
          .field("lateness_p50_ns", b.lateness_p50_ns)
          .field("lateness_p99_ns", b.lateness_p99_ns)
          .field("lateness_max_ns", b.lateness_max_ns)
          .field("cycles", b.cycles)
          .field("overruns", b.overruns)
          .field("frames_sent", b.frames_sent)
          .field("frames_received", b.frames_received)
          .field("frames_lost", b.frames_lost)
          .field("frames_dropped", b.frames_dropped)
          .field("errors", b.errors);
      // Absent rather than 0 without a figure (a bus without distributed clocks).
      if (b.clock_sync) {
        w.field("clock_difference_ns", b.clock_difference_ns).field("clock_master_offset_ns", b.clock_master_offset_ns);
      }
      w.end_object();
      std::cout << w.str() << "\n";
      continue;
    }
    auto us = [](std::int64_t ns) { return std::to_string(ns / 1000) + "us"; };
    std::cout << b.gateway << "/" << b.bus << " (" << b.type << ") " << (b.running ? "running" : "stopped")
              << (b.healthy ? ", healthy" : ", UNHEALTHY") << "\n  period " << us(b.period_ns) << " achieved "
              << us(b.achieved_period_ns) << "  lateness p50 " << us(b.lateness_p50_ns) << " p99 "
              << us(b.lateness_p99_ns) << " max " << us(b.lateness_max_ns) << "\n  cycles " << b.cycles
              << " overruns " << b.overruns << "  frames sent " << b.frames_sent << " received "
              << b.frames_received << " lost " << b.frames_lost << " dropped " << b.frames_dropped << " errors "
              << b.errors << "\n";
    if (b.clock_sync) {
      std::cout << "  distributed clocks: max difference " << b.clock_difference_ns << "ns  master - reference "
                << b.clock_master_offset_ns << "ns\n";
    }
  }
  return 0;
}

// "01 ff", "0x01", "01ff" (any mix over several words) as bytes.
std::vector<std::uint8_t> parse_hex_bytes(const std::vector<std::string>& words) {
  std::vector<std::uint8_t> out;
  for (const auto& w : words) {
    std::size_t at = 0;
    while (at < w.size()) {
      if (w[at] == ' ' || w[at] == ',') {
        ++at;
        continue;
      }
      std::size_t end = w.find_first_of(" ,", at);
      if (end == std::string::npos) end = w.size();
      std::string token = w.substr(at, end - at);
      at = end;
      if (token.size() > 2 && token[0] == '0' && (token[1] == 'x' || token[1] == 'X')) token = token.substr(2);
      if (token.empty() || token.size() % 2 != 0 ||
          token.find_first_not_of("0123456789abcdefABCDEF") != std::string::npos)
        throw UsageError("io write: '" + w + "' is not hex bytes (e.g. 01 ff, 0x01, 01ff)");
      for (std::size_t i = 0; i < token.size(); i += 2)
        out.push_back(static_cast<std::uint8_t>(std::stoul(token.substr(i, 2), nullptr, 16)));
    }
  }
  if (out.empty()) throw UsageError("io write: no bytes given");
  return out;
}

void print_io_json(const IoState& st) {
  JsonWriter w;
  w.begin_object()
      .field("gateway", std::string_view(st.gateway))
      .field("bus", std::string_view(st.bus))
      .field("slave", std::string_view(st.slave))
      .field("address", static_cast<std::uint64_t>(st.address))
      .field("valid", st.valid)
      .field("input_size", static_cast<std::uint64_t>(st.inputs.size()))
      .field("output_size", static_cast<std::uint64_t>(st.outputs.size()))
      .field("inputs", std::string_view(core::hex_bytes(st.inputs)))
      .field("outputs", std::string_view(core::hex_bytes(st.outputs)))
      .field("stamp_ns", st.stamp_ns)
      .end_object();
  std::cout << w.str() << "\n";
}

int cmd_io(Context& ctx) {
  const std::string bus = ctx.args.option_or("bus", "");
  const auto selected = [&](const IoState& st) {
    return (ctx.gateway.empty() || st.gateway == ctx.gateway) && (bus.empty() || st.bus == bus);
  };
  if (ctx.words.size() >= 2) {
    if (ctx.words[1] != "write") throw UsageError("io: expected 'write' after the slave's name, got '" + ctx.words[1] + "'");
    IoWriteRequest req;
    req.slave = ctx.words[0];
    req.bus = bus;
    req.gateway = ctx.gateway;
    req.offset = static_cast<std::uint32_t>(parse_integer("OFFSET", word(ctx, 2, "OFFSET"), 0, 65535));
    req.data = parse_hex_bytes({ctx.words.begin() + 3, ctx.words.end()});
    const IoWriteResult r = ctx.client.io_write(req, ctx.timeout);
    if (ctx.json) {
      JsonWriter w;
      w.begin_object()
          .field("slave", std::string_view(req.slave))
          .field("gateway", std::string_view(r.gateway))
          .field("bus", std::string_view(r.bus))
          .field("offset", static_cast<std::uint64_t>(req.offset))
          .field("bytes", std::string_view(core::hex_bytes(req.data)))
          .field("ok", r.ok)
          .field("status", std::string_view(r.status))
          .field("error", std::string_view(r.error))
          .end_object();
      std::cout << w.str() << std::endl;
    } else if (r.ok) {
      std::cout << "io " << req.slave << " (" << r.gateway << "/" << r.bus << "): " << req.data.size()
                << " byte(s) at offset " << req.offset << " written: " << core::hex_bytes(req.data) << std::endl;
    }
    if (r.ok) return 0;
    return fail("io " + req.slave + " write: " + (r.status.empty() ? "" : r.status + ": ") + r.error);
  }
  auto states = ctx.client.io_states();
  std::erase_if(states, [&](const IoState& st) { return !selected(st); });
  if (ctx.words.size() == 1) {
    std::erase_if(states, [&](const IoState& st) { return st.slave != ctx.words[0]; });
    if (states.empty()) {
      std::string known;
      for (const auto& st : ctx.client.io_states()) known += (known.empty() ? "" : ", ") + st.slave;
      return fail("no I/O slave '" + ctx.words[0] + "'" + (bus.empty() ? "" : " on bus " + bus) +
                  "; I/O slaves: " + (known.empty() ? "(none)" : known));
    }
  }
  for (const auto& st : states) {
    if (ctx.json) {
      print_io_json(st);
      continue;
    }
    const std::string validity = st.valid ? "valid" : "STALE";
    if (ctx.words.empty()) {
      std::cout << st.slave << "  " << st.gateway << "/" << st.bus << "  address=" << st.address << "  " << validity
                << "  in=[" << core::hex_bytes(st.inputs) << "]  out=[" << core::hex_bytes(st.outputs) << "]\n";
    } else {
      std::cout << st.slave << " (" << st.gateway << "/" << st.bus << ", address " << st.address << "): "
                << (st.valid ? "inputs valid" : "inputs STALE (the slave is not exchanging process data)") << "\n"
                << "  inputs  (" << st.inputs.size() << " bytes): " << core::hex_bytes(st.inputs) << "\n"
                << "  outputs (" << st.outputs.size() << " bytes): " << core::hex_bytes(st.outputs) << "\n";
    }
  }
  if (states.empty() && !ctx.json) std::cout << "no I/O slaves\n";
  return 0;
}

const StringSet kGlobal{"domain", "namespace", "gateway", "identity", "interfaces", "json", "timeout", "help"};

StringSet options_of(std::string_view command) {
  StringSet s = kGlobal;
  auto add = [&](std::initializer_list<const char*> names) { s.insert(names.begin(), names.end()); };
  if (command == "status") add({"watch"});
  if (command == "move") add({"relative", "velocity", "accel", "decel", "queued", "no-wait"});
  if (command == "velocity") add({"accel", "for"});
  if (command == "torque") add({"for"});
  if (command == "home") add({"method", "offset"});
  if (command == "events") add({"follow"});
  if (command == "param") add({"type"});
  if (command == "io") add({"bus"});
  return s;
}

int run(int argc, char** argv) {
  const Args args(argc, argv, {"json", "watch", "relative", "queued", "no-wait", "follow", "signed", "help"});
  if (args.positional().empty()) {
    if (args.flag("help")) {
      print_usage(std::cout);
      return 0;
    }
    print_usage(std::cerr);
    return 2;
  }
  const std::string command = args.positional().front();
  if (args.flag("help")) {
    print_command_usage(command);
    return 0;
  }
  const auto* help = std::find_if(std::begin(kCommands), std::end(kCommands),
                                  [&](const CommandHelp& c) { return command == c.name; });
  if (help == std::end(kCommands)) throw UsageError("unknown command '" + command + "'");
  args.reject_unknown(options_of(command));
  const std::size_t words = args.positional().size() - 1;
  if (words < help->min_words) throw UsageError(std::string("missing arguments; usage: ") + help->usage);
  if (words > help->max_words) throw UsageError(std::string("too many arguments; usage: ") + help->usage);

  ClientOptions opts;
  opts.domain = static_cast<std::uint32_t>(parse_integer("--domain", args.option_or("domain", "0"), 0, 232));
  opts.ns = args.option_or("namespace", "drivegate");
  opts.identity = args.option_or("identity", "");
  opts.interfaces = split_commas(args.option_or("interfaces", ""));
  const double timeout_s = args.number("timeout").value_or(5.0);
  if (timeout_s <= 0) throw UsageError("--timeout must be positive");

  install_interrupt_handler();
  Client client(opts);
  Context ctx{client, args, args.flag("json"), Millis(static_cast<std::int64_t>(timeout_s * 1000)),
              args.option_or("gateway", ""), {args.positional().begin() + 1, args.positional().end()}};

  // A record address is checked before anything goes out (discovery included).
  if (command == "param" && ctx.words.size() >= 3 && core::is_record_address(ctx.words[2]))
    if (const auto parsed = core::parse_record_address(ctx.words[2]); !parsed.address)
      throw UsageError("param: " + parsed.error);
  if (int rc = require_gateways(ctx)) return rc;
  if (command == "list") return cmd_list(ctx);
  if (command == "status") return cmd_status(ctx);
  if (command == "enable") return cmd_simple(ctx, command, "enable");
  if (command == "disable") return cmd_simple(ctx, command, "disable");
  if (command == "stop") return cmd_simple(ctx, command, "stop");
  if (command == "quick-stop") return cmd_simple(ctx, command, "quick_stop");
  if (command == "halt") return cmd_simple(ctx, command, "halt");
  if (command == "resume") return cmd_simple(ctx, command, "resume");
  if (command == "reset") return cmd_simple(ctx, command, "fault_reset");
  if (command == "mode") return cmd_mode(ctx);
  if (command == "move") return cmd_move(ctx);
  if (command == "velocity") return cmd_stream(ctx, false);
  if (command == "torque") return cmd_stream(ctx, true);
  if (command == "home") return cmd_home(ctx);
  if (command == "events") return cmd_events(ctx);
  if (command == "param") return cmd_param(ctx);
  if (command == "io") return cmd_io(ctx);
  return cmd_buses(ctx);
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const UsageError& e) {
    std::cerr << "drivegatectl: " << e.what() << " (see drivegatectl --help)\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "drivegatectl: " << e.what() << "\n";
    return 1;
  }
}
