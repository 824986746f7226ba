#include "config/profinet/wire_rules.hpp"

namespace drivegate::config {

namespace {
// The device access point's own submodule: no IO data, but an IOPS in the input frame and an IOCS
// in the output frame like every submodule [IEC 61158-6-10, IODataObject of a submodule without IO].
constexpr ProfinetArSubmodule kDap{0, 1, 0, 0};
}  // namespace

std::vector<ProfinetArSubmodule> ar_submodules(const ProfinetIoDevice& io) {
  std::vector<ProfinetArSubmodule> out{kDap};
  for (const auto& s : io.submodules) out.push_back({s.slot, s.subslot, s.input_bytes, s.output_bytes});
  return out;
}

std::vector<ProfinetArSubmodule> ar_submodules(const ProfinetAxisSpec& axis, int setpoint_bytes, int actual_bytes) {
  return {kDap, {axis.slot, axis.subslot, actual_bytes, setpoint_bytes}};
}

}  // namespace drivegate::config
