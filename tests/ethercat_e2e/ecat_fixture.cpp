#include "tests/ethercat_e2e/ecat_fixture.hpp"

#include <unistd.h>

#include <filesystem>
#include <sstream>

namespace drivegate::test {

std::string EthercatE2e::config_text(const std::string& interface) const {
  std::ostringstream y;
  // duplicate_check short: the gateway is alone in its namespace. status_rate_hz 50 as in the demo.
  y << "gateway: { name: ecat-e2e, dds: { domain: " << dds_.domain << ", namespace: " << dds_.ns
    << ", interfaces: [lo], duplicate_check: 300ms }, status_rate_hz: 50 }\n"
    << "buses:\n"
    << "  - name: ec0\n"
    << "    type: ethercat\n"
    << "    cycle_time: " << kCycle.count() << "ms\n"
    // A loaded two-core machine (and the sanitizers) can hold either process for tens of ms:
    // lost_cycles 100 and a 400 ms SM watchdog keep such a hiccup from losing a slave or faulting
    // a drive, while a real loss still shows within a fraction of a second. The boot retries are
    // short so that a slave that comes back is taken up quickly.
    << "    options: { interface: " << interface
    << ", lost_cycles: 100, sm_watchdog: 400ms, boot_retry: 200ms, boot_retry_max: 1s, sdo_timeout: 2s }\n"
    << "    io:\n"
    << "      - { name: panel, position: 2, vendor_id: 0x99, product_code: 0x1000, inputs: 2, outputs: 2 }\n"
    << "axes:\n"
    << "  - { name: esr, bus: ec0, address: 1, device: esr-triodrive, mechanics: { encoder_counts_per_rev: 4096 } }\n"
    << "  - { name: gen, bus: ec0, address: 3, device: generic-cia402, mechanics: { encoder_counts_per_rev: 4096 } }\n";
  return y.str();
}

void EthercatE2e::SetUp() {
  if (const std::string& why = netns_unavailable(); !why.empty()) GTEST_SKIP() << why;
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  dds_ = unique_dds(info->name());
  ns_gw_ = std::make_unique<NetNamespace>();
  ns_sim_ = std::make_unique<NetNamespace>();
  veth_ = std::make_unique<VethPair>(ns_gw_.get(), ns_sim_.get());
  config_ = write_config_text(std::string("ecat-e2e-") + info->name(), config_text(veth_->a()));
  sim_config_ = write_config_text(std::string("ecat-e2e-sim-") + info->name(), config_text(veth_->b()));
  {
    // Forked from this thread while it is in "sim": the simulator's raw socket opens there.
    const NetnsScope in(*ns_sim_);
    sim_ = std::make_unique<SimProcess>(sim_config_);
  }
  const auto ready = sim_->wait_ready(20s);
  ASSERT_TRUE(ready) << sim_->log();
  ASSERT_EQ(*ready, "drivegate-sim: 3 slaves on ethercat " + veth_->b() + " (bus ec0)");

  in_gw_ = std::make_unique<NetnsScope>(*ns_gw_);
  start_gateway();
  if (HasFatalFailure()) return;
  connect_client();
}

void EthercatE2e::TearDown() {
  // The client first (its participant lives in "gw"), then the gateway before its drives, then
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
  // The files stay for a failed test, whose messages name them.
  if (HasFailure()) return;
  for (const auto& f : {config_, config_ + ".log", sim_config_, sim_config_ + ".sim.log"}) std::filesystem::remove(f);
}

void EthercatE2e::start_gateway() {
  daemon_.reset();
  notify_ = std::make_unique<NotifySocket>();
  daemon_ = std::make_unique<DaemonProcess>(config_, notify_->path());
  ASSERT_TRUE(notify_->wait_for("READY=1", kStartUp)) << daemon_->log();
}

void EthercatE2e::connect_client() {
  auto options = client::options_for(dds_.domain, dds_.ns, "ecat-e2e-client");
  options.interfaces = {"lo"};
  open_client(options);
}

void EthercatE2e::enable(const std::string& axis) {
  const auto r = send(axis, "enable");
  ASSERT_EQ(r.outcome, client::Outcome::Completed) << axis << ": " << r.reason << diagnostics();
  ASSERT_TRUE(wait_axis(axis, [](const client::AxisState& s) { return s.state == "operation_enabled"; }, 5s))
      << axis << diagnostics();
}

void EthercatE2e::set_mode(const std::string& axis, const std::string& mode) {
  auto m = request(axis, "set_mode");
  m.mode = mode;
  const auto r = send(m);
  ASSERT_EQ(r.outcome, client::Outcome::Completed) << axis << " " << mode << ": " << r.reason << diagnostics();
}

bool EthercatE2e::wait_link(const std::string& axis, const std::string& link, const std::string& drive_state,
                            std::chrono::milliseconds timeout) {
  return wait_axis(axis, [&](const client::AxisState& s) {
    return s.link == link && (drive_state.empty() || s.state == drive_state);
  }, timeout);
}

bool EthercatE2e::wait_all(const std::string& drive_state, std::chrono::milliseconds timeout) {
  return client_->wait_until([&] {
    for (const char* axis : {"esr", "gen"}) {
      const auto s = client_->state(axis);
      if (!s || s->link != "operational" || s->state != drive_state) return false;
    }
    const auto p = panel();
    return p && p->valid;
  }, timeout);
}

std::optional<client::IoState> EthercatE2e::panel() const { return client_->io_state("panel"); }

std::string EthercatE2e::sim(const std::string& command) { return sim_->command(command, 5s); }

bool EthercatE2e::wait_sim(const std::string& command, const std::function<bool(const std::string&)>& done,
                           std::chrono::milliseconds timeout, std::string& last) {
  return sim_->wait_answer(command, done, timeout, last);
}

std::string EthercatE2e::field(const std::string& answer, const std::string& key) {
  const auto at = answer.find(" " + key + "=");
  if (at == std::string::npos) return {};
  const auto from = at + key.size() + 2;
  const auto end = answer.find_first_of(" ;", from);
  return answer.substr(from, end == std::string::npos ? std::string::npos : end - from);
}

std::string EthercatE2e::diagnostics() {
  std::ostringstream d;
  if (client_) {
    d << "\n--- axes:";
    for (const auto& s : client_->states())
      d << "\n  " << s.axis << ": link " << s.link << ", " << s.state << ", mode " << s.mode << ", pos " << s.position
        << ", fault 0x" << std::hex << s.fault_code << std::dec << " " << s.fault_text;
    if (const auto b = bus_status())
      d << "\n--- bus: running " << b->running << " healthy " << b->healthy << " cycles " << b->cycles << " sent "
        << b->frames_sent << " received " << b->frames_received << " lost " << b->frames_lost << " errors "
        << b->errors;
    if (const auto p = panel()) d << "\n--- panel: valid " << p->valid;
  }
  if (sim_) {
    d << "\n--- simulator: " << sim_->command("status") << "\n  " << sim_->command("drive 1") << "\n  "
      << sim_->command("drive 3") << "\n  " << sim_->command("io 2") << "\n" << tail(sim_->log(), 20);
  }
  if (daemon_) d << "\n--- drivegated (end of log):\n" << tail(daemon_->log(), 60);
  d << "\n--- files: " << config_ << "{,.log} " << sim_config_ << ".sim.log";
  return d.str();
}

}  // namespace drivegate::test
