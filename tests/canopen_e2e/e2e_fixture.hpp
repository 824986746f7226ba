#pragma once
// End-to-end fixture for the CANopen adapter with the real binaries: per test a config with one
// canopen bus on udp-multicast (a group of this test process, so tests run in parallel)
// and three drives (Kollmorgen AKD on node 1, NORD SK 500P on node 2, STÖBER SD6 on node 3), the
// simulated drives in a drivegate-sim process, drivegated on the same config, and a DDS client on
// the test's own domain and namespace. Every wait is on a condition: the client's data, the
// simulator's answers, the daemon's notify socket.
#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "tests/canopen_e2e/sim_process.hpp"
#include "tests/daemon/daemon_process.hpp"
#include "tests/support/e2e_client.hpp"

namespace drivegate::test {

// The three drives on one canopen bus: 4 ms SYNC at 1 Mbit/s (57 % estimated load, which
// --check-config accepts), axis defaults so that pp moves need no rates of their own, and a homing
// method each device profile lists.
std::string three_drives_config(const std::string& gateway, const DdsIsolation& dds, const BusAddress& bus);

class CanopenE2e : public E2eClientTest {
 protected:
  static constexpr auto kStartUp = 20s;  // DDS discovery, daemon start-up and the drives' boot

  void SetUp() override;
  void TearDown() override;

  // drivegated on the test's config (again, after it was killed); waits for READY=1.
  void start_gateway();
  void kill_gateway();
  // A new DDS client (and event history).
  void connect_client();

  // Every axis' link operational and its drive in `drive_state`.
  bool wait_all(const std::string& drive_state, std::chrono::milliseconds timeout);
  // Streams the set-point (the keep-alive of pv, vl and tq) every 20 ms until `done` holds.
  bool keep_alive_until(const std::string& axis, double position, double velocity, double torque,
                        const std::function<bool(const client::AxisState&)>& done, std::chrono::milliseconds timeout);
  using E2eClientTest::bus_status;
  [[nodiscard]] std::optional<client::BusStatus> bus_status() const { return bus_status("can0"); }

  // What a failure message needs: axis states, the simulator's status, the ends of both logs.
  std::string diagnostics();

  DdsIsolation dds_{};
  BusAddress bus_{};
  std::string yaml_;
  std::string config_;
  std::vector<std::string> configs_;  // this test's config files (with .log and .sim.log next to them)
  std::unique_ptr<SimProcess> sim_;
  std::unique_ptr<NotifySocket> notify_;
  std::unique_ptr<DaemonProcess> daemon_;
};

// The same, for tests that start once every axis is up: link operational, switch on disabled.
class CanopenE2eUp : public CanopenE2e {
 protected:
  void SetUp() override {
    CanopenE2e::SetUp();
    if (HasFatalFailure()) return;
    ASSERT_TRUE(wait_all("switch_on_disabled", kStartUp)) << diagnostics();
  }
};

}  // namespace drivegate::test
