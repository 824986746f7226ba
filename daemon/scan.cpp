#include "daemon/scan.hpp"

#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>
#include <ostream>
#include <sstream>

#include "config/scalars.hpp"
#include "daemon/bus_lock.hpp"

namespace drivegate::daemon {

namespace {

std::string hex32(const std::optional<std::uint32_t>& v) {
  if (!v) return "-";
  char b[16];
  std::snprintf(b, sizeof b, "0x%08X", *v);
  return b;
}

std::string text_or_dash(const std::optional<std::string>& s) {
  if (!s) return "-";
  return "\"" + *s + "\"";
}

// Columns padded to their widest cell, two blanks apart; the last column is not padded.
std::string format_columns(const std::vector<std::vector<std::string>>& rows) {
  std::vector<std::size_t> width;
  for (const auto& r : rows)
    for (std::size_t i = 0; i < r.size(); ++i) {
      if (width.size() <= i) width.push_back(0);
      width[i] = std::max(width[i], r[i].size());
    }
  std::string out;
  for (const auto& r : rows) {
    std::string line;
    for (std::size_t i = 0; i < r.size(); ++i) {
      line += r[i];
      if (i + 1 < r.size()) line += std::string(width[i] - r[i].size() + 2, ' ');
    }
    out += line + "\n";
  }
  return out;
}

}  // namespace

core::ScanResult scan_bus(const core::ScanRequest& request, const config::BusTypeRegistry& types) {
  const auto type = types.find(request.bus_type);
  if (type != nullptr && type->scan) {
    if ((!request.actions.empty() || request.permanent) && !type->scan.writes) {
      std::string writers;
      for (const auto& t : types.types())
        if (t->scan.writes) writers += (writers.empty() ? "" : ", ") + t->name;
      throw core::ScanUsageError((request.actions.empty() ? std::string("--permanent") : request.actions.front().option) +
                                 " is not for " + request.bus_type + ": only a scan of " + writers +
                                 " writes to its devices");
    }
    const config::BusPlan plan = type->scan.plan(request, types);
    // A gateway on this bus would see our requests as another master's (and its devices' answers
    // would confuse both): refuse while one holds the bus, and hold it ourselves while scanning.
    // A bus that holds nothing on this machine has no lock (as daemon/gateway.cpp).
    std::unique_ptr<BusLock> lock;
    if (const auto resource = bus_resource(plan); !resource.empty()) lock = std::make_unique<BusLock>(resource);
    return type->scan.run(plan, request, types);
  }
  std::string scans;
  for (const auto& t : types.types())
    if (t->scan) scans += (scans.empty() ? "" : ", ") + t->name;
  if (type != nullptr && type->available())
    throw core::ScanError("cannot scan " + request.bus_type + ": " + request.bus_type + " has no bus scan (scans: " +
                          scans + ")");
  if (type != nullptr)
    throw core::ScanError("cannot scan " + request.bus_type + ": no adapter in this build (scans: " + scans + ")");
  throw core::ScanError("cannot scan \"" + request.bus_type + "\": not a bus type; scans: " + scans);
}

core::ScanRequest parse_scan_target(const std::string& target) {
  const auto colon = target.find(':');
  if (colon == std::string::npos || colon == 0)
    throw core::ScanError("--scan " + target + ": expected TYPE:WHERE, e.g. canopen:can0");
  core::ScanRequest r;
  r.bus_type = target.substr(0, colon);
  r.where = target.substr(colon + 1);
  return r;
}

std::string format_scan_table(const core::ScanResult& result) {
  std::ostringstream out;
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(result.elapsed).count();
  const auto n = result.devices.size();
  out << result.bus_type << " " << result.description
      << (result.assumed.empty() ? std::string() : ", " + result.assumed) << ": "
      << (n == 0 ? std::string("no devices answered") : std::to_string(n) + (n == 1 ? " device" : " devices"))
      << " (scan took " << ms << " ms)\n";
  if (n > 0) {
    std::vector<std::vector<std::string>> rows{{"address", "device type", "type", "vendor", "product", "revision",
                                                "serial", "name", "hardware", "software", "profile"}};
    for (const auto& d : result.devices)
      rows.push_back({d.address.text, hex32(d.device_type), d.device_type_text.empty() ? "-" : d.device_type_text,
                      hex32(d.identity.vendor_id), hex32(d.identity.product_code), hex32(d.identity.revision),
                      hex32(d.identity.serial), text_or_dash(d.name), text_or_dash(d.hardware_version),
                      text_or_dash(d.software_version),
                      !d.conflict.empty() ? "(conflict)" : d.profile.empty() ? "(none)" : d.profile});
    out << format_columns(rows);
    out << "\n";
    for (const auto& d : result.devices) {
      out << d.address.text << ": " << (d.profile.empty() ? "no profile" : d.profile) << ": " << d.profile_reason
          << "\n";
      for (const auto& note : d.notes) out << "    " << note << "\n";
    }
  }
  for (const auto& note : result.notes) out << "note: " << note << "\n";
  for (const auto& warning : result.warnings) out << "warning: " << warning << "\n";
  return out.str();
}

namespace {

// A YAML double-quoted scalar: `\` and `"` escaped, control characters as \xNN.
std::string yaml_quoted(const std::string& s) {
  std::string q = "\"";
  for (const char c : s) {
    if (c == '\\' || c == '"') {
      q += '\\';
      q += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char b[8];
      std::snprintf(b, sizeof b, "\\x%02X", static_cast<unsigned>(static_cast<unsigned char>(c)));
      q += b;
    } else {
      q += c;
    }
  }
  return q + "\"";
}

// Whether every one of the loader's problems is about the bus cycle (another cycle time may pass).
bool about_the_cycle(const config::ConfigError& e) {
  return std::all_of(e.problems().begin(), e.problems().end(), [](const auto& p) {
    return p.path.find("cycle_time") != std::string::npos || p.message.find("cycle_time") != std::string::npos;
  });
}

std::string skeleton_text(const core::ScanResult& result, core::Duration cycle_time,
                          const std::vector<std::filesystem::path>& extra_dirs) {
  std::ostringstream y;
  y << "# Written by drivegated --scan: " << result.bus_type << " " << result.description << ".\n"
    << "# drivegated --check-config accepts it as it is, but every value marked CHECK is a placeholder:\n"
    << "# set it from the machine before an axis moves (config/README.md has every key).\n"
    << "gateway:\n"
    << "  name: cell-1                # CHECK: this gateway's name, unique on its DDS domain\n"
    << "  dds: { domain: 0, namespace: drivegate }\n";
  if (!extra_dirs.empty()) {
    y << "  device_dirs:\n";
    for (const auto& d : extra_dirs) y << "    - " << yaml_quoted(d.string()) << "\n";
  }
  y << "buses:\n"
    << "  - name: " << result.bus_name << "\n"
    << "    type: " << result.bus_type << "\n"
    << "    cycle_time: " << config::format_duration(cycle_time)
    << "             # CHECK: the bus cycle (CANopen: the SYNC period)\n"
    << "    options:\n";
  for (const auto& [key, value] : result.bus_options) {
    y << "      " << key << ": " << value;
    for (const auto& [check_key, check] : result.bus_option_checks)
      if (check_key == key) y << "    # CHECK: " << check;
    y << "\n";
  }
  for (const auto& [key, items] : result.bus_lists) {
    // An item that starts with '#' is a comment line (an entry left for a person to complete).
    const bool any_item = std::any_of(items.begin(), items.end(), [](const std::string& i) { return i.rfind('#', 0) != 0; });
    y << "    " << key << ":" << (any_item ? "\n" : " []\n");
    for (const auto& item : items) y << "      " << (item.rfind('#', 0) == 0 ? "" : "- ") << item << "\n";
  }
  const auto is_axis = [](const core::FoundDevice& d) { return d.drive && d.conflict.empty(); };
  const bool any = std::any_of(result.devices.begin(), result.devices.end(), is_axis);
  y << "axes:" << (any ? "\n" : " []\n");
  for (const auto& d : result.devices) {
    y << "  # " << d.address.text << ": " << (d.device_type_text.empty() ? "device type unknown" : d.device_type_text);
    if (d.name) y << ", \"" << *d.name << "\"";
    y << "\n  #   " << d.profile_reason << "\n";
    if (!d.conflict.empty()) {
      y << "  #   not an axis here: " << d.conflict << ";\n"
        << "  #   "
        << (d.next_step.empty() ? "give every device its own node-ID (and no node-ID another drive's SDO channels use) "
                                  "and scan again"
                                : d.next_step)
        << "\n";
      continue;
    }
    if (!d.drive) {
      y << "  #   not an axis here" << (d.next_step.empty() ? "" : ": " + d.next_step) << "\n";
      continue;
    }
    // One entry per axis the device carries (a multi-axis slave: each picked by its key).
    const std::vector<std::string> keys = d.axis_keys.empty() ? std::vector<std::string>{""} : d.axis_keys;
    for (std::size_t n = 0; n < keys.size(); ++n) {
      y << "  - name: " << d.profile << "-" << d.address.number << (keys.size() > 1 ? "-" + std::to_string(n) : "")
        << "    # CHECK: the name clients use\n"
        << "    bus: " << result.bus_name << "\n"
        << "    address: " << d.address.number << "\n"
        << "    device: " << d.profile << "\n";
      if (!keys[n].empty()) y << "    " << keys[n] << "\n";
      y << "    unit: rev                 # CHECK: the user unit (mm, deg, rev, ...)\n"
        << "    mechanics:                # CHECK: all three, from the motor and the mechanics\n"
        << "      encoder_counts_per_rev: 131072\n"
        << "      gear_ratio: 1\n"
        << "      feed: 1\n"
        << "    # limits: { min_position: ..., max_position: ..., max_velocity: ..., max_acceleration: ... }  "
           "# CHECK: the machine's limits\n";
    }
  }
  return y.str();
}

}  // namespace

std::string scan_skeleton(const core::ScanResult& result, const config::LoadOptions& options) {
  // Directories beyond the built-in ones go into the file, so that --check-config finds the profiles.
  const auto builtin = config::default_device_dirs();
  std::vector<std::filesystem::path> extra;
  for (const auto& d : options.device_dirs)
    if (std::find(builtin.begin(), builtin.end(), d) == builtin.end()) extra.push_back(std::filesystem::absolute(d));
  std::string first_problems;
  std::string tried;
  for (const auto cycle : result.cycle_times) {
    std::string text = skeleton_text(result, cycle, extra);
    try {
      (void)config::load_plan_from_string(text, "skeleton.yaml", options);
      return text;
    } catch (const config::ConfigError& e) {
      if (first_problems.empty()) first_problems = e.what();
      tried += (tried.empty() ? "" : ", ") + config::format_duration(cycle);
      // Only a problem with the cycle can go away with another cycle time.
      if (!about_the_cycle(e)) throw core::ScanError("the skeleton does not pass the configuration checks, so it is "
                                                     "not written:\n" + std::string(e.what()));
    }
  }
  throw core::ScanError("the skeleton does not pass the configuration checks with any of the cycle times " + tried +
                        ", so it is not written:\n" + first_problems);
}

void write_skeleton(const std::filesystem::path& file, const std::string& text, bool force) {
  const auto dir = file.has_parent_path() ? file.parent_path() : std::filesystem::path(".");
  std::string tmp = (dir / ("." + file.filename().string() + ".XXXXXX")).string();
  const int fd = ::mkstemp(tmp.data());
  if (fd < 0) throw core::ScanError("cannot write " + file.string() + ": " + std::strerror(errno));
  const auto fail = [&](const char* what) {
    const std::string reason = std::strerror(errno);
    ::close(fd);
    ::unlink(tmp.c_str());
    throw core::ScanError("cannot write " + file.string() + ": " + what + ": " + reason);
  };
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t w = ::write(fd, text.data() + done, text.size() - done);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) fail("write");
    done += static_cast<std::size_t>(w);
  }
  // mkstemp makes the file 0600; a configuration is read by the service user too.
  if (::fchmod(fd, 0644) != 0) fail("chmod");
  if (::fsync(fd) != 0) fail("fsync");
  if (::close(fd) != 0) {
    ::unlink(tmp.c_str());
    throw core::ScanError("cannot write " + file.string() + ": close: " + std::strerror(errno));
  }
  // Without --force a link: it fails if the file appeared meanwhile, where a rename would replace it.
  const int moved = force ? ::rename(tmp.c_str(), file.c_str()) : ::link(tmp.c_str(), file.c_str());
  const int err = errno;
  if (moved != 0 || !force) ::unlink(tmp.c_str());
  if (moved != 0 && err == EEXIST) throw core::ScanError(file.string() + " exists; it is kept (--force replaces it)");
  if (moved != 0) throw core::ScanError("cannot write " + file.string() + ": " + std::strerror(err));
}

