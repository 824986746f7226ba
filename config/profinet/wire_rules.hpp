#pragma once
// What the PROFINET configuration needs of the wire rules of adapters/profinet/wire, handed in by
// the adapter's registration (config/ includes no adapter, config/README.md "Bus types"): the
// NameOfStation rules and the C_SDU layout of one AR's cyclic frames.
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "config/profinet/plan.hpp"

namespace drivegate::config {

// A submodule of an AR as the cyclic frames see it: its data and where it sits.
struct ProfinetArSubmodule {
  int slot = 0;
  int subslot = 1;
  int input_bytes = 0;   // device -> controller
  int output_bytes = 0;  // controller -> device
};

// The C_SDU lengths of the input and output IOCR of one AR, with the octets the data objects and
// their status bytes take; `error` says why the submodules do not fit (then the rest is 0).
struct ProfinetCrLengths {
  int input = 0;
  int input_used = 0;
  int output = 0;
  int output_used = 0;
  std::string error;
};

struct ProfinetWireRules {
  // The first NameOfStation rule `name` breaks, in words; empty when it is valid.
  std::function<std::string(std::string_view name)> station_name_error;
  std::function<ProfinetCrLengths(std::span<const ProfinetArSubmodule> submodules)> cr_lengths;
};

// The submodules of the AR to an IO device: the DAP (slot 0, subslot 1, no IO data) and its slots.
std::vector<ProfinetArSubmodule> ar_submodules(const ProfinetIoDevice& io);
// The AR to a PROFIdrive drive: the DAP and the telegram module with its setpoint (output) and
// actual (input) image.
std::vector<ProfinetArSubmodule> ar_submodules(const ProfinetAxisSpec& axis, int setpoint_bytes, int actual_bytes);

}  // namespace drivegate::config
