#include "adapters/profinet/sim/pn_console.hpp"

#include <algorithm>
#include <array>
#include <cstdio>
#include <optional>
#include <span>
#include <sstream>

#include "adapters/profinet/sim/generic_io_persona.hpp"
#include "config/scalars.hpp"
#include "core/param_value.hpp"

namespace drivegate::profinet {

namespace {

// A whole number in [lo, hi] (decimal or 0x hex).
std::optional<std::uint32_t> number(std::string_view s, std::uint32_t lo, std::uint32_t hi) {
  const auto v = config::parse_integer(s);
  if (!v || *v < lo || *v > hi) return std::nullopt;
  return static_cast<std::uint32_t>(*v);
}

std::string hex4(unsigned v) {
  std::array<char, 8> b{};
  std::snprintf(b.data(), b.size(), "0x%04X", v);
  return b.data();
}

std::string ip_text(std::uint32_t ip) {
  return std::to_string(ip >> 24) + "." + std::to_string((ip >> 16) & 0xFF) + "." + std::to_string((ip >> 8) & 0xFF) +
         "." + std::to_string(ip & 0xFF);
}

std::string name_of(const BuiltPnNetwork& n, const PnSimStation& s) { return n.bus() + ":" + s.name; }

// SLOT or SLOT:SUBSLOT as the console takes it; false when `text` is neither.
bool parse_place(std::string_view text, std::optional<std::uint16_t>& slot, std::optional<std::uint16_t>& subslot) {
  const auto colon = text.find(':');
  const auto s = number(text.substr(0, colon), 0, 0x7FFF);
  const auto ss = colon == std::string_view::npos ? std::optional<std::uint32_t>{} : number(text.substr(colon + 1), 1, 0xFFFF);
  if (!s || (colon != std::string_view::npos && !ss)) return false;
  slot = static_cast<std::uint16_t>(*s);
  if (ss) subslot = static_cast<std::uint16_t>(*ss);
  return true;
}

// Bytes as one word of hex digits ("00C3"), "-" for none.
std::string hex_word(std::span<const std::uint8_t> bytes) {
  if (bytes.empty()) return "-";
  std::string s = core::hex_bytes(bytes);
  std::erase(s, ' ');
  return s;
}

std::string_view to_string(PnOutputs o) noexcept {
  switch (o) {
    case PnOutputs::NotYet: return "not-yet";
    case PnOutputs::Valid: return "valid";
    case PnOutputs::Stop: return "stop";
    case PnOutputs::Lost: return "lost";
  }
  return "unknown";
}

// The alarm kinds of the console [IEC 61158-6-10, AlarmType; process alarms go high, the others
// low priority].
struct AlarmKind {
  std::string_view word;
  std::uint16_t type;
  AlarmPriority priority;
  bool diagnosis;  // carries a ChannelDiagnosis
  bool appears;
};
constexpr std::array<AlarmKind, 6> kAlarmKinds{{
    {"process", alarm_type::kProcess, AlarmPriority::High, false, false},
    {"diagnosis", alarm_type::kDiagnosis, AlarmPriority::Low, true, true},
    {"diagnosis-gone", alarm_type::kDiagnosisDisappears, AlarmPriority::Low, true, false},
    {"pull", alarm_type::kPull, AlarmPriority::Low, false, false},
    {"plug", alarm_type::kPlug, AlarmPriority::Low, false, false},
    {"return", alarm_type::kReturnOfSubmodule, AlarmPriority::Low, false, false},
}};
// ChannelErrorType 0009h "error" [IEC 61158-6-10, ChannelErrorType].
constexpr std::uint16_t kDefaultChannelError = 0x0009;

// The submodule a command names: the slot and subslot given (a slot alone: its first submodule;
// neither: the first one with IO data), with the idents plugged there.
struct Place {
  const CmModelSlot* slot = nullptr;
  const CmModelSubmodule* submodule = nullptr;
};
Place place(PnPersona& persona, std::optional<std::uint16_t> slot, std::optional<std::uint16_t> subslot) {
  for (const CmModelSlot& s : persona.slots()) {
    if (slot && s.slot != *slot) continue;
    for (const CmModelSubmodule& m : s.submodules) {
      if (subslot && m.subslot != *subslot) continue;
      const PnPersona::IoLengths l = persona.lengths(s.api, s.slot, m.subslot);
      if (slot || l.input + l.output > 0) return {&s, &m};
    }
  }
  return {};
}

}  // namespace

bool PnConsole::handles(std::string_view verb) noexcept {
  for (const std::string_view v :
       {"power-off", "power-on", "reboot", "abort-ar", "lose", "drive-fault", "alarm", "io", "status"}) {
    if (verb == v) return true;
  }
  return false;
}

std::size_t PnConsole::matches(std::string_view text) const {
  const auto colon = text.find(':');
  const std::string_view bus = colon == std::string_view::npos ? std::string_view{} : text.substr(0, colon);
  const std::string_view name = colon == std::string_view::npos ? text : text.substr(colon + 1);
  return static_cast<std::size_t>(std::count_if(networks_.begin(), networks_.end(), [&](BuiltPnNetwork* n) {
    return (bus.empty() || n->bus() == bus) && n->find(name) != nullptr;
  }));
}

bool PnConsole::find(std::string_view text, Target& out, std::string& error) const {
  const auto colon = text.find(':');
  const std::string_view bus = colon == std::string_view::npos ? std::string_view{} : text.substr(0, colon);
  const std::size_t found = matches(text);
  if (!bus.empty() && std::none_of(networks_.begin(), networks_.end(), [&](BuiltPnNetwork* n) { return n->bus() == bus; })) {
    error = "no simulated PROFINET network " + std::string(bus);
  } else if (found == 0) {
    error = "no simulated PROFINET station " + std::string(text);
  } else if (found > 1) {
    error = "station " + std::string(text) + " is on several networks: name it as BUS:STATION";
  } else {
    const std::string_view name = colon == std::string_view::npos ? text : text.substr(colon + 1);
    for (BuiltPnNetwork* n : networks_) {
      if (!bus.empty() && n->bus() != bus) continue;
      if (PnSimStation* s = n->find(name)) out = {n, s};
    }
  }
  return found == 1;
}

std::string PnConsole::command(std::string_view line, core::TimePoint now) {
  std::istringstream in{std::string(line)};
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
  if (args.empty()) return "error: " + verb + " takes a STATION (" + std::string(kCommands) + ")";
  Target t;
  std::string error;
  if (!find(args[0], t, error)) return "error: " + error;
  PnDevice& d = *t.station->device;
  const std::string id = name_of(*t.network, *t.station);
  const std::size_t want = verb == "lose" ? 3 : verb == "drive-fault" ? 2 : 1;
  if (verb == "alarm") return alarm(t, id, args);
  if (verb == "io") return io(t, id, args);
  if (args.size() != want) {
    if (verb == "lose") return "error: lose takes STATION rx|tx N (N frames, 1..1000000)";
    if (verb == "drive-fault") return "error: drive-fault takes STATION NUMBER (an AKD fault number 1..65535)";
    return "error: " + verb + " takes STATION";
  }
  if (verb == "power-off") {
    d.power_loss();
    return "ok power-off " + id;
  }
  if (verb == "power-on" || verb == "reboot") {
    if (verb == "reboot") d.power_loss();
    d.power_return(now);
    return "ok " + verb + " " + id;
  }
  if (!d.powered()) return "error: " + id + " is off (power-on " + args[0] + ")";
  if (verb == "abort-ar") {
    if (d.ar_state() == CmServerState::NoAr) return "error: " + id + " has no AR";
    d.abort_ar("aborted from the simulator's console");
    return "ok abort-ar " + id;
  }
  if (verb == "lose") {
    const auto n = number(args[2], 1, 1'000'000);
    if ((args[1] != "rx" && args[1] != "tx") || !n) return "error: lose takes STATION rx|tx N (N frames, 1..1000000)";
    if (args[1] == "rx") {
      d.lose_rx_frames(*n);
    } else {
      d.lose_tx_frames(*n);
    }
    return "ok lose " + id + " " + args[1] + " " + std::to_string(*n);
  }
  // drive-fault
  if (t.station->akd == nullptr) return "error: " + id + " (" + t.station->persona + ") is not a drive";
  const auto fault = number(args[1], 1, 0xFFFF);
  if (!fault) return "error: drive-fault takes STATION NUMBER (an AKD fault number 1..65535)";
  t.station->akd->inject_drive_fault(static_cast<std::uint16_t>(*fault));
  return "ok drive-fault " + id + " " + std::to_string(*fault);
}

std::string PnConsole::alarm(const Target& t, const std::string& id, const std::vector<std::string>& args) const {
  constexpr std::string_view kUsage =
      "error: alarm takes STATION process|diagnosis|diagnosis-gone|pull|plug|return [SLOT[:SUBSLOT]] [ERROR]";
  if (args.size() < 2 || args.size() > 4) return std::string(kUsage);
  const auto kind = std::find_if(kAlarmKinds.begin(), kAlarmKinds.end(), [&](const AlarmKind& k) { return k.word == args[1]; });
  if (kind == kAlarmKinds.end()) return std::string(kUsage);
  std::optional<std::uint16_t> slot;
  std::optional<std::uint16_t> subslot;
  if (args.size() >= 3 && !parse_place(args[2], slot, subslot))
    return "error: alarm: \"" + args[2] + "\" is not SLOT or SLOT:SUBSLOT";
  std::uint16_t error_type = kDefaultChannelError;
  if (args.size() == 4) {
    const auto e = number(args[3], 1, 0xFFFF);
    if (!kind->diagnosis || !e) return "error: alarm: ERROR (a ChannelErrorType 1..0xFFFF) goes with diagnosis and diagnosis-gone";
    error_type = static_cast<std::uint16_t>(*e);
  }
  PnDevice& d = *t.station->device;
  if (!d.powered()) return "error: " + id + " is off";
  const Place p = place(d.persona(), slot, subslot);
  if (p.slot == nullptr) return "error: " + id + " has no submodule " + (args.size() >= 3 ? args[2] : "with IO data");
  AlarmNotification n;
  n.priority = kind->priority;
  n.alarm_type = kind->type;
  n.api = p.slot->api;
  n.slot = p.slot->slot;
  n.subslot = p.submodule->subslot;
  n.module_ident = p.slot->module_ident;
  n.submodule_ident = p.submodule->ident;
  // ChannelNumber 8000h (the whole submodule), ChannelProperties: specifier appears (1) or
  // disappears (2) in bits 11-12, fault, direction 0 (manufacturer specific); ChannelErrorType.
  std::array<std::uint8_t, 6> diagnosis{0x80, 0x00, static_cast<std::uint8_t>(kind->appears ? 0x08 : 0x10), 0x00,
                                        static_cast<std::uint8_t>(error_type >> 8), static_cast<std::uint8_t>(error_type)};
  if (kind->diagnosis) {
    n.specifier.channel_diagnosis = true;
    n.specifier.submodule_diagnosis = kind->appears;
    n.specifier.ar_diagnosis = kind->appears;
    n.has_user_structure = true;
    n.user_structure_id = user_structure::kChannelDiagnosis;
    n.user_data = diagnosis;
  }
  if (d.alarm_cr() == nullptr) return "error: " + id + " has no AR (an alarm needs the AR's alarm CR)";
  if (d.alarm_cr()->state() != AlarmSenderState::Open) return "error: " + id + "'s alarm CR is " + std::string(to_string(d.alarm_cr()->state()));
  if (!d.send_alarm(n)) {
    return "error: " + id + ": " + std::to_string(AlarmSender::kQueueDepth) + " " + to_string(n.priority) +
           " priority alarms wait for their AlarmAck already";
  }
  return "ok alarm " + id + " " + args[1] + " slot " + std::to_string(n.slot) + " subslot " + hex4(n.subslot);
}

std::string PnConsole::io(const Target& t, const std::string& id, const std::vector<std::string>& args) {
  GenericIoPersona* dev = t.station->io;
  if (dev == nullptr) return "error: " + id + " (" + t.station->persona + ") is not a generic IO device";
  if (args.size() < 2) return "error: io takes STATION SLOT[:SUBSLOT] [BYTE...]";
  std::optional<std::uint16_t> slot;
  std::optional<std::uint16_t> subslot;
  if (!parse_place(args[1], slot, subslot)) return "error: io: \"" + args[1] + "\" is not SLOT or SLOT:SUBSLOT";
  PnDevice& d = *t.station->device;
  if (!d.powered()) return "error: " + id + " is off (power-on " + args[0] + ")";
  const Place p = place(d.persona(), slot, subslot);
  if (p.slot == nullptr) return "error: " + id + " has no submodule " + args[1];
  const std::uint32_t api = p.slot->api;
  const std::uint16_t s = p.slot->slot;
  const std::uint16_t ss = p.submodule->subslot;
  const std::string where = std::to_string(s) + ":" + std::to_string(ss);
  if (args.size() > 2) {
    const std::size_t inputs = dev->input(api, s, ss).size();
    if (inputs == 0) return "error: io: " + id + " " + where + " has no inputs to set";
    if (args.size() - 2 != inputs) {
      return "error: io: " + id + " " + where + " takes " + std::to_string(inputs) + " input bytes, not " +
             std::to_string(args.size() - 2);
    }
    std::vector<std::uint8_t> values;
    for (std::size_t i = 2; i < args.size(); ++i) {
      const auto v = number(args[i], 0, 0xFF);
      if (!v) return "error: io: \"" + args[i] + "\" is not a byte (0..255 or 0x00..0xFF)";
      values.push_back(static_cast<std::uint8_t>(*v));
    }
    (void)dev->set_input(api, s, ss, values);  // the length is checked above
  }
  return std::string(args.size() > 2 ? "ok " : "") + "io " + id + " " + where + " out=" + hex_word(dev->output(api, s, ss)) +
         " out-state=" + std::string(to_string(dev->outputs(api, s, ss))) + " in=" + hex_word(dev->input(api, s, ss));
}

std::string PnConsole::status_items() const {
  std::string s;
  for (const BuiltPnNetwork* n : networks_) {
    for (std::size_t i = 0; i < n->size(); ++i) {
      const PnSimStation& st = n->station(i);
      const PnDevice& d = *st.device;
      s += " " + name_of(*n, st) + " " + st.persona;
      if (!d.powered()) {
        s += " off;";
        continue;
      }
      const PnDeviceCounters& c = d.counters();
      const AlarmSender* a = d.alarm_cr();
      s += " name=" + std::string(d.name_of_station());
      s += " mac=" + std::string(mac_text(d.mac()).data());
      s += " ip=" + ip_text(d.ip());
      s += " ar=" + std::string(to_string(d.ar_state()));
      s += " cycles=" + std::to_string(c.cycles);
      s += " watchdog=" + std::to_string(c.watchdog_aborts);
      s += " alarm-cr=" + std::to_string(c.alarm_cr_aborts);
      s += " rx-lost=" + std::to_string(c.rx_lost);
      s += " tx-lost=" + std::to_string(c.tx_lost);
      s += " alarms=" + (a != nullptr ? std::to_string(a->counters().queued) + "/" + std::to_string(a->counters().acknowledged) : "-");
      s += ";";
    }
  }
  return s;
}

}  // namespace drivegate::profinet
