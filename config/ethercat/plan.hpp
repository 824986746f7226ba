#pragma once
// The plan parts of the `ethercat` bus type held in Sections: the typed bus options
// (BusPlan::section<EthercatBusOptions>(), with the bus' I/O slaves), an axis' `ethercat:` section
// (EthercatAxisSpec) and a device profile's `ethercat:` section (EthercatDeviceSpec;
// profiles/devices/README.md "EtherCAT"); config/README.md "EtherCAT buses".
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "config/canopen/plan.hpp"  // PdoEntrySpec, StartupWrite: CoE shares CANopen's objects
#include "config/ethercat/esi.hpp"
#include "core/clock.hpp"
#include "profiles/cia402/objects.hpp"

namespace drivegate::config {

// One identity the slave may show in its SII and 1018h (ETG.1000.6; the ESR and Dunkermotoren
// brandings of one drive differ: dunker-ethercat-coe.md §10, quirk 17).
struct EthercatIdentity {
  std::uint32_t vendor_id = 0;
  std::uint32_t product_code = 0;
  std::optional<std::uint32_t> revision;  // absent: any revision
  std::string name;                       // shown in the scan and mismatch reports
};

// A PDO of the assignment (1C12h for SM2 outputs, 1C13h for SM3 inputs), its mapping object and
// entries, written over CoE in PRE-OP: count 0, entries, count [ETG.1000.6 PDO assignment].
struct EthercatPdoSpec {
  std::uint16_t index = 0;  // 1600h..17FFh (RxPDO) or 1A00h..1BFFh (TxPDO)
  std::vector<PdoEntrySpec> entries;
  [[nodiscard]] int bits() const noexcept {
    int b = 0;
    for (const auto& e : entries) b += e.bits;
    return b;
  }
};

struct EthercatDeviceSpec {
  // The identities it may show; empty: any slave whose 1000h names CiA 402 (generic profiles).
  std::vector<EthercatIdentity> identities;
  std::vector<EthercatPdoSpec> rxpdos;       // master -> slave, in 1C12h order
  std::vector<EthercatPdoSpec> txpdos;       // slave -> master, in 1C13h order
  // What the device takes: the mapping objects it has, the entries per PDO, and the objects it lets
  // map per direction (empty: any). ESR/Dunker: 1600h/1601h, 1A00h/1A01h, 8 entries, a whitelist
  // (dunker-ethercat-coe.md §7.1-§7.3, quirks 3 and 5).
  std::vector<std::uint16_t> rx_pdo_indexes;
  std::vector<std::uint16_t> tx_pdo_indexes;
  int max_entries = 254;  // a mapping object's sub-index 0 is UNSIGNED8; 255 is reserved
  std::vector<cia402::ObjectId> rx_mappable;
  std::vector<cia402::ObjectId> tx_mappable;
  bool distributed_clocks = false;  // csp/csv/cst run on SYNC0; false: free run (ESR/Dunker quirk 9)
  bool coe_store = true;            // 1010h works; false: everything is written again at every start
  std::vector<StartupWrite> startup_writes;  // CoE writes in PRE-OP, each read back
  std::vector<cia402::ObjectId> ignored_writes;  // accepted and silently ignored (quirk 8): read back
  int axes = 1;                      // axes on one slave, objects offset by axis_offset per axis
  std::uint16_t axis_offset = 0x800;  // ETG.6010 multi-axis: 6000h + 800h per axis
  std::string persona = "generic-cia402";  // simulator persona
};

enum class EthercatTransportKind : std::uint8_t {
  Raw,        // an Ethernet interface through an AF_PACKET socket (needs CAP_NET_RAW)
  Simulated,  // an in-process line of simulated slaves made from the axes' device profiles
};

// A slave that is not a drive: its process data bytes are published on the I/O topic under `name`
// (`io:` of the bus entry). Identity and sizes, when given, are checked against the slave's SII.
struct EthercatIoSlave {
  std::string name;
  int position = 0;  // 1 = the slave next to the gateway
  std::optional<std::uint32_t> vendor_id;
  std::optional<std::uint32_t> product_code;
  std::optional<int> input_bytes;   // slave -> master
  std::optional<int> output_bytes;  // master -> slave
  std::string esi;         // an ESI file for the slave (absolute path), empty: none
  std::string esi_device;  // the ESI device it was checked against (esi_device_text), empty: none
};

struct EthercatBusOptions {
  EthercatTransportKind transport = EthercatTransportKind::Raw;
  std::string interface;  // Raw: the Ethernet interface
  core::Duration sm_watchdog = std::chrono::milliseconds(100);  // 0: off
  bool distributed_clocks = true;  // SYNC0 for the drives whose profile asks for it
  core::Duration sync0_shift{0};   // SYNC0 after the cycle's frame start
  int lost_cycles = 3;             // cycles without a slave's answer before its axes are lost
  core::Duration transition_timeout = std::chrono::seconds(10);  // PRE-OP -> SAFE-OP -> OP
  core::Duration sdo_timeout = std::chrono::seconds(1);
  core::Duration boot_retry = std::chrono::seconds(1);
  core::Duration boot_retry_max = std::chrono::seconds(10);
  std::vector<EthercatIoSlave> io;
};

// The per-axis `ethercat:` section.
struct EthercatAxisSpec {
  int slave_axis = 0;  // which axis of a multi-axis slave (objects + slave_axis x axis_offset)
  std::string esi;     // an ESI file for the slave (absolute path), empty: none
  std::string esi_device;  // the ESI device the axis' device was checked against (esi_device_text)
  // The ESI device's dictionary (empty without an ESI or when it has none): parameter names and
  // types (find_esi_object), like CanopenAxisOptions::eds_objects.
  std::vector<EsiObject> esi_objects;
};

}  // namespace drivegate::config
