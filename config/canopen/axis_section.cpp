#include "config/canopen/axis_section.hpp"

#include <algorithm>

#include "config/canopen/device_section.hpp"
#include "config/canopen/eds.hpp"
#include "config/object_text.hpp"
#include "config/scalars.hpp"
#include "config/text_util.hpp"

namespace drivegate::config {

namespace {

namespace fs = std::filesystem;

std::string pdo_name(bool receive, const PdoSpec& pdo) {
  return std::string{receive ? "RPDO " : "TPDO "} + std::to_string(pdo.number);
}

std::string type_text(cia402::DataType type) {
  return std::string{to_string(type)} + " (" + std::to_string(size_of(type) * 8) + " bits)";
}

// " (its section at line 12 was skipped: DataType \"x\" is not a data type code)" when the EDS
// describes `id` in a section it could not use; the warning about it is not shown with errors.
std::string skipped_text(const EdsDictionary& eds, cia402::ObjectId id) {
  const EdsSkipped* s = find_eds_skipped(eds.skipped, id);
  if (!s) return "";
  return " (its section at line " + std::to_string(s->line) + " was skipped: " + s->reason + ")";
}

std::string eds_text(const EdsObject& o) {
  return eds_type_name(o.data_type) + " (" + (eds_type_bits(o.data_type) ? std::to_string(*eds_type_bits(o.data_type)) + " bits, " : "") +
         "line " + std::to_string(o.line) + ")";
}

// Every PDO entry of the device must exist in the EDS, be mappable, go the right way and have the
// mapped size: otherwise the drive would abort the mapping at boot (0604 0041h / 0604 0042h).
void check_maps_against_eds(const MapReader& c, const DeviceProfile& device, const std::string& eds_name,
                            const EdsDictionary& eds) {
  const auto& objects = eds.objects;
  const auto& co = device.section<CanopenDeviceSpec>();
  for (const bool receive : {true, false}) {
    for (const auto& pdo : receive ? co.rpdos : co.tpdos) {
      for (const auto& e : pdo.entries) {
        const std::string what = "device \"" + device.name + "\" maps " + object_text(e.object) + " in " +
                                 pdo_name(receive, pdo) + ", ";
        const EdsObject* o = find_eds_object(objects, e.object);
        if (!o) {
          c.error("eds", what + "which " + eds_name + " does not list" + skipped_text(eds, e.object));
          continue;
        }
        if (!o->pdo_mapping) {
          c.error("eds", what + "which " + eds_name + " marks PDOMapping=0 (line " + std::to_string(o->line) + ")");
          continue;
        }
        if (receive ? !o->writable() : !o->readable()) {
          c.error("eds", what + "which is " + std::string{to_string(o->access)} + " in " + eds_name + " (line " +
                             std::to_string(o->line) + ")");
          continue;
        }
        if (eds_type_bits(o->data_type) != e.bits)
          c.error("eds", what + "as " + type_text(e.type) + "; " + eds_name + " has " + eds_text(*o));
      }
    }
  }
}

void check_writes_against_eds(const MapReader& c, const std::vector<StartupWrite>& writes, const std::string& whose,
                              const std::string& eds_name, const EdsDictionary& eds) {
  const auto& objects = eds.objects;
  for (const auto& w : writes) {
    const std::string what = whose + " start-up write of " + object_text(w.def.id) + " ";
    const EdsObject* o = find_eds_object(objects, w.def.id);
    if (!o)
      c.error("eds", what + "names an object " + eds_name + " does not list" + skipped_text(eds, w.def.id));
    else if (!o->writable())
      c.error("eds", what + "names an object that is " + std::string{to_string(o->access)} + " in " + eds_name +
                         " (line " + std::to_string(o->line) + ")");
    else if (eds_type_bits(o->data_type) != size_of(w.def.type) * 8)
      c.error("eds", what + "writes " + type_text(w.def.type) + "; " + eds_name + " has " + eds_text(*o));
  }
}

void read_eds(const MapReader& c, const DeviceProfile* device, const fs::path& base_dir, CanopenAxisOptions& a) {
  const auto text = c.string("eds", Need::Optional);
  if (!text) return;
  const fs::path p{*text};
  const fs::path file = (p.is_absolute() ? p : base_dir / p).lexically_normal();
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) {
    c.error("eds", "file \"" + file.string() + "\" does not exist (relative paths start at the config file's directory)");
    return;
  }
  a.eds = file.string();
  // The EDS' warnings go to the same Problems, so into Plan::warnings and --check-config.
  auto objects = load_eds(file, *c.source().problems);
  if (!objects) {
    c.error("eds", "EDS \"" + file.string() + "\" has errors, listed with its file name");
    return;
  }
  const std::string eds_name = "EDS \"" + file.filename().string() + "\"";
  if (device) {
    check_maps_against_eds(c, *device, eds_name, *objects);
    check_writes_against_eds(c, device->section<CanopenDeviceSpec>().startup_writes, "device \"" + device->name + "\"",
                             eds_name, *objects);
  }
  check_writes_against_eds(c, a.startup_writes, "axis", eds_name, *objects);
  a.eds_objects = std::move(objects->objects);
}

// Synchronous PDOs only move with SYNC; a bus without it would leave the drive's data stale.
void check_sync(const MapReader& axis, const BusPlan& bus, const DeviceProfile& device) {
  const auto& co = device.section<CanopenDeviceSpec>();
  if (!bus.section<CanopenBusOptions>().sync) {
    for (const bool receive : {true, false})
      for (const auto& pdo : receive ? co.rpdos : co.tpdos)
        if (pdo.synchronous()) {
          axis.error("device", "device \"" + device.name + "\" maps synchronous PDOs (" + pdo_name(receive, pdo) +
                                   ", transmission type " + std::to_string(pdo.transmission_type) + ") but bus \"" +
                                   bus.name + "\" has sync: false");
          return;
        }
    return;
  }
  if (!co.sync_periods.empty() &&
      std::find(co.sync_periods.begin(), co.sync_periods.end(), bus.cycle_time) == co.sync_periods.end()) {
    std::vector<std::string> periods;
    for (const auto d : co.sync_periods) periods.push_back(format_duration(d));
    axis.error("bus", "bus \"" + bus.name + "\" cycle_time " + format_duration(bus.cycle_time) +
                          " is not a SYNC period device \"" + device.name + "\" supports (" + join(periods) + ")");
  }
}

}  // namespace

