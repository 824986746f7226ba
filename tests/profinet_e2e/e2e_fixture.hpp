#pragma once
// The fixture of the PROFINET end-to-end tests (the namespaces, processes and waits:
// tests/support/veth_e2e.hpp): drivegate-sim serves two AKDs and an IO device on veth end b,
// which carries the stations' addresses (the devices come up named, without an address);
// drivegated, the IO controller, is on veth end a (192.168.0.1).
//
// Set-up waits until the gateway has found the stations by name, given them their addresses and
// connected them: both axes operational and disabled, the IO device's data valid. Skipped without
// root. The tests: e2e_test.cpp (bring-up, motion, power loss, records), faults_test.cpp (a drive
// fault, a killed gateway, the IO device's bytes).
#include <gtest/gtest.h>

#include <sstream>
#include <string>

#include "tests/support/veth_e2e.hpp"

namespace drivegate::test {

class ProfinetE2e : public VethE2eTest {
 protected:
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
    make_network();
  if (IsSkipped()) return;
    ASSERT_TRUE(ns_gw_->ip({"addr", "add", "192.168.0.1/24", "dev", veth_->a()}).ok());
    for (const char* a : {"192.168.0.10/24", "192.168.0.11/24", "192.168.0.20/24"})
      ASSERT_TRUE(ns_sim_->ip({"addr", "add", a, "dev", veth_->b()}).ok());
    write_configs("pn-e2e", [this](const std::string& interface) { return config_text(interface); });
    // One line per device (its MAC), then this one.
    ASSERT_NO_FATAL_FAILURE(start_sim("drivegate-sim: 3 devices on profinet " + veth_->b() + " (bus pn0)"));
    ASSERT_NO_FATAL_FAILURE(start_gateway_and_client("pn-e2e-client"));
    ASSERT_NO_FATAL_FAILURE(wait_all_up());
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

  std::string diagnostics() override {
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
};

}  // namespace drivegate::test
