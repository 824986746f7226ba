#include "config/bus_types.hpp"

#include <algorithm>

namespace drivegate::config {

namespace {

std::vector<std::string> section_names(const std::vector<std::shared_ptr<const BusTypeInfo>>& types,
                                       std::string BusTypeInfo::*section) {
  std::vector<std::string> out;
  for (const auto& t : types)
    if (!((*t).*section).empty() && std::find(out.begin(), out.end(), (*t).*section) == out.end())
      out.push_back((*t).*section);
  return out;
}

}  // namespace

void BusTypeRegistry::add(BusTypeInfo info) {
  const auto it = std::find_if(types_.begin(), types_.end(), [&](const auto& t) { return t->name == info.name; });
  auto entry = std::make_shared<const BusTypeInfo>(std::move(info));
  if (it != types_.end())
    *it = std::move(entry);
  else
    types_.push_back(std::move(entry));
}

std::shared_ptr<const BusTypeInfo> BusTypeRegistry::find(std::string_view name) const noexcept {
  const auto it = std::find_if(types_.begin(), types_.end(), [&](const auto& t) { return t->name == name; });
  return it == types_.end() ? nullptr : *it;
}

std::vector<std::string> BusTypeRegistry::names() const {
  std::vector<std::string> out;
  for (const auto& t : types_) out.push_back(t->name);
  return out;
}

std::vector<std::string> BusTypeRegistry::available_names() const {
  std::vector<std::string> out;
  for (const auto& t : types_)
    if (t->available()) out.push_back(t->name);
  return out;
}

std::vector<std::string> BusTypeRegistry::axis_sections() const { return section_names(types_, &BusTypeInfo::axis_section); }

std::vector<std::string> BusTypeRegistry::device_sections() const {
  return section_names(types_, &BusTypeInfo::device_section);
}

}  // namespace drivegate::config
