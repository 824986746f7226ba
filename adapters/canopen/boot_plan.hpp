#pragma once
// What the master does to bring one node up, compiled from the plan: the boot steps (identity,
// start-up writes, PDO configuration or verification, SYNC and error-control objects) and the PDO
// layouts the process data engine exchanges. Vendor differences come in as data from the device
// profile's `canopen:` section (adapters/canopen/README.md).
#include <vector>

#include "adapters/canopen/master/node_boot.hpp"
#include "adapters/canopen/master/pdo.hpp"
#include "config/plan.hpp"

namespace drivegate::canopen {

std::vector<BootStep> build_boot_steps(const config::AxisPlan& axis, const config::BusPlan& bus);

struct NodePdoConfig {
  std::vector<RpdoConfig> rpdos;
  std::vector<TpdoConfig> tpdos;
};
NodePdoConfig build_pdo_config(const config::AxisPlan& axis);

}  // namespace drivegate::canopen
