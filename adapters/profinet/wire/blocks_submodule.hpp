#pragma once
// PNIO connection management blocks, part 2: what the controller expects in the device's slots and
// what the device answers where it differs [IEC 61158-6-10 §5.2.2.4 ExpectedSubmoduleBlockReq,
// §5.2.2.5 ModuleDiffBlock].
//
//   ExpectedSubmoduleBlockReq 0104h: NumberOfAPIs u16, per API: API u32, SlotNumber u16,
//     ModuleIdentNumber u32, ModuleProperties u16, NumberOfSubmodules u16, per submodule:
//     SubslotNumber u16, SubmoduleIdentNumber u32, SubmoduleProperties u16, then one
//     DataDescription (two for an input-output submodule): DataDescription u16 (1 input,
//     2 output), SubmoduleDataLength u16, LengthIOCS u8, LengthIOPS u8
//   ModuleDiffBlock 8104h: NumberOfAPIs u16, per API: API u32, NumberOfModules u16, per module:
//     SlotNumber u16, ModuleIdentNumber u32, ModuleState u16, NumberOfSubmodules u16, per
//     submodule: SubslotNumber u16, SubmoduleIdentNumber u32, SubmoduleState u16
//
// For the AKD (digest §4, §24 step 5): slot 0 the DAP, slot 1 one telegram module, API 0x3A00 for
// the telegram submodule; the idents come from its GSDML.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "adapters/profinet/wire/blocks.hpp"

namespace drivegate::profinet {

// SubmoduleProperties bits 0-1 Type [IEC 61158-6-10 "SubmoduleProperties"].
enum class SubmoduleType : std::uint8_t { NoIo = 0, Input = 1, Output = 2, InputOutput = 3 };

struct DataDescription {
  std::uint16_t length = 0;      // SubmoduleDataLength
  std::uint8_t iocs_length = 1;  // LengthIOCS
  std::uint8_t iops_length = 1;  // LengthIOPS
  bool operator==(const DataDescription&) const = default;
};
struct ExpectedSubmodule {
  std::uint16_t subslot = 1;
  std::uint32_t ident = 0;
  std::uint16_t properties = 0;  // bits 0-1 the type; the other bits are written as given
  DataDescription input{};       // written for NoIo (length 0), Input and InputOutput
  DataDescription output{};      // written for Output and InputOutput
  [[nodiscard]] SubmoduleType type() const noexcept { return static_cast<SubmoduleType>(properties & 3); }
  bool operator==(const ExpectedSubmodule&) const = default;
};
// One API entry of the block: one slot with its module and submodules.
struct ExpectedSlot {
  std::uint32_t api = 0;
  std::uint16_t slot = 0;
  std::uint32_t module_ident = 0;
  std::uint16_t module_properties = 0;
  std::span<const ExpectedSubmodule> submodules{};
};
// One block holding `slots` as its API entries (a controller may also send one block per slot).
std::size_t encode_expected_submodule_block(std::span<const ExpectedSlot> slots, std::span<std::uint8_t> out) noexcept;

struct ExpectedSubmoduleBlockView {
  WireError error = WireError::None;
  std::uint16_t api_count = 0;
  std::span<const std::uint8_t> apis{};  // validated; walk with ExpectedSubmoduleReader
  std::size_t size = 0;
};
ExpectedSubmoduleBlockView decode_expected_submodule_block(std::span<const std::uint8_t> in) noexcept;

// A decoded entry, flat: the slot's fields with one of its submodules (a slot without submodules
// yields one entry with has_submodule false).
struct ExpectedEntry {
  std::uint32_t api = 0;
  std::uint16_t slot = 0;
  std::uint32_t module_ident = 0;
  std::uint16_t module_properties = 0;
  bool has_submodule = false;
  ExpectedSubmodule submodule{};
};
class ExpectedSubmoduleReader {
 public:
  explicit ExpectedSubmoduleReader(const ExpectedSubmoduleBlockView& v) noexcept
      : r_(v.apis, ByteOrder::Big), apis_left_(v.error == WireError::None ? v.api_count : 0) {}
  bool next(ExpectedEntry& out) noexcept;

