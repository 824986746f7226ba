#pragma once
// The running gateway: the buses of a compiled plan, their runners and cycle threads. It is the
// daemon's implementation of daemon::Runtime (what the DDS bridge sees) and owns the shutdown
// sequence that stops and disables every axis before the buses are released (DESIGN.md §4).
#include <atomic>
#include <cstddef>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "config/plan.hpp"
#include "core/bus.hpp"
#include "core/bus_runner.hpp"
#include "daemon/bus_lock.hpp"
#include "daemon/cycle_thread.hpp"
#include "daemon/runtime.hpp"

namespace drivegate::daemon {

struct ShutdownReport {
  std::size_t stopped = 0;     // axes that were enabled and got a quick stop
  std::size_t disabled = 0;    // axes confirmed disabled (or without power stage)
  std::vector<std::string> unconfirmed;  // axes that did not confirm within the budget
};

class Gateway final : public Runtime {
 public:
  explicit Gateway(const config::Plan& plan);
  ~Gateway() override;
  Gateway(const Gateway&) = delete;
  Gateway& operator=(const Gateway&) = delete;

  // Takes each bus' interface lock (bus_lock.hpp), opens the bus and starts its cycle thread.
  // Throws core::BusError naming the bus.
  void start();
  // Quick stop every enabled axis, then disable every axis, each phase bounded by `phase_budget`;
  // then stop the cycle threads and release the buses. New client commands are refused from the
  // first call on.
  ShutdownReport shutdown(core::Duration phase_budget);

  // True while every cycle thread keeps its schedule (for the systemd watchdog).
  [[nodiscard]] bool healthy() const noexcept;
  // One line for systemd STATUS= and the log.
  [[nodiscard]] std::string status_line() const;
  // Notes about scheduling requests that could not be honoured (one per bus, may be empty).
  [[nodiscard]] std::vector<std::string> scheduling_notes() const;

  // Runtime
  const std::string& gateway_name() const noexcept override { return name_; }
  std::span<const AxisInfo> axes() const noexcept override { return axes_; }
  bool submit_command(std::size_t axis_id, const core::Command& cmd) override;
  bool submit_setpoint(std::size_t axis_id, const core::Setpoint& sp) override;
  bool submit_parameter(std::size_t axis_id, const core::ParamRequest& req) override;
  ParameterLookup lookup_parameter(std::size_t axis_id, std::string_view name, std::uint16_t index,
                                   std::uint8_t sub) const override;
  core::AxisSnapshot snapshot(std::size_t axis_id) const override;
  std::span<const IoSlaveInfo> io_slaves() const noexcept override { return io_; }
  core::IoSnapshot io_snapshot(std::size_t io_id) const override;
  bool submit_io_write(std::size_t io_id, const core::IoWrite& w) override;
  std::size_t bus_count() const noexcept override { return buses_.size(); }
  BusStatus bus_status(std::size_t bus) const override;
  void drain(Outbox& out) override;
  [[nodiscard]] WakeSignal& output_signal() noexcept override { return output_signal_; }

 private:
  struct BusSlot {
    const config::BusPlan* plan = nullptr;
    std::vector<core::AxisSpec> specs;
    std::unique_ptr<BusLock> lock;  // held while the bus is open
    std::unique_ptr<core::Bus> bus;
    std::unique_ptr<core::BusRunner> runner;
    std::unique_ptr<CycleThread> thread;
    std::size_t first_axis = 0;  // global id of its axis 0
    std::size_t first_io = 0;    // global id of its I/O slave 0
    bool open = false;
  };
  struct AxisRef {
    std::size_t bus;
    core::AxisIndex axis;
  };

  void submit_internal(std::size_t axis_id, core::CommandKind kind);
  template <typename Pred>
  bool wait_all(Pred pred, core::Duration budget) const;

  std::string name_;
  std::vector<AxisInfo> axes_;
  std::vector<AxisRef> refs_;
  std::vector<IoSlaveInfo> io_;
  std::vector<BusSlot> buses_;
  // The bus runners' inbound queues are single-producer; the bridge thread and the shutdown
  // sequence both submit, so submissions are serialised here (control plane only).
  std::mutex submit_mutex_;
  std::atomic<bool> shutting_down_{false};
  WakeSignal output_signal_;
  std::vector<GlobalReply> local_replies_;  // refusals made here; guarded by submit_mutex_
  std::vector<GlobalParamReply> local_param_replies_;  // likewise
  core::CommandId next_internal_ = core::kInternalCommandBit | (core::CommandId{1} << 62);
};

}  // namespace drivegate::daemon
