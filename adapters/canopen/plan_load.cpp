#include "adapters/canopen/plan_load.hpp"

#include <cstdio>

namespace drivegate::canopen {

BusTraffic plan_traffic(const config::BusPlan& bus) {
  BusTraffic t;
  const auto& o = bus.section<config::CanopenBusOptions>();
  t.sync = o.sync;
  t.master_heartbeat = o.heartbeat_period;
  for (const auto& a : bus.axes) {
    const auto& dev = a.device.section<config::CanopenDeviceSpec>();
    NodeTraffic n;
    for (const auto& p : dev.rpdos)
      n.rpdo_dlcs.push_back(static_cast<std::uint8_t>(p.dlc > 0 ? p.dlc : p.mapped_bytes()));
    for (const auto& p : dev.tpdos)
      n.tpdos.push_back({static_cast<std::uint8_t>(p.mapped_bytes()), static_cast<std::uint8_t>(p.transmission_type),
                         std::chrono::microseconds(100) * p.inhibit_time_100us,
                         std::chrono::milliseconds(p.event_timer_ms)});
    if (config::gateway_watch_of(a) == config::GatewayWatch::Guarding) {
      n.error_control = NodeErrorControl::Guarding;
      n.error_control_period = o.guard_time;
    } else {
      n.error_control = NodeErrorControl::Heartbeat;
      n.error_control_period = o.drive_heartbeat;
    }
    t.nodes.push_back(std::move(n));
  }
  return t;
}

std::string describe_cycle_load(const config::BusPlan& bus, const CycleLoad& load) {
  char text[200];
  const double cycle_ms = std::chrono::duration<double, std::milli>(bus.cycle_time).count();
  const double busy_ms = std::chrono::duration<double, std::milli>(load.time).count();
  const std::uint32_t kbits = bus.section<config::CanopenBusOptions>().bitrate / 1000;
  std::snprintf(text, sizeof text, "%u frames, %llu bits = %.3g ms per %.3g ms SYNC cycle at %u kbit/s (%.0f %%)",
                load.frames, static_cast<unsigned long long>(load.bits), busy_ms, cycle_ms, kbits, load.fraction * 100.0);
  return text;
}

CycleLoad plan_cycle_load(const config::BusPlan& bus) {
  return estimate_cycle_load(plan_traffic(bus), bus.section<config::CanopenBusOptions>().bitrate, bus.cycle_time);
}

}  // namespace drivegate::canopen
