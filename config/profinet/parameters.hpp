#pragma once
// Parameters of a PROFIdrive axis by PNU, for the DDS parameter topic and `drivegatectl param`:
// "p930", "p930[1]" or "p930.1" (PNU 930, subindex 1); "r947[0]" likewise ("r" is the usual mark of
// a read-only parameter, the address is the same). The ParameterRef's index is the PNU, its sub the
// subindex, as ProfidriveMaster takes them (record 47, profiles/profidrive).
#include <string_view>

#include "config/bus_types.hpp"
#include "config/plan.hpp"

namespace drivegate::config {

ParameterRef find_profidrive_parameter(const AxisPlan& axis, std::string_view name, cia402::ObjectId id);

}  // namespace drivegate::config
