#pragma once
// The `canopen:` section of a device profile (schema in profiles/devices/README.md) and the
// start-up write lists that both profiles and axes carry.
#include <optional>
#include <string_view>
#include <vector>

#include "config/canopen/plan.hpp"
#include "config/plan.hpp"
#include "config/yaml_reader.hpp"

namespace drivegate::config {

// Reads the `canopen:` map of the profile `root` (if any) into p.sections. Needs p.quirks already
// read.
void read_canopen_device(const MapReader& root, DeviceProfile& p);
// The objects of its PDO maps, RPDOs first (BusTypeInfo::mapped_objects).
std::vector<cia402::ObjectId> canopen_mapped_objects(const DeviceProfile& p);

// A `startup_writes:` list under `parent` (absent: nothing). Objects are "0x6046:1" or, with
// `naming`, manufacturer parameter names ("A83").
// A `gateway_watch:` choice under `parent` (heartbeat | guarding | required | optional); nullopt
// when absent or wrong (the error names the allowed values).
std::optional<GatewayWatch> read_gateway_watch(const MapReader& parent);

// One PDO map entry "INDEX[:SUB] TYPE" (TYPE i8 u8 i16 u16 i32 u32); the type is not checked
// against CiA 402 here (the bus type's reader does that, with its device's quirks).
std::optional<PdoEntrySpec> read_pdo_entry(const YAML::Node& n, const std::string& path, const Source& src);

void read_startup_writes(const MapReader& parent, std::string_view key, const std::optional<ParameterNaming>& naming,
                         std::vector<StartupWrite>& out);

}  // namespace drivegate::config
