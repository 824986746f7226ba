// Frames the simulator answers dissect cleanly in Debian's tshark (issue 9: "every frame it sends
// and receives must dissect cleanly, no Malformed, CoE fields filled"): a bring-up with SDO
// traffic and an emergency is captured (frames sent and returned), written as a classic pcap file
// (link type 1 = Ethernet) and read with `tshark -V`. Skipped when tshark is not installed.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "tests/ethercat_sim/coe_line.hpp"

namespace drivegate::ethercat::sim {
namespace {

using Bytes = std::vector<std::uint8_t>;

void put32(std::ofstream& f, std::uint32_t v) {
  const std::array<char, 4> b{static_cast<char>(v & 0xFF), static_cast<char>((v >> 8) & 0xFF),
                              static_cast<char>((v >> 16) & 0xFF), static_cast<char>(v >> 24)};
  f.write(b.data(), 4);
}
void put16(std::ofstream& f, std::uint16_t v) {
  const std::array<char, 2> b{static_cast<char>(v & 0xFF), static_cast<char>(v >> 8)};
  f.write(b.data(), 2);
}

// pcap: magic A1B2C3D4, version 2.4, zone 0, sigfigs 0, snaplen, link type 1 (Ethernet).
void write_pcap(const std::filesystem::path& path, const std::vector<Bytes>& frames) {
  std::ofstream f(path, std::ios::binary);
  put32(f, 0xA1B2C3D4);
  put16(f, 2);
  put16(f, 4);
  put32(f, 0);
  put32(f, 0);
  put32(f, 65535);
  put32(f, 1);
  std::uint32_t usec = 0;
  for (const Bytes& fr : frames) {
    put32(f, 1700000000);
    put32(f, usec += 100);
    put32(f, static_cast<std::uint32_t>(fr.size()));
    put32(f, static_cast<std::uint32_t>(fr.size()));
    f.write(reinterpret_cast<const char*>(fr.data()), static_cast<std::streamsize>(fr.size()));
  }
}

std::string run(const std::string& cmd) {
  std::string out;
  FILE* p = popen(cmd.c_str(), "r");
  if (p == nullptr) return out;
  std::array<char, 4096> buf{};
  std::size_t n = 0;
  while ((n = std::fread(buf.data(), 1, buf.size(), p)) > 0) out.append(buf.data(), n);
  pclose(p);
  return out;
}

TEST(EthercatSimTshark, BringUpDissectsCleanly) {
  if (std::system("command -v tshark >/dev/null 2>&1") != 0) GTEST_SKIP() << "tshark not installed";
  std::vector<Bytes> capture;
  test::CoeLine l;
  l.bus.capture = &capture;
  l.bus.brd(reg::kType, 1);
  l.preop();
  std::size_t n = encode_sdo_upload_request(l.req, l.next(), 0x1000, 0);
  l.sdo(std::span(l.req.data(), n));
  n = encode_sdo_upload_request(l.req, l.next(), 0x2001, 0);  // normal upload + segments
  l.sdo(std::span(l.req.data(), n));
  n = encode_sdo_upload_segment_request(l.req, l.next(), false);
  l.sdo(std::span(l.req.data(), n));
  n = encode_sdo_upload_request(l.req, l.next(), 0x3000, 0);  // abort
  l.sdo(std::span(l.req.data(), n));
  n = encode_get_od_list_request(l.req, l.next(), OdListType::All);
  l.put(std::span(l.req.data(), n));
  l.get();
  l.esc.post_emergency(CoeEmergency{0x8100, 0x11, {1, 2, 3, 4, 5}});
  l.get();
  ASSERT_GT(capture.size(), 20U);

  const auto path = std::filesystem::temp_directory_path() / ("drivegate-ecat-sim-" + std::to_string(::getpid()) + ".pcap");
  write_pcap(path, capture);
  const std::string out = run("tshark -r '" + path.string() + "' -V 2>&1");
  if (std::getenv("KEEP_PCAP") == nullptr) std::filesystem::remove(path);
  ASSERT_FALSE(out.empty());
  EXPECT_EQ(out.find("Malformed"), std::string::npos) << out;
  EXPECT_EQ(out.find("Exception"), std::string::npos) << out;
  for (const char* field : {"Type: SDO Res (3)", "Initiate Upload Response: 0x43", "Initiate Upload Response: 0x41",
                            "Abort code: 0x06020000", "Info OpCode: List Res (2)", "Type: EMERGENCY (1)",
                            "Idx=0x2001", "Cmd: 'BRD'", "Working Cnt: 1"}) {
    EXPECT_NE(out.find(field), std::string::npos) << "missing: " << field;
  }
  EXPECT_NE(out.find("Frame " + std::to_string(capture.size()) + ":"), std::string::npos);
}

}  // namespace
}  // namespace drivegate::ethercat::sim
