#pragma once
// What a bus scan (`drivegated --scan TYPE:WHERE`) asks and finds, the same for every bus type
// (DESIGN.md §7): CANopen, EtherCAT and PROFINET scanners fill these; the daemon prints them as a
// table and writes a configuration skeleton from them (daemon/scan.hpp).
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "core/clock.hpp"

namespace drivegate::core {

// A scan that cannot run (bad WHERE, a transport that does not open, a bus another gateway holds).
class ScanError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};
// A scan argument that is wrong as written (a write action's MAC or value): found before anything
// is sent; `drivegated` exits 2 with it, as for its other usage errors.
class ScanUsageError : public ScanError {
 public:
  using ScanError::ScanError;
};

// A write action asked for on the scan's command line, run before the listing (PROFINET:
// `--set-name MAC=NAME`, `--set-ip MAC=SUITE`, `--signal MAC|NAME`): the option and its value as
// given. Only a scanner that writes (BusScanner::writes) takes them.
struct ScanAction {
  std::string option;  // "--set-name"
  std::string value;   // "00:1b:1b:00:0a:04=drive-d"
};

struct ScanRequest {
  std::string bus_type;  // "canopen", "ethercat", "profinet"
  // The bus: its transport or interface, then options as "?key=value&key=value", e.g.
  // "can0", "udp-multicast?group=239.1.2.3&port=43113&interface=127.0.0.1".
  std::string where;
  // How long a device has to answer one request (CANopen: an SDO upload).
  Duration answer_timeout = std::chrono::milliseconds(100);
  // How long to listen before the first request (CANopen: boot-ups and heartbeats).
  Duration listen = std::chrono::milliseconds(200);
  // Where device profiles are looked for, in order (as the daemon's LoadOptions::device_dirs).
  std::vector<std::filesystem::path> device_dirs;
  // Run in this order before the listing; `permanent`: the values they set survive a power loss.
  std::vector<ScanAction> actions;
  bool permanent = false;
};

// Where a device sits on its bus: `number` is what an axis' `address` takes in the configuration
// (CANopen node-ID, EtherCAT station position), `text` what a person reads ("5 (05h)",
// "position 3, alias 1001h", "akd-1 192.168.0.10").
struct DeviceAddress {
  int number = 0;
  std::string text;
};

// Identity numbers as the bus reports them (CANopen/CoE 1018h:01..04, EtherCAT SII, PROFINET
// vendor/device id); nullopt where the device does not have them.
struct DeviceIdentityNumbers {
  std::optional<std::uint32_t> vendor_id;
  std::optional<std::uint32_t> product_code;
  std::optional<std::uint32_t> revision;
  std::optional<std::uint32_t> serial;
};

struct FoundDevice {
  DeviceAddress address;
  std::optional<std::uint32_t> device_type;  // CANopen/CoE 1000h
  std::string device_type_text;              // "CiA 402 servo drive", "" when unknown
  DeviceIdentityNumbers identity;
  std::optional<std::string> name;              // CANopen 1008h, PROFINET TypeOfStation; nullopt: not present
  std::optional<std::string> hardware_version;  // 1009h
  std::optional<std::string> software_version;  // 100Ah
  std::string profile;         // the device profile that fits, "" for none
  std::string profile_reason;  // why that one, or why none
  // Without a profile: what to do so that it becomes an axis ("add a device profile for it ...").
  std::string next_step;
  bool drive = false;          // an axis in the configuration skeleton (it has a profile to run it)
  // A device that carries more than one axis (an EtherCAT multi-axis slave): per axis, the
  // bus-specific key that picks it, as a YAML line ("ethercat: { axis: 1 }"). Empty: one axis.
  std::vector<std::string> axis_keys;
  // Why its identity cannot be trusted (more than one device answers at its address or name: a
  // conflict); "" when it can. Such a device has no profile and is no axis; next_step, when given,
  // says how to resolve it.
  std::string conflict;
  std::vector<std::string> notes;  // what a person should know (objects not present, aborts, odd frames)
};

struct ScanResult {
  std::string bus_type;
  std::string bus_name;     // a bus name for the configuration skeleton ("can0")
  std::string description;  // what was scanned, "udp-multicast 239.1.2.3:43113 on 127.0.0.1"
  // The bus' options as the configuration file writes them (key, YAML scalar), in order.
  std::vector<std::pair<std::string, std::string>> bus_options;
  // Options the scan could not learn and assumed: key and what to check, a CHECK comment in the
  // skeleton (CANopen: the bit rate, which SocketCAN does not tell).
  std::vector<std::pair<std::string, std::string>> bus_option_checks;
  // Lists of the bus entry besides its options (EtherCAT `io:`, PROFINET `devices:`): the key, then
  // one YAML flow mapping per item ("{ name: io-3, position: 3, inputs: 2 }"), written as they are;
  // an item starting with '#' is a comment line (an entry a person must complete).
  std::vector<std::pair<std::string, std::vector<std::string>>> bus_lists;
  // What the scan assumed, for the table's first line ("bit rate not given (500 kbit/s assumed ...)");
  // empty: nothing.
  std::string assumed;
  // Cycle times to offer in the skeleton, best first; the first the configuration accepts is used.
  std::vector<Duration> cycle_times;
  std::vector<FoundDevice> devices;  // by address
  std::vector<std::string> notes;    // bus-wide: other masters seen, malformed frames counted
  std::vector<std::string> warnings; // what must be fixed on the bus before a gateway runs it (conflicts)
  // The write actions: one line per action done, in order; `action_failed` the one that failed
  // (the rest were not run), "" when none did. The listing is of the bus after them.
  std::vector<std::string> actions_done;
  std::string action_failed;
  Duration elapsed{};
};

}  // namespace drivegate::core
