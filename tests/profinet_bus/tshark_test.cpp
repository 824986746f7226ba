// The bus' whole bring-up as it goes over the wire (DCP identify and Set IP, Connect, PrmEnd,
// ApplicationReady, the RT class 1 frames both ways, the I&M0 read, a record-47 exchange,
// Release on close), captured at the controller's transport and dissected by tshark: nothing
// malformed, no expert error or warning, every PNIO status OK. Skipped without tshark.
#include <gtest/gtest.h>

#include <optional>
#include <string>
#include <vector>

#include "tests/profinet_bus/bus_harness.hpp"
#include "tests/profinet_rpc/udp_frame.hpp"
#include "tests/support/param_request.hpp"
#include "tests/support/pcap.hpp"

namespace drivegate::profinet::test {
namespace {

using Capture = std::vector<std::vector<std::uint8_t>>;

constexpr MacAddress kControllerMac{0x02, 0x00, 0x00, 0x00, 0x00, 0x01};

// The simulated devices' MACs by their configured address (the harness' stations).
MacAddress mac_of(const std::array<std::uint8_t, 4>& ip) {
  if (ip == std::array<std::uint8_t, 4>{192, 168, 0, 1}) return kControllerMac;
  return sim_mac(ip[3] == 10 ? 1 : ip[3] == 11 ? 2 : 3);
}

class RecordingLink final : public link::Link {
 public:
  RecordingLink(std::unique_ptr<link::Link> inner, Capture& capture) : inner_(std::move(inner)), capture_(capture) {}
  void open() override { inner_->open(); }
  void close() noexcept override { inner_->close(); }
  [[nodiscard]] bool is_open() const noexcept override { return inner_->is_open(); }
  link::SendResult send(std::span<const link::FrameView> frames) noexcept override {
    for (const auto f : frames) record(f);
    return inner_->send(frames);
  }
  std::size_t receive(std::span<link::FrameBuffer> out) noexcept override {
    const std::size_t n = inner_->receive(out);
    for (std::size_t i = 0; i < n; ++i) record(out[i].view());
    return n;
  }
  [[nodiscard]] int wait_fd() const noexcept override { return -1; }
  link::LinkState poll_state(core::TimePoint now) noexcept override { return inner_->poll_state(now); }
  [[nodiscard]] link::LinkState state() const noexcept override { return inner_->state(); }
  [[nodiscard]] link::LinkCounters counters() const noexcept override { return inner_->counters(); }
  [[nodiscard]] std::string describe() const override { return inner_->describe(); }

 private:
  // Every frame but the cyclic ones after the first 100 (tshark's time grows with each).
  void record(std::span<const std::uint8_t> f) {
    if (decode_ethernet(f).frame_class == FrameClass::RtCyclic && ++cyclic_ > 100) return;
    capture_.emplace_back(f.begin(), f.end());
  }
  std::unique_ptr<link::Link> inner_;
  Capture& capture_;
  int cyclic_ = 0;
};

class RecordingPort final : public link::DatagramPort {
 public:
  RecordingPort(std::unique_ptr<link::DatagramPort> inner, Capture& capture) : inner_(std::move(inner)), capture_(capture) {}
  void open() override { inner_->open(); }
  void close() noexcept override { inner_->close(); }
  [[nodiscard]] bool is_open() const noexcept override { return inner_->is_open(); }
  [[nodiscard]] link::Ipv4Endpoint local() const noexcept override { return inner_->local(); }
  link::DatagramStatus send_to(const link::Ipv4Endpoint& to, std::span<const std::uint8_t> payload) noexcept override {
    record(inner_->local(), to, payload);
    return inner_->send_to(to, payload);
  }
  bool receive_from(link::Datagram& out) noexcept override {
    if (!inner_->receive_from(out)) return false;
    record(out.from, inner_->local(), out.view());
    return true;
  }
  [[nodiscard]] int wait_fd() const noexcept override { return -1; }
  [[nodiscard]] link::DatagramCounters counters() const noexcept override { return inner_->counters(); }
  [[nodiscard]] std::string describe() const override { return inner_->describe(); }

 private:
  void record(const link::Ipv4Endpoint& from, const link::Ipv4Endpoint& to, std::span<const std::uint8_t> bytes) {
    capture_.push_back(udp_frame({mac_of(from.address), from.address, from.port}, {mac_of(to.address), to.address, to.port},
                                 bytes, ++ip_id_));
  }
  std::unique_ptr<link::DatagramPort> inner_;
  Capture& capture_;
  std::uint16_t ip_id_ = 0;
};

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t c = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++c;
  return c;
}

TEST(ProfinetBusTshark, BringUpToReleaseDissectsCleanly) {
  Capture capture;
  PnHarness h(kNetwork, [&](ProfinetTransport& t) {
    t.frames = std::make_unique<RecordingLink>(std::move(t.frames), capture);
    t.client = std::make_unique<RecordingPort>(std::move(t.client), capture);
    t.server = std::make_unique<RecordingPort>(std::move(t.server), capture);
  });
  ASSERT_TRUE(h.run_until([&] { return h.all_up() && !h.bus->identity(0).empty(); }, 5s)) << h.details();
  core::ParamRequest r = drivegate::test::param_read(h.next_id++, 922, 0, core::ParamType::U16);
  r.axis = h.axis("x");
  ASSERT_TRUE(h.runner->push_parameter(r));
  core::ParamReply reply;
  ASSERT_TRUE(h.run_until([&] { return h.runner->pop_parameter_reply(reply); }, 3s));
  ASSERT_TRUE(reply.ok) << reply.error.view();
  h.bus->close();
  const std::optional<std::string> dissected = drivegate::test::tshark_dissect(capture, 100);
  if (!dissected) GTEST_SKIP() << "tshark not installed (scripts/install-deps.sh)";
  const std::string& out = *dissected;
  EXPECT_EQ(out.find("Malformed"), std::string::npos) << out.substr(0, 20000);
  EXPECT_EQ(out.find("Exception"), std::string::npos);
  EXPECT_EQ(out.find("[Severity level: Error]"), std::string::npos) << out.substr(0, 20000);
  EXPECT_EQ(out.find("[Severity level: Warning]"), std::string::npos) << out.substr(0, 20000);
  for (const char* field : {"ServiceID: Identify (5)", "ServiceID: Set (4)", "Operation: Connect (0)", "Command: ParameterEnd",
                            "Command: ApplicationReady", "Operation: Read (2)", "Operation: Write (3)",
                            "OrderID: AKD-P00306-NBPN-0000", "Operation: Release (1)", "PROFINET IO Cyclic Service Data Unit"})
    EXPECT_NE(out.find(field), std::string::npos) << "missing: " << field;
  // Three devices: three Connects, PrmEnds and Releases, every response OK.
  EXPECT_EQ(count(out, "Operation: Connect (0)"), 6U);  // request and response each
  EXPECT_EQ(out.find("Status: Error"), std::string::npos);
  EXPECT_GT(count(out, "Status: OK"), 10U);
}

}  // namespace
}  // namespace drivegate::profinet::test
