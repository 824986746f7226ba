// Text for the wire-level enums, for logs and error messages.
#include "adapters/canopen/transport/transport.hpp"
#include "adapters/canopen/wire/nmt_codec.hpp"

namespace drivegate::canopen {

const char* to_string(NmtState s) noexcept {
  switch (s) {
    case NmtState::Initialising: return "boot-up";
    case NmtState::Stopped: return "stopped";
    case NmtState::Operational: return "operational";
    case NmtState::PreOperational: return "pre-operational";
    case NmtState::Unknown: return "unknown";
  }
  return "?";
}

const char* to_string(NmtCommand c) noexcept {
  switch (c) {
    case NmtCommand::Start: return "start";
    case NmtCommand::Stop: return "stop";
    case NmtCommand::EnterPreOperational: return "enter pre-operational";
    case NmtCommand::ResetNode: return "reset node";
    case NmtCommand::ResetCommunication: return "reset communication";
  }
  return "?";
}

const char* to_string(ControllerState s) noexcept {
  switch (s) {
    case ControllerState::Active: return "error active";
    case ControllerState::Warning: return "error warning";
    case ControllerState::Passive: return "error passive";
    case ControllerState::BusOff: return "bus-off";
  }
  return "?";
}

}  // namespace drivegate::canopen
