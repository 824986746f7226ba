#pragma once
// The axis table shared by `drivegatectl status` and drivegate-demo.
#include <chrono>
#include <string>
#include <vector>

#include "client/client.hpp"

namespace drivegate::client {

// Columns: gateway, axis, address (from `links`; CANopen node-IDs as "35 (0x23)"), link, state,
// mode, position, velocity, torque, fault. A state older than `stale_after` (gateway gone or
// network trouble) is marked "(stale)".
std::string format_status_table(const std::vector<AxisState>& states, const std::vector<AxisLink>& links,
                                std::chrono::steady_clock::time_point now,
                                std::chrono::milliseconds stale_after = std::chrono::milliseconds(1000));

// ANSI: clear the screen and move the cursor home, for live views.
inline constexpr const char* kAnsiClearHome = "\x1b[2J\x1b[H";

}  // namespace drivegate::client
