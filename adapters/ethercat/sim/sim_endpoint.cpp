#include "adapters/ethercat/sim/sim_endpoint.hpp"

#include <thread>

#include "core/fd_wait.hpp"

namespace drivegate::ethercat::sim {

void SimEndpoint::service(core::TimePoint now) noexcept {
  if (!started_) {
    started_ = true;
    next_tick_ = now;
  }
  wire_.poll_state(now);
  const auto now_ns = static_cast<std::uint64_t>(core::to_ns(now));
  for (;;) {
    const std::size_t n = wire_.receive(rx_);
    if (n == 0) break;
    counters_.frames_in += n;
    std::size_t answers = 0;
    for (std::size_t i = 0; i < n; ++i) {
      line_.pass(rx_[i].view(), now_ns);
      // One frame in, at most one out: SimLine delivers the answer inside pass().
      if (line_.link().receive(std::span<FrameBuffer>(&answers_[answers], 1)) == 1) {
        out_[answers] = answers_[answers].view();
        ++answers;
      } else {
        ++counters_.no_answer;
      }
    }
    if (answers > 0) {
      const SendResult r = wire_.send(std::span<const FrameView>(out_.data(), answers));
      counters_.frames_out += r.sent;
      counters_.not_sent += r.unsent + r.invalid;
    }
    if (n < rx_.size()) break;
  }
  if (now >= next_tick_) {
    line_.tick(now_ns);
    ++counters_.ticks;
    next_tick_ += kTick;
    if (next_tick_ <= now) next_tick_ = now + kTick;  // late: the ticks missed are not made up
  }
}

void run_endpoint(SimEndpoint& endpoint, const std::atomic<bool>& stop) noexcept {
  const core::SteadyClock clock;
  while (!stop.load(std::memory_order_relaxed)) {
    endpoint.service(clock.now());
    const core::Duration left = endpoint.next_tick() - clock.now();
    if (endpoint.wait_fd() >= 0) {
      core::wait_readable(endpoint.wait_fd(), left);
    } else if (left > core::Duration::zero()) {
      std::this_thread::sleep_for(left);
    }
  }
}

}  // namespace drivegate::ethercat::sim
