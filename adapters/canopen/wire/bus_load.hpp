#pragma once
// Estimated CAN bus load of one SYNC cycle, for --check-config (DESIGN.md §7) and the benchmarks.
// The input describes what a bus sends in plain numbers, so config code fills it from a plan
// without the engines; frame lengths assume worst-case bit stuffing (wire/bit_timing.hpp).
//
// Rates per cycle:
// - SYNC: one frame of DLC 0 per cycle (when the bus produces SYNC).
// - RPDOs: one frame per cycle each. The master sends synchronous ones after every SYNC and
//   event-driven ones at most once per cycle poll, so once per cycle is also their worst case.
// - Synchronous TPDOs (needs SYNC): type n = 1..240 one frame every n-th cycle; type 0 (sent at a
//   SYNC only when the drive's data changed) at worst one per cycle.
// - Event-driven TPDOs (254/255): at worst one per inhibit time [CiA 301 §7.5.2.35: the inhibit
//   time spaces every transmission]. Without an inhibit time a drive sends as fast as its data
//   changes (AKD part 1 §12.5: default TPDO3/4 of a moving axis), which has no bound: they are
//   counted at one per cycle, or one per event timer when that is shorter, and reported in
//   `unbounded` so the check can warn.
// - Error control: a drive's heartbeat (DLC 1) per producer period; node guarding an RTR and a
//   1-byte reply per guard time; the master's heartbeat per its period.
// SDO and EMCY traffic is acyclic and not included.
#include <cstdint>
#include <vector>

#include "core/clock.hpp"

namespace drivegate::canopen {

struct TpdoTraffic {
  std::uint8_t dlc = 0;
  std::uint8_t transmission_type = 1;  // 0..240 synchronous, 254/255 event-driven
  core::Duration inhibit_time{};       // event-driven: minimum spacing (0 = none)
  core::Duration event_timer{};        // event-driven: periodic send (0 = none)
};

enum class NodeErrorControl : std::uint8_t { None, Heartbeat, Guarding };

struct NodeTraffic {
  std::vector<std::uint8_t> rpdo_dlcs;  // frame length of each RPDO the master sends
  std::vector<TpdoTraffic> tpdos;
  NodeErrorControl error_control = NodeErrorControl::Heartbeat;
  core::Duration error_control_period{};  // heartbeat producer time (1017h) or guard time (100Ch)
};

struct BusTraffic {
  bool sync = true;                  // the master produces SYNC every cycle
  core::Duration master_heartbeat{};  // the master's heartbeat period (0 = none)
  std::vector<NodeTraffic> nodes;
};

// Estimated bus occupation of one SYNC cycle, averaged over cycles.
struct CycleLoad {
  std::uint32_t frames = 0;  // per cycle, rounded up
  std::uint64_t bits = 0;    // per cycle, rounded up
  core::Duration time{};     // bits at the bit rate
  double fraction = 0;       // of the cycle time (> 1: the bus cannot carry it)
  std::uint32_t unbounded = 0;  // event-driven TPDOs without an inhibit time (see above)
};

// All zero for a cycle time <= 0; time and fraction zero for a bit rate of 0.
CycleLoad estimate_cycle_load(const BusTraffic& traffic, std::uint32_t bitrate, core::Duration cycle_time) noexcept;

}  // namespace drivegate::canopen
