#include "tests/ethercat_e2e/ecat_fixture.hpp"

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
  make_network();
  if (IsSkipped()) return;
  write_configs("ecat-e2e", [this](const std::string& interface) { return config_text(interface); });
  ASSERT_NO_FATAL_FAILURE(start_sim("drivegate-sim: 3 slaves on ethercat " + veth_->b() + " (bus ec0)"));
  ASSERT_NO_FATAL_FAILURE(start_gateway_and_client("ecat-e2e-client"));
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
