#pragma once
// The plan parts of the `canopen` bus type, held in the plan's Sections: the typed bus options
// (BusPlan::section<CanopenBusOptions>()), an axis' `canopen:` section (CanopenAxisOptions) and a
// device profile's `canopen:` section (CanopenDeviceSpec); config/README.md "CANopen buses",
// profiles/devices/README.md.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "config/canopen/eds.hpp"
#include "config/plan.hpp"
#include "core/clock.hpp"
#include "profiles/cia402/objects.hpp"

namespace drivegate::config {

// The `canopen:` section of a device profile (profiles/devices/README.md): how a CANopen master
// brings the drive up. Everything vendor-specific about CANopen is here as data.
struct PdoEntrySpec {
  cia402::ObjectId object;
  std::uint8_t bits = 0;  // 8, 16 or 32
  cia402::DataType type = cia402::DataType::U8;  // from the entry's type name (i8 u8 i16 u16 i32 u32)
};

struct PdoSpec {
  int number = 1;  // 1..4: RPDO n (1400h+n-1 / 1600h+n-1) or TPDO n (1800h+n-1 / 1A00h+n-1)
  std::vector<PdoEntrySpec> entries;  // at most 8 entries and 64 bits
  int transmission_type = 1;          // 0..240 synchronous, 254/255 event-driven
  int inhibit_time_100us = 0;         // TPDO only; 0 = none
  int event_timer_ms = 0;             // TPDO only; 0 = none
  int dlc = 0;                        // RPDO frame length to send; 0 = the mapped length (NORD pads
                                      // RxPDO1 to 8 bytes: nord-sk500p-ds402.md §8.1)
  [[nodiscard]] int mapped_bytes() const noexcept {
    int bytes = 0;
    for (const auto& e : entries) bytes += e.bits / 8;
    return bytes;
  }
  [[nodiscard]] bool synchronous() const noexcept { return transmission_type <= 240; }
};

enum class PdoPolicy : std::uint8_t {
  Write,   // disable, clear count, write entries, set count, enable [CiA 301; AKD part 1 §12.6]
  Verify,  // read back and compare only; a mismatch fails the boot (SD6: fixed count, mapping
           // needs save + restart: stoeber-sd6-canopen.md quirk 4)
};

enum class ErrorControl : std::uint8_t {
  Heartbeat,  // drive produces 1017h; the master consumes and, if the drive has 1016h, the drive
              // consumes the master's heartbeat
  Guarding,   // master sends RTRs every guard time; the drive's life guarding notices a dead master
              // (SD6: no consumer heartbeat, quirk 7)
};

// How the gateway makes sure the drive notices a dead gateway (DESIGN.md §4), per device profile
// (`canopen.gateway_watch`) and per axis (`canopen: { gateway_watch: }`, which wins).
enum class GatewayWatch : std::uint8_t {
  Heartbeat,  // the drive must have 1016h: it consumes the gateway's heartbeat; the boot fails otherwise
  Guarding,   // node guarding (100Ch/100Dh): the master guards the node with RTRs, the drive's life
              // guarding notices a dead gateway
  Required,   // whichever the drive has (1016h first, else 100Ch/100Dh); the boot fails if it has neither
  Optional,   // as Required, but a drive with neither runs unwatched, with a warning event
};

struct StartupWrite {
  cia402::ObjectDef def;
  std::int64_t value = 0;
  std::string why;  // shown when the write fails
};

// A vendor byte of the EMCY frame (bytes 3..7) with a name, shown with the fault text
// ("event 52, cause 1"). SD6: byte 3 event (E82), byte 4 cause (E43).
struct EmcyVendorField {
  int byte = 3;
  std::string name;
};

// Manufacturer parameters addressable by a name: <letter><line>[<element>] -> index
// base + group * group_stride + line, sub-index element (SD6 digest §2.2: A83 -> 2053h:00).
struct ParameterNaming {
  std::uint16_t base = 0x2000;
  std::uint16_t group_stride = 0x200;
  int max_line = 511;
};

struct CanopenDeviceSpec {
  std::optional<std::uint32_t> device_type;  // 1000h expected value, compared under the mask
  std::uint32_t device_type_mask = 0x00FFFFFF;  // AKD: upper "mode bits" may change (quirk 13)
  std::vector<PdoSpec> rpdos;
  std::vector<PdoSpec> tpdos;
  PdoPolicy pdo_policy = PdoPolicy::Write;
  bool disable_unused_pdos = true;      // switch off PDOs the maps do not use (AKD part 1 §16 step 7)
  ErrorControl error_control = ErrorControl::Heartbeat;
  bool consumer_heartbeat = true;       // the drive has 1016h (watches the master's heartbeat)
  // Default: heartbeat with error_control heartbeat, guarding with error_control guarding.
  GatewayWatch gateway_watch = GatewayWatch::Heartbeat;
  std::vector<StartupWrite> startup_writes;
  std::vector<EmcyVendorField> emcy_fields;
  bool emcy_zero_needs_clear_register = true;  // EMCY 0000h means "no more errors" only with register 0
  std::optional<ParameterNaming> parameter_naming;
  int sdo_channels = 1;                 // SDO server channels (SD6: 4, channels 2..4 need node-ID <= 31)
  std::string persona = "generic";      // simulator persona for this drive (akd, nord-sk500p, stoeber-sd6, generic)
  int fixed_mapping_count = 0;          // PDO mapping sub 0 reads this constant and at most this many
                                        // entries fit (SD6: 6, stoeber-sd6-canopen.md quirks 4, 5); 0 = none
  std::vector<core::Duration> sync_periods;  // SYNC periods the drive supports; empty = any (SD6 A150: 1, 2,
                                             // 4, 8 ms, stoeber-sd6-canopen.md §7)
};

// The per-axis `canopen:` section (axes on a canopen bus; `address` is the node-ID).
struct CanopenAxisOptions {
  std::string eds;  // EDS file (made absolute); objects and mappings are checked against it
  int sdo_channel = 1;  // SDO server channel the gateway uses (1..device sdo_channels)
  std::vector<StartupWrite> startup_writes;  // after the device profile's
  std::optional<GatewayWatch> gateway_watch;  // overrides the device profile's
  std::vector<EdsObject> eds_objects;  // the EDS' objects (empty without an EDS); see find_eds_object()
};

// Options of the `canopen` bus type, typed (the bus `cycle_time` is the SYNC period).
enum class CanTransportKind : std::uint8_t { SocketCan, UdpMulticast, Simulated };

struct CanopenBusOptions {
  CanTransportKind transport = CanTransportKind::SocketCan;
  std::string interface = "can0";      // socketcan: interface; udp-multicast: local IPv4 address
  std::uint32_t bitrate = 500000;      // bit/s (for load estimates and the simulated wire)
  std::string group = "239.74.163.2";  // udp-multicast group [python-can udp_multicast default]
  int port = 43113;
  int gateway_node_id = 127;           // the master's own heartbeat COB-ID 700h + this
  core::Duration heartbeat_period = std::chrono::milliseconds(100);   // master's heartbeat
  core::Duration drive_heartbeat = std::chrono::milliseconds(100);    // 1017h written to drives
  int heartbeat_misses = 3;            // a drive is lost after this many periods of silence
  core::Duration guard_time = std::chrono::milliseconds(100);         // 100Ch for guarding drives
  int life_time_factor = 3;            // 100Dh
  core::Duration sdo_timeout = std::chrono::milliseconds(100);
  int sdo_retries = 2;
  core::Duration boot_retry = std::chrono::seconds(1);       // first back-off after a failed boot
  core::Duration boot_retry_max = std::chrono::seconds(10);  // back-off doubles up to this
  bool sync = true;                    // produce SYNC every cycle
  // Synchronous RPDOs go after a SYNC when changed, unchanged at least this often; 0 = after every
  // SYNC (adapters/canopen/master/pdo.hpp RpdoConfig::refresh).
  core::Duration rpdo_refresh = std::chrono::milliseconds(100);
};

// The axis' gateway watch: its own option, else its device profile's.
[[nodiscard]] inline GatewayWatch gateway_watch_of(const AxisPlan& a) noexcept {
  return a.section<CanopenAxisOptions>().gateway_watch.value_or(a.device.section<CanopenDeviceSpec>().gateway_watch);
}

}  // namespace drivegate::config
