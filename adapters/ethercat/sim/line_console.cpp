#include "adapters/ethercat/sim/line_console.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <optional>
#include <span>
#include <sstream>

#include "adapters/ethercat/sim/cia402_slave.hpp"
#include "adapters/ethercat/sim/generic_io.hpp"
#include "adapters/ethercat/wire/al_status.hpp"
#include "adapters/ethercat/wire/registers.hpp"
#include "core/axis_types.hpp"
#include "core/bytes.hpp"

namespace drivegate::ethercat::sim {

namespace {

std::optional<unsigned long> parse_number(std::string_view s) {
  int base = 10;
  if (s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X')) {
    s.remove_prefix(2);
    base = 16;
  }
  unsigned long v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v, base);
  if (s.empty() || ec != std::errc{} || end != s.data() + s.size()) return std::nullopt;
  return v;
}

std::string hex4(unsigned v) {
  std::array<char, 8> b{};
  std::snprintf(b.data(), b.size(), "0x%04X", v);
  return b.data();
}

// The states a slave can be held at, as the console names them (registers.hpp to_string).
std::optional<AlState> parse_state(std::string_view s) {
  std::string u;
  for (const char c : s) {
    if (c != '-' && c != '_') u += static_cast<char>(c >= 'a' && c <= 'z' ? c - 'a' + 'A' : c);
  }
  if (u == "INIT") return AlState::Init;
  if (u == "PREOP") return AlState::PreOp;
  if (u == "SAFEOP") return AlState::SafeOp;
  return std::nullopt;
}

std::string name_of(const BuiltLine& line, std::size_t index) { return line.bus() + ":" + std::to_string(index + 1); }

std::string hex_bytes(std::span<const std::uint8_t> bytes) {
  std::string s;
  for (const std::uint8_t b : bytes) {
    std::array<char, 4> t{};
    std::snprintf(t.data(), t.size(), "%02x", b);
    s += t.data();
  }
  return s;
}

// `drive K`: what the drive model does, which the master sees only through the process data.
std::string drive_detail(const SimSlave& slave, const std::string& id) {
  const auto* drive = dynamic_cast<const Cia402Slave*>(slave.parts.app.get());
  if (drive == nullptr) return "error: " + id + " (" + slave.persona + ") is not a CiA 402 drive";
  if (!slave.powered) return "drive " + id + " " + slave.persona + " off";
  const auto& m = drive->drive();
  std::string s = "drive " + id + " " + slave.persona;
  s += " state=" + std::string(core::to_string(m.state()));
  s += " sw=" + hex4(m.statusword());
  s += " mode=" + std::to_string(m.active_mode());
  s += " pos=" + std::to_string(static_cast<long long>(std::llround(m.position())));
  s += " error=" + hex4(static_cast<unsigned>(m.read_object({0x603F, 0}).value));
  s += " sync0=" + (slave.esc->sync0_running() ? std::to_string(slave.esc->sync0_pulses()) : std::string("off"));
  return s;
}

// `io K [BYTE...]`: a generic I/O slave's outputs as the master wrote them, and its inputs.
std::string io_detail(SimSlave& slave, const std::string& id, const std::vector<std::string>& bytes) {
  auto* io = dynamic_cast<GenericIoSlave*>(slave.parts.app.get());
  if (io == nullptr) return "error: " + id + " (" + slave.persona + ") is not a generic I/O slave";
  if (bytes.size() > io->inputs().size())
    return "error: io: " + id + " has " + std::to_string(io->inputs().size()) + " input bytes";
  std::vector<std::uint8_t> values;
  for (const auto& b : bytes) {
    const auto v = parse_number(b);
    if (!v || *v > 0xFF) return "error: io: \"" + b + "\" is not a byte (0..255 or 0x00..0xFF)";
    values.push_back(static_cast<std::uint8_t>(*v));
  }
  std::copy(values.begin(), values.end(), io->inputs().begin());
  return std::string(values.empty() ? "" : "ok ") + "io " + id + " out=" + hex_bytes(io->outputs()) +
         " in=" + hex_bytes(io->inputs());
}

}  // namespace

bool LineConsole::handles(std::string_view verb) noexcept {
  for (const std::string_view v :
       {"power-off", "power-on", "break-after", "mend", "drop", "corrupt", "stick", "unstick", "status", "drive", "io"}) {
    if (verb == v) return true;
  }
  return false;
}

bool LineConsole::find(std::string_view text, Slot& out, std::string& error) const {
  const auto colon = text.find(':');
  const std::string_view bus = colon == std::string_view::npos ? std::string_view{} : text.substr(0, colon);
  const auto k = parse_number(colon == std::string_view::npos ? text : text.substr(colon + 1));
  if (text.empty() || !k || *k < 1) {
    error = "\"" + std::string(text) + "\" is not a slave position 1.. (or BUS:K)";
    return false;
  }
  std::size_t found = 0;
  bool bus_known = bus.empty();
  for (BuiltLine* l : lines_) {
    if (!bus.empty() && l->bus() != bus) continue;
    bus_known = true;
    if (*k <= l->size()) {
      out = Slot{l, static_cast<std::size_t>(*k - 1)};
      ++found;
    }
  }
  if (!bus_known) {
    error = "no simulated EtherCAT line " + std::string(bus);
    return false;
  }
  if (found == 0) {
    error = "no simulated EtherCAT slave " + std::string(text);
    if (lines_.size() == 1) error += " (the line has " + std::to_string(lines_.front()->size()) + ")";
    return false;
  }
  if (found > 1) {
    error = "slave " + std::string(text) + " is on several lines: name it as BUS:K";
    return false;
  }
  return true;
}

