#pragma once
// End-to-end fixture for the EtherCAT adapter with the real binaries (the namespaces, processes
// and waits: tests/support/veth_e2e.hpp). drivegate-sim serves the line on veth end b: an ESR
// TrioDrive at 1, a generic I/O panel at 2, a generic CiA 402 drive with distributed clocks at 3.
#include <chrono>
#include <functional>
#include <optional>
#include <string>

#include "tests/support/veth_e2e.hpp"

namespace drivegate::test {

class EthercatE2e : public VethE2eTest {
 protected:
  static constexpr auto kCycle = std::chrono::milliseconds(2);

  void SetUp() override;

  // The config both processes read (the interface differs: each names its own veth end).
  [[nodiscard]] std::string config_text(const std::string& interface) const;

  void set_mode(const std::string& axis, const std::string& mode);

  // The axis' link is `link` and its drive in `drive_state` ("" any).
  bool wait_link(const std::string& axis, const std::string& link, const std::string& drive_state,
                 std::chrono::milliseconds timeout);
  // Every axis operational in `drive_state`, the panel's inputs valid.
  bool wait_all(const std::string& drive_state, std::chrono::milliseconds timeout);
  using E2eClientTest::bus_status;
  [[nodiscard]] std::optional<client::BusStatus> bus_status() const { return bus_status("ec0"); }
  [[nodiscard]] std::optional<client::IoState> panel() const;

  // `drive K` answer's field `key` ("state", "pos", "error", "sync0"), "" when missing.
  static std::string field(const std::string& answer, const std::string& key);

  // Axis states, bus status, the simulator's status and the ends of both logs.
  std::string diagnostics() override;
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
