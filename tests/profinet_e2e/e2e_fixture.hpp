#pragma once
// The fixture of the PROFINET end-to-end tests:
//
//   namespace "sim": drivegate-sim serving two AKDs and an IO device on veth end b, which carries
//                    the stations' addresses (the devices come up named, without an address)
//   namespace "gw":  drivegated, the IO controller, on veth end a (192.168.0.1), and the test's
//                    DDS client on that namespace's loopback
//
// Set-up waits until the gateway has found the stations by name, given them their addresses and
// connected them: both axes operational and disabled, the IO device's data valid. Skipped without
// root. The tests: e2e_test.cpp (bring-up, motion, power loss, records), faults_test.cpp (a drive
// fault, a killed gateway, the IO device's bytes).
#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <memory>
#include <sstream>
#include <string>

#include "tests/canopen_e2e/sim_process.hpp"
#include "tests/daemon/daemon_process.hpp"
#include "tests/support/e2e_client.hpp"
#include "tests/support/netns.hpp"

namespace drivegate::test {

class ProfinetE2e : public E2eClientTest {
 protected:
  static constexpr auto kStartUp = 40s;

  // Both processes read it; each names its own veth end. data_hold_factor 60 (960 ms): a loaded
  // two-core machine under the sanitizers held a process for up to 957 ms (30 was too few).
  std::string config_text(const std::string& interface) const {
    std::ostringstream y;
    y << "gateway: { name: pn-e2e, dds: { domain: " << dds_.domain << ", namespace: " << dds_.ns
      << ", interfaces: [lo], duplicate_check: 300ms }, status_rate_hz: 50 }\n"
      << "buses:\n"
      << "  - name: pn0\n"
      << "    type: profinet\n"
      << "    cycle_time: 1ms\n"
      << "    options: { interface: " << interface << ", reduction_ratio: 16, data_hold_factor: 60 }\n"
      << "    devices:\n"
      << "      - { station: akd-x, ip: 192.168.0.10 }\n"
      << "      - { station: akd-y, ip: 192.168.0.11 }\n"
      << "      - { station: io-block, ip: 192.168.0.20 }\n"
      << "    io:\n"
      << "      - name: valves\n"
      << "        station: io-block\n"
      << "        dap_ident: 0x10\n"
      << "        slots:\n"
      << "          - { slot: 1, module_ident: 0x20, submodule_ident: 0x21, inputs: 2 }\n"
      << "          - { slot: 2, module_ident: 0x30, submodule_ident: 0x31, outputs: 2 }\n"
      << "axes:\n"
      << "  - { name: x, bus: pn0, address: 1, device: kollmorgen-akd-profinet, unit: rev, "
         "profinet: { station: akd-x, telegram: 1 } }\n"
      << "  - { name: y, bus: pn0, address: 2, device: kollmorgen-akd-profinet, unit: rev, "
         "profinet: { station: akd-y, telegram: 352 } }\n";
    return y.str();
  }

  void SetUp() override {
    if (const std::string& why = netns_unavailable(); !why.empty()) GTEST_SKIP() << why;
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dds_ = unique_dds(info->name());
    ns_gw_ = std::make_unique<NetNamespace>();
    ns_sim_ = std::make_unique<NetNamespace>();
    veth_ = std::make_unique<VethPair>(ns_gw_.get(), ns_sim_.get());
    ASSERT_TRUE(ns_gw_->ip({"addr", "add", "192.168.0.1/24", "dev", veth_->a()}).ok());
    for (const char* a : {"192.168.0.10/24", "192.168.0.11/24", "192.168.0.20/24"})
      ASSERT_TRUE(ns_sim_->ip({"addr", "add", a, "dev", veth_->b()}).ok());
    config_ = write_config_text(std::string("pn-e2e-") + info->name(), config_text(veth_->a()));
    sim_config_ = write_config_text(std::string("pn-e2e-sim-") + info->name(), config_text(veth_->b()));
    {
      const NetnsScope in(*ns_sim_);
      sim_ = std::make_unique<SimProcess>(sim_config_);
    }
    // One line per device (its MAC), then the ready line.
    std::optional<std::string> ready;
    for (int i = 0; i < 4 && (!ready || ready->find(" devices on profinet ") == std::string::npos); ++i)
      ready = sim_->wait_ready(20s);
    ASSERT_TRUE(ready) << sim_->log();
    ASSERT_EQ(*ready, "drivegate-sim: 3 devices on profinet " + veth_->b() + " (bus pn0)");
    in_gw_ = std::make_unique<NetnsScope>(*ns_gw_);
    ASSERT_NO_FATAL_FAILURE(start_gateway());
    auto options = client::options_for(dds_.domain, dds_.ns, "pn-e2e-client");
    options.interfaces = {"lo"};
    open_client(options);
    ASSERT_NO_FATAL_FAILURE(wait_all_up());
  }

