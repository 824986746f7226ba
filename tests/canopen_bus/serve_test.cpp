// Acyclic traffic between cycles (CanopenBus::serve_until): a real CycleThread and BusRunner over
// a CANopen bus whose simulated drive answers from its own thread on the wire-emulating in-process
// bus (sim/threaded_wire.hpp), on the monotonic clock.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <optional>
#include <thread>
#include <vector>

#include "adapters/canopen/canopen_bus.hpp"
#include "adapters/canopen/sim/threaded_wire.hpp"
#include "core/fd_guard.hpp"
#include "adapters/canopen/wire/bit_timing.hpp"
#include "config/loader.hpp"
#include "core/bus_runner.hpp"
#include "daemon/cycle_thread.hpp"
#include "tests/support/alloc_counter.hpp"
#include "tests/support/param_request.hpp"

namespace drivegate::canopen::test {
namespace {

using namespace std::chrono_literals;

// One generic drive (its 5FF0h:00 is a 4 KiB DOMAIN, sim/slave_node.hpp), 4 ms SYNC at 1 Mbit/s.
const char* kOneDrive = R"(gateway: { name: serve-test }
buses:
  - { name: can0, type: canopen, cycle_time: 4ms, options: { transport: sim, bitrate: 1000000 } }
axes:
  - { name: a1, bus: can0, address: 1, device: generic-cia402, mechanics: { encoder_counts_per_rev: 10000 } }
)";

constexpr std::size_t kDomainSize = 4096;
constexpr std::uint64_t kSegments = (kDomainSize + 6) / 7;  // 586 upload segments

// Waits for `done` (checked every millisecond) at most `budget` of real time.
template <typename F>
bool wait_for(F done, std::chrono::milliseconds budget) {
  const auto end = std::chrono::steady_clock::now() + budget;
  while (!done()) {
    if (std::chrono::steady_clock::now() > end) return false;
    std::this_thread::sleep_for(1ms);
  }
  return true;
}

struct ServedBus {
  explicit ServedBus(bool serve = true)
      : plan(config::load_plan_from_string(kOneDrive, "serve-test.yaml")),
        wire(plan.buses.at(0)),
        bus(plan.buses.at(0), wire.gateway()) {
    for (const auto& a : plan.buses[0].axes) specs.push_back(a.spec);
    runner = std::make_unique<core::BusRunner>(bus, specs);
    daemon::CycleThread::Schedule sched;
    sched.period = plan.buses[0].cycle_time;
    sched.status_window = 100ms;
    daemon::CycleThread::Between between;
    if (serve)
      between = [this](core::TimePoint deadline) {
        bus.serve_until(deadline);
        // The counters are the bus thread's; this copy may be read while it runs.
        waits.store(bus.serve_counters().waits, std::memory_order_relaxed);
        held.store(bus.serve_counters().held_frames, std::memory_order_relaxed);
      };
    thread = std::make_unique<daemon::CycleThread>(
        sched, [this](core::TimePoint now, std::uint64_t) { runner->cycle(now); }, std::move(between));
  }
  ~ServedBus() {
    thread->stop();
    bus.close();
    wire.stop();
  }
  void start() {
    bus.open(core::SteadyClock{}.now());
    wire.start();
    ASSERT_TRUE(thread->start());
    ASSERT_TRUE(wait_for([&] { return bus.link_state(0) == core::LinkState::Operational; }, 5000ms))
        << bus.link_detail(0);
  }
  std::uint64_t cycles() const { return thread->timing().cycles; }
  bool push_upload(core::CommandId id) {
    core::ParamRequest r = drivegate::test::param_read(id, 0x5FF0, 0, core::ParamType::Domain);
    r.axis = 0;
    return runner->push_parameter(r);
  }
  bool reply(core::ParamReply& out) { return runner->pop_parameter_reply(out); }

