#include "config/profinet/axis_section.hpp"

#include <map>

#include "config/scalars.hpp"
#include "config/text_util.hpp"
#include "profiles/profidrive/profidrive_master.hpp"
#include "profiles/profidrive/telegram.hpp"

namespace drivegate::config {

namespace {

std::string telegram_list(const std::vector<std::uint16_t>& telegrams) {
  std::vector<std::string> s;
  for (const auto t : telegrams) s.push_back(std::to_string(t));
  return join(s);
}

// What the telegram lets the master do (profiles/profidrive/README.md "What the telegram allows"):
// the modes of the axis are the device's that the telegram carries, homing with a method other
// than 0 needs HOME_MODE (353) and a homing offset HOME_DIST (352, 353). Telegram 400's layout is
// read from the drive at start (PNU 915/916), so only what every layout allows is taken for it.
void check_telegram(const MapReader& axis, const MapReader& section, std::uint16_t telegram, AxisPlan& a) {
  const auto layout = profidrive::standard_layout(telegram);
  profidrive::TelegramCapabilities caps;
  if (layout) caps = profidrive::capabilities_of(*layout);
  const std::string what = "telegram " + std::to_string(telegram);
  if (layout) {
    core::ModeSet modes;
    const auto keep = [&](core::Mode m, bool carried) {
      if (carried && a.spec.modes.contains(m)) modes.add(m);
    };
    keep(core::Mode::ProfileVelocity, caps.speed || caps.mdi);  // speed mode, or real-time jog on MDI
    keep(core::Mode::ProfilePosition, caps.mdi);
    keep(core::Mode::Homing, caps.position);
    keep(core::Mode::TraversingBlock, caps.position);
    a.spec.modes = modes;
    if (a.spec.default_mode != core::Mode::None && !modes.contains(a.spec.default_mode))
      axis.map("defaults", Need::Optional)
          .error("mode", "mode " + std::string{core::mode_short_name(a.spec.default_mode)} + " is not possible with " + what +
                             " (" + (caps.position ? "position mode" : "speed mode") + "); choose another telegram or mode");
  }
  const MapReader homing = axis.map("homing", Need::Optional);
  const auto& h = a.spec.homing;
  if (h.method != 0 && !caps.home_mode)
    (homing.present() ? homing : section)
        .error(homing.present() ? "method" : "telegram",
               what + " carries no HOME_MODE: the drive homes with the HOME.MODE set in it, so homing.method must be 0 "
                      "(telegram 353 sends the method), got " + std::to_string(h.method));
  if (h.offset != 0 && !caps.home_dist)
    homing.error("offset", what + " carries no HOME_DIST: set HOME.DIST in the drive and homing.offset to 0 (telegrams "
                                  "352 and 353 send it), got " + format_number(h.offset));
}

}  // namespace

void read_profinet_axis(const MapReader& axis, const BusPlan& bus, const DeviceProfile* device,
                        const std::filesystem::path& /*base_dir*/, AxisPlan& a) {
  if (device && !device->has_section<ProfidriveDeviceSpec>()) {
    axis.error("device", "device profile \"" + device->name + "\" has no profidrive section, which an axis on a "
                         "profinet bus needs (profiles/devices/README.md \"PROFIdrive\")");
    device = nullptr;
  }
  auto& ax = a.sections.edit<ProfinetAxisSpec>();
  const MapReader c = axis.map("profinet", Need::Required);
  c.check_keys({"station", "telegram", "slot", "subslot"});
  const auto& options = bus.section<ProfinetBusOptions>();
  if (const auto station = c.string("station", Need::Required)) {
    if (options.station(*station) == nullptr) {
      std::vector<std::string> known;
      for (const auto& s : options.stations) known.push_back(s.name);
      c.error("station", "unknown station " + in_quotes(*station) + did_you_mean(*station, known) + " (bus \"" + bus.name +
                             "\" lists: " + join(known) + ")");
    }
    ax.station = *station;
  }
  // Slot 1, subslot 1: where the AKD takes its telegram module [§4.1].
  ax.slot = static_cast<int>(c.integer("slot", Need::Optional, 1, 0x7FFF, "a slot number (1..32767)").value_or(1));
  ax.subslot = static_cast<int>(c.integer("subslot", Need::Optional, 1, 0x7FFF, "a subslot number (1..32767)").value_or(1));
  const auto telegram = c.integer("telegram", Need::Required, 0, 65535, "a telegram number");
  if (!device) return;
  const auto& spec = device->section<ProfidriveDeviceSpec>();
  if (telegram) {
    const auto t = static_cast<std::uint16_t>(*telegram);
    if (!spec.offers(t))
      c.error("telegram", "device \"" + device->name + "\" offers telegrams " + telegram_list(spec.telegrams) + ", got " +
                              std::to_string(t));
    else if (t == 0)
      c.error("telegram", "telegram 0's size is set by the module in the drive, which the configuration cannot give; "
                          "use 400 for a free mapping");
    else
      ax.telegram = t;
  }
  // The drive cannot exchange data faster than this [AKD: 16 ms, §2].
  if (options.update_time() < spec.min_update_time)
    axis.error("bus", "bus \"" + bus.name + "\" updates the IO data every " + format_duration(options.update_time()) +
                          " (cycle_time " + format_duration(options.send_clock) + " x reduction_ratio " +
                          std::to_string(options.reduction_ratio) + "); device \"" + device->name +
                          "\" needs at least " + format_duration(spec.min_update_time) + ": raise reduction_ratio");
  if (ax.telegram != 0) check_telegram(axis, c, ax.telegram, a);
}

void check_profinet_stations(const BusPlan& bus, const BusEntry& at) {
  const auto& options = bus.section<ProfinetBusOptions>();
  std::map<std::string, std::string> users;  // station -> who uses it
  const auto use = [&](const std::string& station, const std::string& who) {
    if (station.empty()) return;
    // One AR per station: a PROFIdrive AKD carries one axis [§6], an IO device is one entry.
    if (const auto [it, added] = users.emplace(station, who); !added)
      at.source.error(at.mark, at.path, "station " + in_quotes(station) + " is used by " + it->second + " and by " + who +
                                            ": one station is one axis or one IO device");
  };
  for (const auto& a : bus.axes) use(a.section<ProfinetAxisSpec>().station, "axis \"" + a.spec.name + "\"");
  for (const auto& io : options.io) use(io.station, "IO device \"" + io.name + "\"");
  for (const auto& s : options.stations)
    if (users.find(s.name) == users.end())
      at.source.warning(at.mark, at.path + ".devices",
                        "station " + in_quotes(s.name) + " is used by no axis and no IO device; it is not connected");
}

}  // namespace drivegate::config