int run_scan_command(const ScanCommand& command, std::ostream& out, std::ostream& err) {
  try {
    core::ScanRequest request = parse_scan_target(command.target);
    std::error_code ec;
    if (!command.write_config.empty() && !command.force && std::filesystem::exists(command.write_config, ec))
      throw core::ScanError(command.write_config + " exists; it is kept (--force replaces it)");
    request.answer_timeout = command.answer_timeout;
    config::LoadOptions load;
    load.device_dirs = command.device_dirs;
    for (const auto& d : config::default_device_dirs()) load.device_dirs.push_back(d);
    request.device_dirs = load.device_dirs;
    request.actions = command.actions;
    request.permanent = command.permanent;
    const core::ScanResult result = scan_bus(request, load.bus_types);
    for (const auto& line : result.actions_done) out << line << "\n";
    out << format_scan_table(result) << std::flush;
    if (!result.action_failed.empty()) {
      err << "drivegated: --scan " << command.target << ": " << result.action_failed << "\n";
      return 1;
    }
    if (!command.write_config.empty()) {
      write_skeleton(command.write_config, scan_skeleton(result, load), command.force);
      out << "wrote " << command.write_config << "\n";
    }
    return 0;
  } catch (const core::ScanUsageError& e) {
    err << "drivegated: --scan " << command.target << ": " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {  // ScanError, BusError from the bus lock
    err << "drivegated: --scan " << command.target << ": " << e.what() << "\n";
    return 1;
  }
}

}  // namespace drivegate::daemon
