// `drivegated --scan` as a process: drivegate-sim's drives on a udp-multicast group of this test
// process, the table it prints, the skeleton it writes and that `--check-config` accepts it; and
// the ways a scan is refused.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include "daemon/bus_lock.hpp"
#include "tests/canopen_e2e/sim_process.hpp"
#include "tests/daemon/daemon_process.hpp"

namespace drivegate::test {
namespace {

using namespace std::chrono_literals;

struct Outcome {
  int status = -1;
  std::string out;  // stdout and stderr
};

Outcome drivegated(const std::string& args) {
  Outcome r;
  const std::string cmd = std::string(DRIVEGATED_PATH) + " " + args + " 2>&1";
  FILE* p = ::popen(cmd.c_str(), "r");
  if (p == nullptr) return r;
  char buf[512];
  while (std::fgets(buf, sizeof buf, p) != nullptr) r.out += buf;
  const int status = ::pclose(p);
  r.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

// The scan's WHERE for a bus of unique_bus_address() (tests/canopen_e2e/sim_process.hpp).
std::string where(const BusAddress& bus) {
  return "'canopen:udp-multicast?group=" + bus.group + "&port=" + std::to_string(bus.port) + "&interface=127.0.0.1'";
}

std::string drives_config(const BusAddress& bus) {
  std::ostringstream y;
  y << "gateway: { name: scan-sim }\n"
    << "buses:\n"
    << "  - name: can0\n"
    << "    type: canopen\n"
    << "    cycle_time: 4ms\n"
    << "    options: { transport: udp-multicast, interface: 127.0.0.1, group: " << bus.group << ", port: " << bus.port
    << ", bitrate: 1000000 }\n"
    << "axes:\n"
    << "  - { name: akd, bus: can0, address: 1, device: kollmorgen-akd, mechanics: { encoder_counts_per_rev: 1048576 } }\n"
    << "  - { name: nord, bus: can0, address: 2, device: nord-sk500p, mechanics: { encoder_counts_per_rev: 4096 } }\n"
    << "  - { name: sd6, bus: can0, address: 3, device: stoeber-sd6, mechanics: { encoder_counts_per_rev: 131072 } }\n";
  return y.str();
}

bool has_line(const std::string& text, const std::string& regex) {
  return std::regex_search(text, std::regex(regex, std::regex::multiline));
}

TEST(ScanProcess, FindsTheSimulatedDrivesAndWritesAConfigurationCheckConfigAccepts) {
  const BusAddress bus = unique_bus_address(0);
  const std::string sim_config = write_config_text("scan-sim", drives_config(bus));
  SimProcess sim(sim_config);
  ASSERT_TRUE(sim.wait_ready(10s)) << sim.log();

  const std::string file = sim_config + ".scanned.yaml";
  std::filesystem::remove(file);
  const Outcome scan = drivegated("--scan " + where(bus) + " --write-config " + file);
  ASSERT_EQ(scan.status, 0) << scan.out;
  EXPECT_TRUE(has_line(scan.out, "^canopen udp-multicast " + bus.group + ":" + std::to_string(bus.port) +
                                     " on 127.0.0.1, bit rate not given \\(500 kbit/s assumed for the answer times "
                                     "and the load estimate\\): 3 devices \\(scan took [0-9]+ ms\\)$"))
      << scan.out;
  EXPECT_TRUE(has_line(scan.out, "^1 \\(01h\\) +0x00020192 +CiA 402 drive: servo drive +0x0000006A +0x3630304D .*\"M006\" +- +\"0.20\" +kollmorgen-akd$"))
      << scan.out;
  EXPECT_TRUE(has_line(scan.out, "^2 \\(02h\\) +0x00010192 .*\"NORD SK 500P\" .* generic-cia402$")) << scan.out;
  EXPECT_TRUE(has_line(scan.out, "^3 \\(03h\\) +0x00020192 .*0x000000B9 .* stoeber-sd6$")) << scan.out;
  EXPECT_TRUE(has_line(scan.out, "its SDO channel 4$")) << scan.out;
  EXPECT_TRUE(has_line(scan.out, "^wrote " + file + "$")) << scan.out;

  const Outcome check = drivegated("--check-config " + file);
  EXPECT_EQ(check.status, 0) << check.out << "\n" << scan.out;
  EXPECT_NE(check.out.find("axis kollmorgen-akd-1"), std::string::npos) << check.out;
  std::ifstream text_in(file);
  std::ostringstream text;
  text << text_in.rdbuf();
  // The sim runs at 1 Mbit/s; the scan was not told, so the skeleton's 500000 is marked.
  EXPECT_TRUE(has_line(text.str(), "^      bitrate: 500000 +# CHECK: the bus' bit rate \\(not read from the interface"))
      << text.str();
  const YAML::Node written = YAML::LoadFile(file);
  EXPECT_EQ(written["buses"][0]["options"]["group"].as<std::string>(), bus.group);
  EXPECT_EQ(written["buses"][0]["options"]["port"].as<int>(), bus.port);
  ASSERT_EQ(written["axes"].size(), 3U);
  EXPECT_EQ(written["axes"][0]["device"].as<std::string>(), "kollmorgen-akd");
  EXPECT_EQ(written["axes"][1]["address"].as<int>(), 2);
  EXPECT_EQ(written["axes"][2]["device"].as<std::string>(), "stoeber-sd6");

  // The file is kept unless --force.
  std::ofstream(file) << "# mine\n";
  const Outcome again = drivegated("--scan " + where(bus) + " --write-config " + file);
  EXPECT_EQ(again.status, 1);
  EXPECT_NE(again.out.find("exists; it is kept (--force replaces it)"), std::string::npos) << again.out;
  std::ifstream in(file);
  std::ostringstream kept;
  kept << in.rdbuf();
  EXPECT_EQ(kept.str(), "# mine\n");
  const Outcome forced = drivegated("--scan " + where(bus) + " --write-config " + file + " --force");
  EXPECT_EQ(forced.status, 0) << forced.out;
  EXPECT_EQ(drivegated("--check-config " + file).status, 0);
  std::filesystem::remove(file);
}

TEST(ScanProcess, ADriveOnAnSd6ExtraChannelIsWarnedAboutAndNoAxisInTheSkeleton) {
  // The field case: an SD6 at 3, whose SDO channel 2 answers on node-ID 35 (SD6 §5.3), and a
  // drive at 35.
  const BusAddress bus = unique_bus_address(3);
  std::string config = drives_config(bus);
  config = config.substr(0, config.find("  - { name: akd")) +
           "  - { name: sd6, bus: can0, address: 3, device: stoeber-sd6, mechanics: { encoder_counts_per_rev: 131072 } }\n"
           "  - { name: gen, bus: can0, address: 35, device: generic-cia402, mechanics: { encoder_counts_per_rev: 4096 } }\n";
  SimProcess sim(write_config_text("scan-sim-conflict", config));
  ASSERT_TRUE(sim.wait_ready(10s)) << sim.log();
  const std::string file = ::testing::TempDir() + "scan-conflict-" + std::to_string(::getpid()) + ".yaml";
  std::filesystem::remove(file);
  const Outcome scan = drivegated("--scan " + where(bus) + " --write-config " + file);
  ASSERT_EQ(scan.status, 0) << scan.out;
  EXPECT_TRUE(has_line(scan.out, "^3 \\(03h\\) .* stoeber-sd6$")) << scan.out;
  EXPECT_TRUE(has_line(scan.out, "^35 \\(23h\\) .* \\(conflict\\)$")) << scan.out;
  EXPECT_TRUE(has_line(scan.out, "^    1000h: answered twice, differently: ")) << scan.out;
  EXPECT_TRUE(has_line(scan.out, "^warning: node-ID 35: more than one device answers on 623h/5A3h \\(a node-ID "
                                 "conflict, or another drive's extra SDO channel: node 3 is a stoeber-sd6 whose SDO "
                                 "channel 2 is node-ID 35\\); its identity cannot be trusted$"))
      << scan.out;
  const YAML::Node written = YAML::LoadFile(file);
  ASSERT_EQ(written["axes"].size(), 1U) << scan.out;
  EXPECT_EQ(written["axes"][0]["address"].as<int>(), 3);
  EXPECT_EQ(drivegated("--check-config " + file).status, 0);
  std::filesystem::remove(file);
}

TEST(ScanProcess, NobodyThereSaysSoWithinASecond) {
  const BusAddress bus = unique_bus_address(1);
  const Outcome scan = drivegated("--scan " + where(bus));
  ASSERT_EQ(scan.status, 0) << scan.out;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(scan.out, m, std::regex(": no devices answered \\(scan took ([0-9]+) ms\\)"))) << scan.out;
  EXPECT_LT(std::stoi(m[1]), 1000);
}

TEST(ScanProcess, RefusedWhileAGatewayHoldsTheBus) {
  const BusAddress bus = unique_bus_address(2);
  const daemon::BusLock lock("canopen udp-multicast " + bus.group + ":" + std::to_string(bus.port));
  const Outcome scan = drivegated("--scan " + where(bus));
  EXPECT_EQ(scan.status, 1);
  EXPECT_NE(scan.out.find("is already driven by process " + std::to_string(::getpid())), std::string::npos) << scan.out;
}

TEST(ScanProcess, RefusalsAreOneClearLine) {
  // This kernel may or may not have CAN; either way there is no interface of this name.
  Outcome r = drivegated("--scan canopen:dgscan9");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("drivegated: --scan canopen:dgscan9: cannot open the bus: socketcan: "), std::string::npos) << r.out;
  // No interface of this name either: the scan never sends on a real network.
  r = drivegated("--scan ethercat:dgscan9");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("drivegated: --scan ethercat:dgscan9: "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("dgscan9"), r.out.rfind("dgscan9")) << "the link's line names the interface: " << r.out;
  r = drivegated("--scan profinet:dgscan9");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("drivegated: --scan profinet:dgscan9: cannot open the network: profinet: "), std::string::npos)
      << r.out;
  r = drivegated("--scan sim:x");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("cannot scan sim: sim has no bus scan (scans: canopen, ethercat, profinet)"), std::string::npos) << r.out;
  r = drivegated("--scan can0");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("expected TYPE:WHERE"), std::string::npos) << r.out;
  r = drivegated("--scan canopen:can0 --scan-timeout 0s");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.out.find("--scan-timeout takes a duration above 0"), std::string::npos) << r.out;
  r = drivegated("--write-config x.yaml");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.out.find("go with --scan"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace drivegate::test
