#include "adapters/profinet/sim/network_builder.hpp"

#include <algorithm>

#include "config/profinet/plan.hpp"

namespace drivegate::profinet {

namespace {

std::string quoted(std::string_view s) { return "'" + std::string(s) + "'"; }

// An AKD for the axis on `station`, its telegram plugged (the controller's Connect may pick another).
std::unique_ptr<PnSimStation> akd_station(const config::BusPlan& bus, const config::AxisPlan& axis,
                                          const config::ProfinetStation& station) {
  const auto& spec = axis.section<config::ProfinetAxisSpec>();
  const std::string where = "bus " + quoted(bus.name) + ", station " + quoted(station.name) + " (axis " +
                            quoted(axis.spec.name) + ")";
  if (axis.device.name != kAkdProfinetProfile) {
    throw PnBuildError(where + ": device profile " + quoted(axis.device.name) +
                       " has no simulated PROFINET device (drivegate-sim simulates " + std::string(kAkdProfinetProfile) + ")");
  }
  if (!akd::offers_telegram(spec.telegram)) {
    throw PnBuildError(where + ": the simulated AKD has no module for telegram " + std::to_string(spec.telegram));
  }
  auto s = std::make_unique<PnSimStation>();
  AkdPersonaConfig c;
  c.drive.telegram = spec.telegram;
  c.vendor_id = station.vendor_id.value_or(kSimAkdVendorId);
  auto persona = std::make_unique<AkdPersona>(c);
  s->akd = persona.get();
  s->persona_impl = std::move(persona);
  s->persona = std::string(kAkdProfinetProfile);
  s->used_by = "axis " + axis.spec.name;
  return s;
}

// A generic device with the DAP and, for an io: entry, its submodules (slot by slot, API 0).
std::unique_ptr<PnSimStation> io_station(const config::ProfinetIoDevice* io, const config::ProfinetStation& station) {
  GenericIoPersonaConfig c;
  c.vendor_id = station.vendor_id.value_or(kSimIoVendorId);
  c.slots.push_back({0, 0, io != nullptr ? io->dap_ident : kSimDapModule,
                     {{1, io != nullptr ? io->dap_submodule_ident : kSimDapSubmodule, 0, 0}}});
  if (io != nullptr) {
    for (const config::ProfinetIoSubmodule& m : io->submodules) {
      const auto slot = static_cast<std::uint16_t>(m.slot);
      if (c.slots.back().slot != slot) c.slots.push_back({0, slot, m.module_ident, {}});
      c.slots.back().submodules.push_back({static_cast<std::uint16_t>(m.subslot), m.submodule_ident,
                                           static_cast<std::uint16_t>(m.input_bytes),
                                           static_cast<std::uint16_t>(m.output_bytes)});
    }
  }
  auto s = std::make_unique<PnSimStation>();
  auto persona = std::make_unique<GenericIoPersona>(std::move(c));
  s->io = persona.get();
  s->persona_impl = std::move(persona);
  s->persona = std::string(kGenericIoPersona);
  s->used_by = io != nullptr ? "io " + io->name : std::string{};
  return s;
}

}  // namespace

MacAddress sim_station_mac(std::size_t bus_index, std::size_t station_index) {
  if (bus_index > 0xFF || station_index >= 0xFFFF) {
    throw PnBuildError("simulated PROFINET network: at most 256 buses of 65535 stations each");
  }
  const std::size_t n = station_index + 1;
  return {0x02, 0x50, 0x4E, static_cast<std::uint8_t>(bus_index), static_cast<std::uint8_t>(n >> 8),
          static_cast<std::uint8_t>(n & 0xFF)};
}

PnSimStation& BuiltPnNetwork::add(std::unique_ptr<PnSimStation> station, const PnDeviceConfig& config) {
  station->device = &network_.add(config, *station->persona_impl);
  stations_.push_back(std::move(station));
  return *stations_.back();
}

PnSimStation* BuiltPnNetwork::find(std::string_view name) noexcept {
  const auto it = std::find_if(stations_.begin(), stations_.end(), [name](const auto& s) { return s->name == name; });
  return it == stations_.end() ? nullptr : it->get();
}

std::unique_ptr<BuiltPnNetwork> build_pn_network(const config::BusPlan& bus, std::size_t bus_index) {
  const auto& options = bus.section<config::ProfinetBusOptions>();
  auto net = std::make_unique<BuiltPnNetwork>(bus.name);
  for (std::size_t i = 0; i < options.stations.size(); ++i) {
    const config::ProfinetStation& station = options.stations[i];
    const auto axis = std::find_if(bus.axes.begin(), bus.axes.end(), [&station](const config::AxisPlan& a) {
      return a.section<config::ProfinetAxisSpec>().station == station.name;
    });
    const auto io = std::find_if(options.io.begin(), options.io.end(),
                                 [&station](const config::ProfinetIoDevice& d) { return d.station == station.name; });
    std::unique_ptr<PnSimStation> s = axis != bus.axes.end() ? akd_station(bus, *axis, station)
                                      : io_station(io != options.io.end() ? &*io : nullptr, station);
    s->name = station.name;
    PnDeviceConfig c;
    c.dcp.mac = sim_station_mac(bus_index, i);
    c.dcp.type_of_station = s->akd != nullptr ? "AKD" : "drivegate-sim generic IO";
    c.dcp.vendor_id = station.vendor_id.value_or(s->akd != nullptr ? kSimAkdVendorId : kSimIoVendorId);
    c.dcp.device_id = station.device_id.value_or(s->akd != nullptr ? kSimAkdDeviceId : kSimIoDeviceId);
    c.dcp.name_of_station = station.name;  // stored: an engineering tool named the device
    // No IP address: the controller assigns the configured one by DCP.
    const MacAddress& m = c.dcp.mac;
    c.activity = {0xDEA50000U | static_cast<std::uint32_t>(i), static_cast<std::uint16_t>(bus_index), 1,
                  {0, 0, m[0], m[1], m[2], m[3], m[4], m[5]}};
    net->add(std::move(s), c);
  }
  return net;
}

}  // namespace drivegate::profinet
