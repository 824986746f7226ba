#pragma once
// An ESI file given for a slave (`esi:` of an axis' `ethercat:` section or of an `io:` slave):
// which device of the file the slave is, and the checks of the device profile against it
// (config/README.md "EtherCAT buses", "ESI files").
#include <filesystem>
#include <optional>
#include <string>

#include "config/ethercat/esi.hpp"
#include "config/ethercat/plan.hpp"
#include "config/plan.hpp"
#include "config/yaml_reader.hpp"

namespace drivegate::config {

// The file `m.esi` names (relative paths start at `base_dir`), parsed; its own problems carry its
// file name and line, and the key gets one error saying so. nullopt when absent or broken;
// `absolute` is set whenever the key names an existing file.
std::optional<EsiFile> read_esi_key(const MapReader& m, const std::filesystem::path& base_dir, std::string& absolute);

// The device of `esi` an axis of `device` is: one whose identity (vendor, product code, and the
// revision when the profile gives one) is one of the profile's; of several revisions the highest.
// A profile without identities (any CiA 402 slave) takes the file's only product, which must have
// profile 402 when it says. nullptr after an error at `m.esi`.
const EsiDevice* pick_esi_device(const MapReader& m, const EsiFile& esi, const std::string& esi_name,
                                 const DeviceProfile& device);

// The device profile's PDO maps, fixed PDOs and start-up writes against the ESI device; objects
// of axis `slave_axis` are offset by the profile's axis_offset (ETG.6010 multi-axis). Errors at
// `m.esi`.
void check_device_against_esi(const MapReader& m, const DeviceProfile& device, int slave_axis,
                              const std::string& esi_name, const EsiDevice& dev);

// An `io:` slave's ESI: picks the device by the slave's product code (or the file's only product),
// checks the vendor, and the slave's inputs/outputs against the PDOs the ESI assigns by default;
// fills vendor_id and product_code when not given.
void check_io_slave_against_esi(const MapReader& m, const EsiFile& esi, const std::string& esi_name,
                                EthercatIoSlave& slave);

}  // namespace drivegate::config
