#pragma once
// What the master does to bring one node up, compiled from the plan: the boot steps (identity,
// start-up writes, PDO configuration or verification, SYNC and error-control objects) and the PDO
// layouts the process data engine exchanges. Vendor differences come in as data from the device
// profile's `canopen:` section (adapters/canopen/README.md).
#include <vector>

#include "adapters/canopen/master/node_boot.hpp"
#include "adapters/canopen/master/pdo.hpp"
#include "config/canopen/plan.hpp"

namespace drivegate::canopen {

// What the error-control probes of a boot found (NodeBoot::found()), with gateway_watch required
// or optional: the drive has 1016h (and took the gateway's entry in 1016h:01), 100Ch, 100Ch and
// 100Dh; it has 1016h but refused the entry (the consumer-heartbeat bit is then clear).
inline constexpr std::uint8_t kFoundConsumerHeartbeat = 1U << 0;
inline constexpr std::uint8_t kFoundGuardTime = 1U << 1;
inline constexpr std::uint8_t kFoundGuarding = 1U << 2;
inline constexpr std::uint8_t kConsumerHeartbeatRefused = 1U << 3;

// How the gateway and the drive watch each other after a boot that succeeded.
enum class WatchOutcome : std::uint8_t {
  Heartbeat,  // the drive consumes the gateway's heartbeat (1016h); the master consumes the drive's
  Guarding,   // the master guards the node with RTRs; the drive's life guarding watches the gateway
  Unwatched,  // the master consumes the drive's heartbeat; the drive does not watch the gateway
};
WatchOutcome watch_outcome(config::GatewayWatch watch, std::uint8_t found) noexcept;

std::vector<BootStep> build_boot_steps(const config::AxisPlan& axis, const config::BusPlan& bus);

struct NodePdoConfig {
  std::vector<RpdoConfig> rpdos;
  std::vector<TpdoConfig> tpdos;
};
// The node's PDOs from its device profile; synchronous RPDOs get the bus' rpdo_refresh.
NodePdoConfig build_pdo_config(const config::AxisPlan& axis, core::Duration rpdo_refresh);

}  // namespace drivegate::canopen
