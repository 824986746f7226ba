#include "config/bus_types.hpp"

#include <algorithm>

#include "config/canopen/bus_options.hpp"

namespace drivegate::config {

BusTypeRegistry BusTypeRegistry::builtin() {
  BusTypeRegistry r;
  BusTypeInfo sim{"sim", true, 1, 127, {}, "sim"};
  sim.options.push_back({"acyclic_latency_cycles", OptionKind::Integer, 1, 1000, std::int64_t{1},
                         "cycles before a simulated drive answers an acyclic read/write", {}});
  r.add(std::move(sim));
  r.add(canopen_bus_type());
  // EtherCAT configured station addresses; PROFINET device numbers.
  r.add({"ethercat", false, 1, 65535, {}, ""});
  r.add({"profinet", false, 1, 65535, {}, ""});
  return r;
}

void BusTypeRegistry::add(BusTypeInfo info) {
  const auto it = std::find_if(types_.begin(), types_.end(), [&](const BusTypeInfo& t) { return t.name == info.name; });
  if (it != types_.end())
    *it = std::move(info);
  else
    types_.push_back(std::move(info));
}

const BusTypeInfo* BusTypeRegistry::find(std::string_view name) const noexcept {
  const auto it = std::find_if(types_.begin(), types_.end(), [&](const BusTypeInfo& t) { return t.name == name; });
  return it == types_.end() ? nullptr : &*it;
}

std::vector<std::string> BusTypeRegistry::names() const {
  std::vector<std::string> out;
  for (const auto& t : types_) out.push_back(t.name);
  return out;
}

std::vector<std::string> BusTypeRegistry::available_names() const {
  std::vector<std::string> out;
  for (const auto& t : types_)
    if (t.available) out.push_back(t.name);
  return out;
}

std::vector<std::string> BusTypeRegistry::axis_sections() const {
  std::vector<std::string> out;
  for (const auto& t : types_)
    if (!t.axis_section.empty() && std::find(out.begin(), out.end(), t.axis_section) == out.end())
      out.push_back(t.axis_section);
  return out;
}

}  // namespace drivegate::config
