#pragma once
// Captures for Wireshark's dissectors as an independent judge of our frames: a classic pcap file
// (global header, then one record per frame; link type 1 = Ethernet), and a command's output.
#include <array>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/bytes.hpp"

namespace drivegate::test {

namespace pcap_detail {
inline void put32(std::ofstream& f, std::uint32_t v) {
  std::array<std::uint8_t, 4> b{};
  core::put_u32(b, 0, v);
  f.write(reinterpret_cast<const char*>(b.data()), b.size());
}
inline void put16(std::ofstream& f, std::uint16_t v) {
  std::array<std::uint8_t, 2> b{};
  core::put_u16(b, 0, v);
  f.write(reinterpret_cast<const char*>(b.data()), b.size());
}
}  // namespace pcap_detail

// pcap: magic A1B2C3D4 (little-endian file), version 2.4, zone 0, sigfigs 0, snaplen, link type 1;
// the frames `step_us` apart.
inline void write_pcap(const std::filesystem::path& path, const std::vector<std::vector<std::uint8_t>>& frames,
                       std::uint32_t step_us = 1000) {
  using pcap_detail::put16;
  using pcap_detail::put32;
  std::ofstream f(path, std::ios::binary);
  put32(f, 0xA1B2C3D4);
  put16(f, 2);
  put16(f, 4);
  put32(f, 0);
  put32(f, 0);
  put32(f, 65535);
  put32(f, 1);
  std::uint32_t usec = 0;
  for (const auto& fr : frames) {
    put32(f, 1700000000);
    put32(f, usec += step_us);
    put32(f, static_cast<std::uint32_t>(fr.size()));
    put32(f, static_cast<std::uint32_t>(fr.size()));
    f.write(reinterpret_cast<const char*>(fr.data()), static_cast<std::streamsize>(fr.size()));
  }
}

// What a shell command prints on standard output ("" when it cannot start).
inline std::string command_output(const std::string& cmd) {
  std::string out;
  FILE* p = popen(cmd.c_str(), "r");
  if (p == nullptr) return out;
  std::array<char, 4096> buf{};
  std::size_t n = 0;
  while ((n = std::fread(buf.data(), 1, buf.size(), p)) > 0) out.append(buf.data(), n);
  pclose(p);
  return out;
}

}  // namespace drivegate::test
