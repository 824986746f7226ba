#pragma once
// `drivegated --scan TYPE:WHERE` (DESIGN.md §7): one scanner per bus type, the table of what was
// found, and the configuration skeleton `--write-config FILE` writes. Bus-neutral: a scanner
// fills a core::ScanResult (core/scan.hpp), everything here reads only that.
#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

#include "config/loader.hpp"
#include "core/scan.hpp"

namespace drivegate::daemon {

// Runs the scanner of request.bus_type from `types` while holding the bus as a gateway would
// (daemon/bus_lock.hpp). Throws core::ScanError (or core::BusError) with one line a person can act
// on: for a type without a scanner, naming the types that have one.
core::ScanResult scan_bus(const core::ScanRequest& request, const config::BusTypeRegistry& types);

// "canopen:can0" -> bus_type "canopen", where "can0". Throws core::ScanError without a ':'.
core::ScanRequest parse_scan_target(const std::string& target);

// The table: one row per device (address, device type, identity in hex, name and versions, device
// profile, "(conflict)" where more than one device answers), then per device its profile reason
// and notes, then the bus notes and the warnings. Says so when the bus has no device.
std::string format_scan_table(const core::ScanResult& result);

// A configuration that --check-config accepts as it is: the gateway, the scanned bus with its
// options and lists (an item starting with '#' is written as a comment line), one axis per device
// that has a device profile and a trusted identity (the rest as comments with the reason and its
// next_step), and comments on what to fill in (mechanics, limits, names). Checked
// here with the configuration loader, with the first of result.cycle_times it accepts; throws
// core::ScanError with the loader's problems when none is accepted.
std::string scan_skeleton(const core::ScanResult& result, const config::LoadOptions& options);

// Writes `text` to `file` through a temporary file in the same directory and a rename, so that the
// file is either the old one or complete. An existing file is kept unless `force`. Throws
// core::ScanError.
void write_skeleton(const std::filesystem::path& file, const std::string& text, bool force);

// What `drivegated --scan` was given.
struct ScanCommand {
  std::string target;  // TYPE:WHERE
  core::Duration answer_timeout = std::chrono::milliseconds(100);
  std::vector<std::filesystem::path> device_dirs;  // --device-dir, searched before the built-in ones
  std::string write_config;  // FILE, or empty
  bool force = false;
  std::vector<core::ScanAction> actions;  // --set-name, --set-ip, --signal in order (a scanner that writes)
  bool permanent = false;                 // --permanent
};

// Runs the write actions, prints one line per action done, then the table to `out`, writes the
// skeleton when asked. Returns the exit code: 0 when the scan ran (also with no device: the table
// says so); 2 for an action argument that is wrong as written (nothing sent); 1 with the reason on
// `err` otherwise (an action that failed: after the table, which shows the bus as it is then).
int run_scan_command(const ScanCommand& command, std::ostream& out, std::ostream& err);

}  // namespace drivegate::daemon
