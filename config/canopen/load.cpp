#include "config/canopen/load.hpp"

#include <cstdio>

namespace drivegate::config {

canopen::BusTraffic canopen_traffic(const BusPlan& bus) {
  canopen::BusTraffic t;
  const auto& o = bus.canopen;
  t.sync = o.sync;
  t.master_heartbeat = o.heartbeat_period;
  for (const auto& a : bus.axes) {
    const auto& dev = a.device.canopen;
    canopen::NodeTraffic n;
    for (const auto& p : dev.rpdos)
      n.rpdo_dlcs.push_back(static_cast<std::uint8_t>(p.dlc > 0 ? p.dlc : p.mapped_bytes()));
    for (const auto& p : dev.tpdos)
      n.tpdos.push_back({static_cast<std::uint8_t>(p.mapped_bytes()), static_cast<std::uint8_t>(p.transmission_type),
                         std::chrono::microseconds(100) * p.inhibit_time_100us,
                         std::chrono::milliseconds(p.event_timer_ms)});
    if (gateway_watch_of(a) == GatewayWatch::Guarding) {
      n.error_control = canopen::NodeErrorControl::Guarding;
      n.error_control_period = o.guard_time;
    } else {
      n.error_control = canopen::NodeErrorControl::Heartbeat;
      n.error_control_period = o.drive_heartbeat;
    }
    t.nodes.push_back(std::move(n));
  }
  return t;
}

std::string describe_canopen_load(const BusPlan& bus, const canopen::CycleLoad& load) {
  char text[200];
  const double cycle_ms = std::chrono::duration<double, std::milli>(bus.cycle_time).count();
  const double busy_ms = std::chrono::duration<double, std::milli>(load.time).count();
  std::snprintf(text, sizeof text, "%u frames, %llu bits = %.3g ms per %.3g ms SYNC cycle at %u kbit/s (%.0f %%)",
                load.frames, static_cast<unsigned long long>(load.bits), busy_ms, cycle_ms, bus.canopen.bitrate / 1000,
                load.fraction * 100.0);
  return text;
}

canopen::CycleLoad canopen_cycle_load(const BusPlan& bus) {
  return canopen::estimate_cycle_load(canopen_traffic(bus), bus.canopen.bitrate, bus.cycle_time);
}

}  // namespace drivegate::config