void read_canopen_axis(const MapReader& axis, const BusPlan& bus, const DeviceProfile* device,
                       const fs::path& base_dir, AxisPlan& a) {
  if (device && !device->has_section<CanopenDeviceSpec>()) {
    axis.error("device", "device profile \"" + device->name + "\" has no canopen section, which an axis on a "
                         "canopen bus needs (profiles/devices/README.md)");
    device = nullptr;
  }
  if (a.address != 0 && a.address == bus.section<CanopenBusOptions>().gateway_node_id)
    axis.error("address", "node-ID " + std::to_string(a.address) + " is the gateway's own on bus \"" + bus.name +
                              "\" (option gateway_node_id); give the drive another node-ID or change gateway_node_id");

  auto& co = a.sections.edit<CanopenAxisOptions>();
  const MapReader c = axis.map("canopen", Need::Optional);
  c.check_keys({"eds", "sdo_channel", "startup_writes", "gateway_watch"});
  co.gateway_watch = read_gateway_watch(c);
  if (const auto ch = c.integer("sdo_channel", Need::Optional, 1, 4)) {
    const int channels = device ? device->section<CanopenDeviceSpec>().sdo_channels : 4;
    if (*ch > channels)
      c.error("sdo_channel", "device \"" + device->name + "\" has " + std::to_string(channels) + " SDO channel" +
                                 (channels == 1 ? "" : "s") + ", got " + std::to_string(*ch));
    // Channel k answers on 580h + 20h*(k-1) + node-ID, which leaves channel 1's range above node 31
    // [stoeber-sd6-canopen.md §5.3].
    else if (*ch > 1 && a.address > 31)
      c.error("sdo_channel", "SDO channels 2..4 need node-ID <= 31 (their COB-IDs 580h + 20h x (channel - 1) + "
                             "node-ID overlap channel 1 above 31); axis node-ID is " + std::to_string(a.address));
    else
      co.sdo_channel = static_cast<int>(*ch);
  }
  const std::optional<ParameterNaming> naming =
      device ? device->section<CanopenDeviceSpec>().parameter_naming : std::nullopt;
  read_startup_writes(c, "startup_writes", naming, co.startup_writes);
  read_eds(c, device, base_dir, co);
  if (device) check_sync(axis, bus, *device);
}

}  // namespace drivegate::config
