#pragma once
// The `profinet` bus type's options (with defaults and help), the bus entry's `devices:` (the
// stations on the network) and `io:` (generic IO devices) lists, and their typed, cross-checked
// view ProfinetBusOptions. The bus `cycle_time` is the send clock; the IO data go every
// cycle_time x reduction_ratio (the update time).
#include <cstdint>
#include <string>
#include <vector>

#include "config/bus_types.hpp"
#include "config/profinet/plan.hpp"
#include "config/profinet/wire_rules.hpp"
#include "config/yaml_reader.hpp"

namespace drivegate::config {

std::vector<OptionSpec> profinet_options();

// After the generic option reading filled bus.options: the interface and station names, the
// timing rules, the `devices:` and `io:` lists of the bus entry `bus_map`, into ProfinetBusOptions.
void read_profinet_bus(const ProfinetWireRules& rules, const MapReader& bus_map, const MapReader& options, BusPlan& bus);

const char* to_string(ProfinetIpAssignment a) noexcept;  // "temporary", "permanent"
std::string ipv4_text(std::uint32_t address);             // "192.168.0.10"

// What keeps `ip` with `netmask` from being a station's IP suite ("" when nothing): the netmask
// must be contiguous, the address a unicast host of its subnet (not 0.x, 127.x, multicast or
// reserved, not the subnet's first or last address). The message follows "must be ..." / "got".
std::string ipv4_netmask_problem(std::uint32_t netmask);
std::string ipv4_host_problem(std::uint32_t ip, std::uint32_t netmask);

}  // namespace drivegate::config
