#pragma once
// CANopen node-IDs as drivegatectl shows them to people: decimal and hex, "35 (0x23)", since
// drive tools and manuals give them either way. JSON output keeps plain numbers.
#include <cstdint>
#include <string>
#include <string_view>

namespace drivegate::client {

// "35 (0x23)" on a canopen bus, "35" on another; "" for an unknown bus type (no axis_link yet).
std::string format_address(std::string_view bus_type, std::uint32_t address);

// The gateway's CANopen texts with every "node N" also in hex: "node 35 (0x23) configured".
// Numbers above 127 (not a node-ID) and ones already followed by their hex stay as they are.
std::string annotate_node_ids(std::string_view text);

}  // namespace drivegate::client