std::size_t LineConsole::matches(std::string_view text) const {
  const auto colon = text.find(':');
  const std::string_view bus = colon == std::string_view::npos ? std::string_view{} : text.substr(0, colon);
  const auto k = parse_number(colon == std::string_view::npos ? text : text.substr(colon + 1));
  if (!k || *k < 1) return 0;
  std::size_t n = 0;
  for (const BuiltLine* l : lines_) {
    if ((bus.empty() || l->bus() == bus) && *k <= l->size()) ++n;
  }
  return n;
}

BuiltLine* LineConsole::find_line(std::string_view bus, std::string& error) const {
  if (bus.empty()) {
    if (lines_.size() == 1) return lines_.front();
    error = lines_.empty() ? "no simulated EtherCAT line" : "several EtherCAT lines: name one (BUS)";
    return nullptr;
  }
  for (BuiltLine* l : lines_) {
    if (l->bus() == bus) return l;
  }
  error = "no simulated EtherCAT line " + std::string(bus);
  return nullptr;
}

std::string LineConsole::command(std::string_view text) {
  std::istringstream in{std::string(text)};
  std::string verb;
  in >> verb;
  std::vector<std::string> args;
  for (std::string a; in >> a;) args.push_back(a);
  if (verb.empty()) return "error: empty command";
  if (!handles(verb)) return "error: unknown command \"" + verb + "\" (" + std::string(kCommands) + ")";
  if (verb == "status") {
    if (!args.empty()) return "error: status takes no arguments";
    return "status:" + status_items();
  }
  std::string error;
  if (verb == "mend" || verb == "drop" || verb == "corrupt") {
    const bool counted = verb != "mend";
    const std::size_t bus_arg = counted ? 1 : 0;
    if (args.size() > bus_arg + 1 || args.size() < bus_arg) {
      return "error: " + verb + " takes " + (counted ? "N [BUS] (N frames, 1..1000000)" : "[BUS]");
    }
    BuiltLine* line = find_line(args.size() > bus_arg ? args[bus_arg] : std::string{}, error);
    if (line == nullptr) return "error: " + error;
    if (!counted) {
      line->mend();
      return "ok mend " + line->bus();
    }
    const auto n = parse_number(args[0]);
    if (!n || *n < 1 || *n > 1'000'000) return "error: " + verb + " takes N [BUS] (N frames, 1..1000000)";
    if (verb == "drop") {
      line->drop(*n);
    } else {
      line->corrupt(*n);
    }
    return "ok " + verb + " " + line->bus() + " " + std::to_string(*n);
  }
  if (verb == "drive" || verb == "io") {
    if (args.empty() || (verb == "drive" && args.size() != 1)) return "error: " + verb + " takes K" + (verb == "io" ? " [BYTE...]" : "");
    Slot s;
    if (!find(args[0], s, error)) return "error: " + error;
    SimSlave& slave = s.line->slave(s.index);
    const std::string id = name_of(*s.line, s.index);
    return verb == "drive" ? drive_detail(slave, id) : io_detail(slave, id, {args.begin() + 1, args.end()});
  }
  // The commands on one slave.
  const std::size_t want = verb == "stick" ? 3 : 1;
  if (args.size() != want) {
    return "error: " + verb + " takes " + (verb == "stick" ? "K STATE CODE (STATE INIT, PRE-OP or SAFE-OP; CODE 0x0001..0xFFFF)" : "K");
  }
  Slot s;
  if (!find(args[0], s, error)) return "error: " + error;
  const std::string id = name_of(*s.line, s.index);
  if (verb == "power-off") {
    s.line->power_off(s.index);
    return "ok power-off " + id;
  }
  if (verb == "power-on") {
    s.line->power_on(s.index);
    return "ok power-on " + id;
  }
  if (verb == "break-after") {
    s.line->break_after(s.index);
    return "ok break-after " + id;
  }
  if (verb == "unstick") {
    s.line->unstick(s.index);
    return "ok unstick " + id;
  }
  // stick
  const auto state = parse_state(args[1]);
  const auto code = parse_number(args[2]);
  if (!state) return "error: stick: \"" + args[1] + "\" is not INIT, PRE-OP or SAFE-OP (unstick lifts the limit)";
  if (!code || *code < 1 || *code > 0xFFFF) return "error: stick: the AL status code is 0x0001..0xFFFF, got \"" + args[2] + "\"";
  s.line->stick(s.index, *state, static_cast<std::uint16_t>(*code));
  return "ok stick " + id + " " + std::string(to_string(*state)) + " " + hex4(static_cast<unsigned>(*code)) + " (" +
         std::string(al_status_text(static_cast<std::uint16_t>(*code))) + ")";
}

std::string LineConsole::status_items() const {
  std::string s;
  for (const BuiltLine* l : lines_) {
    for (std::size_t k = 0; k < l->size(); ++k) {
      const SimSlave& slave = l->slave(k);
      s += " " + name_of(*l, k) + " " + slave.persona;
      if (!slave.powered) {
        s += " off;";
        continue;
      }
      const EscSlave& esc = *slave.esc;
      const bool error = (core::get_u16(esc.memory(), reg::kAlStatus) & kAlErrorBit) != 0;
      s += " station=" + hex4(esc.station_address());
      s += " state=" + std::string(to_string(esc.state())) + (error ? "+ERR" : "");
      s += " code=" + hex4(esc.al_status_code());
      s += " frames=" + std::to_string(slave.frames_seen);
      if (const auto at = l->stuck_at(k)) s += " stuck=" + std::string(to_string(*at));
      s += ";";
    }
    if (const auto cut = l->broken_after()) s += " " + l->bus() + " cable cut after " + std::to_string(*cut + 1) + ";";
  }
  return s;
}

}  // namespace drivegate::ethercat::sim
