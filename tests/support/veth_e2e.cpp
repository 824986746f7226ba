#include "tests/support/veth_e2e.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <optional>

namespace drivegate::test {

using namespace std::chrono_literals;

void VethE2eTest::make_network() {
  if (const std::string& why = netns_unavailable(); !why.empty()) GTEST_SKIP() << why;
  dds_ = unique_dds(::testing::UnitTest::GetInstance()->current_test_info()->name());
  ns_gw_ = std::make_unique<NetNamespace>();
  ns_sim_ = std::make_unique<NetNamespace>();
  veth_ = std::make_unique<VethPair>(ns_gw_.get(), ns_sim_.get());
}

void VethE2eTest::write_configs(const std::string& stem, const std::function<std::string(const std::string&)>& text) {
  const std::string name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
  config_ = write_config_text(stem + "-" + name, text(veth_->a()));
  sim_config_ = write_config_text(stem + "-sim-" + name, text(veth_->b()));
}

void VethE2eTest::start_sim(const std::string& ready) {
  {
    // Forked from this thread while it is in "sim": the simulator's raw socket opens there.
    const NetnsScope in(*ns_sim_);
    sim_ = std::make_unique<SimProcess>(sim_config_);
  }
  std::optional<std::string> line;
  for (int i = 0; i < 16; ++i) {
    line = sim_->wait_ready(20s);
    if (!line || *line == ready) break;
  }
  ASSERT_TRUE(line) << sim_->log();
  ASSERT_EQ(*line, ready) << sim_->log();
}

void VethE2eTest::start_gateway_and_client(const std::string& client_name) {
  in_gw_ = std::make_unique<NetnsScope>(*ns_gw_);
  ASSERT_NO_FATAL_FAILURE(start_gateway());
  auto options = client::options_for(dds_.domain, dds_.ns, client_name);
  options.interfaces = {"lo"};
  open_client(options);
}

void VethE2eTest::start_gateway() {
  daemon_.reset();
  notify_ = std::make_unique<NotifySocket>();
  daemon_ = std::make_unique<DaemonProcess>(config_, notify_->path());
  ASSERT_TRUE(notify_->wait_for("READY=1", kStartUp)) << daemon_->log();
}

void VethE2eTest::enable(const std::string& axis) {
  const auto r = send(axis, "enable");
  ASSERT_EQ(r.outcome, client::Outcome::Completed) << axis << ": " << r.reason << diagnostics();
  ASSERT_TRUE(wait_axis(axis, [](const client::AxisState& s) { return s.state == "operation_enabled"; }, 5s))
      << axis << diagnostics();
}

std::string VethE2eTest::sim(const std::string& command) { return sim_->command(command, 5s); }

bool VethE2eTest::wait_sim(const std::string& command, const std::function<bool(const std::string&)>& done,
                           std::chrono::milliseconds timeout, std::string& last) {
  return sim_->wait_answer(command, done, timeout, last);
}

void VethE2eTest::TearDown() {
  // The client first (its participant lives in "gw"), then the gateway before its devices, then
  // the namespaces: this thread leaves "gw" before it is deleted.
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

}  // namespace drivegate::test
