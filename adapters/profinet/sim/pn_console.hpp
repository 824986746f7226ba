#pragma once
// The fault console of simulated PROFINET networks (issue 10 "Simulator": fault injection from
// drivegate-sim's console): one command a line, one answer line each, "ok ..." or "error: ...".
//
//   power-off STATION        the device loses power: its AR ends without a word, it hears nothing,
//                            its temporary IP address (and name) are gone (pn_device.hpp)
//   power-on STATION         power back: the device boots with what it stored (the config's
//                            name; an IP address only when the controller set it permanently)
//   reboot STATION           power-off and power-on at once
//   abort-ar STATION         the device ends its AR (the controller sees the input CR fall silent)
//   lose STATION rx|tx N     the next N cyclic frames the device receives / sends are lost
//   drive-fault STATION NUMBER  an AKD fault number (e.g. 501) into the drive (ZSW1 bit 3; PNU 947)
//   alarm STATION KIND [SLOT[:SUBSLOT]] [ERROR]
//                            an alarm over the running AR's alarm CR; KIND process (high
//                            priority), diagnosis / diagnosis-gone (a ChannelDiagnosis of the whole
//                            submodule, ChannelErrorType ERROR, default 0x0009 "error", appearing /
//                            disappearing), pull, plug, return (return of submodule) (low
//                            priority); the submodule defaults to the first one with IO data (the
//                            AKD's telegram in slot 1), the idents are those plugged there
//   io STATION SLOT[:SUBSLOT] [BYTE...]
//                            a generic IO device's submodule (SUBSLOT: the slot's first):
//                            "io pn0:io-block 2:1 out=11C3 out-state=valid in=-", the outputs the
//                            controller wrote last and what they were worth (valid, stop: the
//                            controller in STOP or the IOPS bad, not-yet, lost: no AR), and the
//                            inputs it sends ("-": none); with bytes (as many as it has inputs) it
//                            sets the inputs from the next cycle on ("ok io ..."). The device never
//                            takes its inputs from its outputs.
//   status                   per device: BUS:STATION persona name=... mac=... ip=... ar=...
//                            cycles=N watchdog=N alarm-cr=N rx-lost=N tx-lost=N alarms=SENT/ACKED;
//                            (" BUS:STATION persona off;" without power)
//
// STATION is a configured NameOfStation, BUS:STATION when several networks have it. Numbers are
// decimal or 0x hex. Commands that need the time take the caller's (the thread that runs the
// networks).
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "adapters/profinet/sim/network_builder.hpp"
#include "core/clock.hpp"

namespace drivegate::profinet {

class PnConsole {
 public:
  static constexpr std::string_view kCommands =
      "power-off STATION, power-on STATION, reboot STATION, abort-ar STATION, lose STATION rx|tx N, "
      "drive-fault STATION NUMBER, alarm STATION process|diagnosis|diagnosis-gone|pull|plug|return "
      "[SLOT[:SUBSLOT]] [ERROR], io STATION SLOT[:SUBSLOT] [BYTE...], status (STATION: a NameOfStation or "
      "BUS:STATION)";

  // The network must outlive the console; commands run on the thread that runs it.
  void add(BuiltPnNetwork& network) { networks_.push_back(&network); }
  [[nodiscard]] bool empty() const noexcept { return networks_.empty(); }

  // Whether `verb` is one of the console's commands.
  [[nodiscard]] static bool handles(std::string_view verb) noexcept;
  // How many stations `text` (STATION or BUS:STATION) names.
  [[nodiscard]] std::size_t matches(std::string_view text) const;
  // One command line in, one answer line out.
  [[nodiscard]] std::string command(std::string_view line, core::TimePoint now);
  // `status` items (above), each starting with a blank and ending with ';'.
  [[nodiscard]] std::string status_items() const;

 private:
  struct Target {
    BuiltPnNetwork* network = nullptr;
    PnSimStation* station = nullptr;
  };
  // The station `text` names, or the error sentence in `error`.
  bool find(std::string_view text, Target& out, std::string& error) const;
  [[nodiscard]] std::string alarm(const Target& t, const std::string& id, const std::vector<std::string>& args) const;
  [[nodiscard]] static std::string io(const Target& t, const std::string& id, const std::vector<std::string>& args);

  std::vector<BuiltPnNetwork*> networks_;
};

}  // namespace drivegate::profinet
