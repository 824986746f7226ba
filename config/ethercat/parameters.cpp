#include "config/ethercat/parameters.hpp"

#include <cstdio>

#include "config/ethercat/esi.hpp"
#include "config/ethercat/plan.hpp"
#include "config/text_util.hpp"
#include "profiles/cia402/standard_types.hpp"

namespace drivegate::config {

namespace {

// The type the device profile gives an object: its PDO maps and start-up writes name types.
std::optional<core::ParamType> device_profile_type(const AxisPlan& axis, cia402::ObjectId id) {
  if (!axis.device.has_section<EthercatDeviceSpec>()) return std::nullopt;
  const auto& dev = axis.device.section<EthercatDeviceSpec>();
  for (const auto* pdos : {&dev.rxpdos, &dev.txpdos})
    for (const auto& pdo : *pdos)
      for (const auto& e : pdo.entries)
        if (e.object == id) return cia402::to_param_type(e.type);
  for (const auto& w : dev.startup_writes)
    if (w.def.id == id) return cia402::to_param_type(w.def.type);
  return std::nullopt;
}

std::string id_text(cia402::ObjectId id) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "%04X:%u", unsigned{id.index}, unsigned{id.sub});
  return buf;
}

}  // namespace

ParameterRef find_ethercat_parameter(const AxisPlan& axis, std::string_view name, cia402::ObjectId id) {
  ParameterRef out;
  const auto& ax = axis.section<EthercatAxisSpec>();
  const auto& objects = ax.esi_objects;
  const EsiObject* entry = nullptr;
  if (name.empty()) {
    out.id = id;
    entry = find_esi_object(objects, id);
  } else {
    const auto found = find_esi_objects(objects, name);
    if (found.size() > 1) {
      std::vector<std::string> ids;
      for (const EsiObject* o : found) ids.push_back(id_text(o->id));
      out.error = "'" + std::string(name) + "' names " + std::to_string(found.size()) + " objects in the ESI of axis '" +
                  axis.spec.name + "' (" + join(ids) + "); use INDEX:SUB";
      return out;
    }
    if (found.empty()) {
      out.name_unknown = true;
      out.error = "axis '" + axis.spec.name + "' has no object named '" + std::string(name) + "'" +
                  (ax.esi.empty() ? " (give the axis an ESI file to use names, or use INDEX:SUB)"
                                  : " in its ESI (a sub-item is named OBJECT:SUB)");
      return out;
    }
    entry = found.front();
    out.id = entry->id;
  }
  if (entry != nullptr && core::param_type_from_cia(entry->data_type) != core::ParamType::Unknown) {
    out.type = core::param_type_from_cia(entry->data_type);
    out.type_source = "the ESI";
  } else if (const auto from_profile = device_profile_type(axis, *out.id)) {
    out.type = *from_profile;
    out.type_source = "device profile " + axis.device.name;
  }
  return out;
}

}  // namespace drivegate::config