  config::Plan plan;
  sim::ThreadedSimWire wire;
  CanopenBus bus;
  std::vector<core::AxisSpec> specs;
  std::unique_ptr<core::BusRunner> runner;
  std::unique_ptr<daemon::CycleThread> thread;
  std::atomic<std::uint64_t> waits{0};
  std::atomic<std::uint64_t> held{0};
};

// Answered between cycles, a 4 KiB upload (586 segment exchanges) takes a few dozen 4 ms cycles;
// answered once per cycle it took one cycle per segment.
TEST(ServeBetweenCycles, UploadTakesFarFewerCyclesThanSegments) {
  ServedBus s;
  s.start();
  const daemon::TimingSnapshot before = s.thread->timing();
  ASSERT_TRUE(s.push_upload(1));
  core::ParamReply r;
  ASSERT_TRUE(wait_for([&] { return s.reply(r); }, 10000ms));
  const daemon::TimingSnapshot after = s.thread->timing();
  const std::uint64_t used = after.cycles - before.cycles;
  ASSERT_TRUE(r.ok) << r.error.c_str();
  ASSERT_EQ(r.size, kDomainSize);
  for (std::size_t i = 0; i < kDomainSize; ++i) ASSERT_EQ(r.data[i], static_cast<std::uint8_t>(i * 7 + 1)) << i;
  RecordProperty("cycles", static_cast<int>(used));
  EXPECT_LT(used, kSegments / 4) << "cycles for " << kSegments << " segments";

  // The cycle's bookkeeping is as without serving: every period between the two snapshots' cycle
  // starts is a cycle or a skipped slot (give or take those two cycles' lateness).
  const auto periods = static_cast<double>(after.last_cycle_ns - before.last_cycle_ns) /
                       static_cast<double>(std::chrono::nanoseconds(s.plan.buses[0].cycle_time).count());
  EXPECT_NEAR(static_cast<double>(used + after.skipped_slots - before.skipped_slots), periods, 2.0);
  s.thread->stop();
  const auto& c = s.bus.serve_counters();
  EXPECT_GT(c.sdo_frames, kSegments / 2);  // most responses were handled between cycles
  EXPECT_EQ(c.held_full, 0U);
  // The TPDOs that came in meanwhile were held and handled by their cycle as before.
  EXPECT_GT(c.held_frames, used);
  // A drive thread starved by a loaded machine may miss a TPDO now and then; held frames handled
  // out of their cycle would miss one in most cycles.
  EXPECT_LT(s.bus.pdos(0).counters().missed, used / 4);
  EXPECT_EQ(s.bus.unexpected_frames(), 0U);
}

// Without SDO work the thread sleeps through the period: no wait on the fd, no frame read
// between cycles, although TPDOs and heartbeats arrive all the time.
TEST(ServeBetweenCycles, IdleBusDoesNotWakePerFrame) {
  ServedBus s;
  s.start();
  // The boot's SDO traffic ends with the NMT start; give its last exchange a few cycles.
  std::uint64_t from = s.cycles();
  ASSERT_TRUE(wait_for([&] { return s.cycles() >= from + 5; }, 1000ms));
  const std::uint64_t waits = s.waits.load();
  const std::uint64_t held = s.held.load();
  const std::uint64_t frames = s.bus.counters().frames_received;
  from = s.cycles();
  ASSERT_TRUE(wait_for([&] { return s.cycles() >= from + 50; }, 2000ms));
  EXPECT_GT(s.bus.counters().frames_received - frames, 80U);  // 2 TPDOs per cycle, heartbeats
  EXPECT_EQ(s.waits.load() - waits, 0U);
  EXPECT_EQ(s.held.load() - held, 0U);
}

// The bus thread stops while a transfer is in flight: stop() returns within about a period, the
// transfer stays unfinished, and closing the bus still releases the drive's watch on the gateway
// (1016h:01 := 0) instead of queueing that write behind the rest of the upload.
TEST(ServeBetweenCycles, StopsWithTransferInFlight) {
  ServedBus s;
  s.start();
  ASSERT_TRUE(s.push_upload(1));
  const std::uint64_t first = s.cycles();
  ASSERT_TRUE(wait_for([&] { return s.cycles() >= first + 3; }, 1000ms));
  const auto t0 = std::chrono::steady_clock::now();
  s.thread->stop();
  EXPECT_LT(std::chrono::steady_clock::now() - t0, 50ms);
  EXPECT_FALSE(s.thread->running());
  EXPECT_GT(s.bus.serve_counters().sdo_frames, 0U);
  EXPECT_EQ(s.bus.sdo().pending(0), 1U);  // still on its way: nobody completed it behind our back
  core::ParamReply r;
  EXPECT_FALSE(s.reply(r));
  const auto consumer = [&] {
    return s.wire.locked([](InprocBus&, sim::SimNetwork& net) { return net.node(0).nmt().heartbeat_consumer(); });
  };
  ASSERT_NE(consumer(), 0U);
  s.bus.close();
  EXPECT_TRUE(wait_for([&] { return consumer() == 0; }, 1000ms));
}

// The drive falls silent mid transfer: the SDO timeout still ends it, and waiting for the answer
// that never comes does not spin (a few waits per cycle at most).
TEST(ServeBetweenCycles, SilentDriveTimesOutWithoutBusyLooping) {
  ServedBus s;
  s.start();
  ASSERT_TRUE(s.push_upload(1));
  const std::uint64_t first = s.cycles();
  ASSERT_TRUE(wait_for([&] { return s.cycles() >= first + 2; }, 1000ms));
  s.wire.locked([](InprocBus&, sim::SimNetwork& net) { net.node(0).set_silent(true); });
  const std::uint64_t silent_from = s.cycles();
  core::ParamReply r;
  ASSERT_TRUE(wait_for([&] { return s.reply(r); }, 5000ms));
  const std::uint64_t cycles = s.cycles() - first;
  s.thread->stop();
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.error_code, 0x05040000U) << r.error.c_str();  // SDO protocol timed out
  EXPECT_LE(s.cycles() - silent_from, 60U);  // sdo_timeout 100 ms = 25 cycles, plus the wait for the reply
  const auto& c = s.bus.serve_counters();
  EXPECT_LE(c.waits, c.sdo_frames + c.held_frames + 2 * cycles) << cycles << " cycles";
}

