#pragma once
// The base of the end-to-end fixtures of the raw-Ethernet buses (EtherCAT, PROFINET) with the
// real binaries. Per test:
//
//   namespace "sim": drivegate-sim serving the bus on veth end b
//   namespace "gw":  drivegated running the bus on veth end a, and the test's DDS client; both use
//                    loopback alone (gateway.dds.interfaces / ClientOptions::interfaces: lo)
//
// The test thread enters "gw" (NetnsScope) before drivegated is forked and before the client's
// participant exists, so that every socket and thread of the participant is made in "gw" and DDS
// never leaves that namespace's loopback; it leaves "gw" only after the client is gone. The
// namespaces and the pair are unique per process and removed by their destructors, also when a
// test fails. Every wait is on a condition with a bounded timeout: the client's data, the
// simulator's console answers, the daemon's notify socket.
#include <chrono>
#include <functional>
#include <memory>
#include <string>

#include "tests/canopen_e2e/sim_process.hpp"
#include "tests/daemon/daemon_process.hpp"
#include "tests/support/e2e_client.hpp"
#include "tests/support/netns.hpp"

namespace drivegate::test {

class VethE2eTest : public E2eClientTest {
 protected:
  // Bus start-up and DDS discovery on a loaded two-core machine (and under the sanitizers):
  // generous, but bounded.
  static constexpr auto kStartUp = std::chrono::seconds(40);

  // The namespaces and the pair, this test's DDS domain and namespace. Skips the test where
  // namespaces cannot be made (IsSkipped() then).
  void make_network();
  // Both processes' config files, `text(interface)` with each one's veth end, named after `stem`
  // and the test.
  void write_configs(const std::string& stem, const std::function<std::string(const std::string&)>& text);
  // drivegate-sim in "sim" on its config, up to its line `ready` (other lines before it skipped).
  void start_sim(const std::string& ready);
  // The test thread into "gw", drivegated up to READY=1, the client connected.
  void start_gateway_and_client(const std::string& client_name);
  // drivegated on the test's config in "gw" (the test thread is in it), up to READY=1.
  void start_gateway();

  // enable, with the final reply and the published state checked.
  void enable(const std::string& axis);
  // One simulator console command, its answer.
  std::string sim(const std::string& command);
  // Asks `command` until `done(answer)` holds; the last answer in `last`.
  bool wait_sim(const std::string& command, const std::function<bool(const std::string&)>& done,
                std::chrono::milliseconds timeout, std::string& last);

  // The client, the gateway, the simulator, then the namespaces; the files stay for a failed test.
  void TearDown() override;
  // What the fixture can tell about a failure: states, the simulator, the ends of both logs.
  virtual std::string diagnostics() = 0;

  std::unique_ptr<NetNamespace> ns_gw_;
  std::unique_ptr<NetNamespace> ns_sim_;
  std::unique_ptr<VethPair> veth_;
  std::unique_ptr<NetnsScope> in_gw_;
  DdsIsolation dds_{};
  std::string config_;      // drivegated's
  std::string sim_config_;  // drivegate-sim's (its log next to it)
  std::unique_ptr<SimProcess> sim_;
  std::unique_ptr<NotifySocket> notify_;
  std::unique_ptr<DaemonProcess> daemon_;
};

}  // namespace drivegate::test
