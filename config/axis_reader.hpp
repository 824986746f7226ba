#pragma once
// Reading one entry of `axes:` into an AxisPlan, checked against its bus and device profile.
#include <cstddef>
#include <filesystem>
#include <optional>
#include <vector>

#include "config/bus_types.hpp"
#include "config/device_profile.hpp"
#include "config/plan.hpp"
#include "config/yaml_reader.hpp"

namespace drivegate::config {

// Positions, speeds and ramps in user units are limited to this (config/README.md "Ranges").
inline constexpr double kMaxUserValue = 1e12;

struct AxisContext {
  const std::vector<BusPlan>& buses;
  const BusTypeRegistry& bus_types;
  DeviceCatalog& devices;
  std::filesystem::path base_dir;  // the config file's directory: relative paths (EDS files) start here
};

struct ReadAxis {
  AxisPlan plan;
  std::optional<std::size_t> bus;  // index into AxisContext::buses; none when the bus is unknown
};

ReadAxis read_axis(const MapReader& axis, AxisContext& ctx);

}  // namespace drivegate::config
