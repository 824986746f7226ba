#pragma once
// GSDML files (the XML file a PROFINET IO device's vendor ships, GSDML V2.x schema), read through
// tinyxml2 as far as the configuration needs them: the device identity, the device access points
// and the modules with their submodules, ident numbers and cyclic data lengths. Problems are
// reported with the file's name and line and an element path
// ("io.xml:40:1: ModuleItem[2]/VirtualSubmoduleList/VirtualSubmoduleItem[1]: has no SubmoduleIdentNumber").
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "config/config_error.hpp"

namespace drivegate::config {

// A GSDML file above this size is refused (large modular devices ship files of a few MiB).
inline constexpr std::uint64_t kMaxGsdmlBytes = 16ULL * 1024 * 1024;

struct GsdmlSubmodule {
  std::string id;
  std::uint32_t ident = 0;  // SubmoduleIdentNumber
  int input_bytes = 0;      // IOData/Input: the sum of its DataItems
  int output_bytes = 0;     // IOData/Output
  std::optional<int> fixed_subslot;  // FixedInSubslots, when it names one subslot
  int line = 0;
};

// A DeviceAccessPointItem (slot 0) or a ModuleItem.
struct GsdmlModule {
  std::string id;
  std::uint32_t ident = 0;  // ModuleIdentNumber
  std::vector<GsdmlSubmodule> submodules;  // VirtualSubmoduleList
  int line = 0;
};

struct GsdmlFile {
  std::uint16_t vendor_id = 0;  // DeviceIdentity VendorID
  std::uint16_t device_id = 0;  // DeviceIdentity DeviceID
  std::vector<GsdmlModule> daps;
  std::vector<GsdmlModule> modules;
};

// nullopt when the file has errors (all reported to `problems` under its name).
std::optional<GsdmlFile> load_gsdml(const std::filesystem::path& file, Problems& problems);
std::optional<GsdmlFile> load_gsdml_text(std::string_view text, const std::string& label, Problems& problems);

// The module or DAP with this ID, or nullptr.
const GsdmlModule* find_gsdml_module(const std::vector<GsdmlModule>& modules, std::string_view id) noexcept;

}  // namespace drivegate::config
