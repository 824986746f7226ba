// `drivegated --scan profinet:IFACE --write-config F` as a process against simulated PROFINET IO
// devices on the other end of a veth pair: an in-process PnSimNetwork (two AKDs, a generic IO
// device) behind a PnSimLinkRunner served from a thread in its own network namespace. The table
// lists all three with their fields and profile, `drivegated --check-config F` accepts what it
// wrote; a missing and a down interface are one error line each. The write actions (--set-name,
// --set-ip, --permanent, --signal) on a fourth device that comes up without name and address, and
// their refusals. Skipped without root (tests/support/netns.hpp).
#include <gtest/gtest.h>

#include <poll.h>
#include <sys/wait.h>

#include <array>
#include <atomic>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

#include "adapters/link/raw_socket_link.hpp"
#include "adapters/link/udp_endpoint.hpp"
#include "adapters/profinet/link/profinet_link.hpp"
#include "adapters/profinet/sim/akd_persona.hpp"
#include "adapters/profinet/sim/generic_io_persona.hpp"
#include "adapters/profinet/sim/pn_sim_link.hpp"
#include "config/loader.hpp"
#include "config/profinet/plan.hpp"
#include "tests/support/netns.hpp"

namespace drivegate::profinet {
namespace {

using drivegate::test::NetNamespace;
using drivegate::test::NetnsScope;
using drivegate::test::VethPair;
using namespace std::chrono_literals;

PnDeviceConfig device(std::uint8_t n, const std::string& name, std::uint16_t vendor, std::uint16_t id,
                      const std::string& type) {
  PnDeviceConfig c;
  c.dcp.mac = {0x00, 0x1B, 0x1B, 0x00, 0x0A, n};
  c.dcp.type_of_station = type;
  c.dcp.vendor_id = vendor;
  c.dcp.device_id = id;
  c.dcp.name_of_station = name;
  c.dcp.ip.address = {192, 168, 0, static_cast<std::uint8_t>(10 + n)};
  c.dcp.ip.netmask = {255, 255, 255, 0};
  c.activity = {0xA0000000U + n, 0, 0, {1, 2, 3, 4, 5, 6, 7, n}};
  return c;
}

// Runs a command in the caller's network namespace; its output (stdout and stderr) and exit code.
std::pair<int, std::string> run(const std::string& command) {
  std::string out;
  FILE* p = ::popen((command + " 2>&1").c_str(), "r");
  if (p == nullptr) return {-1, "popen failed"};
  std::array<char, 4096> buf{};
  for (std::size_t n; (n = std::fread(buf.data(), 1, buf.size(), p)) > 0;) out.append(buf.data(), n);
  const int status = ::pclose(p);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

class ProfinetScanVeth : public ::testing::Test {
 protected:
  void SetUp() override {
    if (const std::string& why = drivegate::test::netns_unavailable(); !why.empty()) GTEST_SKIP() << why;
    ns_ctl_ = std::make_unique<NetNamespace>();
    ns_dev_ = std::make_unique<NetNamespace>();
    veth_ = std::make_unique<VethPair>(ns_ctl_.get(), ns_dev_.get());
    veth_->set(VethPair::End::B, {"promisc", "on"});
    ASSERT_TRUE(ns_ctl_->ip({"addr", "add", "192.168.0.1/24", "dev", veth_->a()}).ok());
    // 192.168.0.14: for a device that gets it by DCP (ProfinetScanVethWrite).
    for (const char* a : {"192.168.0.11/24", "192.168.0.12/24", "192.168.0.13/24", "192.168.0.14/24"})
      ASSERT_TRUE(ns_dev_->ip({"addr", "add", a, "dev", veth_->b()}).ok());
    add_devices();
    link::RawSocketOptions o;
    o.interface = veth_->b();
    link_ = std::make_unique<link::RawSocketLink>(kFrameRules, o);
    const std::string dev_if = veth_->b();
    runner_ = std::make_unique<PnSimLinkRunner>(net_, *link_, [dev_if](const link::Ipv4Endpoint& local) {
      link::UdpOptions u = rpc_udp_options(dev_if, local.port);
      u.address = local.address;
      return std::make_unique<link::UdpEndpoint>(u);
    });
    {
      const NetnsScope in(*ns_dev_);
      runner_->open();
    }
    server_ = std::thread([this] { serve(); });
  }

  void TearDown() override { stop_serving(); }

  virtual void add_devices() {
    akd_a_ = std::make_unique<AkdPersona>(AkdPersonaConfig{});
    akd_b_ = std::make_unique<AkdPersona>(AkdPersonaConfig{});
    io_ = std::make_unique<GenericIoPersona>(io_config());
    // [sim] The AKD's DCP identity as the profile's profidrive section names it.
    net_.add(device(1, "drive-a", 0x0118, 0x0501, "AKD"), *akd_a_);
    net_.add(device(2, "drive-b", 0x0118, 0x0501, "AKD"), *akd_b_);
    net_.add(device(3, "io-c", 0x0FEE, 0x0042, "IO-1"), *io_);
  }

  static GenericIoPersonaConfig io_config() {
    return {{{0, 0, 0x10, {{1, 0x10, 0, 0}}}, {0, 1, 0x20, {{1, 0x21, 2, 0}}}}, 0x0FEE, "IO-1", "1"};
  }

  // The devices stop answering; their state can then be read from this thread.
  void stop_serving() {
    stop_ = true;
    if (server_.joinable()) server_.join();
  }

  // The devices answer until the test ends; waits for traffic at most 1 ms at a time.
  void serve() {
    std::vector<pollfd> fds;
    for (const int fd : runner_->wait_fds()) fds.push_back({fd, POLLIN, 0});
    const core::SteadyClock clock;
    while (!stop_) {
      runner_->run_once(clock.now());
      (void)::poll(fds.data(), fds.size(), 1);
    }
  }

  std::pair<int, std::string> drivegated(const std::string& args) {
    const NetnsScope in(*ns_ctl_);
    return run(std::string(DRIVEGATED_PATH) + " " + args);
  }

  std::unique_ptr<NetNamespace> ns_ctl_, ns_dev_;
  std::unique_ptr<VethPair> veth_;
  std::unique_ptr<AkdPersona> akd_a_, akd_b_;
  std::unique_ptr<GenericIoPersona> io_;
  PnSimNetwork net_;
  std::unique_ptr<link::RawSocketLink> link_;
  std::unique_ptr<PnSimLinkRunner> runner_;
  std::thread server_;
  std::atomic<bool> stop_{false};
};

TEST_F(ProfinetScanVeth, ListsEveryDeviceAndWritesAConfigThatChecks) {
  const auto written = std::filesystem::temp_directory_path() /
                       ("drivegate-pn-scan-test-" + std::to_string(::getpid()) + ".yaml");
  std::filesystem::remove(written);
  const auto scan = drivegated("--scan profinet:" + veth_->a() + " --write-config " + written.string());
  EXPECT_EQ(scan.first, 0) << scan.second;
  const std::string& t = scan.second;
  EXPECT_NE(t.find("profinet raw ethernet " + veth_->a()), std::string::npos) << t;
  EXPECT_NE(t.find(": 3 devices"), std::string::npos) << t;
  // Station, IP and MAC; role; vendor and device ID; TypeOfStation; profile.
  for (const std::string row : {"drive-a 192.168.0.11 00:1b:1b:00:0a:01  -            IO device  0x00000118  0x00000501",
                                "drive-b 192.168.0.12 00:1b:1b:00:0a:02  -            IO device  0x00000118  0x00000501",
                                "io-c 192.168.0.13 00:1b:1b:00:0a:03     -            IO device  0x00000FEE  0x00000042"})
    EXPECT_NE(t.find(row), std::string::npos) << row << "\n" << t;
  EXPECT_NE(t.find("drive-a 192.168.0.11 00:1b:1b:00:0a:01: kollmorgen-akd-profinet: vendor 0x0118 device 0x0501 is its "
                   "profidrive identity\n"),
            std::string::npos)
      << t;
  EXPECT_NE(t.find("drive-b 192.168.0.12 00:1b:1b:00:0a:02: kollmorgen-akd-profinet:"), std::string::npos) << t;
  EXPECT_NE(t.find("io-c 192.168.0.13 00:1b:1b:00:0a:03: no profile: vendor 0x0FEE device 0x0042 matches no device "
                   "profile"),
            std::string::npos)
      << t;
  EXPECT_NE(t.find("\"IO-1\""), std::string::npos) << t;
  EXPECT_EQ(t.find("warning:"), std::string::npos) << t;
  EXPECT_NE(t.find("wrote " + written.string()), std::string::npos) << t;

  const auto check = run(std::string(DRIVEGATED_PATH) + " --check-config " + written.string());
  std::ifstream f(written);
  std::stringstream yaml;
  yaml << f.rdbuf();
  EXPECT_EQ(check.first, 0) << check.second << "\n" << yaml.str();
  const config::Plan plan = config::load_plan(written.string());
  const auto& o = plan.buses.at(0).section<config::ProfinetBusOptions>();
  EXPECT_EQ(o.interface, veth_->a());
  ASSERT_EQ(o.stations.size(), 3U);
  EXPECT_EQ(o.stations[2].name, "io-c");
  EXPECT_EQ(o.stations[2].ip, 0xC0A8000DU);
  ASSERT_EQ(plan.buses[0].axes.size(), 2U);
  EXPECT_EQ(plan.buses[0].axes[1].section<config::ProfinetAxisSpec>().station, "drive-b");
  EXPECT_EQ(plan.buses[0].axes[1].section<config::ProfinetAxisSpec>().telegram, 352);
  EXPECT_NE(yaml.str().find("# - { name: io-3, station: io-c, gsdml: FILE }"), std::string::npos) << yaml.str();
  std::filesystem::remove(written);
}

TEST_F(ProfinetScanVeth, AMissingOrDownInterfaceIsOneLine) {
  auto r = drivegated("--scan profinet:dgnosuch0");
  EXPECT_EQ(r.first, 1);
  EXPECT_EQ(r.second, "drivegated: --scan profinet:dgnosuch0: cannot open the network: profinet: no network interface "
                      "'dgnosuch0'; give the name of the Ethernet port the devices are on\n");
  veth_->set_up(VethPair::End::A, false);
  r = drivegated("--scan profinet:" + veth_->a());
  EXPECT_EQ(r.first, 1);
  EXPECT_EQ(r.second, "drivegated: --scan profinet:" + veth_->a() + ": cannot open the network: profinet: interface '" +
                          veth_->a() + "' is down; bring it up with 'ip link set " + veth_->a() + " up'\n");
}

// A fourth device (a generic IO device) that comes up without NameOfStation and IP address, as a
// fresh or replaced one does; drive-b has a connection (DCP Set of name and IP refused, BlockError 6).
class ProfinetScanVethWrite : public ProfinetScanVeth {
 protected:
  void add_devices() override {
    ProfinetScanVeth::add_devices();
    fresh_ = std::make_unique<GenericIoPersona>(io_config());
    PnDeviceConfig c = device(4, "", 0x0FEE, 0x0042, "IO-1");
    c.dcp.ip = {};
    net_.add(c, *fresh_);
    net_.device(1).dcp().set_in_operation(true);
  }

  // The scan with the fastest Identify (ResponseDelayFactor 1: 400 ms) and `args`.
  std::pair<int, std::string> scan(const std::string& args) {
    return drivegated("--scan profinet:" + veth_->a() + "?response_delay=1 " + args);
  }
  std::string error_prefix() const { return "drivegated: --scan profinet:" + veth_->a() + "?response_delay=1: "; }

  std::unique_ptr<GenericIoPersona> fresh_;
};

TEST_F(ProfinetScanVethWrite, ADeviceWithoutANameIsNamedAndAddressedThenListed) {
  const auto r = scan("--set-name 00:1b:1b:00:0a:04=io-d --set-ip 00:1b:1b:00:0a:04=192.168.0.14/24 --permanent");
  EXPECT_EQ(r.first, 0) << r.second;
  const std::string& t = r.second;
  EXPECT_EQ(t.find("00:1b:1b:00:0a:04: NameOfStation set to \"io-d\" (was none), permanent (kept over a power loss)\n"
                   "00:1b:1b:00:0a:04 (\"io-d\"): IP suite set to 192.168.0.14/255.255.255.0 gateway 0.0.0.0 (was none), "
                   "permanent (kept over a power loss)\n"
                   "profinet raw ethernet "),
            0U)
      << t;
  EXPECT_NE(t.find(": 4 devices"), std::string::npos) << t;
  EXPECT_NE(t.find("io-d 192.168.0.14 00:1b:1b:00:0a:04     -            IO device  0x00000FEE  0x00000042"), std::string::npos)
      << t;
  EXPECT_EQ(t.find("warning:"), std::string::npos) << t;
  stop_serving();
  DcpResponder& d = net_.device(3).dcp();
  EXPECT_EQ(d.name_of_station(), "io-d");
  EXPECT_EQ(d.ip().address, (std::array<std::uint8_t, 4>{192, 168, 0, 14}));
  d.power_cycle();  // permanent: kept
  EXPECT_EQ(d.name_of_station(), "io-d");
  EXPECT_EQ(d.ip().netmask, (std::array<std::uint8_t, 4>{255, 255, 255, 0}));
}

TEST_F(ProfinetScanVethWrite, WithoutPermanentTheDeviceForgetsAtAPowerLoss) {
  const auto r = scan("--set-name 00:1b:1b:00:0a:04=io-d");
  EXPECT_EQ(r.first, 0) << r.second;
  EXPECT_EQ(r.second.find("00:1b:1b:00:0a:04: NameOfStation set to \"io-d\" (was none), temporary (forgotten at a power "
                          "loss; the controller finds its stations by name: --permanent keeps it)\n"),
            0U)
      << r.second;
  EXPECT_NE(r.second.find("io-d (no IP) 00:1b:1b:00:0a:04"), std::string::npos) << r.second;
  stop_serving();
  DcpResponder& d = net_.device(3).dcp();
  EXPECT_EQ(d.name_of_station(), "io-d");
  d.power_cycle();
  EXPECT_EQ(d.name_of_station(), "");
}

TEST_F(ProfinetScanVethWrite, ANameAnotherDeviceHasIsRefusedUnsent) {
  auto r = scan("--set-name 00:1b:1b:00:0a:04=drive-a");
  EXPECT_EQ(r.first, 1) << r.second;
  EXPECT_NE(r.second.find("\n" + error_prefix() +
                          "--set-name 00:1b:1b:00:0a:04=drive-a: \"drive-a\" is the name of 00:1b:1b:00:0a:01 already "
                          "(two devices with one name: the controller would use neither); nothing sent\n"),
            std::string::npos)
      << r.second;
  EXPECT_NE(r.second.find(": 4 devices"), std::string::npos) << r.second;  // the listing still runs
  // Its own name again is no conflict.
  r = scan("--set-name 00:1b:1b:00:0a:01=drive-a --permanent");
  EXPECT_EQ(r.first, 0) << r.second;
  EXPECT_EQ(r.second.find("00:1b:1b:00:0a:01: NameOfStation set to \"drive-a\" (was \"drive-a\"), permanent"), 0U)
      << r.second;
  stop_serving();
  EXPECT_EQ(net_.device(3).dcp().counters().sets, 0U);
  EXPECT_EQ(net_.device(3).dcp().name_of_station(), "");
  EXPECT_EQ(net_.device(0).dcp().counters().sets, 1U);
}

TEST_F(ProfinetScanVethWrite, AMacNobodyHasABadArgumentAndARefusalAreOneLineEach) {
  auto r = scan("--set-ip 00:1b:1b:00:0a:09=192.168.0.19/24");
  EXPECT_EQ(r.first, 1) << r.second;
  EXPECT_NE(r.second.find("\n" + error_prefix() + "--set-ip 00:1b:1b:00:0a:09=192.168.0.19/24: no device answers at "
                          "00:1b:1b:00:0a:09 (DCP Identify all on " + veth_->a() + "); nothing sent\n"),
            std::string::npos)
      << r.second;
  // Checked before anything is sent: one line, no listing, exit 2.
  r = scan("--set-ip 00:1b:1b:00:0a:04=192.168.0.14/24 --set-name 00:1b:1b:00:0a:04=IO-D");
  EXPECT_EQ(r, std::make_pair(2, error_prefix() + "--set-name 00:1b:1b:00:0a:04=IO-D: \"IO-D\" is no NameOfStation: the "
                                                  "name has upper-case letters; PROFINET names are lower case\n"));
  // drive-b has a connection: its BlockError in words; the actions after it are not run.
  r = scan("--set-ip 00:1b:1b:00:0a:02=192.168.0.22/24 --signal drive-a");
  EXPECT_EQ(r.first, 1) << r.second;
  EXPECT_NE(r.second.find(error_prefix() + "--set-ip 00:1b:1b:00:0a:02=192.168.0.22/24: the device refused the value "
                                           "(BlockError): device in operation, SET not possible (a controller is "
                                           "connected to it: stop that first)\n"),
            std::string::npos)
      << r.second;
  EXPECT_EQ(r.second.find("Signal sent"), std::string::npos) << r.second;
  stop_serving();
  EXPECT_EQ(net_.device(3).dcp().counters().sets, 0U);
  EXPECT_EQ(net_.device(1).dcp().counters().set_errors, 1U);
  EXPECT_EQ(net_.device(0).dcp().counters().signals, 0U);
}

TEST_F(ProfinetScanVethWrite, SignalFlashesTheDeviceByNameOrMac) {
  const auto r = scan("--signal drive-b --signal 00:1b:1b:00:0a:04");
  EXPECT_EQ(r.first, 0) << r.second;
  EXPECT_EQ(r.second.find("00:1b:1b:00:0a:02 (\"drive-b\"): Signal sent, its LED flashes\n"
                          "00:1b:1b:00:0a:04: Signal sent, its LED flashes\n"),
            0U)
      << r.second;
  stop_serving();
  EXPECT_EQ(net_.device(1).dcp().counters().signals, 1U);
  EXPECT_EQ(net_.device(3).dcp().counters().signals, 1U);
  EXPECT_EQ(net_.device(0).dcp().counters().signals, 0U);
  EXPECT_EQ(net_.device(2).dcp().counters().signals, 0U);
}

}  // namespace
}  // namespace drivegate::profinet