// Between cycles allocates nothing: serve_until() called directly, with the cycles around it,
// while an upload is in flight.
TEST(ServeBetweenCycles, ServingAllocatesNothing) {
  const config::Plan plan = config::load_plan_from_string(kOneDrive, "serve-test.yaml");
  const auto& bp = plan.buses.at(0);
  sim::ThreadedSimWire wire(bp);
  CanopenBus bus(bp, wire.gateway());
  std::vector<core::AxisSpec> specs{bp.axes[0].spec};
  core::BusRunner runner(bus, specs);
  const core::SteadyClock clock;
  bus.open(clock.now());
  wire.start();
  const auto cycle = [&] {
    const auto now = clock.now();
    runner.cycle(now);
    bus.serve_until(now + bp.cycle_time);
    std::this_thread::sleep_until(std::chrono::steady_clock::time_point(now.time_since_epoch() + bp.cycle_time));
  };
  for (int i = 0; i < 2000 && bus.link_state(0) != core::LinkState::Operational; ++i) cycle();
  ASSERT_EQ(bus.link_state(0), core::LinkState::Operational);
  core::ParamRequest req = drivegate::test::param_read(1, 0x5FF0, 0, core::ParamType::Domain);
  req.axis = 0;
  ASSERT_TRUE(runner.push_parameter(req));
  runner.cycle(clock.now());  // the request is taken and its upload starts
  std::size_t allocations = 0;
  core::ParamReply r;
  for (int i = 0; i < 500 && !runner.pop_parameter_reply(r); ++i) {
    const auto now = clock.now();
    const drivegate::test::AllocationScope scope;
    bus.serve_until(now + bp.cycle_time);
    allocations += scope.count();
    runner.cycle(clock.now());
  }
  EXPECT_TRUE(r.ok) << r.error.c_str();
  EXPECT_GT(bus.serve_counters().sdo_frames, kSegments / 2);
  EXPECT_EQ(allocations, 0U);
  bus.close();
  wire.stop();
}

// A transport the test scripts: it delivers what the test puts in `inbox`, records every frame
// sent with the bus' time, and its wait_fd() is the descriptor the test gives it.
struct Script {
  explicit Script(int wait_fd) : fd(wait_fd) {}
  std::vector<CanFrame> inbox;
  std::vector<std::pair<core::TimePoint, CanFrame>> sent;
  core::FdGuard fd;
};

class ScriptedTransport final : public Transport {
 public:
  explicit ScriptedTransport(std::shared_ptr<Script> script) : script_(std::move(script)) {}
  void open() override { open_ = true; }
  void close() noexcept override { open_ = false; }
  [[nodiscard]] bool is_open() const noexcept override { return open_; }
  std::size_t receive(std::span<CanFrame> out, core::TimePoint) noexcept override {
    const std::size_t n = std::min(out.size(), script_->inbox.size());
    std::copy_n(script_->inbox.begin(), n, out.begin());
    script_->inbox.erase(script_->inbox.begin(), script_->inbox.begin() + static_cast<std::ptrdiff_t>(n));
    return n;
  }
  SendResult send(const CanFrame& frame, core::TimePoint now) noexcept override {
    script_->sent.emplace_back(now, frame);
    return SendResult::Sent;
  }
  [[nodiscard]] ControllerState controller_state() const noexcept override { return ControllerState::Active; }
  [[nodiscard]] TransportCounters counters() const noexcept override { return {}; }
  [[nodiscard]] std::string describe() const override { return "scripted"; }
  [[nodiscard]] int wait_fd() const noexcept override { return script_->fd.get(); }

 private:
  std::shared_ptr<Script> script_;
  bool open_ = false;
};

// Four drives that boot at once and never answer SDO, at 125 kbit/s (an 8-byte frame: 1.08 ms).
const char* kFourSilentDrives = R"(gateway: { name: serve-test }
buses:
  - { name: can0, type: canopen, cycle_time: 20ms,
      options: { transport: sim, bitrate: 125000, sdo_timeout: 1ms, sdo_retries: 2 } }
