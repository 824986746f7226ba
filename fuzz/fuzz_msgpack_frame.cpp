// decode_msgpack_frame on arbitrary datagrams (the udp-multicast transport's receive path,
// adapters/canopen/transport/msgpack_frame.hpp). Invariants: a decoded frame is valid(); it
// encodes into at most kMsgpackFrameMaxSize bytes; those bytes decode to the same frame and
// timestamp; and encoding that again gives the same bytes (the encoder is canonical).
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <span>

#include "adapters/canopen/transport/msgpack_frame.hpp"

namespace {

using drivegate::canopen::CanFrame;

bool same_frame(const CanFrame& a, const CanFrame& b) {
  if (a.id != b.id || a.dlc != b.dlc || a.extended != b.extended || a.remote != b.remote) return false;
  const auto pa = a.payload();
  const auto pb = b.payload();
  return std::memcmp(pa.data(), pb.data(), pa.size()) == 0;
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace drivegate::canopen;
  const auto d = decode_msgpack_frame(std::span<const std::uint8_t>(data, size));
  if (d.error != MsgpackFrameError::None) return 0;
  if (!d.frame.valid()) std::abort();

  std::array<std::uint8_t, kMsgpackFrameMaxSize> first{};
  const std::size_t n = encode_msgpack_frame(d.frame, d.timestamp_s, first);
  if (n == 0 || n > first.size()) std::abort();
  const auto again = decode_msgpack_frame(std::span<const std::uint8_t>(first.data(), n));
  if (again.error != MsgpackFrameError::None || !same_frame(d.frame, again.frame) ||
      !same_bits(d.timestamp_s, again.timestamp_s) || again.error_frame) {
    std::abort();
  }
  std::array<std::uint8_t, kMsgpackFrameMaxSize> second{};
  if (encode_msgpack_frame(again.frame, again.timestamp_s, second) != n || first != second) std::abort();
  return 0;
}
