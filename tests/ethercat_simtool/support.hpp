#pragma once
// Shared by the simulator tool tests: plans from YAML text (the ethercat type with a stand-in
// factory, as drivegate-sim loads them), a BRD count through a built line in memory, and a small
// master on any Link (Transactions + LineBoot, plus single datagrams) for the tests over veth.
#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "adapters/ethercat/link/ethercat_link.hpp"
#include "adapters/ethercat/master/line_boot.hpp"
#include "adapters/ethercat/master/transactions.hpp"
#include "adapters/ethercat/sim/line_builder.hpp"
#include "adapters/ethercat/wire/frame.hpp"
#include "config/ethercat/bus_type.hpp"
#include "config/loader.hpp"
#include "core/bytes.hpp"
#include "core/clock.hpp"
#include "core/fd_wait.hpp"

namespace drivegate::ethercat::sim::test {

inline config::LoadOptions load_options() {
  config::LoadOptions o;
  config::BusTypeInfo t = config::ethercat_bus_type();
  t.make_bus = [](const config::BusPlan&) -> std::unique_ptr<core::Bus> { return nullptr; };
  o.bus_types.add(std::move(t));
  return o;
}

inline config::Plan plan_of(const std::string& yaml) {
  return config::load_plan_from_string(yaml, "t.yaml", load_options());
}

// An ethercat bus with three I/O slaves (positions 1..3) on `interface`.
inline std::string three_io_config(const std::string& interface) {
  return R"(gateway: { name: simtool-test }
buses:
  - name: ec0
    type: ethercat
    cycle_time: 1ms
    options: { interface: )" +
         interface + R"( }
    io:
      - { name: a, position: 1, inputs: 2, outputs: 2 }
      - { name: b, position: 2, inputs: 1, outputs: 1 }
      - { name: c, position: 3, vendor_id: 0x99, product_code: 0x1000, inputs: 4, outputs: 0 }
)";
}

// The identities LineBoot expects for three_io_config() (line_builder: generic-io's defaults).
inline const std::vector<ExpectedSlave> kThreeIo{
    {kSimIoVendorId, kSimIoProductCode, 1, "Generic I/O"},
    {kSimIoVendorId, kSimIoProductCode, 1, "Generic I/O"},
    {0x99, 0x1000, 1, "Generic I/O"},
};

inline constexpr MacAddress kMasterMac{0x02, 0, 0, 0, 0, 0x01};

// One datagram in one frame through a built line in memory; the WKC and data when it returned.
struct Answer {
  std::uint16_t wkc = 0;
  std::vector<std::uint8_t> data;
};
inline std::optional<Answer> through(BuiltLine& line, Command c, std::uint32_t address, std::uint16_t length,
                                     std::span<const std::uint8_t> data = {}, std::uint64_t now_ns = 0) {
  std::array<std::uint8_t, kMaxFrameSize> tx{};
  FrameBuilder b(tx, kMasterMac, kMasterMac);
  EXPECT_TRUE(b.add(c, 0x42, address, length, data).ok());
  const auto frame = b.finish();
  line.pass(FrameView(frame.data(), frame.size()), now_ns);
  std::array<FrameBuffer, 1> rx;
  if (line.link().receive(rx) != 1) return std::nullopt;
  FrameParser p(rx[0].view());
  Datagram d;
  if (!p.next(d)) return std::nullopt;
  return Answer{d.wkc, std::vector<std::uint8_t>(d.data.begin(), d.data.end())};
}
inline std::optional<std::uint16_t> count(BuiltLine& line) {
  const auto a = through(line, Command::BRD, 0, 2);
  return a ? std::optional<std::uint16_t>(a->wkc) : std::nullopt;
}

// A master on a Link for the tests: LineBoot to PRE-OP and later transitions, and single datagrams,
// each cycle waiting for its frames up to `answer_time` (frames the line does not return are lost
// then).
class TestMaster final : public DatagramOwner {
 public:
  explicit TestMaster(Link& link, core::Duration answer_time = std::chrono::milliseconds(50))
      : link_(link), answer_time_(answer_time) {}

  // One cycle: the boot (when running) queues, frames go out, answers are awaited.
  void cycle() {
    const core::TimePoint now = clock_.now();
    if (boot_) boot_->poll(now, tx_);
    const auto frames = tx_.take_frames(now + answer_time_);
    for (const auto& f : frames) link_.send(FrameView(f.data(), f.size()));
    for (const auto end = now + answer_time_; tx_.frames_in_flight() > 0;) {
      const std::size_t n = link_.receive(rx_);
      for (std::size_t i = 0; i < n; ++i) tx_.on_frame(rx_[i].view());
      if (n > 0) continue;
      const core::Duration left = end - clock_.now();
      if (left <= core::Duration::zero()) break;
      core::wait_readable(link_.wait_fd(), left);
    }
    tx_.expire(now + answer_time_);  // what has not come back is lost
  }

  // Boots the line to PRE-OP; true when LineBoot says ok(). The boot stays for request_state().
  bool boot(std::span<const ExpectedSlave> expected, std::chrono::seconds timeout = std::chrono::seconds(10)) {
    boot_ = std::make_unique<LineBoot>(expected, LineBootConfig{});
    boot_->start(clock_.now());
    for (const auto end = clock_.now() + timeout; boot_->status() == LineStatus::Running && clock_.now() < end;) cycle();
    return boot_->ok();
  }
  // Runs a transition of the slave at `index` to its end (Ready or Failed).
  SlaveReport transition(std::size_t index, AlState target, std::chrono::seconds timeout = std::chrono::seconds(10)) {
    EXPECT_TRUE(boot_ && boot_->request_state(index, target, clock_.now()));
    for (const auto end = clock_.now() + timeout; boot_->slave(index).status == SlaveStatus::Busy && clock_.now() < end;)
      cycle();
    return boot_->slave(index);
  }
  [[nodiscard]] LineBoot& line_boot() { return *boot_; }

  // One datagram, sent until it comes back (at most `tries` times); its WKC and data.
  std::optional<Answer> datagram(Command c, std::uint32_t address, std::uint16_t length, int tries = 1) {
    for (int i = 0; i < tries; ++i) {
      answer_.reset();
      tx_.queue(this, 1, c, address, length);
      cycle();
      if (answer_) return answer_;
    }
    return std::nullopt;
  }
  // The number of slaves answering a BRD (its working counter); nullopt when the frame was lost.
  std::optional<std::uint16_t> count(int tries = 1) {
    const auto a = datagram(Command::BRD, 0, 2, tries);
    return a ? std::optional<std::uint16_t>(a->wkc) : std::nullopt;
  }
  // The AL status (0130h) of the slave at `position` (0-based) by auto-increment address.
  std::optional<std::uint16_t> al_status(std::uint16_t position) {
    const auto a = datagram(Command::APRD, physical_address(auto_increment_adp(position), 0x0130), 2, 3);
    if (!a || a->wkc != 1) return std::nullopt;
    return core::get_u16(a->data, 0);
  }

  void on_result(std::uint32_t /*tag*/, const DatagramAnswer& a) noexcept override {
    if (a.outcome == DatagramOutcome::Answered) answer_ = Answer{a.wkc, std::vector<std::uint8_t>(a.data.begin(), a.data.end())};
  }

 private:
  Link& link_;
  core::Duration answer_time_;
  core::SteadyClock clock_;
  Transactions tx_;
  std::unique_ptr<LineBoot> boot_;
  std::array<FrameBuffer, 16> rx_{};
  std::optional<Answer> answer_;
};

}  // namespace drivegate::ethercat::sim::test
