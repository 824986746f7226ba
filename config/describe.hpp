#pragma once
// The human-readable printout of a plan, for `drivegated --check-config FILE`.
#include <string>

#include "config/plan.hpp"

namespace drivegate::config {

std::string describe_plan(const Plan& plan);

}  // namespace drivegate::config
