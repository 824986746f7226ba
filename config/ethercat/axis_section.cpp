#include "config/ethercat/axis_section.hpp"

#include <map>

#include "config/ethercat/bus_options.hpp"
#include "config/ethercat/esi_checks.hpp"

namespace drivegate::config {

void read_ethercat_axis(const MapReader& axis, const BusPlan& bus, const DeviceProfile* device,
                        const std::filesystem::path& base_dir, AxisPlan& a) {
  if (device && !device->has_section<EthercatDeviceSpec>()) {
    axis.error("device", "device profile \"" + device->name + "\" has no ethercat section, which an axis on an "
                         "ethercat bus needs (profiles/devices/README.md \"EtherCAT\")");
    device = nullptr;
  }
  auto& ax = a.sections.edit<EthercatAxisSpec>();
  const MapReader c = axis.map("ethercat", Need::Optional);
  c.check_keys({"axis", "esi"});
  const int axes = device ? device->section<EthercatDeviceSpec>().axes : 1;
  if (const auto n = c.integer("axis", Need::Optional, 0, 7, "an axis index of the slave (0 = its first)")) {
    if (*n >= axes)
      c.error("axis", "device \"" + (device ? device->name : std::string{}) + "\" carries " + std::to_string(axes) +
                          (axes == 1 ? " axis" : " axes") + " per slave (0.." + std::to_string(axes - 1) + "), got " +
                          std::to_string(*n));
    else
      ax.slave_axis = static_cast<int>(*n);
  }
  // The ESI's problems go to the same Problems with its file name, so into Plan::warnings and
  // --check-config.
  if (const auto esi = read_esi_key(c, base_dir, ax.esi); esi && device) {
    const std::string esi_name = "ESI \"" + std::filesystem::path{ax.esi}.filename().string() + "\"";
    if (const EsiDevice* dev = pick_esi_device(c, *esi, esi_name, *device)) {
      ax.esi_device = esi_device_text(*dev);
      check_device_against_esi(c, *device, ax.slave_axis, esi_name, *dev);
      ax.esi_objects = dev->objects;
    }
  }
  if (device && device->section<EthercatDeviceSpec>().distributed_clocks &&
      !bus.section<EthercatBusOptions>().distributed_clocks)
    axis.source().warning(axis.mark_of("device"), axis.field("device"),
                          "device \"" + device->name + "\" runs its cyclic modes on SYNC0, but bus \"" + bus.name +
                              "\" has distributed_clocks: false; the drive runs free, which it may refuse");
}

std::string ethercat_address_key(const AxisPlan& a) {
  const int n = a.section<EthercatAxisSpec>().slave_axis;
  return n == 0 ? std::to_string(a.address) : std::to_string(a.address) + " axis " + std::to_string(n);
}

void check_ethercat_slaves(const BusPlan& bus, const BusEntry& at) {
  std::map<int, const AxisPlan*> first_at;  // position -> first axis there
  for (const auto& a : bus.axes) {
    const auto [it, added] = first_at.emplace(a.address, &a);
    if (!added && it->second->device.name != a.device.name)
      at.source.error(at.mark, at.path,
                      "axes \"" + it->second->spec.name + "\" and \"" + a.spec.name + "\" share the slave at position " +
                          std::to_string(a.address) + " but name different devices (\"" + it->second->device.name +
                          "\", \"" + a.device.name + "\")");
  }
  for (const auto& io : bus.section<EthercatBusOptions>().io)
    if (const auto it = first_at.find(io.position); it != first_at.end())
      at.source.error(at.mark, at.path + ".io",
                      "I/O slave \"" + io.name + "\" is at position " + std::to_string(io.position) + ", where axis \"" +
                          it->second->spec.name + "\" is");
}

}  // namespace drivegate::config
