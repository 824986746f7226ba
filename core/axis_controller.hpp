#pragma once
// The interface a device profile (CiA 402, PROFIdrive) implements for one axis. It works in drive
// units and knows nothing about the bus underneath (DESIGN.md §2 rule 3). Its methods are called
// only from the bus' cycle thread and must not allocate, lock, log or block.
#include <string_view>

#include "core/clock.hpp"
#include "core/command.hpp"

namespace drivegate::core {

// Where a controller reports the outcome of commands and what happened to its drive: every change
// of state and of the drive's mode (StateChanged, ModeChanged), faults and warnings.
class ControllerSink {
 public:
  virtual void completed(CommandId id) noexcept = 0;
  virtual void failed(CommandId id, std::string_view reason) noexcept = 0;
  virtual void event(EventKind kind, std::uint32_t code, std::string_view text) noexcept = 0;
  virtual void parameter_done(const ParamReply& reply) noexcept = 0;

 protected:
  ~ControllerSink() = default;
};

struct Admission {
  bool accepted = true;
  Text reason;        // why not, in words a person can act on
  bool busy = false;  // refused only for now (no free slot): the caller may offer it again later
  static Admission accept() noexcept { return {}; }
  static Admission reject(std::string_view why) noexcept { return {false, Text(why), false}; }
};

class AxisController {
 public:
  virtual ~AxisController() = default;

  // Start a command. The runner has already checked units, limits, NaN and mode support; the
  // controller checks what depends on the drive's present state. An accepted command later gets
  // exactly one ControllerSink::completed() or failed() with the same id, unless it finishes at
  // once, in which case completed() may be called from inside submit() as well.
  virtual Admission submit(const DriveCommand& cmd, TimePoint now, ControllerSink& sink) noexcept = 0;

  // A set-point for the cyclic mode the axis is in (ip/csp/csv/cst). Ignored in other modes.
  virtual void setpoint(const DriveSetpoint& sp, TimePoint now) noexcept = 0;

  // Read or write one object acyclically. An accepted request later gets exactly one
  // ControllerSink::parameter_done() with the same id.
  virtual Admission parameter(const ParamRequest& req, TimePoint now) noexcept = 0;

  // One cycle: read the inputs the bus delivered, advance state machines and handshakes, write
  // the outputs the bus will send.
  virtual void update(TimePoint now, ControllerSink& sink) noexcept = 0;

  // The link to the drive was lost (or came back): drop every handshake in flight (failing the
  // commands), forget cached drive state and come back disabled (DESIGN.md §4 safety rules).
  virtual void link_lost(TimePoint now, ControllerSink& sink) noexcept = 0;

  [[nodiscard]] virtual const DriveFeedback& feedback() const noexcept = 0;
};

}  // namespace drivegate::core
