#pragma once
// NMT module control (COB-ID 000h, DLC 2: command specifier, node-ID; 0 = all nodes) and the
// error-control byte on 700h+n (boot-up 00h, heartbeat and node-guard replies: state in bits 6..0,
// toggle in bit 7 for guarding) [CiA 301 §7.2.8; AKD part 1 §6, §11; SD6 digest §6.7, §6.8].
#include <array>
#include <cstdint>
#include <optional>
#include <span>

#include "adapters/canopen/wire/cob_id.hpp"

namespace drivegate::canopen {

enum class NmtCommand : std::uint8_t {
  Start = 0x01,
  Stop = 0x02,
  EnterPreOperational = 0x80,
  ResetNode = 0x81,
  ResetCommunication = 0x82,
};

// The state a node reports on 700h+n. Initialising (00h) is the boot-up message.
enum class NmtState : std::uint8_t {
  Initialising = 0x00,
  Stopped = 0x04,
  Operational = 0x05,
  PreOperational = 0x7F,
  Unknown = 0xFF,  // not a wire value: nothing heard yet
};
const char* to_string(NmtState s) noexcept;
const char* to_string(NmtCommand c) noexcept;

inline std::array<std::uint8_t, 2> encode_nmt(NmtCommand cs, NodeId node) noexcept {
  return {static_cast<std::uint8_t>(cs), node};
}

struct NmtFrame {
  NmtCommand command;
  NodeId node;  // 0 = all
};
// nullopt for a wrong length, an unknown command or a node-ID above 127.
inline std::optional<NmtFrame> decode_nmt(std::span<const std::uint8_t> p) noexcept {
  if (p.size() != 2 || p[1] > kMaxNodeId) return std::nullopt;
  switch (p[0]) {
    case 0x01:
    case 0x02:
    case 0x80:
    case 0x81:
    case 0x82: return NmtFrame{static_cast<NmtCommand>(p[0]), p[1]};
    default: return std::nullopt;
  }
}

struct ErrorControlFrame {
  NmtState state;
  bool toggle;  // bit 7: meaningful for node-guard replies only
};
// Heartbeat / boot-up / guard reply: DLC 1, state byte with a known value in bits 6..0.
inline std::optional<ErrorControlFrame> decode_error_control(std::span<const std::uint8_t> p) noexcept {
  if (p.size() != 1) return std::nullopt;
  const auto s = static_cast<std::uint8_t>(p[0] & 0x7F);
  if (s != 0x00 && s != 0x04 && s != 0x05 && s != 0x7F) return std::nullopt;
  return ErrorControlFrame{static_cast<NmtState>(s), (p[0] & 0x80) != 0};
}
inline std::uint8_t encode_error_control(NmtState s, bool toggle = false) noexcept {
  return static_cast<std::uint8_t>(static_cast<std::uint8_t>(s) | (toggle ? 0x80 : 0));
}

}  // namespace drivegate::canopen
