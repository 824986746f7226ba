#pragma once
// The plan parts of the `profinet` bus type held in Sections: the typed bus options
// (BusPlan::section<ProfinetBusOptions>(), with the stations on the network and the generic IO
// devices), an axis' `profinet:` section (ProfinetAxisSpec) and a device profile's `profidrive:`
// section (ProfidriveDeviceSpec; profiles/devices/README.md "PROFIdrive"); config/README.md
// "PROFINET buses". Reference device: Kollmorgen AKD PROFINET (akd-profinet-profidrive.md).
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/clock.hpp"

namespace drivegate::config {

// 31.25 us: the base of the send clock (SendClockFactor x 31.25 us) [IEC 61158-6-10, IOCRBlockReq].
inline constexpr core::Duration kProfinetClockBase = std::chrono::nanoseconds(31250);
// DataHoldFactor x update time may not exceed 1.92 s [IEC 61158-6-10, IOCRBlockReq DataHoldFactor].
inline constexpr core::Duration kProfinetMaxDataHold = std::chrono::milliseconds(1920);

// How the controller gives a station its IP suite over DCP Set (akd-profinet-profidrive.md §3.1
// step 3): temporary (lost at power off; the controller sets it again at every start) or permanent
// (the device stores it; on the AKD it overwrites IP.* [§3.2]).
enum class ProfinetIpAssignment : std::uint8_t { Temporary, Permanent };

// A station on the network: what DCP finds it by and the IP suite it is given.
struct ProfinetStation {
  std::string name;  // NameOfStation
  std::uint32_t ip = 0;  // host order, a.b.c.d = a << 24 | ...
  std::uint32_t netmask = 0;
  std::uint32_t gateway = 0;  // 0: none
  // Checked against the DCP identify answer (DeviceID block) when given.
  std::optional<std::uint16_t> vendor_id;
  std::optional<std::uint16_t> device_id;
};

// One submodule of a generic IO device: where it is plugged, its idents (the ExpectedSubmodule
// block of the connect request) and its cyclic data.
struct ProfinetIoSubmodule {
  int slot = 0;
  int subslot = 1;
  std::uint32_t module_ident = 0;
  std::uint32_t submodule_ident = 0;
  int input_bytes = 0;   // device -> controller
  int output_bytes = 0;  // controller -> device
  std::string gsdml_id;  // the GSDML module's ID it came from, empty: given in the file
};

// A record written to a submodule between the connect and PrmEnd (IODWriteReq).
struct ProfinetRecordWrite {
  int slot = 0;
  int subslot = 1;
  std::uint16_t index = 0;
  std::vector<std::uint8_t> data;
};

// A station that is not a drive: its input and output bytes are published on the I/O topic under
// `name` (`io:` of the bus entry).
struct ProfinetIoDevice {
  std::string name;
  std::string station;
  std::uint32_t dap_ident = 0;  // slot 0, the device access point (from the GSDML or dap_ident)
  // Its submodule in subslot 1 (the GSDML DAP's first VirtualSubmoduleItem, or dap_submodule_ident).
  std::uint32_t dap_submodule_ident = 1;
  std::vector<ProfinetIoSubmodule> submodules;  // slots >= 1, in slot/subslot order
  std::vector<ProfinetRecordWrite> records;
  std::string gsdml;  // a GSDML file (absolute path), empty: none
};

struct ProfinetBusOptions {
  bool simulated = false;  // transport sim: simulated devices inside drivegated
  std::string interface;
  int reduction_ratio = 16;    // update time = cycle_time (the send clock) x this
  int data_hold_factor = 3;    // update times without a frame until the data are invalid
  core::Duration dcp_timeout = std::chrono::seconds(3);  // identify by name: time to answer
  ProfinetIpAssignment ip_assignment = ProfinetIpAssignment::Temporary;
  std::string controller_station = "drivegate";  // the controller's own NameOfStation (CMInitiatorStationName)
  std::vector<ProfinetStation> stations;
  std::vector<ProfinetIoDevice> io;
  core::Duration send_clock{std::chrono::milliseconds(1)};  // the bus cycle_time
  [[nodiscard]] core::Duration update_time() const noexcept { return send_clock * reduction_ratio; }
  [[nodiscard]] core::Duration data_hold_time() const noexcept { return update_time() * data_hold_factor; }
  [[nodiscard]] const ProfinetStation* station(const std::string& station_name) const noexcept {
    for (const auto& s : stations)
      if (s.name == station_name) return &s;
    return nullptr;
  }
};

// The per-axis `profinet:` section: the PROFIdrive drive it is, and where its telegram sits.
struct ProfinetAxisSpec {
  std::string station;
  std::uint16_t telegram = 0;
  int slot = 1;     // the telegram module's slot [§4.1: slot 1]
  int subslot = 1;  // [§4.1, INF: subslot 1]
};

// The numbers the controller's Connect names the drive's modules by (ExpectedSubmoduleBlockReq):
// the device access point in slot 0, and the telegram module, whose idents are a base plus the
// telegram number. A device's GSDML holds them.
struct ProfidriveIdents {
  std::uint32_t api = 0x3A00;  // the PROFIdrive profile's API [akd-profinet-profidrive.md §2]
  std::uint32_t dap_module = 0;
  std::uint32_t dap_submodule = 0;
  std::uint32_t telegram_module_base = 0;
  std::uint32_t telegram_submodule_base = 0;
  [[nodiscard]] std::uint32_t telegram_module(std::uint16_t telegram) const noexcept { return telegram_module_base + telegram; }
  [[nodiscard]] std::uint32_t telegram_submodule(std::uint16_t telegram) const noexcept {
    return telegram_submodule_base + telegram;
  }
};

// A device profile's `profidrive:` section.
struct ProfidriveDeviceSpec {
  unsigned single_turn_bits = 16;            // PNU 1002 [§17.2]
  double acc_full_scale_rpm_per_s = 50e6;    // MDI_ACC 2^16 [§17.3]
  std::optional<double> peak_current_a;      // DRV.IPEAK [§17.4]; absent: read from the drive
  std::vector<std::uint16_t> telegrams;      // the telegram modules the device offers [§4.3]
  core::Duration min_update_time = std::chrono::milliseconds(1);  // fastest cyclic update [§2]
  std::map<std::string, bool> quirks;        // only names from known_profidrive_quirks()
  std::optional<ProfidriveIdents> idents;    // absent: a PROFINET bus cannot connect the drive
  // The DCP identity (DeviceID block: VendorID, DeviceID) the drive answers an Identify with: how
  // `drivegated --scan profinet:IFACE` knows the drive. Both or neither.
  std::optional<std::uint16_t> vendor_id;
  std::optional<std::uint16_t> device_id;
  [[nodiscard]] bool offers(std::uint16_t telegram) const noexcept {
    for (const auto t : telegrams)
      if (t == telegram) return true;
    return false;
  }
};

}  // namespace drivegate::config