axes:
  - { name: a1, bus: can0, address: 1, device: generic-cia402, mechanics: { encoder_counts_per_rev: 10000 } }
  - { name: a2, bus: can0, address: 2, device: generic-cia402, mechanics: { encoder_counts_per_rev: 10000 } }
  - { name: a3, bus: can0, address: 3, device: generic-cia402, mechanics: { encoder_counts_per_rev: 10000 } }
  - { name: a4, bus: can0, address: 4, device: generic-cia402, mechanics: { encoder_counts_per_rev: 10000 } }
)";

bool is_sdo_request(const CanFrame& f) { return !f.extended && f.id >= 0x601 && f.id <= 0x604; }

// The bus of kFourSilentDrives on a ScriptedTransport waiting on `wait_fd`, booted until the
// boot's first SDO request went out on every channel in one cycle.
struct SilentDrives {
  explicit SilentDrives(int wait_fd)
      : plan(config::load_plan_from_string(kFourSilentDrives, "serve-test.yaml")),
        script(std::make_shared<Script>(wait_fd)),
        bus(plan.buses.at(0), std::make_unique<ScriptedTransport>(script)) {}
  ~SilentDrives() { bus.close(); }
  // Returns the time the bus sent the four requests with, or nullopt.
  std::optional<core::TimePoint> boot() {
    bus.open(clock.now());
    for (std::uint32_t node = 1; node <= 4; ++node) script->inbox.push_back(make_frame(0x700 + node, {0x00}));
    for (int i = 0; i < 10; ++i) {
      const auto now = clock.now();
      bus.receive(now);
      bus.transmit(now);
      if (std::count_if(script->sent.begin(), script->sent.end(),
                        [](const auto& s) { return is_sdo_request(s.second); }) == 4) {
        const core::TimePoint at = script->sent.back().first;
        script->sent.clear();
        return at;
      }
    }
    return std::nullopt;
  }

  config::Plan plan;
  std::shared_ptr<Script> script;
  CanopenBus bus;
  const core::SteadyClock clock;
};

// Several SDO channels whose retries fall due together shortly before the next cycle: between
// cycles only the frames that are off the wire (sent back to back) kServeGuard plus two frame
// times before the deadline go out; the others wait for the cycle and are not lost.
TEST(ServeBetweenCycles, ParallelTransfersNearTheDeadlineKeepTheQuietWindow) {
  SilentDrives d(::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC));
  ASSERT_GE(d.script->fd.get(), 0);
  const auto requested = d.boot();
  ASSERT_TRUE(requested);
  auto& bus = d.bus;
  const auto& script = d.script;
  const auto& clock = d.clock;

  // The four retries fall due 1 ms later; the next cycle starts 5 ms later: room for two frames.
  const core::Duration frame = frame_time(8, 125000);
  const core::TimePoint deadline = *requested + 1ms + 5ms;
  bus.serve_until(deadline);
  ASSERT_LT(clock.now(), deadline);
  ASSERT_FALSE(script->sent.empty()) << "no retry went out between cycles";
  core::TimePoint wire_free{};
  for (const auto& [at, f] : script->sent) {
    EXPECT_TRUE(is_sdo_request(f)) << std::hex << f.id;
    wire_free = std::max(wire_free, at) + frame;
  }
  EXPECT_LE(wire_free, deadline - CanopenBus::kServeGuard - 2 * frame)
      << script->sent.size() << " frames sent between cycles end on the wire "
      << std::chrono::duration_cast<std::chrono::microseconds>(wire_free - deadline).count()
      << " us after the deadline";

  // The cycle sends the retries that did not fit: every channel retried.
  const auto now = clock.now();
  bus.receive(now);
  bus.transmit(now);
  for (std::uint32_t node = 1; node <= 4; ++node) {
    EXPECT_TRUE(std::any_of(script->sent.begin(), script->sent.end(),
                            [node](const auto& s) { return s.second.id == 0x600 + node; }))
        << "node " << node << " was never retried";
  }
  EXPECT_GE(bus.sdo().counters().retries, 4U);
  EXPECT_EQ(bus.sdo().counters().timeouts, 0U);
}

// A descriptor that reports a hang-up or error without data (a CAN interface going down sets the
// socket's error) ends serving at once instead of waking again and again until the deadline.
TEST(ServeBetweenCycles, HungUpDescriptorDoesNotBusyLoop) {
  int fds[2];
  ASSERT_EQ(::pipe2(fds, O_CLOEXEC), 0);
  ::close(fds[1]);  // the read end now reports POLLHUP and never data
  SilentDrives d(fds[0]);
  ASSERT_TRUE(d.boot());
  const auto start = d.clock.now();
  d.bus.serve_until(start + 20ms);  // the SDO transfers stay in flight: there is work to wait for
  EXPECT_LT(d.clock.now() - start, 5ms);
  EXPECT_EQ(d.bus.serve_counters().waits, 1U);
  EXPECT_EQ(d.bus.serve_counters().fd_errors, 1U);
}

}  // namespace
}  // namespace drivegate::canopen::test
