#pragma once
// End-to-end fixture for the EtherCAT adapter with the real binaries. Per test:
//
//   namespace "sim": drivegate-sim serving the line on veth end b (ESR TrioDrive at 1, a generic
//                    I/O panel at 2, a generic CiA 402 drive with distributed clocks at 3)
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
#include <optional>
#include <string>

#include "tests/canopen_e2e/sim_process.hpp"
#include "tests/daemon/daemon_process.hpp"
#include "tests/support/e2e_client.hpp"
#include "tests/support/netns.hpp"

namespace drivegate::test {

class EthercatE2e : public E2eClientTest {
 protected:
  // Line boot, PDO set-up, DC set-up and DDS discovery on a loaded two-core machine (and under
  // the sanitizers): generous, but bounded.
  static constexpr auto kStartUp = 40s;
  static constexpr auto kCycle = 2ms;

  void SetUp() override;
  void TearDown() override;

  // The config both processes read (the interface differs: each names its own veth end).
  [[nodiscard]] std::string config_text(const std::string& interface) const;

  // drivegated on the test's config, in the "gw" namespace; waits for READY=1.
  void start_gateway();
  void connect_client();

  // enable, with the final reply and the state checked.
  void enable(const std::string& axis);
  void set_mode(const std::string& axis, const std::string& mode);

  // The axis' link is `link` and its drive in `drive_state` ("" any).
  bool wait_link(const std::string& axis, const std::string& link, const std::string& drive_state,
                 std::chrono::milliseconds timeout);
  // Every axis operational in `drive_state`, the panel's inputs valid.
  bool wait_all(const std::string& drive_state, std::chrono::milliseconds timeout);
  using E2eClientTest::bus_status;
  [[nodiscard]] std::optional<client::BusStatus> bus_status() const { return bus_status("ec0"); }
  [[nodiscard]] std::optional<client::IoState> panel() const;

  // One simulator console command, its answer.
  std::string sim(const std::string& command);
  // Asks `command` until `done(answer)` holds; the last answer in `last`.
  bool wait_sim(const std::string& command, const std::function<bool(const std::string&)>& done,
                std::chrono::milliseconds timeout, std::string& last);
  // `drive K` answer's field `key` ("state", "pos", "error", "sync0"), "" when missing.
  static std::string field(const std::string& answer, const std::string& key);

  // Axis states, bus status, the simulator's status and the ends of both logs.
  std::string diagnostics();

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

// The same, for tests that start once the line is in OP: both axes operational and disabled,
// the panel exchanging.
class EthercatE2eUp : public EthercatE2e {
 protected:
  void SetUp() override {
    EthercatE2e::SetUp();
    if (HasFatalFailure() || IsSkipped()) return;
    ASSERT_TRUE(wait_all("switch_on_disabled", kStartUp)) << diagnostics();
  }
};

}  // namespace drivegate::test
