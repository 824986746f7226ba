#pragma once
// The PROFINET bus scan (`drivegated --scan profinet:IFACE`, DESIGN.md §7, issue 10 "Scan"): which
// devices answer a DCP Identify all on the interface, what they are, and which device profile runs
// them. Needs no configuration and only reads (no Connect), but for the write actions asked for:
//
//   0. `--set-name MAC=NAME`, `--set-ip MAC=A.B.C.D/MASK[/GATEWAY]`, `--signal MAC|NAME`
//      (profinet_scan_actions, checked before anything is sent): one Identify all first (the
//      target must answer; a name another MAC answers with is refused unsent), then per action a
//      DCP Set (NameOfStation, IP parameter: temporary unless ScanRequest::permanent; Control
//      Signal, flash once) and its response's BlockError [IEC 61158-6-10 §4.3, DCP Set]. The first
//      that fails ends the actions (ScanResult::action_failed); the listing runs after them.
//
//   1. The raw link on IFACE (RawSocketLink with kFrameRules; its one-line errors for no
//      CAP_NET_RAW, no such interface or an interface that is down pass through), the
//      interface's MAC (the requests' source) and IPv4 address (for the skeleton's addresses).
//   2. One Identify all with a ResponseDelayFactor (`response_delay=N`, default
//      kScanResponseDelayFactor), the answers collected for identify_window(N) by the DcpClient
//      [IEC 61158-6-10 §4.3, DCP Identify; ResponseDelayFactor].
//   3. Per device: MAC, NameOfStation, IP suite, VendorID/DeviceID, DeviceRole, TypeOfStation; the
//      device profile whose `profidrive:` vendor_id/device_id is its DeviceID.
//
// A device without a NameOfStation, with one that breaks the NameOfStation rules, or with one
// another device answers with too cannot be addressed by a configuration (the controller finds its
// stations by name, akd-profinet-profidrive.md §3.1): flagged in the table, left out of the
// skeleton's devices with the reason. A device without an IP address (or with one outside the
// interface's subnet, or another device's) gets a suggested free one in the skeleton, marked CHECK.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "adapters/profinet/controller/dcp_client.hpp"
#include "config/bus_types.hpp"
#include "config/plan.hpp"
#include "core/scan.hpp"

namespace drivegate::profinet {

// The default ResponseDelayFactor: the answers spread over 160 ms, so that a few dozen devices do
// not answer in one burst; the window is then 2 s (identify_window).
inline constexpr std::uint16_t kScanResponseDelayFactor = 16;
// At most this many answers are kept; more are counted in a note.
inline constexpr std::size_t kMaxScanStations = 512;

// The interface the scan ran on: its name and its first IPv4 address (0: none), for the skeleton.
struct ScanInterface {
  std::string name;
  std::uint32_t address = 0;  // a.b.c.d = a << 24 | ...
  std::uint32_t netmask = 0;
};

// The device profiles with a profidrive section in the directories, in name order; broken ones are
// left out with a note in `notes`.
std::vector<config::DeviceProfile> profinet_scan_profiles(const std::vector<std::filesystem::path>& dirs,
                                                          const config::BusTypeRegistry& types,
                                                          std::vector<std::string>& notes);

// The telegram an axis of `profile` gets in the skeleton: of the telegrams it offers, the one whose
// layout carries the most of its modes; among those one with HOME_DIST but without HOME_MODE
// (telegram 353 sends a homing method every cycle, which would override the drive's own
// HOME.MODE that the skeleton cannot know), then the lowest number. 0 when it offers none the
// configuration takes.
std::uint16_t skeleton_telegram(const config::DeviceProfile& profile);

// The table's rows and the skeleton's parts of what answered on `iface`, profiles matched. The
// skeleton's send clock is 1 ms and its reduction_ratio the smallest that gives every matched
// drive at least its min_update_time.
core::ScanResult profinet_scan_result(std::span<const DcpStation> stations, const ScanInterface& iface,
                                      const std::vector<config::DeviceProfile>& profiles);

// `profinet:IFACE[?response_delay=N]` checked by the configuration's rules for a profinet bus
// (interface), and the scan's own `response_delay` (ResponseDelayFactor 1..6400), and its actions
// (profinet_scan_actions). Throws core::ScanError naming the option.
config::BusPlan profinet_scan_plan(const core::ScanRequest& request, const config::BusTypeRegistry& types);
// `response_delay=N` of the request (checked by profinet_scan_plan), else kScanResponseDelayFactor.
std::uint16_t profinet_scan_response_delay(const core::ScanRequest& request);

// A write action of the scan, checked.
struct DcpAction {
  enum class Kind : std::uint8_t { SetName, SetIp, Signal };
  Kind kind = Kind::SetName;
  std::string text;      // the option and its value as given ("--set-name 00:1b:1b:00:0a:04=drive-d")
  bool by_name = false;  // Signal: the device that answers with `name` (else the one at `mac`)
  MacAddress mac{};
  std::string name;      // SetName: the name to give it; Signal by name: the device's
  IpSuite ip{};          // SetIp
};

// The request's actions, checked as written: the MAC (unicast, parse_mac), the NameOfStation
// rules, an IP suite with an address that ip_suite_problem passes (the netmask dotted or a prefix
// length); one name and one IP suite per MAC, a name for one MAC only; --permanent only with a
// Set of name or IP. Throws core::ScanUsageError with one line naming the argument.
std::vector<DcpAction> profinet_scan_actions(const core::ScanRequest& request);

// The scan on a RawSocketLink on the plan's interface in real time, after the request's actions.
// Throws core::ScanError when the interface does not open.
core::ScanResult run_profinet_scan(const config::BusPlan& plan, const core::ScanRequest& request,
                                   const config::BusTypeRegistry& types);

}  // namespace drivegate::profinet