  // drivegated in namespace "gw" (the test thread is in it), up to READY=1.
  void start_gateway() {
    daemon_.reset();
    notify_ = std::make_unique<NotifySocket>();
    daemon_ = std::make_unique<DaemonProcess>(config_, notify_->path());
    ASSERT_TRUE(notify_->wait_for("READY=1", kStartUp)) << daemon_->log();
  }

  // Both axes operational and disabled, the IO device's data valid.
  void wait_all_up() {
    ASSERT_TRUE(client_->wait_until([&] {
      for (const char* axis : {"x", "y"}) {
        const auto s = client_->state(axis);
        if (!s || s->link != "operational" || s->state != "switch_on_disabled") return false;
      }
      const auto v = client_->io_state("valves");
      return v && v->valid;
    }, kStartUp)) << diagnostics();
  }

  // enable, with the final reply and the published state checked.
  void enable(const std::string& axis) {
    const auto r = send(axis, "enable");
    ASSERT_EQ(r.outcome, client::Outcome::Completed) << axis << ": " << r.reason << diagnostics();
    ASSERT_TRUE(wait_axis(axis, [](const client::AxisState& s) { return s.state == "operation_enabled"; }, 5s))
        << axis << diagnostics();
  }

  // One simulator console command, its answer.
  std::string sim(const std::string& command) { return sim_->command(command, 5s); }
  // Sends `command` until `done(answer)` holds; the last answer in `last`.
  bool wait_sim(const std::string& command, const std::function<bool(const std::string&)>& done,
                std::chrono::milliseconds timeout, std::string& last) {
    return sim_->wait_answer(command, done, timeout, last);
  }
  // The `key=` field of `station`'s item in a `status` answer (pn_console.hpp), "" when missing.
  static std::string station_field(const std::string& status, const std::string& station, const std::string& key) {
    const auto at = status.find(" pn0:" + station + " ");
    if (at == std::string::npos) return {};
    const std::string item = status.substr(at, status.find(';', at) - at);
    const auto k = item.find(" " + key + "=");
    if (k == std::string::npos) return {};
    const auto from = k + key.size() + 2;
    return item.substr(from, item.find(' ', from) - from);
  }

  void TearDown() override {
    client_.reset();
    daemon_.reset();
    notify_.reset();
    sim_.reset();
    in_gw_.reset();
    veth_.reset();
    ns_sim_.reset();
    ns_gw_.reset();
    if (config_.empty()) return;  // skipped
    for (const auto& log : {config_ + ".log", sim_config_ + ".sim.log"}) expect_no_sanitizer_report(log);
    if (HasFailure()) return;  // the files stay for a failed test, whose messages name them
    for (const auto& f : {config_, config_ + ".log", sim_config_, sim_config_ + ".sim.log"}) std::filesystem::remove(f);
  }

  std::string diagnostics() {
    std::ostringstream d;
    if (client_) {
      d << "\n--- axes:";
      for (const auto& s : client_->states())
        d << "\n  " << s.axis << ": link " << s.link << ", " << s.state << ", mode " << s.mode << ", velocity " << s.velocity
          << ", fault " << s.fault_code << " " << s.fault_text;
      if (const auto v = client_->io_state("valves")) d << "\n--- valves: valid " << v->valid;
    }
    if (sim_) {
      d << "\n--- simulator: " << sim_->command("status") << "\n  " << sim_->command("io io-block 1") << "\n  "
        << sim_->command("io io-block 2") << "\n" << tail(sim_->log(), 20);
    }
    if (daemon_) d << "\n--- drivegated (end of log):\n" << tail(daemon_->log(), 60);
    return d.str();
  }

  std::unique_ptr<NetNamespace> ns_gw_;
  std::unique_ptr<NetNamespace> ns_sim_;
  std::unique_ptr<VethPair> veth_;
  std::unique_ptr<NetnsScope> in_gw_;
  DdsIsolation dds_{};
  std::string config_;
  std::string sim_config_;
  std::unique_ptr<SimProcess> sim_;
  std::unique_ptr<NotifySocket> notify_;
  std::unique_ptr<DaemonProcess> daemon_;
};

}  // namespace drivegate::test
