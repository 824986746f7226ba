#pragma once
// EtherCAT Slave Information (ESI, ETG.2000): the XML file a vendor ships with an EtherCAT slave.
// drivegate reads what the configuration checks and the parameter names need: the vendor and each
// device's identity, name, profile number, mailbox protocols, SyncManagers, the RxPDOs/TxPDOs it
// lists (fixed or default), the DC operation modes and the CoE object dictionary with its data
// types. Everything else (groups, images, EEPROM contents, modules and slots) is read past.
//
// The file layout [ETG.2000 §5]:
//   EtherCATInfo/Vendor/Id                      vendor ID (HexDecValue: "#x0000000F" or "15")
//   EtherCATInfo/Descriptions/Devices/Device*   one per product code and revision
//     Type (ProductCode=, RevisionNo=)            identity; the text is the order name ("EL1008")
//     Name (LcId=)                                1033 (English) preferred, else the first
//     Profile/ProfileNo, Profile/Dictionary       device profile (402: drives) and the CoE dictionary
//     Mailbox/CoE (SdoInfo= PdoAssign= PdoConfig= CompleteAccess= SegmentedSdo=)
//     Sm* (MinSize= MaxSize= DefaultSize= StartAddress= ControlByte= Enable=) MBoxOut|MBoxIn|Outputs|Inputs
//     RxPdo*/TxPdo* (Fixed= Mandatory= Sm=) Index, Name, Entry*(Index, SubIndex, BitLen, Name, DataType)
//     Dc/OpMode* Name, Desc, AssignActivate, CycleTimeSync0 (Factor=), ShiftTimeSync0
//
// Problems are "FILE:LINE:1: PATH: message" with PATH an XPath-like element path with 1-based
// positions ("Device[2]/RxPdo[1]/Entry[3]/BitLen"). What the checks rely on (identities, PDO
// entries, object indices and sizes) must be right: a bad number or a missing element there is an
// error and the file is refused. A data type that is neither an ETG base type nor defined in the
// file's DataTypes is a warning (the object keeps its BitSize), like the other oddities of files
// made by other tools.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "config/config_error.hpp"
#include "profiles/cia402/objects.hpp"

namespace drivegate::config {

// Flags/Access of an object or sub-item [ETG.2000 AccessType].
enum class EsiAccess : std::uint8_t { ReadOnly, ReadWrite, WriteOnly };
std::string_view to_string(EsiAccess access) noexcept;  // "ro", "rw", "wo"

// One accessible entry of the dictionary: a VAR object (sub-index 0) or one sub-index of an ARRAY
// or RECORD, with its type resolved through the file's DataTypes to a base type.
struct EsiObject {
  cia402::ObjectId id;
  std::string name;    // the object's Name; a sub-item's name ("Vendor ID", "SubIndex 001")
  std::string parent;  // the Name of the object a sub-item belongs to; empty for a VAR object
  std::string type;    // base type name as the file writes it ("UINT", "DINT", "STRING(8)"); the
                       // Type as written when it could not be resolved
  std::uint16_t data_type = 0;  // CiA 301 data type code of the base type, 0: none known
  int bits = 0;                 // BitSize (for sub-items: of the sub-item)
  EsiAccess access = EsiAccess::ReadOnly;
  bool rx_mappable = false;     // Flags/PdoMapping contains R (may be mapped into an RxPDO)
  bool tx_mappable = false;     // ... T (TxPDO)
  std::string default_data;     // Info/DefaultData verbatim (hex bytes, little-endian), may be empty
  int line = 0;                 // line of its Object element

