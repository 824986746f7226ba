#include "adapters/profinet/bus_type.hpp"

#include <array>
#include <memory>

#include "adapters/profinet/profinet_bus.hpp"
#include "adapters/profinet/scan.hpp"
#include "adapters/profinet/wire/rt.hpp"
#include "adapters/profinet/wire/station_name.hpp"
#include "config/profinet/bus_type.hpp"
#include "core/bus.hpp"

namespace drivegate::profinet {

namespace {

std::string station_name_error(std::string_view name) {
  const NameError e = validate_name_of_station(name);
  return e == NameError::None ? std::string{} : std::string{to_string(e)};
}

// Both IOCRs of one AR through the layout the RT frames will use (wire/rt.hpp).
config::ProfinetCrLengths cr_lengths(std::span<const config::ProfinetArSubmodule> subs) {
  config::ProfinetCrLengths out;
  // An AR plugs at most this many submodules here: the DAP and the slots of one IO device entry.
  constexpr std::size_t kMaxSubmodules = 256;
  if (subs.size() > kMaxSubmodules) {
    out.error = std::to_string(subs.size()) + " submodules, at most " + std::to_string(kMaxSubmodules) + " per device";
    return out;
  }
  std::array<IoSubmodule, kMaxSubmodules> list{};
  for (std::size_t i = 0; i < subs.size(); ++i) {
    IoSubmodule& s = list[i];
    s.input_length = static_cast<std::uint16_t>(subs[i].input_bytes);
    s.output_length = static_cast<std::uint16_t>(subs[i].output_bytes);
    s.kind = subs[i].input_bytes > 0 && subs[i].output_bytes > 0 ? IoKind::InputOutput
             : subs[i].input_bytes > 0                           ? IoKind::Input
             : subs[i].output_bytes > 0                          ? IoKind::Output
                                                                 : IoKind::NoIo;
  }
  std::array<IoPlacement, kMaxSubmodules> placements{};
  const auto used = std::span<const IoSubmodule>(list).first(subs.size());
  const CsduLayout in = compute_csdu_layout(CrDirection::Input, used, placements);
  const CsduLayout output = compute_csdu_layout(CrDirection::Output, used, placements);
  for (const auto* l : {&in, &output})
    if (!l->ok()) {
      out.error = std::string{l == &in ? "input" : "output"} + " frame: " + std::string{to_string(l->error)};
      return out;
    }
  out.input = in.length;
  out.input_used = in.used;
  out.output = output.length;
  out.output_used = output.used;
  return out;
}

std::unique_ptr<core::Bus> make_bus(const config::BusPlan& plan) { return make_profinet_bus(plan); }

}  // namespace

config::BusTypeInfo bus_type() {
  config::BusTypeInfo t = config::profinet_bus_type({station_name_error, cr_lengths});
  t.make_bus = make_bus;
  t.scan = {.plan = profinet_scan_plan, .run = run_profinet_scan, .writes = true};
  return t;
}

}  // namespace drivegate::profinet
