#pragma once
// One bus' cyclic work and its boundary with the control plane (DESIGN.md §3). The control plane
// pushes commands, set-points and parameter requests into bounded lock-free queues and reads axis
// snapshots through seqlocks; the cycle thread calls cycle() once per period and pushes replies,
// events and parameter replies back. cycle() never allocates, locks, logs or blocks.
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/axis_runner.hpp"
#include "core/axis_spec.hpp"
#include "core/bus.hpp"
#include "core/io.hpp"
#include "core/seqlock.hpp"
#include "core/spsc_queue.hpp"

namespace drivegate::core {

class BusRunner final : private RunnerOutput {
 public:
  // `specs[i]` describes `bus.controller(i)`. Both must outlive the runner.
  BusRunner(Bus& bus, const std::vector<AxisSpec>& specs);

  // --- Control plane (one producer thread for the inbound queues) ---
  bool push_command(const Command& cmd) noexcept { return commands_.push(cmd); }
  bool push_setpoint(const Setpoint& sp) noexcept { return setpoints_.push(sp); }
  bool push_parameter(const ParamRequest& req) noexcept { return params_.push(req); }
  // A write to an I/O slave's outputs (index as bus().io_info()); its reply comes back through
  // pop_io_reply().
  bool push_io_write(const IoWrite& w) noexcept { return io_writes_.push(w); }
  // One consumer thread for the outbound queues.
  bool pop_reply(Reply& r) noexcept { return replies_.pop(r); }
  bool pop_event(Event& e) noexcept { return events_.pop(e); }
  bool pop_parameter_reply(ParamReply& r) noexcept { return param_replies_.pop(r); }
  bool pop_io_reply(IoWriteReply& r) noexcept { return io_replies_.pop(r); }
  // Any thread.
  [[nodiscard]] AxisSnapshot snapshot(std::size_t axis) const noexcept { return snapshots_[axis].load(); }
  [[nodiscard]] std::size_t axis_count() const noexcept { return axes_.size(); }
  // The I/O slave's bytes as the latest cycle left them.
  [[nodiscard]] IoSnapshot io_snapshot(std::size_t k) const noexcept { return io_snapshots_[k].load(); }
  [[nodiscard]] std::size_t io_count() const noexcept { return io_count_; }
  [[nodiscard]] Bus& bus() noexcept { return bus_; }
  // Outbound items lost because the control plane did not drain in time.
  [[nodiscard]] std::uint64_t dropped_outputs() const noexcept { return dropped_.load(std::memory_order_relaxed); }

  // The snapshots are stored for readers at most this often (0, the default: every cycle). A
  // snapshot of every axis every cycle is a good part of a large bus' cycle; the daemon's readers
  // sample them at the DDS status rate. Set before the cycle thread starts.
  void set_publish_period(Duration period) noexcept { publish_period_ = period; }

  // --- Cycle thread ---
  // Returns true when it queued replies, events or parameter replies for the control plane.
  bool cycle(TimePoint now) noexcept;

 private:
  void reply(const Reply& r) noexcept override;
  void event(const Event& e) noexcept override;
  void parameter_reply(const ParamReply& r) noexcept override;
  // A record request (ParamRequest::record) to the bus; false: the bus is busy, offer it again.
  bool record(const ParamRequest& req, TimePoint now) noexcept;

  // Per cycle, at most this many inbound items are taken so one burst cannot stretch a cycle.
  static constexpr std::size_t kMaxCommandsPerCycle = 16;
  static constexpr std::size_t kMaxSetpointsPerCycle = 256;
  static constexpr std::size_t kMaxParamsPerCycle = 8;
  static constexpr std::size_t kMaxIoWritesPerCycle = 8;
  // Flow control towards the control plane: a command is taken only while the reply queue has room
  // for this many more replies (a command, the one it supersedes and every axis' completions of
  // one cycle); a parameter request only while every request in flight has room for its reply.
  // What is not taken waits in the inbound queue, and the control plane in front of it waits too:
  // no reply is ever dropped for want of room.
  [[nodiscard]] bool room_for_command() const noexcept;
  [[nodiscard]] bool room_for_parameter() const noexcept;

  Bus& bus_;
  std::vector<AxisRunner> axes_;
  std::unique_ptr<Seqlock<AxisSnapshot>[]> snapshots_;
  std::size_t io_count_ = 0;
  std::unique_ptr<Seqlock<IoSnapshot>[]> io_snapshots_;
  IoSnapshot io_scratch_{};  // filled by the bus each cycle (kept here: it is large for the stack)
  std::uint64_t cycles_ = 0;
  Duration publish_period_ = Duration::zero();
  TimePoint next_publish_{};

  SpscQueue<Command, 64> commands_;
  SpscQueue<Setpoint, 256> setpoints_;
  SpscQueue<ParamRequest, 32> params_;
  SpscQueue<Reply, 1024> replies_;
  SpscQueue<Event, 256> events_;
  SpscQueue<ParamReply, 256> param_replies_;
  // A write is taken only while its reply has room, so no I/O reply is ever dropped.
  SpscQueue<IoWrite, 32> io_writes_;
  SpscQueue<IoWriteReply, 64> io_replies_;
  std::atomic<std::uint64_t> dropped_{0};
  std::size_t reply_headroom_ = 0;
  std::size_t params_in_flight_ = 0;  // taken, reply not yet queued
  ParamRequest held_param_{};         // refused for now by its axis (no free slot): offered again first
  bool param_held_ = false;
  ParamReply record_reply_{};  // a record's reply on its way (kept here: it is large for the stack)
  bool queued_ = false;  // this cycle queued outputs
};

}  // namespace drivegate::core
