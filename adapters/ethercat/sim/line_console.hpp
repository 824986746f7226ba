#pragma once
// The fault console of simulated EtherCAT lines (issue 9 "Simulator": fault injection from
// drivegate-sim's console): one command a line, one answer line each, "ok ..." or "error: ...".
//
//   power-off K        slave K loses power: it and the slaves behind it vanish from the line
//   power-on K         power back: the slave restarts in INIT with station address 0
//   break-after K      the cable between slave K and K+1 is cut
//   mend [BUS]         the cable is whole again
//   drop N [BUS]       the next N frames are lost on the line
//   corrupt N [BUS]    the next N frames arrive with a bad CRC at the first slave (counted in its
//                      0300h, dropped)
//   stick K STATE CODE slave K refuses every state above STATE (INIT, PRE-OP, SAFE-OP) with AL
//                      status code CODE; above it now, it drops there with the error set
//   unstick K          lifts that
//   status             per slave: BUS:K persona station=0x.... state=... code=0x.... frames=N
//   drive K            a CiA 402 drive's model: BUS:K persona state=operation_enabled sw=0x0237
//                      mode=7 pos=1234 error=0x0000 sync0=N (SYNC0 pulses so far, "off" when not running)
//   io K [BYTE...]     a generic I/O slave's bytes: BUS:K out=00c3 in=0000 (the outputs the master
//                      wrote, the inputs it reads); with bytes (decimal or 0x hex), sets the inputs
//                      from the first on (the slave does not loop its outputs back)
//
// K is a position (1 = next to the master), or BUS:K when several lines have one; BUS may be left
// out while there is one line. Numbers are decimal or 0x hex.
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "adapters/ethercat/sim/line_builder.hpp"

namespace drivegate::ethercat::sim {

class LineConsole {
 public:
  static constexpr std::string_view kCommands =
      "power-off K, power-on K, break-after K, mend [BUS], drop N [BUS], corrupt N [BUS], stick K STATE CODE, "
      "unstick K, status, drive K, io K [BYTE...] (K: a position 1.. or BUS:K)";

  // The line must outlive the console; commands run on the thread that services it.
  void add(BuiltLine& line) { lines_.push_back(&line); }
  [[nodiscard]] bool empty() const noexcept { return lines_.empty(); }

  // Whether `verb` is one of the console's commands.
  [[nodiscard]] static bool handles(std::string_view verb) noexcept;
  // How many slaves `text` (K or BUS:K) names.
  [[nodiscard]] std::size_t matches(std::string_view text) const;
  // One command line in, one answer line out.
  [[nodiscard]] std::string command(std::string_view line);
  // `status` items, each " BUS:K persona station=0x1001 state=PRE-OP code=0x0000 frames=12;"
  // (" BUS:K persona off;" without power; " stuck=SAFE-OP" before the `;` of a stuck slave), and
  // " BUS cable cut after K;" for a broken line.
  [[nodiscard]] std::string status_items() const;

 private:
  struct Slot {
    BuiltLine* line = nullptr;
    std::size_t index = 0;
  };
  // The slave `text` names, or the error sentence in `error`.
  bool find(std::string_view text, Slot& out, std::string& error) const;
  // The line `bus` names (empty: the only one), or the error sentence.
  BuiltLine* find_line(std::string_view bus, std::string& error) const;

  std::vector<BuiltLine*> lines_;
};

}  // namespace drivegate::ethercat::sim
