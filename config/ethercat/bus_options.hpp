#pragma once
// The `ethercat` bus type's options (with defaults and help), the bus entry's `io:` list of I/O
// slaves, and their typed, cross-checked view EthercatBusOptions. The bus `cycle_time` is the
// period of the cyclic frame (and of SYNC0 where distributed clocks run).
#include <vector>

#include "config/bus_types.hpp"
#include "config/ethercat/plan.hpp"
#include "config/yaml_reader.hpp"

namespace drivegate::config {

std::vector<OptionSpec> ethercat_options();

// After the generic option reading filled bus.options: the interface name, the ranges that depend
// on the cycle, and the `io:` list of the bus entry `bus_map`, into the bus' EthercatBusOptions.
void read_ethercat_bus(const MapReader& bus_map, const MapReader& options, BusPlan& bus);

// "raw", "sim".
const char* to_string(EthercatTransportKind kind) noexcept;

}  // namespace drivegate::config
