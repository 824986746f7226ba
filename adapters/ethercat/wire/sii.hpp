#pragma once
// SII (slave information interface) EEPROM image [ETG.1000.6 §5.4 "SII coding": fixed
// header words 0000h-003Fh and the categories (strings Table 20, general Table 21, ...)]. The image is a little-endian word
// array. Words 00h-07h are the ESC configuration area with a CRC-8 in the low byte of word 07h;
// from word 40h on come categories, each a type word, a size word (in words) and the data, up to
// the end category FFFFh.
//
// parse_sii() reads an image into fixed-capacity tables (string views point into the image, so
// the image must outlive the result); impossible lengths become issues, never out-of-bounds
// reads. build_sii() writes an image from a profile (the simulator's EEPROMs); what it writes,
// parse_sii() reads back.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

namespace drivegate::ethercat {

// Word addresses of the fixed header [ETG.1000.6 §5.4].
namespace sii_word {
inline constexpr std::uint16_t kPdiControl = 0x0000;
inline constexpr std::uint16_t kPdiConfiguration = 0x0001;
inline constexpr std::uint16_t kSyncImpulseLength = 0x0002;
inline constexpr std::uint16_t kPdiConfiguration2 = 0x0003;
inline constexpr std::uint16_t kStationAlias = 0x0004;
inline constexpr std::uint16_t kChecksum = 0x0007;            // low byte: CRC-8 of words 0-6
inline constexpr std::uint16_t kVendorId = 0x0008;            // u32
inline constexpr std::uint16_t kProductCode = 0x000A;         // u32
inline constexpr std::uint16_t kRevision = 0x000C;            // u32
inline constexpr std::uint16_t kSerial = 0x000E;              // u32
inline constexpr std::uint16_t kBootstrapRxMailboxOffset = 0x0014;
inline constexpr std::uint16_t kBootstrapRxMailboxSize = 0x0015;
inline constexpr std::uint16_t kBootstrapTxMailboxOffset = 0x0016;
inline constexpr std::uint16_t kBootstrapTxMailboxSize = 0x0017;
inline constexpr std::uint16_t kStandardRxMailboxOffset = 0x0018;
inline constexpr std::uint16_t kStandardRxMailboxSize = 0x0019;
inline constexpr std::uint16_t kStandardTxMailboxOffset = 0x001A;
inline constexpr std::uint16_t kStandardTxMailboxSize = 0x001B;
inline constexpr std::uint16_t kMailboxProtocols = 0x001C;
inline constexpr std::uint16_t kEepromSize = 0x003E;          // EEPROM size in KiBit, minus 1
inline constexpr std::uint16_t kVersion = 0x003F;
inline constexpr std::uint16_t kFirstCategory = 0x0040;
}  // namespace sii_word

inline constexpr std::size_t kSiiHeaderBytes = 2 * sii_word::kFirstCategory;  // 128

// Mailbox protocols word 001Ch bits [ETG.1000.6 §5.4].
namespace mailbox_protocol {
inline constexpr std::uint16_t kAoE = 0x0001;
inline constexpr std::uint16_t kEoE = 0x0002;
inline constexpr std::uint16_t kCoE = 0x0004;
inline constexpr std::uint16_t kFoE = 0x0008;
inline constexpr std::uint16_t kSoE = 0x0010;
inline constexpr std::uint16_t kVoE = 0x0020;
}  // namespace mailbox_protocol

// General category CoE details bits [ETG.1000.6 Table 21].
namespace coe_details {
inline constexpr std::uint8_t kSdo = 0x01;
inline constexpr std::uint8_t kSdoInfo = 0x02;
inline constexpr std::uint8_t kPdoAssign = 0x04;
inline constexpr std::uint8_t kPdoConfig = 0x08;
inline constexpr std::uint8_t kUploadAtStartup = 0x10;
inline constexpr std::uint8_t kSdoCompleteAccess = 0x20;
}  // namespace coe_details

// Category types [ETG.1000.6 §5.4].
enum class SiiCategory : std::uint16_t {
  Nop = 0,
  Strings = 10,
  DataTypes = 20,
  General = 30,
  Fmmu = 40,
  SyncM = 41,
  FmmuX = 42,
  SyncUnit = 43,
  TxPdo = 50,
  RxPdo = 51,
  Dc = 60,
  End = 0xFFFF,
};
std::string_view to_string(SiiCategory c) noexcept;

// CRC-8 of the ESC configuration area: polynomial x^8 + x^2 + x + 1 (07h), initial value FFh, no
// reflection, no final XOR, over the 14 bytes of words 0-6 [ETG.1000.6 §5.4, word 7 "checksum"].
std::uint8_t sii_crc8(std::span<const std::uint8_t> bytes) noexcept;

struct SiiIdentity {
  std::uint32_t vendor_id = 0;
  std::uint32_t product_code = 0;
  std::uint32_t revision = 0;
  std::uint32_t serial = 0;
  bool operator==(const SiiIdentity&) const = default;
};

// Offsets are ESC addresses (e.g. 1000h), sizes in bytes.
struct SiiMailbox {
  std::uint16_t rx_offset = 0;  // master -> slave (SM0)
  std::uint16_t rx_size = 0;
  std::uint16_t tx_offset = 0;  // slave -> master (SM1)
  std::uint16_t tx_size = 0;
  bool present() const noexcept { return rx_size != 0 && tx_size != 0; }
  bool operator==(const SiiMailbox&) const = default;
};

// General category, 32 bytes [ETG.1000.6 Table 21]. String fields are 1-based string indexes.
struct SiiGeneral {
  std::uint8_t group_index = 0;
  std::uint8_t image_index = 0;
  std::uint8_t order_index = 0;
  std::uint8_t name_index = 0;
  std::uint8_t coe_details = 0;
  std::uint8_t foe_details = 0;
  std::uint8_t eoe_details = 0;
  std::uint8_t soe_channels = 0;
  std::uint8_t ds402_channels = 0;
  std::uint8_t sysman_class = 0;
  std::uint8_t flags = 0;             // bit 0 enable SAFE-OP, bit 1 enable not-LRW, bit 2 mailbox DLL, ...
  std::int16_t current_on_ebus = 0;   // mA, negative = feeds the E-bus
  std::uint16_t physical_ports = 0;   // 4 bits per port: 0 unused, 1 MII, 3 EBUS, 4 fast hot connect
  std::uint16_t physical_memory_address = 0;
  bool operator==(const SiiGeneral&) const = default;
};
inline constexpr std::size_t kSiiGeneralBytes = 32;

// FMMU category: one usage byte per FMMU [ETG.1000.6 §5.4].
namespace sii_fmmu_usage {
inline constexpr std::uint8_t kUnused = 0x00;
inline constexpr std::uint8_t kOutputs = 0x01;
inline constexpr std::uint8_t kInputs = 0x02;
inline constexpr std::uint8_t kSyncMStatus = 0x03;
inline constexpr std::uint8_t kUnused2 = 0xFF;
}  // namespace sii_fmmu_usage

// SyncM category element, 8 bytes [ETG.1000.6 §5.4].
namespace sii_sm_type {
inline constexpr std::uint8_t kUnused = 0;
inline constexpr std::uint8_t kMailboxOut = 1;
inline constexpr std::uint8_t kMailboxIn = 2;
inline constexpr std::uint8_t kOutputs = 3;
inline constexpr std::uint8_t kInputs = 4;
}  // namespace sii_sm_type
struct SiiSyncManager {
  std::uint16_t physical_start = 0;
  std::uint16_t length = 0;
  std::uint8_t control = 0;
  std::uint8_t status = 0;
  std::uint8_t enable = 0;  // bit 0 enable, bit 1 fixed content, bit 2 virtual, bit 3 OP only
  std::uint8_t type = 0;    // sii_sm_type
  bool operator==(const SiiSyncManager&) const = default;
};
inline constexpr std::size_t kSiiSyncManagerBytes = 8;

// TXPDO/RXPDO categories: an 8-byte PDO header then 8 bytes per entry [ETG.1000.6 §5.4].
struct SiiPdoEntry {
  std::uint16_t index = 0;
  std::uint8_t subindex = 0;
  std::uint8_t name_index = 0;
  std::uint8_t data_type = 0;   // CoE data type index (e.g. 06h UNSIGNED16)
  std::uint8_t bit_length = 0;
  std::uint16_t flags = 0;
  bool operator==(const SiiPdoEntry&) const = default;
};
struct SiiPdo {
  bool tx = false;              // TXPDO (inputs) or RXPDO (outputs)
  std::uint16_t index = 0;
  std::uint8_t entry_count = 0; // as declared
  std::uint8_t sm = 0;
  std::uint8_t sync = 0;        // DC sync
  std::uint8_t name_index = 0;
  std::uint16_t flags = 0;
  std::size_t first_entry = 0;  // into SiiInfo::entries
  std::size_t stored_entries = 0;  // entries kept (fewer than entry_count only on an issue)
};
inline constexpr std::size_t kSiiPdoHeaderBytes = 8;
inline constexpr std::size_t kSiiPdoEntryBytes = 8;

// DC category element, 24 bytes [ETG.1000.6 §5.4].
struct SiiDc {
  std::uint32_t cycle_time0 = 0;
  std::uint32_t shift_time0 = 0;
  std::uint32_t shift_time1 = 0;
  std::int16_t sync1_cycle_factor = 0;
  std::uint16_t assign_activate = 0;
  std::int16_t sync0_cycle_factor = 0;
  std::uint8_t name_index = 0;
  std::uint8_t description_index = 0;
  bool operator==(const SiiDc&) const = default;
};
inline constexpr std::size_t kSiiDcBytes = 24;

// ---- Parse ------------------------------------------------------------------------------------

enum class SiiProblem : std::uint8_t {
  ImageTooShort,           // error: fewer than 128 bytes, no header
  ChecksumMismatch,        // warning: word 7 low byte differs from the CRC of words 0-6
  NoEndCategory,           // warning: the image ends before a category header / the end marker
  CategoryBeyondImage,     // error: a category's size runs past the image
  StringBeyondCategory,    // error: a string's length runs past the strings category
  GeneralTooShort,         // error: general category shorter than 32 bytes
  PdoHeaderTruncated,      // error: bytes left in a PDO category that do not hold a PDO header
  PdoEntriesBeyondCategory,// error: a PDO's entry count runs past its category
  SizeNotMultiple,         // warning: SyncM/DC category size not a multiple of its element (rest ignored)
  StringIndexOutOfRange,   // warning: a name index beyond the strings present
  DuplicateCategory,       // warning: general/strings category seen again (the first is kept)
  TooManyStrings,          // warning: over capacity, the rest is dropped
  TooManyFmmus,
  TooManySyncManagers,
  TooManyPdos,
  TooManyPdoEntries,
  TooManyDcs,
};
std::string_view to_string(SiiProblem p) noexcept;
bool is_error(SiiProblem p) noexcept;

struct SiiIssue {
  SiiProblem problem = SiiProblem::ImageTooShort;
  std::uint32_t word = 0;  // word address where it was found
};

inline constexpr std::size_t kSiiMaxStrings = 255;
inline constexpr std::size_t kSiiMaxFmmus = 16;
inline constexpr std::size_t kSiiMaxSyncManagers = 16;
inline constexpr std::size_t kSiiMaxPdos = 64;
inline constexpr std::size_t kSiiMaxPdoEntries = 512;
inline constexpr std::size_t kSiiMaxDcs = 8;
inline constexpr std::size_t kSiiMaxIssues = 16;

// The fixed header's fields a device describes itself with (what parse_sii reads and build_sii
// writes; the checksum, size and version are the image's own).
struct SiiHeader {
  std::uint16_t pdi_control = 0;
  std::uint16_t pdi_configuration = 0;
  std::uint16_t sync_impulse_length = 0;
  std::uint16_t pdi_configuration2 = 0;
  std::uint16_t station_alias = 0;
  SiiIdentity identity{};
  SiiMailbox bootstrap_mailbox{};
  SiiMailbox standard_mailbox{};
  std::uint16_t mailbox_protocols = 0;
  bool operator==(const SiiHeader&) const = default;
};

struct SiiInfo {
  // Fixed header
  SiiHeader header{};
  std::uint8_t checksum = 0;           // as stored
  std::uint8_t checksum_computed = 0;  // CRC-8 of words 0-6
  std::uint16_t eeprom_size = 0;       // word 3Eh as stored
  std::uint16_t version = 0;
  bool header_valid = false;