 private:
  Reader r_;
  std::uint16_t apis_left_;
  std::uint16_t submodules_left_ = 0;
  ExpectedEntry slot_{};
};

// ---- ModuleDiffBlock -----------------------------------------------------------------------------

// ModuleState [IEC 61158-6-10 "ModuleState"].
enum class ModuleState : std::uint16_t { NoModule = 0, WrongModule = 1, ProperModule = 2, Substitute = 3 };
std::string_view to_string(ModuleState s) noexcept;

// SubmoduleState with FormatIndicator (bit 15) = 1 [IEC 61158-6-10 "SubmoduleState"]:
// bits 0-2 AddInfo, bit 3 QualifiedInfo, bit 4 MaintenanceRequired, bit 5 MaintenanceDemanded,
// bit 6 DiagInfo, bits 7-10 ARInfo, bits 11-14 IdentInfo.
namespace submodule_state {
inline constexpr std::uint16_t kFormatIndicator = 0x8000;
inline constexpr std::uint16_t kDiagInfo = 0x0040;
inline constexpr std::uint16_t kMaintenanceRequired = 0x0010;
inline constexpr std::uint16_t kMaintenanceDemanded = 0x0020;
constexpr std::uint8_t ident_info(std::uint16_t s) noexcept { return static_cast<std::uint8_t>((s >> 11) & 0x0F); }
constexpr std::uint8_t ar_info(std::uint16_t s) noexcept { return static_cast<std::uint8_t>((s >> 7) & 0x0F); }
// IdentInfo: 0 OK, 1 Substitute, 2 Wrong, 3 NoSubmodule; ARInfo: 0 Own, 1 ApplicationReadyPending,
// 2 Superordinated locked, 3 Locked by IO controller, 4 Locked by IO supervisor.
inline constexpr std::uint8_t kIdentOk = 0;
inline constexpr std::uint8_t kIdentSubstitute = 1;
inline constexpr std::uint8_t kIdentWrong = 2;
inline constexpr std::uint8_t kIdentNoSubmodule = 3;
inline constexpr std::uint8_t kArOwn = 0;
inline constexpr std::uint8_t kArApplicationReadyPending = 1;
inline constexpr std::uint8_t kArSuperordinatedLocked = 2;
inline constexpr std::uint8_t kArLockedByController = 3;
inline constexpr std::uint8_t kArLockedBySupervisor = 4;
}  // namespace submodule_state

struct ModuleDiffSubmodule {
  std::uint16_t subslot = 0;
  std::uint32_t ident = 0;
  std::uint16_t state = 0;
  bool operator==(const ModuleDiffSubmodule&) const = default;
};
struct ModuleDiffModule {
  std::uint16_t slot = 0;
  std::uint32_t ident = 0;
  ModuleState state = ModuleState::ProperModule;
  std::span<const ModuleDiffSubmodule> submodules{};
};
struct ModuleDiffApi {
  std::uint32_t api = 0;
  std::span<const ModuleDiffModule> modules{};
};
// For the simulator and the tests.
std::size_t encode_module_diff_block(std::span<const ModuleDiffApi> apis, std::span<std::uint8_t> out) noexcept;

struct ModuleDiffBlockView {
  WireError error = WireError::None;
  std::uint16_t api_count = 0;
  std::span<const std::uint8_t> apis{};  // validated; walk with ModuleDiffReader
  std::size_t size = 0;
};
ModuleDiffBlockView decode_module_diff_block(std::span<const std::uint8_t> in) noexcept;

struct ModuleDiffEntry {
  std::uint32_t api = 0;
  std::uint16_t slot = 0;
  std::uint32_t module_ident = 0;
  std::uint16_t module_state = 0;  // ModuleState value, raw
  bool has_submodule = false;
  ModuleDiffSubmodule submodule{};
};
class ModuleDiffReader {
 public:
  explicit ModuleDiffReader(const ModuleDiffBlockView& v) noexcept
      : r_(v.apis, ByteOrder::Big), apis_left_(v.error == WireError::None ? v.api_count : 0) {}
  bool next(ModuleDiffEntry& out) noexcept;

 private:
  Reader r_;
  std::uint16_t apis_left_;
  std::uint16_t modules_left_ = 0;
  std::uint16_t submodules_left_ = 0;
  ModuleDiffEntry module_{};
};

// The differences as text, one line per finding, e.g.
//   "slot 1: wrong module (ident 0x00000009, expected 0x00000007)"
//   "slot 1 subslot 1: wrong submodule (ident 0x00000002, expected 0x00000001)"
//   "slot 2: no module"
//   "slot 1 subslot 1: application ready pending"
// `expected` (optional) gives the idents the controller asked for. Written into `out` (cut at its
// end; no allocation); returns a view of what was written.
std::string_view module_diff_report(const ModuleDiffBlockView& v, std::span<const ExpectedSlot> expected,
                                    std::span<char> out) noexcept;

}  // namespace drivegate::profinet
