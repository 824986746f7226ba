#pragma once
// Ethernet II + IPv4 + UDP around a DCE/RPC datagram, for captures tshark reads
// (tshark_test.cpp). IPv4 header without options [RFC 791], its checksum computed; the UDP
// checksum is 0, "not computed", which IPv4 allows [RFC 768].
#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace drivegate::profinet::test {

struct UdpEndpoint {
  std::array<std::uint8_t, 6> mac{};
  std::array<std::uint8_t, 4> ip{};
  std::uint16_t port = 0;
};

inline std::vector<std::uint8_t> udp_frame(const UdpEndpoint& src, const UdpEndpoint& dst,
                                           std::span<const std::uint8_t> payload, std::uint16_t ip_id) {
  std::vector<std::uint8_t> f;
  auto be16 = [&f](std::size_t v) {
    f.push_back(static_cast<std::uint8_t>((v >> 8) & 0xFF));
    f.push_back(static_cast<std::uint8_t>(v & 0xFF));
  };
  f.insert(f.end(), dst.mac.begin(), dst.mac.end());
  f.insert(f.end(), src.mac.begin(), src.mac.end());
  be16(0x0800);
  const std::size_t ip_start = f.size();
  f.push_back(0x45);  // version 4, IHL 5
  f.push_back(0x00);
  be16(20 + 8 + payload.size());
  be16(ip_id);
  be16(0x4000);  // don't fragment
  f.push_back(64);  // TTL
  f.push_back(17);  // UDP
  be16(0);          // checksum, below
  f.insert(f.end(), src.ip.begin(), src.ip.end());
  f.insert(f.end(), dst.ip.begin(), dst.ip.end());
  std::uint32_t sum = 0;
  for (std::size_t i = ip_start; i < ip_start + 20; i += 2) sum += static_cast<std::uint32_t>((f[i] << 8) | f[i + 1]);
  while (sum > 0xFFFF) sum = (sum & 0xFFFF) + (sum >> 16);
  const auto checksum = static_cast<std::uint16_t>(~sum & 0xFFFF);
  f[ip_start + 10] = static_cast<std::uint8_t>(checksum >> 8);
  f[ip_start + 11] = static_cast<std::uint8_t>(checksum & 0xFF);
  be16(src.port);
  be16(dst.port);
  be16(8 + payload.size());
  be16(0);
  f.insert(f.end(), payload.begin(), payload.end());
  return f;
}

}  // namespace drivegate::profinet::test
