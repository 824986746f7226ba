// FrameParser (adapters/ethercat/wire/frame.hpp) on whatever arrives on the raw socket.
// Invariants: every datagram's data and WKC lie inside the frame and inside the EtherCAT length;
// a well-formed untagged frame without C or reserved bits is rebuilt byte for byte by FrameBuilder from the
// parsed datagrams (same headers, data, WKCs and padding) and parses again to the same count.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "adapters/ethercat/wire/frame.hpp"
#include "core/bytes.hpp"

namespace {

using namespace drivegate::ethercat;

constexpr std::size_t kMaxDatagrams = kMaxEcatLength / kDatagramOverhead + 1;  // 12 bytes each at least

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 4096) return 0;
  const std::span<const std::uint8_t> frame(data, size);
  FrameParser p(frame);
  std::array<Datagram, kMaxDatagrams> seen{};
  std::size_t n = 0;
  Datagram d;
  while (p.next(d)) {
    const std::size_t end = p.info().first_datagram_offset + p.info().ecat_length;
    if (d.data_offset + d.data.size() != d.wkc_offset || d.wkc_offset + kWkcSize > end || end > size) std::abort();
    if (d.data.data() != data + d.data_offset) std::abort();
    if (n >= seen.size()) std::abort();
    seen[n++] = d;
  }
  if (p.error() != FrameError::None || p.info().vlan || size > kMaxFrameSize) return 0;
  const std::uint16_t ecat_word = drivegate::core::get_u16({data, size}, kEthernetHeaderSize);
  if (ecat_word & 0x0800) return 0;  // reserved bit: the builder writes 0
  for (std::size_t i = 0; i < n; ++i) {
    // C bit and the reserved bits 11-13 of the length word: the builder writes 0 there.
    const std::size_t at = seen[i].header_offset + 6;
    if (seen[i].header.circulating || (data[at + 1] & 0x38) != 0) return 0;
  }
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  MacAddress dst{}, src{};
  std::copy(data, data + 6, dst.begin());
  std::copy(data + 6, data + 12, src.begin());
  FrameBuilder b(buf, dst, src);
  for (std::size_t i = 0; i < n; ++i) {
    const DatagramHeader& h = seen[i].header;
    const AddResult r = b.add(h.command, h.index, h.address, h.length, seen[i].data, h.irq, seen[i].wkc);
    if (!r.ok() || r.slot.data_offset != seen[i].data_offset) std::abort();
  }
  const auto rebuilt = b.finish();
  const std::size_t used = p.info().first_datagram_offset + p.info().ecat_length;
  if (rebuilt.size() < used || !std::equal(rebuilt.begin(), rebuilt.begin() + static_cast<std::ptrdiff_t>(used), data)) {
    std::abort();
  }
  std::size_t again = 0;
  if (validate_frame(rebuilt, &again) != FrameError::None || again != n) std::abort();
  return 0;
}