  [[nodiscard]] bool readable() const noexcept { return access != EsiAccess::WriteOnly; }
  [[nodiscard]] bool writable() const noexcept { return access != EsiAccess::ReadOnly; }
};

struct EsiPdoEntry {
  cia402::ObjectId object;  // index 0: a gap of `bits` bits (padding)
  int bits = 0;             // BitLen
  std::string name;
  std::string data_type;    // as written ("UINT"), may be empty
  int line = 0;
  [[nodiscard]] bool padding() const noexcept { return object.index == 0; }
};

struct EsiPdo {
  std::uint16_t index = 0;  // 1600h..17FFh RxPDO, 1A00h..1BFFh TxPDO
  std::string name;
  bool fixed = false;       // Fixed="1": its mapping cannot be changed
  bool mandatory = false;
  std::optional<int> sm;    // Sm=: assigned to this SyncManager by default; absent: optional PDO
  std::vector<EsiPdoEntry> entries;
  int line = 0;
  [[nodiscard]] int bits() const noexcept {
    int b = 0;
    for (const auto& e : entries) b += e.bits;
    return b;
  }
};

// What an Sm element's text says the SyncManager carries.
enum class EsiSmKind : std::uint8_t { MBoxOut, MBoxIn, Outputs, Inputs, Unknown };
struct EsiSm {
  EsiSmKind kind = EsiSmKind::Unknown;
  std::string text;  // as written
  std::optional<std::uint32_t> min_size, max_size, default_size;
  std::optional<std::uint16_t> start_address;
  std::optional<std::uint8_t> control_byte;
  bool enable = false;
  int line = 0;
};

struct EsiMailbox {
  bool coe = false, eoe = false, foe = false, soe = false, aoe = false;
  // Attributes of Mailbox/CoE [ETG.2000 MailboxType]: what the slave's CoE server supports.
  bool sdo_info = false;
  bool pdo_assign = false;   // 1C12h/1C13h may be written
  bool pdo_config = false;   // 1600h../1A00h.. may be written
  bool complete_access = false;
  bool segmented_sdo = true;  // the schema's default
};

struct EsiOpMode {
  std::string name;  // "DC", "SM"
  std::string desc;
  std::uint32_t assign_activate = 0;  // written to ESC register 0980h; 0: no SYNC output
  std::optional<std::uint32_t> cycle_time_sync0;  // ns; the text of CycleTimeSync0
  std::optional<std::int32_t> cycle_time_sync0_factor;  // its Factor= (multiple of the bus cycle)
  std::optional<std::int64_t> shift_time_sync0;  // ns
  int line = 0;
};

struct EsiDevice {
  std::uint32_t product_code = 0;
  std::optional<std::uint32_t> revision;  // RevisionNo, absent in some files
  std::string type;  // Type's text, the order name ("EL1008", "TrioDrive D/ES")
  std::string name;  // Name, LcId 1033 preferred
  std::optional<std::uint32_t> profile_no;  // Profile/ProfileNo (402 for CiA 402 drives, 5001 I/O)
  std::optional<EsiMailbox> mailbox;
  std::vector<EsiSm> sms;
  std::vector<EsiPdo> rxpdos;
  std::vector<EsiPdo> txpdos;
  std::vector<EsiOpMode> op_modes;
  bool has_dictionary = false;     // Profile/Dictionary/Objects was given
  std::vector<EsiObject> objects;  // sorted by index and sub-index, each id once
  int line = 0;
};

struct EsiFile {
  std::uint32_t vendor_id = 0;
  std::string vendor_name;
  std::vector<EsiDevice> devices;  // in file order
};

// Vendors' ESI files run to many megabytes (one file per terminal family); larger ones are refused.
inline constexpr std::uint64_t kMaxEsiBytes = 64 * 1024 * 1024;
// Dictionary entries (objects and sub-indices) per device: real devices have a few thousand.
inline constexpr std::size_t kMaxEsiEntries = 65536;
// Warnings reported per file; the rest are counted in one last warning.
inline constexpr std::size_t kMaxEsiWarnings = 50;

// Parses an ESI file. Problems go to `problems` with the file name and line; the result is
// nullopt when there was an error.
std::optional<EsiFile> load_esi(const std::filesystem::path& file, Problems& problems);
// The same for text in memory; `label` names it in messages.
std::optional<EsiFile> load_esi_text(std::string_view text, const std::string& label, Problems& problems);

// A HexDecValue [ETG.2000]: "#x" (or "0x") hex, or decimal; surrounding blanks allowed. nullopt
// when it is neither or does not fit 64 bits.
std::optional<std::uint64_t> parse_esi_number(std::string_view text) noexcept;
// The same with an optional '-' before a decimal value (ShiftTimeSync0, Factor), within int64.
std::optional<std::int64_t> parse_esi_signed(std::string_view text) noexcept;

// "0x0000000F": how identities are written in messages (8 hex digits).
std::string esi_hex32(std::uint32_t v);
// "\"TrioDrive D/ES\" (product 0x00006755, revision 0x00000001)" for messages.
std::string esi_device_text(const EsiDevice& d);

// The devices with this product code (and revision, when given), in file order.
std::vector<const EsiDevice*> find_esi_devices(const EsiFile& file, std::uint32_t product_code,
                                               std::optional<std::uint32_t> revision);

// The entry with this index and sub-index, or nullptr.
const EsiObject* find_esi_object(std::span<const EsiObject> objects, cia402::ObjectId id) noexcept;
// The entries a parameter name stands for: a VAR object by its Name, a sub-item by
// "OBJECT:SUB" (both names, ASCII case-insensitive, blanks around ':' ignored). Several when the
// name is not unique.
std::vector<const EsiObject*> find_esi_objects(std::span<const EsiObject> objects, std::string_view name);
// The one entry the name stands for, or nullptr (none or several).
const EsiObject* find_esi_object(std::span<const EsiObject> objects, std::string_view name);

}  // namespace drivegate::config
