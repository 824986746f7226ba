#pragma once
// Personas of the simulated CANopen drives: where each reference drive's slave differs from plain
// CiA 301/402, as data. A device profile names its persona (`canopen.persona`); SlaveNode reads
// the fields below and never tests a name. The values and their sources are in persona.cpp:
//   akd          Kollmorgen AKD (akd-canopen-part1-communication.md, akd-canopen-part2-ds402.md)
//   nord-sk500p  NORD SK 500P (nord-sk500p-ds402.md)
//   stoeber-sd6  STÖBER SD6 with CA6 (stoeber-sd6-canopen.md)
//   generic      a drive that follows CiA 301/402 to the letter
//   generic-no-heartbeat  the same without 1016h: it can watch the gateway by node guarding only
//   generic-no-watch      the same without 1016h, 100Ch and 100Dh: it cannot watch the gateway
//   generic-fixed-heartbeat  1016h with a fixed entry (writes of 1016h:01 refused with 06010002h)
//                         and no 100Ch/100Dh: it cannot watch the gateway either
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

#include "adapters/canopen/sim/nmt_slave.hpp"
#include "adapters/canopen/sim/slave_pdo.hpp"
#include "profiles/cia402/objects.hpp"
#include "profiles/cia402/sim/object_dictionary.hpp"

namespace drivegate::canopen::sim {

// Where a manufacturer object's value comes from.
enum class VendorValue : std::uint8_t {
  Stored,              // a parameter: written, read back, back to its power-on value on reset
  NodeId,              // the node-ID (SD6 A83)
  DeviceState,         // the CiA 402 state as 0 not ready .. 7 quick stop active (SD6 E48, 1002h)
  NmtState,            // 4 pre-operational, 5 stopped, 6 operational (SD6 A246, quirk 18)
  EventNumber,         // the fault's event (EmcyRule::event), or Persona::no_fault_event (SD6 E82)
  EventCause,          // the fault's cause, 0 without a fault (SD6 E43)
  ManufacturerStatus,  // AKD 1002h bits (part 2 §2.5)
};

// A manufacturer-specific or vendor-added object the drive model does not have.
struct VendorObject {
  cia402::ObjectDef def;
  cia402::sim::Access access = cia402::sim::Access::ReadWrite;
  std::int64_t value = 0;  // power-on value of a Stored object
  VendorValue source = VendorValue::Stored;
  bool mappable = false;  // into an RPDO when writable, into a TPDO when readable
  std::optional<std::int64_t> min;
  std::optional<std::int64_t> max;
};

// The error register and the event byte of a fault's EMCY (SD6 Tab. 17, stoeber-sd6-canopen.md §6.9).
struct EmcyRule {
  std::uint16_t code = 0;
  std::uint8_t error_register = 0;
  std::uint8_t event = 0;  // vendor byte 3 (E82)
};

// A PDO's power-on parameters; its COB-ID is the predefined one of the node (CiA 301 §7.3.3).
struct PdoDefault {
  bool valid = true;
  std::uint8_t transmission_type = 255;
  std::array<std::uint32_t, 8> mapping{};  // wire/pdo_mapping.hpp entries; zeros after the last
};

struct ObjectValue {
  cia402::ObjectId id;
  std::int64_t value = 0;
};

struct Persona {
  std::string_view name = "generic";

  // Identity (1000h, 1018h:01..03): nullopt takes the device profile's value (or the model's).
  std::optional<std::uint32_t> device_type;
  std::optional<std::uint32_t> vendor_id;
  std::optional<std::uint32_t> product_code;
  std::optional<std::uint32_t> revision;
  std::optional<std::int8_t> initial_mode;  // 6060h at power-on, when the drive supports it
  // Identity strings, const VISIBLE_STRINGs (CiA 301 §7.5.2.6-8): 1008h device name, 1009h
  // hardware version, 100Ah software version. Empty: the drive does not have the object.
  std::string_view device_name = "drivegate simulated CiA 402 drive";
  std::string_view hardware_version = "sim-1";
  std::string_view software_version = "drivegate-sim 1.0";

  // Communication objects.
  int sdo_channels = 1;               // SDO servers; channels 2..4 use the SD6 COB-ID scheme (wire/cob_id.hpp)
  bool upload_without_size = false;   // expedited uploads answered with 42h
  bool heartbeat_consumer = true;     // 1016h with one entry
  std::uint32_t heartbeat_consumer_abort = 0;  // non-zero: every write of 1016h:01 is refused with it
  bool node_guarding = true;          // 100Ch guard time and 100Dh life time factor
  bool emcy_inhibit = true;           // 1015h
  bool emcy_cob_writable = true;      // 1014h (only its valid bit: the EMCY always goes to 80h + node-ID)
  bool sdo_parameters = true;         // 1200h (and 1201h.. for the extra channels)
  bool store_parameters = true;       // 1010h:01 takes the "save" signature
  NmtSlaveOptions nmt;

  // PDOs.
  SlavePdoOptions pdo;
  // true: the device profile's maps are the power-on mapping (a drive commissioned with them);
  // false: the tables below (the drive's factory defaults).
  bool pdo_defaults_from_profile = true;
  std::span<const PdoDefault> rpdo_defaults;
  std::span<const PdoDefault> tpdo_defaults;

  // Application objects.
  std::span<const VendorObject> vendor_objects;
  std::span<const cia402::ObjectId> hidden;        // drive-model objects this drive does not have (06020000h)
  std::span<const cia402::ObjectId> not_mappable;  // drive-model objects it does not map
  std::span<const ObjectValue> application_defaults;  // power-on values that differ from the model's
  std::uint32_t supported_modes_cleared = 0;  // 6502h bits the drive does not report
  bool mode_zero_refused = false;             // 6060h = 0 is refused (SDO abort; RPDO value dropped)

  // EMCY manufacturer bytes.
  std::uint8_t fault_byte3 = 0;        // byte 3 of a fault EMCY that has no rule
  bool emcy_state_follow_up = false;   // after each fault EMCY, 0000h with the error register
  std::span<const EmcyRule> emcy_rules;  // per code: register and byte 3
  bool emcy_cause_byte4 = false;         // byte 4 carries the fault's cause
  std::uint8_t no_fault_event = 0;     // byte 3 of the 0000h EMCY when the fault is left
  // The fault a life-guarding or consumer-heartbeat timeout raises, with its cause byte.
  std::uint16_t comm_loss_code = 0x8130;
  std::uint8_t comm_loss_cause = 0;
};

// The persona with that name; nullptr for an unknown name.
const Persona* find_persona(std::string_view name) noexcept;
// The same, throwing std::invalid_argument that lists the known names.
const Persona& persona_for(std::string_view name);

}  // namespace drivegate::canopen::sim
