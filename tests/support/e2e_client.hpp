#pragma once
// What every end-to-end fixture with the real binaries does through the DDS client: commands with
// their replies, waits on axis states and events, set-point streams, the bus status. The fixtures
// (tests/canopen_e2e, tests/ethercat_e2e) derive from E2eClientTest and add their bus, their
// processes and their diagnostics. Every wait is on the client's data with a bounded timeout.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "client/client.hpp"

namespace drivegate::test {

using namespace std::chrono_literals;

// The last `lines` lines of `text` (all of it when it has fewer).
std::string tail(const std::string& text, std::size_t lines);
// The whole file, "" when it cannot be read.
std::string read_file(const std::string& path);
// A sanitizer's report from a child process lands in its log, not in the test: fails the test
// with the log when `log` holds one.
void expect_no_sanitizer_report(const std::string& log);

class E2eClientTest : public ::testing::Test {
 protected:
  // A new client (the event history starts again).
  void open_client(const client::ClientOptions& options);

  client::CommandRequest request(const std::string& axis, const std::string& kind) const;
  // Sends and waits for the final reply.
  client::CommandResult send(const client::CommandRequest& r, std::chrono::milliseconds timeout = 15s);
  client::CommandResult send(const std::string& axis, const std::string& kind,
                             std::chrono::milliseconds timeout = 15s);
  // Sends and waits for the first reply only: a velocity or torque command runs (and has no final
  // reply) until a later command, the command timeout or the drive ends it.
  client::CommandResult start(const client::CommandRequest& r, std::chrono::milliseconds timeout = 15s);

  [[nodiscard]] client::AxisState state(const std::string& axis) const;
  bool wait_axis(const std::string& axis, const std::function<bool(const client::AxisState&)>& done,
                 std::chrono::milliseconds timeout);
  // Streams a position ramp from the axis' position at `speed` user units per second for
  // `duration`, one set-point every 10 ms as a motion controller would; returns the last target.
  double stream_ramp(const std::string& axis, double speed, std::chrono::milliseconds duration);
  // Every event so far, in arrival order.
  const std::vector<client::AxisEvent>& events();
  // An event of `axis` (empty: bus events) of `kind` whose text or state contains `what`.
  bool wait_event(const std::string& axis, const std::string& kind, const std::string& what,
                  std::chrono::milliseconds timeout);
  [[nodiscard]] std::optional<client::BusStatus> bus_status(const std::string& bus) const;

  std::unique_ptr<client::Client> client_;

 private:
  std::vector<client::AxisEvent> events_;
  std::uint64_t event_cursor_ = 0;
};

}  // namespace drivegate::test
