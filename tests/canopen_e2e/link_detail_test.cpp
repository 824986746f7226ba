// drivegatectl status AXIS against the real daemon and drives: a drive whose boot fails shows the
// step that failed, and once a later boot succeeds the detail says so.
#include <sys/wait.h>

#include <array>
#include <atomic>
#include <cstdio>
#include <thread>

#include "tests/canopen_e2e/e2e_fixture.hpp"

namespace drivegate::test {
namespace {

class CanopenE2eLink : public CanopenE2eUp {
 protected:
  // drivegatectl on this test's domain and namespace: its stdout and stderr.
  std::string ctl(const std::string& args) const {
    const std::string cmd = std::string(DRIVEGATECTL_PATH) + " --domain " + std::to_string(dds_.domain) +
                            " --namespace " + dds_.ns + " --timeout 10 " + args + " 2>&1";
    std::string text;
    FILE* p = ::popen(cmd.c_str(), "r");
    if (p == nullptr) return text;
    std::array<char, 4096> buf{};
    for (std::size_t n = 0; (n = std::fread(buf.data(), 1, buf.size(), p)) > 0;) text.append(buf.data(), n);
    ::pclose(p);
    return text;
  }
  // Runs `status AXIS` until its output contains `what`; the last output is left in `text`.
  bool status_shows(const std::string& axis, const std::string& what, std::chrono::milliseconds timeout,
                    std::string& text) const {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    do {
      text = ctl("status " + axis);
      if (text.find(what) != std::string::npos) return true;
    } while (std::chrono::steady_clock::now() < deadline);
    return false;
  }
};

TEST_F(CanopenE2eLink, StatusShowsTheFailingBootStepAndThenTheRecovery) {
  // The AKD (node 1) goes quiet: its link is lost.
  ASSERT_EQ(sim_->command("silent 1 on"), "ok silent node 1 on");
  ASSERT_TRUE(wait_axis("akd", [](const client::AxisState& s) { return s.link == "lost"; }, 5s)) << diagnostics();

  // Once it is heard again, every boot is refused the vendor-ID (1018h:01): the abort is armed
  // again and again (each one answers one request), so the failure stays until the test ends it.
  ASSERT_EQ(sim_->command("abort 1 0x1018:1 0x08000000"), "ok abort node 1");
  ASSERT_EQ(sim_->command("silent 1 off"), "ok silent node 1 off");
  std::atomic<bool> refuse{true};
  std::thread arm([&] {
    while (refuse) {
      sim_->command("abort 1 0x1018:1 0x08000000");
      std::this_thread::sleep_for(20ms);  // re-arming pace; the gateway retries after >= 1 s
    }
  });
  std::string out;
  const bool failed = status_shows("akd", "node 1 (0x01): identity: read 1018h:01 failed: general error", 20s, out);
  refuse = false;
  arm.join();
  ASSERT_TRUE(failed) << out << diagnostics();
  EXPECT_NE(out.find("(abort 0x08000000)"), std::string::npos) << out;
  EXPECT_NE(out.find("akd: link lost for "), std::string::npos) << "since when: " << out;

  // The next boot succeeds, and the detail says so.
  ASSERT_TRUE(status_shows("akd", "node 1 (0x01) configured", 20s, out)) << out << diagnostics();
  EXPECT_NE(out.find("akd: link operational for "), std::string::npos) << out;
  EXPECT_NE(out.find("akd   1 (0x01)  operational"), std::string::npos) << "the address column: " << out;

  // JSON: the numbers, and the detail in the gateway's own words.
  const std::string json = ctl("--json status akd");
  EXPECT_NE(json.find(R"("bus_type":"canopen","address":1,)"), std::string::npos) << json;
  EXPECT_NE(json.find(R"("link_detail":"node 1 configured")"), std::string::npos) << json;
}

}  // namespace
}  // namespace drivegate::test
