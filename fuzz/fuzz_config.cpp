// config::load_plan_from_string (config/loader.hpp) on arbitrary YAML: the daemon's start-up and
// `--check-config` read files people write by hand. The contract is a Plan or a ConfigError that
// lists the problems; any other exception escaping the loader is a finding, as are crashes and
// sanitizer reports. Device profiles are read from the source tree (the label sits in config/,
// like demo.yaml, so relative device_dirs resolve the same way).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "config/config_error.hpp"
#include "config/loader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace drivegate::config;
  const std::string_view yaml(reinterpret_cast<const char*>(data), size);
  static const LoadOptions options;
  try {
    (void)load_plan_from_string(yaml, DRIVEGATE_FUZZ_CONFIG_LABEL, options);
  } catch (const ConfigError&) {
    // The loader's answer to bad input.
  }
  // Anything else propagates: libFuzzer and the replay driver report an uncaught exception as a
  // crash with its type.
  return 0;
}
