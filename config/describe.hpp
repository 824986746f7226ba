#pragma once
// The human-readable printout of a plan, for `drivegated --check-config FILE`.
#include <string>
#include <vector>

#include "config/plan.hpp"

namespace drivegate::config {

std::string describe_plan(const Plan& plan);

// What loading `next` instead of `running` would change, one line each in the words of the
// printout ("axis x: max velocity: 200 mm/s -> 250 mm/s", "bus can1: added"); empty when nothing
// would. Used when drivegated re-reads its configuration on SIGHUP.
std::vector<std::string> describe_changes(const Plan& running, const Plan& next);

}  // namespace drivegate::config
