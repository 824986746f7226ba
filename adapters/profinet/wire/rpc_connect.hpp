#pragma once
// The Connect call (opnum 0) as one unit: composing the request a controller sends to open an IO
// AR, and walking the response's blocks [IEC 61158-6-10 §5.1.2 "IODConnectReq/Res",
// §4.10.3.2 connect sequence].
//
//   request:  RPC header | NDR | ARBlockReq | IOCRBlockReq (input) | IOCRBlockReq (output) |
//             AlarmCRBlockReq | ExpectedSubmoduleBlockReq per slot
//   response: RPC header | NDR (PNIOStatus) | ARBlockRes | IOCRBlockRes × n | AlarmCRBlockRes |
//             ModuleDiffBlock (only when the device differs from the expectation)
//
// For the AKD (digest §24 step 5): one input and one output CR of RT class 1, slot 0 (DAP) and
// slot 1 (one telegram module), update time at least 16 ms.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "adapters/profinet/wire/blocks.hpp"
#include "adapters/profinet/wire/blocks_submodule.hpp"
#include "adapters/profinet/wire/rpc.hpp"

namespace drivegate::profinet {

struct ConnectRequest {
  ArBlockReq ar{};
  IocrParams input{};  // type forced to input
  std::span<const IocrApiSpec> input_apis{};
  IocrParams output{};  // type forced to output
  std::span<const IocrApiSpec> output_apis{};
  AlarmCrBlockReq alarm{};
  std::span<const ExpectedSlot> expected{};  // one ExpectedSubmoduleBlockReq per entry
};
// `h` as pnio_request_header(..., Opnum::Connect) gives it. Returns the datagram size or 0.
std::size_t encode_connect_request(const RpcHeader& h, std::uint32_t args_maximum, const ConnectRequest& c,
                                   std::span<std::uint8_t> out) noexcept;

inline constexpr std::size_t kMaxConnectIocrs = 8;
inline constexpr std::size_t kMaxConnectExpectedBlocks = 32;

// The device side (simulator): a Connect request datagram with each block decoded. Required: one
// ARBlockReq, at least one IOCRBlockReq, one AlarmCRBlockReq [IEC 61158-6-10 §5.1.2, CMRPC
// checks "IOCR Missing", "Wrong AlarmCRBlock count"]; other block types are counted and skipped.
struct ConnectRequestView {
  WireError error = WireError::None;
  RpcHeader header{};
  std::uint32_t args_maximum = 0;
  ArBlockReqView ar{};
  std::array<IocrBlockReqView, kMaxConnectIocrs> iocrs{};
  std::size_t iocr_count = 0;
  AlarmCrBlockReqView alarm_cr{};
  std::array<ExpectedSubmoduleBlockView, kMaxConnectExpectedBlocks> expected{};
  std::size_t expected_count = 0;
  std::size_t other_blocks = 0;
};
ConnectRequestView decode_connect_request(std::span<const std::uint8_t> datagram) noexcept;

struct ConnectResponseView {
  WireError error = WireError::None;
  RpcHeader header{};
  PnioStatus status{};  // from the NDR wrapper; not OK: the blocks may be absent
  bool has_ar = false;
  ArBlockRes ar{};
  std::array<IocrBlockRes, kMaxConnectIocrs> iocrs{};
  std::size_t iocr_count = 0;
  bool has_alarm_cr = false;
  AlarmCrBlockRes alarm_cr{};
  bool has_module_diff = false;
  ModuleDiffBlockView module_diff{};  // views the datagram; report with module_diff_report
  std::size_t other_blocks = 0;       // blocks this view does not read (e.g. ARRPCBlockRes)
  [[nodiscard]] const IocrBlockRes* iocr(std::uint16_t type, std::uint16_t reference) const noexcept;
};
// A whole Connect response datagram: a PNIO response with opnum Connect, its blocks each decoded.
// With PNIOStatus OK an ARBlockRes is required (MissingBlock otherwise).
ConnectResponseView decode_connect_response(std::span<const std::uint8_t> datagram) noexcept;

// The device side (simulator, tests): a Connect response with the given blocks; `module_diff` empty
// writes no ModuleDiffBlock.
struct ConnectResponse {
  ArBlockRes ar{};
  std::span<const IocrBlockRes> iocrs{};
  AlarmCrBlockRes alarm_cr{};
  std::span<const ModuleDiffApi> module_diff{};
};
std::size_t encode_connect_response(const RpcHeader& h, const PnioStatus& status, std::uint32_t maximum_count,
                                    const ConnectResponse& c, std::span<std::uint8_t> out) noexcept;

}  // namespace drivegate::profinet
