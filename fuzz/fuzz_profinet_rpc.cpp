// The PNIO RPC decoders (adapters/profinet/wire/rpc.hpp, rpc_calls.hpp, rpc_connect.hpp) on
// whatever arrives on UDP port 34964: decode_rpc, decode_pnio_request/response, the NDR wrappers in
// both byte orders, decode_rpc_fault, decode_connect_request, decode_connect_response with its
// ModuleDiff report.
// Invariants: every view inside the input; a decoded header re-encodes to the same 80 bytes (but
// the reserved drep octet); a decoded request or response whose counts are the ones the composer
// writes is rebuilt byte for byte by finish_pnio_request/response; a Connect response holds at most
// kMaxConnectIocrs IOCRs and its report fits the buffer.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <string_view>

#include "adapters/profinet/wire/rpc.hpp"
#include "adapters/profinet/wire/rpc_calls.hpp"
#include "adapters/profinet/wire/rpc_connect.hpp"

namespace {

using namespace drivegate::profinet;

std::span<const std::uint8_t> input;

void inside(std::span<const std::uint8_t> s) {
  if (s.empty()) return;
  if (s.data() < input.data() || s.data() + s.size() > input.data() + input.size()) std::abort();
}

void same_prefix(std::span<const std::uint8_t> rebuilt, std::size_t n) {
  if (rebuilt.size() < n || input.size() < n) std::abort();
  for (std::size_t i = 0; i < n; ++i) {
    if (i == 6) continue;  // drep[2], reserved: written as 0
    if (rebuilt[i] != input[i]) std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 65536) return 0;
  input = std::span<const std::uint8_t>(data, size);
  static std::array<std::uint8_t, 65536 + 128> out{};

  const RpcView rpc = decode_rpc(input);
  if (rpc.error == WireError::None) {
    inside(rpc.body);
    if (rpc.body.size() != rpc.header.fragment_length) std::abort();
    if (encode_rpc_header(rpc.header, out) != kRpcHeaderSize) std::abort();
    same_prefix(out, kRpcHeaderSize);
  }
  for (const ByteOrder order : {ByteOrder::Little, ByteOrder::Big}) {
    inside(decode_ndr_request(input, order).ndr.blocks);
    inside(decode_ndr_response(input, order).ndr.blocks);
    (void)decode_rpc_fault(input, order);
  }

  const PnioRequestView req = decode_pnio_request(input);
  if (req.error == WireError::None) {
    const NdrRequest& n = req.ndr;
    inside(n.blocks);
    if (n.blocks.size() != n.args_length) std::abort();
    if (n.maximum_count == n.args_maximum && n.offset == 0 &&
        rpc.header.fragment_length == kNdrHeaderSize + n.args_length) {
      std::copy(n.blocks.begin(), n.blocks.end(), out.begin() + kPnioBlocksOffset);
      const std::size_t len = finish_pnio_request(req.header, n.args_maximum, n.args_length, out);
      if (len != kPnioBlocksOffset + n.args_length) std::abort();
      same_prefix(out, len);
    }
  }
  const PnioResponseView res = decode_pnio_response(input);
  if (res.error == WireError::None) {
    const NdrResponse& n = res.ndr;
    inside(n.blocks);
    if (n.offset == 0 && rpc.header.fragment_length == kNdrHeaderSize + n.args_length) {
      std::copy(n.blocks.begin(), n.blocks.end(), out.begin() + kPnioBlocksOffset);
      const std::size_t len = finish_pnio_response(res.header, n.status, n.maximum_count, n.args_length, out);
      if (len != kPnioBlocksOffset + n.args_length) std::abort();
      same_prefix(out, len);
    }
  }

  const ConnectResponseView c = decode_connect_response(input);
  if (c.error == WireError::None) {
    if (c.iocr_count > kMaxConnectIocrs) std::abort();
    if (c.status.ok() && !c.has_ar) std::abort();
    if (c.has_module_diff) {
      inside(c.module_diff.apis);
      static std::array<char, 256> text{};
      const std::string_view r = module_diff_report(c.module_diff, {}, text);
      if (r.size() > text.size() || (!r.empty() && r.data() != text.data())) std::abort();
    }
  }
  const ConnectRequestView cr = decode_connect_request(input);
  if (cr.error == WireError::None) {
    if (cr.iocr_count == 0 || cr.iocr_count > kMaxConnectIocrs || cr.expected_count > kMaxConnectExpectedBlocks) {
      std::abort();
    }
    inside(std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(cr.ar.block.station_name.data()),
                                         cr.ar.block.station_name.size()));
    for (std::size_t i = 0; i < cr.iocr_count; ++i) inside(cr.iocrs[i].apis);
    for (std::size_t i = 0; i < cr.expected_count; ++i) inside(cr.expected[i].apis);
  }
  std::array<char, 64> status_text{};
  if (describe(c.status, status_text).size() > status_text.size()) std::abort();
  return 0;
}
