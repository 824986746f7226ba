#pragma once
// Simulated drives on the wire-emulating in-process bus, run in a thread of their own on the
// monotonic clock, as real drives answer on a real cable while the gateway's cycle thread sleeps.
// The gateway's end (gateway()) is a Transport whose wait_fd() becomes readable when a frame for
// it has come off the wire, like a SocketCAN socket; SimPeer (sim_network.hpp), by contrast, steps
// the drives inside the gateway's cycle and has no such fd. For benchmarks and tests of what the
// cycle thread does between cycles (CanopenBus::serve_until).
//
// The drive thread runs the medium to each frame's end on the clock, steps the drives whenever a
// frame reaches them and every `step` besides (their models, heartbeats), and puts what they send
// on the wire. One mutex guards the in-process bus and the drives: it stands in for the kernel's
// locking of a socket's queues, so the gateway end takes it in send() and receive().
#include <sys/types.h>

#include <atomic>
#include <memory>
#include <mutex>
#include <thread>

#include "adapters/canopen/sim/sim_network.hpp"
#include "core/fd_guard.hpp"
#include "adapters/canopen/transport/inproc_bus.hpp"
#include "config/plan.hpp"

namespace drivegate::canopen::sim {

class ThreadedSimWire {
 public:
  // One drive per axis of the plan, as SimPeer::wire() builds them, on a wire at the plan's bit
  // rate. Throws std::invalid_argument (what SimPeer::wire throws) or std::system_error (no eventfd).
  explicit ThreadedSimWire(const config::BusPlan& plan, core::Duration step = std::chrono::milliseconds(1));
  ~ThreadedSimWire();  // stops the thread
  ThreadedSimWire(const ThreadedSimWire&) = delete;
  ThreadedSimWire& operator=(const ThreadedSimWire&) = delete;

  // The gateway's end, for CanopenBus; once (null afterwards). It may outlive this object.
  std::unique_ptr<Transport> gateway();

  // Starts / stops the drive thread (stop() is safe to call more than once).
  void start();
  void stop() noexcept;

  // Runs f(InprocBus&, SimNetwork&) under the lock: fault injection, statistics.
  template <typename F>
  auto locked(F&& f) {
    const std::lock_guard lock(shared_->mutex);
    return f(shared_->bus, shared_->network);
  }
  // Times the drive thread woke up (for tests that bound it).
  [[nodiscard]] std::uint64_t wakeups() const noexcept { return wakeups_.load(std::memory_order_relaxed); }

  // The wire, both ends and the drives, shared with the gateway's end.
  struct Shared {
    explicit Shared(const config::BusPlan& plan);
    std::mutex mutex;
    InprocBus bus;
    std::unique_ptr<InprocEndpoint> drives_end;
    std::unique_ptr<InprocEndpoint> gateway_end;
    SimNetwork network;
    core::FdGuard gateway_ready;  // eventfd: readable while the gateway's end has frames
    core::FdGuard wire_changed;   // eventfd: the gateway sent a frame (wakes the drive thread)
    bool gateway_signalled = false;
  };

 private:
  void run() noexcept;

  std::shared_ptr<Shared> shared_;
  std::unique_ptr<Transport> gateway_;
  core::Duration step_;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> wakeups_{0};
};

}  // namespace drivegate::canopen::sim
