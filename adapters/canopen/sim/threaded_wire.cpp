// ThreadedSimWire: see threaded_wire.hpp.
#include "adapters/canopen/sim/threaded_wire.hpp"

#include <sys/eventfd.h>
#include <sys/prctl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <system_error>

#include "adapters/canopen/sim/slave_config.hpp"
#include "core/fd_wait.hpp"

namespace drivegate::canopen::sim {
namespace {

int make_eventfd() {
  const int fd = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  if (fd < 0) throw std::system_error(errno, std::generic_category(), "eventfd");
  return fd;
}

void signal(int fd) noexcept {
  const std::uint64_t one = 1;
  [[maybe_unused]] const auto n = ::write(fd, &one, sizeof one);
}

void drain(int fd) noexcept {
  std::uint64_t count = 0;
  [[maybe_unused]] const auto n = ::read(fd, &count, sizeof count);
}

// The gateway's end: the in-process endpoint under the shared lock, with an fd that is readable
// while frames wait for it.
class GatewayEnd final : public Transport {
 public:
  explicit GatewayEnd(std::shared_ptr<ThreadedSimWire::Shared> shared) : shared_(std::move(shared)) {}

  void open() override {
    const std::lock_guard lock(shared_->mutex);
    shared_->gateway_end->open();
  }
  void close() noexcept override {
    const std::lock_guard lock(shared_->mutex);
    shared_->gateway_end->close();
  }
  [[nodiscard]] bool is_open() const noexcept override {
    const std::lock_guard lock(shared_->mutex);
    return shared_->gateway_end->is_open();
  }
  std::size_t receive(std::span<CanFrame> out, core::TimePoint now) noexcept override {
    const std::lock_guard lock(shared_->mutex);
    const std::size_t got = shared_->gateway_end->receive(out, now);
    if (shared_->gateway_signalled && shared_->gateway_end->available() == 0) {
      drain(shared_->gateway_ready.get());
      shared_->gateway_signalled = false;
    }
    return got;
  }
  SendResult send(const CanFrame& frame, core::TimePoint now) noexcept override {
    const std::lock_guard lock(shared_->mutex);
    const SendResult r = shared_->gateway_end->send(frame, now);
    if (r == SendResult::Sent) signal(shared_->wire_changed.get());
    return r;
  }
  // One lock and one wake-up of the drive thread per batch, as a real transport's one sendmmsg.
  SendBatchResult send_batch(std::span<const CanFrame> frames, core::TimePoint now) noexcept override {
    const std::lock_guard lock(shared_->mutex);
    const SendBatchResult r = shared_->gateway_end->send_batch(frames, now);
    if (r.sent > 0) signal(shared_->wire_changed.get());
    return r;
  }
  [[nodiscard]] ControllerState controller_state() const noexcept override {
    const std::lock_guard lock(shared_->mutex);
    return shared_->gateway_end->controller_state();
  }
  [[nodiscard]] TransportCounters counters() const noexcept override { return shared_->gateway_end->counters(); }
  [[nodiscard]] std::string describe() const override {
    return shared_->gateway_end->describe() + " (simulated drives in their own thread)";
  }
  [[nodiscard]] int wait_fd() const noexcept override { return shared_->gateway_ready.get(); }

 private:
  std::shared_ptr<ThreadedSimWire::Shared> shared_;
};

}  // namespace

ThreadedSimWire::Shared::Shared(const config::BusPlan& plan)
    : bus(plan.section<config::CanopenBusOptions>().bitrate, sim_wire_options(plan)),
      drives_end(bus.connect()),
      gateway_end(bus.connect()),
      network(*drives_end),
      gateway_ready(make_eventfd()),
      wire_changed(make_eventfd()) {
  drives_end->open();
  for (const auto& axis : plan.axes) network.add(slave_config_for(axis));
}

ThreadedSimWire::ThreadedSimWire(const config::BusPlan& plan, core::Duration step)
    : shared_(std::make_shared<Shared>(plan)), gateway_(std::make_unique<GatewayEnd>(shared_)), step_(step) {}

ThreadedSimWire::~ThreadedSimWire() { stop(); }

std::unique_ptr<Transport> ThreadedSimWire::gateway() { return std::move(gateway_); }

void ThreadedSimWire::start() {
  if (thread_.joinable()) return;
  stop_.store(false, std::memory_order_release);
  thread_ = std::thread([this] { run(); });
}

void ThreadedSimWire::stop() noexcept {
  stop_.store(true, std::memory_order_release);
  signal(shared_->wire_changed.get());
  if (thread_.joinable()) thread_.join();
}

void ThreadedSimWire::run() noexcept {
  // Frames end on the wire every ~100 us at 1 Mbit/s: wake at their end, not up to 50 us later.
  ::prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);
  const core::SteadyClock clock;
  Shared& s = *shared_;
  core::TimePoint next_step{};
  while (!stop_.load(std::memory_order_acquire)) {
    wakeups_.fetch_add(1, std::memory_order_relaxed);
    core::TimePoint wake{};
    core::TimePoint now{};
    {
      const std::lock_guard lock(s.mutex);
      now = clock.now();
      s.bus.advance(now);
      const bool tick = now >= next_step;
      if (tick || s.drives_end->available() > 0) {
        s.network.step(now);  // the drives answer what reached them and send what is due
        s.bus.advance(now);
        if (tick) next_step = now + step_;
      }
      if (!s.gateway_signalled && s.gateway_end->available() > 0) {
        signal(s.gateway_ready.get());
        s.gateway_signalled = true;
      }
      wake = std::min(s.bus.next_change(), next_step);
    }
    if (core::wait_readable(s.wire_changed.get(), wake - now) != 0) drain(s.wire_changed.get());
  }
}

}  // namespace drivegate::canopen::sim
