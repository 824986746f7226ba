#include "tests/ethercat_e2e/ecat_fixture.hpp"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

namespace drivegate::test {

namespace {

// The last `lines` lines of `text`.
std::string tail(const std::string& text, std::size_t lines) {
  std::size_t at = text.size();
  for (std::size_t n = 0; n <= lines; ++n) {  // one more: the text ends with a newline
    if (at == 0) return text;
    at = text.rfind('\n', at - 1);
    if (at == std::string::npos) return text;
  }
  return text.substr(at + 1);
}

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

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
  for (const auto& log : {config_ + ".log", sim_config_ + ".sim.log"}) {
    const std::string text = read_file(log);
    EXPECT_EQ(text.find("Sanitizer"), std::string::npos) << log << ":\n" << text;
    EXPECT_EQ(text.find("runtime error:"), std::string::npos) << log << ":\n" << text;
  }
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
  client_.reset();
  events_.clear();
  event_cursor_ = 0;
  auto options = client::options_for(dds_.domain, dds_.ns, "ecat-e2e-client");
  options.interfaces = {"lo"};
  client_ = std::make_unique<client::Client>(options);
}

client::CommandRequest EthercatE2e::request(const std::string& axis, const std::string& kind) const {
  client::CommandRequest r;
  r.axis = axis;
  r.kind = kind;
  return r;
}

client::CommandResult EthercatE2e::send(const client::CommandRequest& r, std::chrono::milliseconds timeout) {
  return client_->send(r, true, timeout);
}

client::CommandResult EthercatE2e::send(const std::string& axis, const std::string& kind,
                                        std::chrono::milliseconds timeout) {
  return send(request(axis, kind), timeout);
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

client::AxisState EthercatE2e::state(const std::string& axis) const {
  return client_->state(axis).value_or(client::AxisState{});
}

bool EthercatE2e::wait_axis(const std::string& axis, const std::function<bool(const client::AxisState&)>& done,
                            std::chrono::milliseconds timeout) {
  return client_->wait_until([&] {
    const auto s = client_->state(axis);
    return s && done(*s);
  }, timeout);
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

double EthercatE2e::stream_ramp(const std::string& axis, double speed, std::chrono::milliseconds duration) {
  constexpr auto kPeriod = 10ms;
  const double start = state(axis).position;
  double target = start;
  auto next = std::chrono::steady_clock::now();
  for (auto left = duration; left > 0ms; left -= kPeriod) {
    target += speed * std::chrono::duration<double>(kPeriod).count();
    const std::string error = client_->stream_setpoint(axis, {}, target, 0, 0);
    EXPECT_TRUE(error.empty()) << error;
    // The set-point generator's period (a controller's own clock), not a wait for the gateway.
    next += kPeriod;
    std::this_thread::sleep_until(next);
  }
  return target;
}

const std::vector<client::AxisEvent>& EthercatE2e::events() {
  for (auto& e : client_->events_since(event_cursor_)) events_.push_back(std::move(e));
  return events_;
}

bool EthercatE2e::wait_event(const std::string& axis, const std::string& kind, const std::string& what,
                             std::chrono::milliseconds timeout) {
  return client_->wait_until([&] {
    for (const auto& e : events()) {
      if (e.axis == axis && e.kind == kind &&
          (e.text.find(what) != std::string::npos || e.state.find(what) != std::string::npos))
        return true;
    }
    return false;
  }, timeout);
}

std::optional<client::BusStatus> EthercatE2e::bus_status() const {
  for (const auto& b : client_->buses())
    if (b.bus == "ec0") return b;
  return std::nullopt;
}

std::optional<client::IoState> EthercatE2e::panel() const { return client_->io_state("panel"); }

std::string EthercatE2e::sim(const std::string& command) { return sim_->command(command, 5s); }

bool EthercatE2e::wait_sim(const std::string& command, const std::function<bool(const std::string&)>& done,
                           std::chrono::milliseconds timeout, std::string& last) {
  for (const auto end = std::chrono::steady_clock::now() + timeout;;) {
    last = sim(command);
    if (done(last)) return true;
    if (std::chrono::steady_clock::now() >= end) return false;
    std::this_thread::sleep_for(20ms);  // the pace of the console requests; each answer is the condition
  }
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
