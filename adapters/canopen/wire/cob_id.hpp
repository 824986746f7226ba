#pragma once
// COB-IDs of the CiA 301 predefined connection set, and the function-code split the master uses
// to route received frames [CiA 301 §7.3.3; AKD part 1 §4; SD6 digest §5.3, TV-8].
#include <cstdint>
#include <optional>

namespace drivegate::canopen {

using NodeId = std::uint8_t;  // 1..127; 0 addresses all nodes in NMT commands

inline constexpr NodeId kMinNodeId = 1;
inline constexpr NodeId kMaxNodeId = 127;
constexpr bool valid_node_id(int id) noexcept { return id >= kMinNodeId && id <= kMaxNodeId; }

namespace cob {
inline constexpr std::uint32_t kNmt = 0x000;
inline constexpr std::uint32_t kSync = 0x080;
inline constexpr std::uint32_t kTime = 0x100;
inline constexpr std::uint32_t kEmcyBase = 0x080;
inline constexpr std::uint32_t kTpdoBase[4] = {0x180, 0x280, 0x380, 0x480};  // drive -> master
inline constexpr std::uint32_t kRpdoBase[4] = {0x200, 0x300, 0x400, 0x500};  // master -> drive
inline constexpr std::uint32_t kSdoTxBase = 0x580;  // server -> client (response)
inline constexpr std::uint32_t kSdoRxBase = 0x600;  // client -> server (request)
inline constexpr std::uint32_t kErrorControlBase = 0x700;

constexpr std::uint32_t emcy(NodeId n) noexcept { return kEmcyBase + n; }
constexpr std::uint32_t tpdo(int pdo, NodeId n) noexcept { return kTpdoBase[pdo] + n; }  // pdo 0..3
constexpr std::uint32_t rpdo(int pdo, NodeId n) noexcept { return kRpdoBase[pdo] + n; }
constexpr std::uint32_t sdo_tx(NodeId n) noexcept { return kSdoTxBase + n; }
constexpr std::uint32_t sdo_rx(NodeId n) noexcept { return kSdoRxBase + n; }
constexpr std::uint32_t error_control(NodeId n) noexcept { return kErrorControlBase + n; }

// STÖBER SD6 SDO server channels 2..4 [SD6 digest §5.3, quirk 1]: channel k (1..4) uses
// Tx 580h + 20h*(k-1) + id and Rx 600h + 20h*(k-1) + id; node-ID <= 31 once channels 2..4 are used.
constexpr std::uint32_t sdo_tx(int channel, NodeId n) noexcept { return kSdoTxBase + 0x20U * unsigned(channel - 1) + n; }
constexpr std::uint32_t sdo_rx(int channel, NodeId n) noexcept { return kSdoRxBase + 0x20U * unsigned(channel - 1) + n; }

// Bits of a COB-ID entry in 1005h/1014h/1400h../1800h.. [CiA 301 §7.5.2.3 and §7.5.2.35].
inline constexpr std::uint32_t kInvalid = 0x80000000U;  // bit 31: PDO/EMCY not valid
inline constexpr std::uint32_t kNoRtr = 0x40000000U;    // bit 30: no RTR allowed on this PDO
inline constexpr std::uint32_t kIdMask = 0x7FFU;
}  // namespace cob

// What a standard-id frame is, by its function code (bits 10..7) and node-id (bits 6..0).
enum class Function : std::uint8_t {
  Nmt, Sync, Emcy, Time, Tpdo, Rpdo, SdoTx, SdoRx, ErrorControl, Other
};

struct CobSplit {
  Function function = Function::Other;
  NodeId node = 0;
  int index = 0;  // PDO number 0..3
};

constexpr CobSplit split_cob_id(std::uint32_t id) noexcept {
  const auto fc = (id >> 7) & 0xFU;
  const auto node = static_cast<NodeId>(id & 0x7FU);
  if (id > 0x7FF) return {};
  switch (fc) {
    case 0x0: return id == cob::kNmt ? CobSplit{Function::Nmt, 0, 0} : CobSplit{};
    case 0x1: return node == 0 ? CobSplit{Function::Sync, 0, 0} : CobSplit{Function::Emcy, node, 0};
    case 0x2: return node == 0 ? CobSplit{Function::Time, 0, 0} : CobSplit{};
    case 0x3: return {Function::Tpdo, node, 0};
    case 0x4: return {Function::Rpdo, node, 0};
    case 0x5: return {Function::Tpdo, node, 1};
    case 0x6: return {Function::Rpdo, node, 1};
    case 0x7: return {Function::Tpdo, node, 2};
    case 0x8: return {Function::Rpdo, node, 2};
    case 0x9: return {Function::Tpdo, node, 3};
    case 0xA: return {Function::Rpdo, node, 3};
    case 0xB: return {Function::SdoTx, node, 0};
    case 0xC: return {Function::SdoRx, node, 0};
    case 0xE: return {Function::ErrorControl, node, 0};
    default: return {};
  }
}

}  // namespace drivegate::canopen
