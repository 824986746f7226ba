#pragma once
// Captures for Wireshark's dissectors as an independent judge of our frames: a classic pcap file
// (global header, then one record per frame; link type 1 = Ethernet), and tshark's dissection of it.
#include <unistd.h>

#include <array>
#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/bytes.hpp"
#include "tests/support/run_program.hpp"

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

// `tshark -r FILE -V` of `frames` written to a temporary pcap file (`step_us` apart): the full
// dissection, stdout and stderr. nullopt when tshark is not installed. The file is removed
// afterwards unless KEEP_PCAP is set in the environment.
inline std::optional<std::string> tshark_dissect(const std::vector<std::vector<std::uint8_t>>& frames,
                                                 std::uint32_t step_us = 1000) {
  if (run_program({"tshark", "--version"}).status == 127) return std::nullopt;
  static std::atomic<unsigned> serial{0};
  const auto path = std::filesystem::temp_directory_path() /
                    ("drivegate-tshark-" + std::to_string(::getpid()) + "-" + std::to_string(serial++) + ".pcap");
  write_pcap(path, frames, step_us);
  RunResult r = run_program({"tshark", "-r", path.string(), "-V"});
  if (std::getenv("KEEP_PCAP") == nullptr) std::filesystem::remove(path);
  return std::move(r.output);
}

}  // namespace drivegate::test
