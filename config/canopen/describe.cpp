#include "config/canopen/describe.hpp"

#include <cstdio>

#include "config/canopen/bus_options.hpp"
#include "config/object_text.hpp"
#include "config/scalars.hpp"
#include "config/text_util.hpp"

namespace drivegate::config {

namespace {

std::string pdo_text(const PdoSpec& pdo, bool receive) {
  std::string t = pdo.synchronous() ? "sync (type " + std::to_string(pdo.transmission_type) + ")"
                                    : "event (type " + std::to_string(pdo.transmission_type);
  if (!pdo.synchronous()) {
    if (pdo.inhibit_time_100us > 0)
      t += ", inhibit " + format_duration(std::chrono::microseconds(100) * pdo.inhibit_time_100us);
    if (pdo.event_timer_ms > 0) t += ", timer " + format_duration(std::chrono::milliseconds(pdo.event_timer_ms));
    t += ")";
  }
  std::vector<std::string> entries;
  for (const auto& e : pdo.entries) entries.push_back(object_text(e.object) + " " + std::string{to_string(e.type)});
  t += ": " + join(entries) + " (" + std::to_string(pdo.mapped_bytes()) + " bytes";
  if (receive && pdo.dlc > 0) t += ", sent as " + std::to_string(pdo.dlc);
  return t + ")";
}

// "5", "1048576 (0x100000)": registers and bit fields read better in hex as well.
std::string value_text(std::int64_t v) {
  if (v >= -9 && v <= 9) return std::to_string(v);
  char buf[24];
  std::snprintf(buf, sizeof buf, "0x%llX", static_cast<unsigned long long>(v));
  return v < 0 ? std::to_string(v) : std::to_string(v) + " (" + buf + ")";
}

}  // namespace

void describe_canopen_axis(const BusPlan& b, const AxisPlan& a, DescribeRows& rows) {
  const auto& bus = b.section<CanopenBusOptions>();
  const auto& co = a.device.section<CanopenDeviceSpec>();
  const auto& ax = a.section<CanopenAxisOptions>();
  const auto row = [&](std::string label, std::string value) { rows.emplace_back(std::move(label), std::move(value)); };
  if (co.device_type) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "1000h = %08Xh under mask %08Xh", *co.device_type, co.device_type_mask);
    row("device type", buf);
  }
  if (gateway_watch_of(a) != GatewayWatch::Guarding) {
    std::string t = "heartbeat: drive sends every " + format_duration(bus.drive_heartbeat) + ", lost after " +
                    std::to_string(bus.heartbeat_misses) + " silent periods";
    if (gateway_watch_of(a) == GatewayWatch::Heartbeat)
      t += "; drive watches the gateway's heartbeat (1016h, " +
           format_duration(bus.heartbeat_period * bus.heartbeat_misses) + ")";
    row("error control", t);
  } else {
    row("error control", "guarding every " + format_duration(bus.guard_time) + ", life time factor " +
                               std::to_string(bus.life_time_factor) + " (drive stops after " +
                               format_duration(bus.guard_time * bus.life_time_factor) + " without guarding)");
  }
  switch (gateway_watch_of(a)) {
    case GatewayWatch::Heartbeat: row("gateway watch", "heartbeat: the drive must have 1016h"); break;
    case GatewayWatch::Guarding: row("gateway watch", "guarding: the drive must have 100Ch/100Dh"); break;
    case GatewayWatch::Required:
      row("gateway watch", "required: 1016h, else node guarding; a drive with neither is not started");
      break;
    case GatewayWatch::Optional:
      row("gateway watch", "optional: 1016h, else node guarding; a drive with neither runs unwatched (warning: it "
                             "does not stop by itself if the gateway dies)");
      break;
  }
  row("SDO channel", std::to_string(ax.sdo_channel));
  row("PDO maps", co.pdo_policy == PdoPolicy::Write
                        ? std::string{"written at boot"} + (co.disable_unused_pdos ? ", unused PDOs disabled" : "")
                        : "verified only (configured in the drive" +
                              (co.fixed_mapping_count > 0
                                   ? "; mapping count fixed at " + std::to_string(co.fixed_mapping_count) + ")"
                                   : std::string{")"}));
  for (const auto& pdo : co.rpdos) row("RPDO " + std::to_string(pdo.number), pdo_text(pdo, true));
  for (const auto& pdo : co.tpdos) row("TPDO " + std::to_string(pdo.number), pdo_text(pdo, false));
  for (const auto* writes : {&co.startup_writes, &ax.startup_writes})
    for (const auto& w : *writes)
      row("start-up write", object_text(w.def.id) + " " + std::string{to_string(w.def.type)} + " = " +
                                  value_text(w.value) + " -- " + w.why);
  if (!ax.eds.empty())
    row("EDS", ax.eds + " (" + std::to_string(ax.eds_objects.size()) + " objects)");
  if (bus.transport == CanTransportKind::Simulated) row("simulated drive", "persona " + co.persona);
}

void describe_canopen_bus(const BusPlan& b, DescribeRows& rows) {
  const auto& c = b.section<CanopenBusOptions>();
  std::string link = std::string{to_string(c.transport)};
  if (c.transport == CanTransportKind::SocketCan) link += " on " + c.interface;
  if (c.transport == CanTransportKind::UdpMulticast) link += " " + c.group + ":" + std::to_string(c.port) + " from " + c.interface;
  rows.emplace_back("CAN", link + ", " + std::to_string(c.bitrate / 1000) + " kbit/s, gateway node-ID " +
                               std::to_string(c.gateway_node_id));
  rows.emplace_back("SYNC", c.sync ? "every " + format_duration(b.cycle_time) : std::string{"off"});
  if (c.sync)
    rows.emplace_back("sync RPDOs", c.rpdo_refresh > core::Duration::zero()
                                        ? "after a SYNC when changed, unchanged every " + format_duration(c.rpdo_refresh)
                                        : std::string{"after every SYNC"});
}

}  // namespace drivegate::config
