#include "config/canopen/parameters.hpp"

#include "config/canopen/eds.hpp"
#include "config/canopen/parameter_names.hpp"
#include "config/canopen/plan.hpp"
#include "profiles/cia402/standard_types.hpp"

namespace drivegate::config {

namespace {

// The type the device profile gives an object: its PDO maps and start-up writes name types.
std::optional<core::ParamType> device_profile_type(const AxisPlan& axis, cia402::ObjectId id) {
  const auto& dev = axis.device.section<CanopenDeviceSpec>();
  for (const auto* pdos : {&dev.rpdos, &dev.tpdos})
    for (const auto& pdo : *pdos)
      for (const auto& e : pdo.entries)
        if (e.object == id) return cia402::to_param_type(e.type);
  for (const auto* writes : {&dev.startup_writes, &axis.section<CanopenAxisOptions>().startup_writes})
    for (const auto& w : *writes)
      if (w.def.id == id) return cia402::to_param_type(w.def.type);
  return std::nullopt;
}

}  // namespace

ParameterRef find_canopen_parameter(const AxisPlan& axis, std::string_view name, cia402::ObjectId id) {
  ParameterRef out;
  const auto& co = axis.section<CanopenAxisOptions>();
  const auto& eds = co.eds_objects;
  const EdsObject* entry = nullptr;
  if (name.empty()) {
    out.id = id;
    entry = find_eds_object(eds, id);
  } else if ((entry = find_eds_object(eds, name)) != nullptr) {
    out.id = entry->id;
  } else if (const auto& naming = axis.device.section<CanopenDeviceSpec>().parameter_naming) {
    const auto r = resolve_parameter_name(name, *naming);
    if (!r.id) {
      out.error = "'" + std::string(name) + "' is not a parameter of device " + axis.device.name + ": " + r.error;
      return out;
    }
    out.id = *r.id;
    entry = find_eds_object(eds, *r.id);
  } else {
    out.error = "axis '" + axis.spec.name + "' has no object named '" + std::string(name) + "'" +
                (co.eds.empty() ? " (give the axis an EDS file to use names, or use INDEX:SUB)" : " in its EDS");
    return out;
  }
  if (entry != nullptr && core::param_type_from_cia(entry->data_type) != core::ParamType::Unknown) {
    out.type = core::param_type_from_cia(entry->data_type);
    out.type_source = "the EDS";
  } else if (const auto from_profile = device_profile_type(axis, *out.id)) {
    out.type = *from_profile;
    out.type_source = "device profile " + axis.device.name;
  }
  return out;
}

}  // namespace drivegate::config
