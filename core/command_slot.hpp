#pragma once
// A command a device profile's controller has accepted and still owes its one final reply
// (core/axis_controller.hpp): the CiA 402 and the PROFIdrive masters keep their commands in these.
#include <string_view>

#include "core/axis_controller.hpp"
#include "core/command.hpp"

namespace drivegate::core {

struct CommandSlot {
  bool active = false;
  CommandId id = 0;
  CommandKind kind = CommandKind::Enable;

  // The final reply; nothing when the slot holds no command.
  void fail(std::string_view reason, ControllerSink& sink) noexcept {
    if (!active) return;
    active = false;
    sink.failed(id, reason);
  }
  void complete(ControllerSink& sink) noexcept {
    if (!active) return;
    active = false;
    sink.completed(id);
  }
  // Ends the command because `by` takes its place, saying which (command ids are the gateway's own
  // bookkeeping, meaningless to the client that reads this).
  void abort(const DriveCommand& by, ControllerSink& sink) noexcept {
    if (!active) return;
    Text reason;
    if (is_internal(by.id))
      reason.format("aborted by the gateway's %s", to_string(by.kind).data());
    else if (kind == by.kind)
      reason.format("superseded by a newer %s command", to_string(by.kind).data());
    else
      reason.format("aborted by a %s command", to_string(by.kind).data());
    fail(reason.view(), sink);
  }
};

}  // namespace drivegate::core
