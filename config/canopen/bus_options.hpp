#pragma once
// The `canopen` bus type's options (with defaults and help) and their typed, cross-checked view
// CanopenBusOptions. The bus `cycle_time` is the SYNC period.
#include <vector>

#include "config/bus_types.hpp"
#include "config/canopen/plan.hpp"
#include "config/yaml_reader.hpp"

namespace drivegate::config {

// The option keys, defaults and ranges.
std::vector<OptionSpec> canopen_options();

// After the generic option reading filled bus.options: checks what a single option cannot (bit
// rate among the CiA 301 rates, multicast group, whole milliseconds, ...) and fills the bus' CanopenBusOptions.
// `bus_map` is the bus entry, `options` its options map (possibly absent).
void read_canopen_bus(const MapReader& bus_map, const MapReader& options, BusPlan& bus);

// "socketcan", "udp-multicast", "sim".
const char* to_string(CanTransportKind kind) noexcept;

}  // namespace drivegate::config
