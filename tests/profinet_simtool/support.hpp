#pragma once
// Shared by the PROFINET simulator tool tests: a config with two AKD axes and a generic IO device
// on one profinet bus, its plan as drivegate-sim loads it (the build's bus types, the in-tree
// device profiles), and the controller's station list made from its `devices:`.
#include <cstdint>
#include <string>
#include <vector>

#include "adapters/profinet/controller/station_finder.hpp"
#include "config/loader.hpp"
#include "config/profinet/plan.hpp"

namespace drivegate::profinet::test {

// Stations akd-x (axis x, telegram 9), akd-y (axis y, telegram 1, vendor and device ID given) and
// io-block (io panel: an input submodule of 2 octets in slot 1, an output one of 1 in slot 2) on
// `interface`; `extra` goes at the end of `devices:`.
inline std::string pn_config(const std::string& interface, const std::string& extra = "") {
  return R"(gateway: { name: pnsim-test }
buses:
  - name: pn0
    type: profinet
    cycle_time: 1ms
    options: { interface: )" +
         interface + R"( }
    devices:
      - { station: akd-x, ip: 192.168.0.10, gateway: 192.168.0.1 }
      - { station: akd-y, ip: 192.168.0.11, vendor_id: 0x0FEE, device_id: 0x0042 }
      - { station: io-block, ip: 192.168.0.20 }
)" + extra + R"(    io:
      - name: panel
        station: io-block
        dap_ident: 0x100
        slots:
          - { slot: 1, module_ident: 0x210, submodule_ident: 0x11, inputs: 2 }
          - { slot: 2, subslot: 1, module_ident: 0x220, submodule_ident: 0x12, outputs: 1 }
axes:
  - { name: x, bus: pn0, address: 1, device: kollmorgen-akd-profinet, profinet: { station: akd-x, telegram: 9 } }
  - { name: y, bus: pn0, address: 2, device: kollmorgen-akd-profinet, profinet: { station: akd-y, telegram: 1 } }
)";
}

inline config::Plan plan_of(const std::string& yaml) { return config::load_plan_from_string(yaml, "t.yaml"); }

inline std::array<std::uint8_t, 4> octets(std::uint32_t v) {
  return {static_cast<std::uint8_t>(v >> 24), static_cast<std::uint8_t>(v >> 16), static_cast<std::uint8_t>(v >> 8),
          static_cast<std::uint8_t>(v)};
}

// What the controller looks for: each configured station by name, with its IP suite and IDs.
inline std::vector<StationConfig> stations_of(const config::ProfinetBusOptions& o) {
  std::vector<StationConfig> out;
  for (const auto& s : o.stations) {
    out.push_back({s.name, {octets(s.ip), octets(s.netmask), octets(s.gateway)}, s.vendor_id, s.device_id});
  }
  return out;
}

}  // namespace drivegate::profinet::test
