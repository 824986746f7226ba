#include "tests/canopen_e2e/e2e_fixture.hpp"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <sstream>

namespace drivegate::test {

namespace {

// drivegated --check-config on the file; its exit status, the output in `out`.
int check_config(const std::string& file, std::string& out) {
  const std::string cmd = std::string(DRIVEGATED_PATH) + " --check-config " + file + " 2>&1";
  FILE* p = ::popen(cmd.c_str(), "r");
  if (p == nullptr) return -1;
  char buf[512];
  while (std::fgets(buf, sizeof buf, p) != nullptr) out += buf;
  const int status = ::pclose(p);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace

std::string three_drives_config(const std::string& gateway, const DdsIsolation& dds, const BusAddress& bus) {
  std::ostringstream y;
  y << "gateway: { name: " << gateway << ", dds: { domain: " << dds.domain << ", namespace: " << dds.ns
    << " }, status_rate_hz: 50 }\n"
    << "buses:\n"
    << "  - name: can0\n"
    << "    type: canopen\n"
    << "    cycle_time: 4ms\n"
    << "    options: { transport: udp-multicast, interface: 127.0.0.1, group: " << bus.group << ", port: " << bus.port
    << ", bitrate: 1000000 }\n"
    << "axes:\n"
    // 2^20 counts per motor rev on a 5 mm screw. Homing 34: the next index pulse in the positive
    // direction, an AKD method (akd-canopen-part2-ds402.md §9.2) that moves the motor.
    << "  - { name: akd, bus: can0, address: 1, device: kollmorgen-akd, unit: mm, mechanics: { feed: 5 },\n"
    << "      defaults: { velocity: 50, acceleration: 500, deceleration: 500 },\n"
    << "      homing: { method: 34, search_velocity: 10, zero_velocity: 5, acceleration: 200 } }\n"
    // Positions in revolutions; 35 (the current position is home) is in the profile's list (§6).
    << "  - { name: nord, bus: can0, address: 2, device: nord-sk500p,\n"
    << "      defaults: { velocity: 10, acceleration: 100, deceleration: 100 }, homing: { method: 35 } }\n"
    // 10000 counts per revolution as commissioned in DS6; 35 is the one method the profile lists.
    << "  - { name: sd6, bus: can0, address: 3, device: stoeber-sd6, mechanics: { encoder_counts_per_rev: 10000 },\n"
    << "      defaults: { velocity: 10, acceleration: 100, deceleration: 100 }, homing: { method: 35 } }\n";
  return y.str();
}

void CanopenE2e::SetUp() {
  static unsigned slot = 0;
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  dds_ = unique_dds(info->name());
  bus_ = unique_bus_address(slot++);
  yaml_ = three_drives_config("e2e", dds_, bus_);
  config_ = write_config_text(std::string("canopen-e2e-") + info->name(), yaml_);
  configs_.push_back(config_);
  std::string plan;
  ASSERT_EQ(check_config(config_, plan), 0) << plan;
  ASSERT_NE(plan.find("load:"), std::string::npos) << plan;

  sim_ = std::make_unique<SimProcess>(config_);
  const auto ready = sim_->wait_ready(10s);
  ASSERT_TRUE(ready) << sim_->log();
  ASSERT_EQ(*ready, "drivegate-sim: 3 nodes on udp-multicast " + bus_.group + ":" + std::to_string(bus_.port));

  start_gateway();
  if (HasFatalFailure()) return;
  connect_client();
}

void CanopenE2e::connect_client() { open_client(client::options_for(dds_.domain, dds_.ns, "e2e-client")); }

void CanopenE2e::TearDown() {
  // The client first, so that nothing it waits for outlives the processes; then the gateway
  // before its drives, as a real cell is switched off.
  client_.reset();
  daemon_.reset();
  notify_.reset();
  sim_.reset();
  // A sanitizer's report from drivegated or drivegate-sim lands in their logs, not in this test.
  for (const auto& c : configs_) {
    for (const char* suffix : {".log", ".sim.log"}) expect_no_sanitizer_report(c + suffix);
  }
  // The files stay for a failed test, whose messages name them.
  if (HasFailure()) return;
  for (const auto& c : configs_) {
    for (const char* suffix : {"", ".log", ".sim.log"}) std::filesystem::remove(c + suffix);
  }
}

void CanopenE2e::start_gateway() {
  // A restarted daemon gets a copy of the config, so that its log does not overwrite the first's.
  const std::string file = daemon_ ? write_config_text("canopen-e2e-restart", yaml_) : config_;
  if (file != config_) configs_.push_back(file);
  daemon_.reset();
  notify_ = std::make_unique<NotifySocket>();
  daemon_ = std::make_unique<DaemonProcess>(file, notify_->path());
  ASSERT_TRUE(notify_->wait_for("READY=1", kStartUp)) << daemon_->log();
}

void CanopenE2e::kill_gateway() {
  const auto rc = daemon_->terminate(SIGKILL, 5s);
  ASSERT_TRUE(rc.has_value());
  EXPECT_EQ(*rc, 128 + SIGKILL);
}

bool CanopenE2e::wait_all(const std::string& drive_state, std::chrono::milliseconds timeout) {
  return client_->wait_until([&] {
    for (const char* axis : {"akd", "nord", "sd6"}) {
      const auto s = client_->state(axis);
      if (!s || s->link != "operational" || s->state != drive_state) return false;
    }
    return true;
  }, timeout);
}

bool CanopenE2e::keep_alive_until(const std::string& axis, double position, double velocity, double torque,
                                  const std::function<bool(const client::AxisState&)>& done,
                                  std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < end) {
    const std::string error = client_->stream_setpoint(axis, {}, position, velocity, torque);
    EXPECT_TRUE(error.empty()) << error;
    if (wait_axis(axis, done, 20ms)) return true;
  }
  return false;
}

std::string CanopenE2e::diagnostics() {
  std::ostringstream d;
  d << "\n--- axes:";
  if (client_) {
    for (const auto& s : client_->states())
      d << "\n  " << s.axis << ": link " << s.link << ", " << s.state << ", mode " << s.mode << ", pos " << s.position
        << ", vel " << s.velocity << ", fault 0x" << std::hex << s.fault_code << std::dec << " " << s.fault_text;
  }
  if (sim_) d << "\n--- simulator: " << sim_->command("status") << "\n" << tail(sim_->log(), 20);
  if (daemon_) d << "\n--- drivegated (end of log):\n" << tail(daemon_->log(), 60);
  d << "\n--- files:";
  for (const auto& c : configs_) d << " " << c << "{,.log,.sim.log}";
  return d.str();
}

}  // namespace drivegate::test
