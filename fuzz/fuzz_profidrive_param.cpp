// The PROFIdrive parameter-access decoders (profiles/profidrive/param_access.hpp) on whatever a
// drive returns through record 47: decode_param_response and decode_param_request, then
// check_response between the two and the fault-buffer reader on the decoded words.
// Invariants: every block's data lies inside the input and holds count x format size bytes; a
// decoded response re-encodes (encode_param_response) to bytes that decode to the same header and
// blocks; a decoded read request re-encodes to the input bytes exactly; a decoded change request
// with 41h..43h formats re-encodes to bytes that decode to the same addresses and values.
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "profiles/profidrive/fault_buffer.hpp"
#include "profiles/profidrive/param_access.hpp"

namespace {

using namespace drivegate::profidrive;

std::span<const std::uint8_t> input;

void inside(std::span<const std::uint8_t> s) {
  if (s.empty()) return;
  if (s.data() < input.data() || s.data() + s.size() > input.data() + input.size()) std::abort();
}

bool same_block(const ValueBlock& a, const ValueBlock& b) {
  if (a.format != b.format || a.count != b.count || a.data.size() != b.data.size()) return false;
  for (std::size_t i = 0; i < a.data.size(); ++i) {
    if (a.data[i] != b.data[i]) return false;
  }
  return true;
}

void check_blocks(std::span<const ValueBlock> blocks) {
  for (const ValueBlock& b : blocks) {
    inside(b.data);
    if (b.data.size() != format_size(b.format) * b.count) std::abort();
    if (b.is_error() && b.count != 1 && b.count != 2) std::abort();
    for (std::size_t i = 0; i < b.count; ++i) (void)b.value(i);
    (void)param_error_text(b.error_number());
  }
}

void check_response_roundtrip(const ParamResponse& r) {
  static std::array<std::uint8_t, kMaxParamRecord> out{};
  const EncodeResult e = encode_param_response(out, r);
  if (e.error == ParamError::TooLong) return;  // the decoder reads records of any length
  if (e.error != ParamError::None) std::abort();
  const ResponseResult again = decode_param_response(std::span<const std::uint8_t>(out).first(e.size));
  if (again.error != ParamError::None) std::abort();
  const ParamResponse& a = again.response;
  if (a.reference != r.reference || a.response_id != r.response_id || a.axis != r.axis || a.count != r.count ||
      a.block_count != r.block_count)
    std::abort();
  for (std::size_t i = 0; i < r.block_count; ++i) {
    if (!same_block(a.blocks[i], r.blocks[i])) std::abort();
  }
}

void check_request_roundtrip(const ParamRequest& q) {
  static std::array<std::uint8_t, kMaxParamRecord> out{};
  if (q.id == RequestId::Read) {
    const EncodeResult e = encode_read_request(out, q.reference, q.addresses(), q.axis);
    if (e.error != ParamError::None || e.size != input.size()) std::abort();
    for (std::size_t i = 0; i < e.size; ++i) {
      if (out[i] != input[i]) std::abort();
    }
    return;
  }
  static std::array<std::array<std::uint32_t, kMaxElements>, kMaxParameters> values{};
  std::array<ParamChange, kMaxParameters> changes{};
  for (std::size_t i = 0; i < q.count; ++i) {
    const ValueBlock& b = q.values[i];
    if (b.format != format::kByte && b.format != format::kWord && b.format != format::kDWord) return;
    for (std::size_t k = 0; k < b.count; ++k) values[i][k] = b.value(k);
    changes[i] = ParamChange{q.params[i], b.format, std::span<const std::uint32_t>(values[i]).first(b.count)};
  }
  const EncodeResult e = encode_change_request(out, q.reference, std::span<const ParamChange>(changes).first(q.count), q.axis);
  if (e.error == ParamError::TooLong) return;
  if (e.error != ParamError::None) std::abort();
  const RequestResult again = decode_param_request(std::span<const std::uint8_t>(out).first(e.size));
  if (again.error != ParamError::None || again.request.count != q.count) std::abort();
  for (std::size_t i = 0; i < q.count; ++i) {
    if (!(again.request.params[i] == q.params[i]) || !same_block(again.request.values[i], q.values[i])) std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 4096) return 0;
  input = std::span<const std::uint8_t>(data, size);

  const ResponseResult r = decode_param_response(input);
  // On an error the header fields are what the input said; only the blocks decoded so far count.
  if (r.response.block_count > kMaxParameters || r.response.block_count > r.response.count) std::abort();
  if (r.error == ParamError::None && (r.response.count == 0 || r.response.count > kMaxParameters)) std::abort();
  check_blocks(r.response.values());
  if (r.error == ParamError::None) check_response_roundtrip(r.response);

  const RequestResult q = decode_param_request(input);
  if (q.error == ParamError::None) {
    check_blocks(std::span<const ValueBlock>(q.request.values).first(q.request.id == RequestId::Change ? q.request.count : 0));
    check_request_roundtrip(q.request);
  }
  if (r.error == ParamError::None && q.error == ParamError::None) {
    (void)to_string(check_response(q.request, r.response).mismatch);
  }

  // The fault-buffer reader fed with the words of each block.
  FaultBufferReader reader(8, 2);
  std::array<std::uint16_t, 256> words{};
  for (const ValueBlock& b : r.response.values()) {
    if (const auto n = u16_values(b, words)) reader.on_values(std::span<const std::uint16_t>(words).first(*n));
  }
  (void)reader.snapshot().current();
  return 0;
}
