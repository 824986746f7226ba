#pragma once
// Personas of the simulated EtherCAT CiA 402 drives (Cia402Slave, cia402_slave.hpp): where each
// reference drive differs from plain CoE/CiA 402, as data. A device profile names its persona
// (`ethercat.persona`); Cia402Slave reads the fields below and never tests a name. The values
// and their sources are in ethercat_persona.cpp:
//   esr-triodrive   ESR TrioDrive/MidiDrive D/ES, Dunkermotoren DME (dunker-ethercat-coe.md)
//   generic-cia402  a drive that follows CiA 402 / ETG.6010 to the letter, with DC SYNC0
//   generic-cia402-2axis  the same as a two-axis slave (ETG.6010 multi-axis: axis 1 at +800h)
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "profiles/cia402/objects.hpp"
#include "profiles/cia402/sim/object_dictionary.hpp"

namespace drivegate::ethercat::sim {

// A mapping object's power-on content: entries `index << 16 | subindex << 8 | bits` [ETG.1000.6
// PDO mapping object; dunker-ethercat-coe.md §7.2].
struct EcatPdoDefault {
  std::uint16_t index = 0;                    // 1600h..17FFh or 1A00h..1BFFh
  std::span<const std::uint32_t> entries{};   // the count (:00) is entries.size()
};

// An object the drive model holds with another type on this drive (ESR 6060h/6061h as INTEGER16).
struct EcatTypeOverride {
  cia402::ObjectId id;
  cia402::DataType type = cia402::DataType::U32;
};

// A narrower range than the object's type for master writes (06090031h above, 06090032h below).
struct EcatObjectRange {
  cia402::ObjectId id;
  std::int64_t min = 0;
  std::int64_t max = 0;
};

struct EcatObjectValue {
  cia402::ObjectId id;
  std::int64_t value = 0;
};

// Where a manufacturer object's value comes from.
enum class EcatVendorSource : std::uint8_t {
  Stored,        // a parameter (or a constant when read-only): written, read back
  TorqueActual,  // the model's torque, per mille (ESR 6078h current actual value: illustrative)
};

// An object the drive model does not have.
struct EcatVendorObject {
  cia402::ObjectDef def;
  cia402::sim::Access access = cia402::sim::Access::ReadWrite;
  std::int64_t value = 0;  // power-on value of a Stored object
  EcatVendorSource source = EcatVendorSource::Stored;
  std::string_view name{};  // its name in SDO Information (empty: the CiA name, where it has one)
};

struct EthercatPersona {
  std::string_view name;

  // Identity: SII words 8..0Fh and 1018h:01..03 (ETG.1000.6 §5.4), 1000h, 1008h..100Ah.
  std::uint32_t vendor_id = 0;
  std::uint32_t product_code = 0;
  std::uint32_t revision = 0;
  std::uint32_t device_type = 0x00020192;
  std::string_view device_name;
  std::string_view hardware_version;
  std::string_view software_version;
  std::string_view sii_group;  // SII general category strings
  std::string_view sii_order;

  // The ESC: distributed clocks unit present (EscConfig::dc_supported, SII DC category).
  bool dc_supported = false;

  // Drive modes (6060h values the drive takes, 6502h) and 6060h at power-on.
  std::span<const std::int8_t> modes;
  std::int8_t initial_mode = 0;

  // PDOs [ETG.1000.6 PDO mapping/assignment; dunker §7]. The mapping objects that exist per
  // direction, with their power-on content (an index listed without a default is empty).
  std::span<const EcatPdoDefault> rx_pdos;
  std::span<const EcatPdoDefault> tx_pdos;
  std::uint8_t max_entries = 8;   // entries per mapping object (sub-index 0 at most this)
  std::uint8_t assign_slots = 4;  // 1C12h/1C13h sub-indexes 1..n
  // 1C12h/1C13h power-on content: sub-index 1..n values and the count.
  std::span<const std::uint16_t> rx_assign;
  std::uint8_t rx_assign_count = 1;
  std::span<const std::uint16_t> tx_assign;
  std::uint8_t tx_assign_count = 1;
  // The objects a PDO may carry per direction (exact index and sub-index); empty: any object of
  // the device profile or manufacturer area (2000h..) with the access the direction needs.
  std::span<const cia402::ObjectId> rx_mappable;
  std::span<const cia402::ObjectId> tx_mappable;
  // RxPDO mapping writable in SAFE-OP too (ESR quirk 4: locked only in OP); TxPDO mapping and the
  // assignment are writable in PRE-OP only.
  bool rx_mapping_writable_in_safeop = false;
  std::uint16_t process_data_capacity = 128;  // bytes per direction (SM2 and SM3 at most)

  // Objects.
  std::span<const EcatTypeOverride> type_overrides;
  std::span<const EcatVendorObject> vendor_objects;
  std::span<const cia402::ObjectId> hidden;          // model objects this drive does not have
  std::span<const cia402::ObjectId> ignored_writes;  // accepted and not applied (ESR quirk 8)
  std::span<const EcatObjectRange> ranges;
  std::span<const EcatObjectValue> application_defaults;  // power-on values that differ from the model's
  bool store_parameters = true;         // 1010h:01 takes "save" (ESR quirk 10: absent)
  bool sync_manager_parameters = false; // 1C32h/1C33h (ESR quirk 9: absent)

  // Behaviour.
  std::int16_t abort_option_default = 0;  // 6007h at power-on
  std::int16_t abort_option_max = 3;      // 6007h values 0..max (CiA 402: 0..3; ESR: 0..1)
  // true: a requested exit from OP while the drive is Operation enabled runs the 6007h reaction
  // too; false: only the SM watchdog does (ESR §8.2).
  bool abort_on_requested_leave_op = false;
  std::uint16_t comm_loss_code = 0x8100;  // the fault 6007h = 1 raises (CiA 301 "communication")
  bool controlword_bit6_absolute = false;  // pp: bit 6 = 1 absolute (ESR quirk 14), CiA: relative
  bool ip_status_bit12 = true;             // 6041h bit 12 "ip mode active" (ESR quirk 7: absent)
  bool fine_interpolation = false;  // ip set-points ramped over 60C2h in 1 ms steps (ESR §12)
  bool transition_error_emcy = false;  // EMCY A000h when the ESC refuses a state (ESR App. C)
  bool emcy_on_fault_clear = true;     // EMCY 0000h when the faults clear (ESR: only faults, §8.1)

  // Axes on the slave, each its own drive model [ETG.6010 §4 modular device profile: axis n's
  // profile objects 6000h..67FFh at + n x axis_offset, 6007h included]. The mapping defaults
  // name the objects as the slave numbers them (axis 1's controlword at 6040h + axis_offset); the
  // whitelists, ranges, type overrides, hidden, ignored objects and application defaults name
  // axis 0's objects and apply to every axis.
  std::uint8_t axes = 1;
  std::uint16_t axis_offset = 0x800;
};

// The persona with that name; nullptr for an unknown name.
const EthercatPersona* find_ethercat_persona(std::string_view name) noexcept;
// The same, throwing std::invalid_argument that lists the known names.
const EthercatPersona& ethercat_persona_for(std::string_view name);
// The known names, comma separated (for messages).
std::string ethercat_persona_names();

}  // namespace drivegate::ethercat::sim