  // Categories
  std::array<std::string_view, kSiiMaxStrings> strings{};
  std::size_t string_count = 0;
  bool has_general = false;
  SiiGeneral general{};
  std::array<std::uint8_t, kSiiMaxFmmus> fmmus{};
  std::size_t fmmu_count = 0;
  std::array<SiiSyncManager, kSiiMaxSyncManagers> sync_managers{};
  std::size_t sync_manager_count = 0;
  std::array<SiiPdo, kSiiMaxPdos> pdos{};
  std::size_t pdo_count = 0;
  std::array<SiiPdoEntry, kSiiMaxPdoEntries> entries{};
  std::size_t entry_count = 0;
  std::array<SiiDc, kSiiMaxDcs> dcs{};
  std::size_t dc_count = 0;
  bool end_seen = false;

  std::array<SiiIssue, kSiiMaxIssues> issues{};
  std::size_t issue_count = 0;  // issues beyond the capacity are dropped (the count stays at max)

  // EEPROM size in bytes from word 3Eh: (value + 1) KiBit / 8.
  std::size_t eeprom_bytes() const noexcept { return (static_cast<std::size_t>(eeprom_size) + 1) * 128; }
  bool checksum_ok() const noexcept { return checksum == checksum_computed; }
  // String by 1-based index; empty for 0 or an index beyond the strings present.
  std::string_view string(std::uint8_t index) const noexcept;
  std::span<const SiiPdoEntry> entries_of(const SiiPdo& p) const noexcept;
  bool has(SiiProblem p) const noexcept;
  // No error-level issue (warnings allowed).
  bool ok() const noexcept;
};

// Parses `image` into `out` (reset first). SiiInfo is large (~20 KB): keep it off small stacks.
void parse_sii(std::span<const std::uint8_t> image, SiiInfo& out) noexcept;

// ---- Build ------------------------------------------------------------------------------------

struct SiiBuildEntry {
  std::uint16_t index = 0;
  std::uint8_t subindex = 0;
  std::string_view name{};
  std::uint8_t data_type = 0;
  std::uint8_t bit_length = 0;
  std::uint16_t flags = 0;
};

struct SiiBuildPdo {
  std::uint16_t index = 0;
  std::uint8_t sm = 0;
  std::uint8_t sync = 0;
  std::string_view name{};
  std::uint16_t flags = 0;
  std::span<const SiiBuildEntry> entries{};
};

struct SiiBuildDc {
  SiiDc dc{};                  // name_index is filled in from `name`
  std::string_view name{};
};

struct SiiProfile {
  SiiHeader header{};
  std::string_view group{};
  std::string_view image{};
  std::string_view order{};
  std::string_view name{};
  SiiGeneral general{};        // index fields are filled in from the four names above
  std::span<const std::uint8_t> fmmus{};
  std::span<const SiiSyncManager> sync_managers{};
  std::span<const SiiBuildPdo> tx_pdos{};
  std::span<const SiiBuildPdo> rx_pdos{};
  std::span<const SiiBuildDc> dcs{};
  std::size_t eeprom_bytes = 2048;  // multiple of 128 (1 KiBit), at most 8 MiBit; rest filled with FFh
};

enum class SiiBuildError : std::uint8_t {
  None,
  InvalidEepromSize,  // not a positive multiple of 128 bytes, or too large for word 3Eh
  OutputTooSmall,     // `out` smaller than eeprom_bytes
  ContentTooLarge,    // the categories do not fit in eeprom_bytes
  TooManyStrings,     // more than 255 distinct strings
  StringTooLong,      // a string over 255 bytes
  TooManyEntries,     // a PDO with more than 255 entries
};
std::string_view to_string(SiiBuildError e) noexcept;

struct SiiBuildResult {
  SiiBuildError error = SiiBuildError::None;
  std::size_t size = 0;  // bytes written (eeprom_bytes) on success
  bool ok() const noexcept { return error == SiiBuildError::None; }
};

SiiBuildResult build_sii(const SiiProfile& profile, std::span<std::uint8_t> out) noexcept;

}  // namespace drivegate::ethercat
