#pragma once
// Runs one axis on its bus' cycle thread: validates and converts commands (the one place where
// user units become drive units and back), hands them to the profile controller, turns the
// controller's outcomes into replies and events, enforces the command timeout of live modes
// (DESIGN.md §4 safety rules) and builds the axis snapshot. Nothing here allocates.
#include <cstdint>

#include "core/axis_controller.hpp"
#include "core/axis_spec.hpp"
#include "core/command.hpp"

namespace drivegate::core {

// Where an axis runner puts what it produces. Implemented by BusRunner with lock-free queues.
class RunnerOutput {
 public:
  virtual void reply(const Reply& r) noexcept = 0;
  virtual void event(const Event& e) noexcept = 0;
  virtual void parameter_reply(const ParamReply& r) noexcept = 0;

 protected:
  ~RunnerOutput() = default;
};

class AxisRunner final : private ControllerSink {
 public:
  AxisRunner(AxisIndex index, const AxisSpec& spec, AxisController& controller) noexcept;

  void command(const Command& cmd, TimePoint now, RunnerOutput& out) noexcept;
  void setpoint(const Setpoint& sp, TimePoint now, RunnerOutput& out) noexcept;
  // False when the controller has no room for it now (nothing was replied): offer it again later.
  bool parameter(const ParamRequest& req, TimePoint now, RunnerOutput& out) noexcept;

  // Start of a cycle, right after the bus delivered inputs: takes note of the link state, so
  // commands handled in this cycle see it.
  void observe_link(TimePoint now, LinkState link, std::string_view detail, RunnerOutput& out) noexcept;
  // True when observe_link(link) would change nothing but the detail text: a caller that needs
  // the detail only in snapshots may skip fetching it then (BusRunner: between publishes).
  [[nodiscard]] bool link_unchanged(LinkState link) const noexcept { return link_observed_ && link == last_link_; }
  // One cycle, after commands were handled and before the bus sends outputs. `snapshot`: build
  // snapshot() this cycle (a caller that stores snapshots only now and then skips the others).
  void update(TimePoint now, RunnerOutput& out, bool snapshot = true) noexcept;
  // Both, for callers without commands in between.
  void update(TimePoint now, LinkState link, RunnerOutput& out) noexcept {
    observe_link(now, link, {}, out);
    update(now, out);
  }

  // As of the last update() that built it.
  [[nodiscard]] const AxisSnapshot& snapshot() const noexcept { return snapshot_; }
  // The drive's state now (Unknown before it reported one).
  [[nodiscard]] AxisState state() const noexcept;
  [[nodiscard]] const AxisSpec& spec() const noexcept { return spec_; }
  [[nodiscard]] std::uint64_t rejected_setpoints() const noexcept { return rejected_setpoints_; }

 private:
  // ControllerSink
  void completed(CommandId id) noexcept override;
  void failed(CommandId id, std::string_view reason) noexcept override;
  void event(EventKind kind, std::uint32_t code, std::string_view text) noexcept override;
  void parameter_done(const ParamReply& reply) noexcept override;

  void send_reply(CommandId id, ReplyStatus status, std::string_view reason) noexcept;
  void emit(EventKind kind, std::uint32_t code, std::string_view text) noexcept;
  void check_command_timeout(TimePoint now) noexcept;
  void check_soft_limits(TimePoint now) noexcept;
  void internal_stop(CommandKind kind, TimePoint now, std::string_view why) noexcept;
  void end_live_command(ReplyStatus status, std::string_view reason) noexcept;
  // Why the gateway itself ended a client's command: the reason of the stop under way, if any.
  [[nodiscard]] std::string_view gateway_stop_reason() const noexcept;
  void watch_live_command() noexcept;
  void select_default_mode(TimePoint now) noexcept;
  void build_snapshot(TimePoint now) noexcept;

  AxisIndex index_;
  const AxisSpec& spec_;
  AxisController& controller_;
  RunnerOutput* out_ = nullptr;  // valid during a call from the cycle thread
  TimePoint now_{};

  // Command timeout bookkeeping: armed when a live-source command or set-point was accepted.
  bool live_armed_ = false;
  TimePoint last_activity_{};
  CommandId next_internal_ = kInternalCommandBit | 1;

  // Relative moves are resolved against the target of a move still in flight.
  CommandId move_in_flight_ = 0;
  double move_target_ = 0;
  bool limit_stop_sent_ = false;  // soft-limit stop issued for the present excursion

  // The configured default mode is selected once the drive reports after each link-up.
  bool default_mode_pending_ = true;
  int default_mode_attempts_ = 0;

  // The velocity or torque command that set the axis running (DESIGN.md §4). Its final reply is
  // given when the run ends, not when the drive reaches the speed: completed when a later command
  // ends it, failed (with the reason) when the gateway or the drive does.
  CommandId live_command_ = 0;
  bool live_reached_ = false;  // the controller finished its handshake; the reply is held back
  Text ending_;                // while the gateway stops the axis itself: why (non-empty)

  // The mode a client's accepted command is switching the axis into, while that command is in the
  // controller's hands (0: none): set-points are judged against it, not against the mode the drive
  // still shows, so a velocity command's keep-alives from pp are not refused as pp's.
  CommandId entering_id_ = 0;
  Mode entering_mode_ = Mode::None;
  bool submit_finished_ = false;  // the command inside controller_.submit() completed or failed there

  LinkState last_link_ = LinkState::Offline;
  std::int64_t link_since_ns_ = 0;
  bool link_observed_ = false;
  CommandId active_command_ = 0;
  CommandId submitting_ = 0;    // id inside controller_.submit(), for inline completion
  CommandKind submitting_kind_ = CommandKind::Enable;
  bool accepted_sent_ = false;  // Accepted already queued for submitting_
  std::uint64_t cycle_ = 0;
  std::uint64_t rejected_setpoints_ = 0;
  AxisSnapshot snapshot_;
};

}  // namespace drivegate::core
