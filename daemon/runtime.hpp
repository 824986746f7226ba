#pragma once
// What the control plane (the DDS bridge) sees of a running gateway. The implementation owns the
// buses and their cycle threads; this interface hides them behind axis ids (an index into axes()).
//
// Threading: submit_*() may be called from any control-plane thread (the implementation
// serialises them in front of its single-producer queues); drain() from one thread only.
// snapshot(), bus_status() and output_signal() from any thread.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/axis_types.hpp"
#include "core/bus.hpp"
#include "core/command.hpp"
#include "core/io.hpp"
#include "daemon/wake_signal.hpp"

namespace drivegate::daemon {

struct AxisInfo {
  std::string name;
  std::string bus;
  std::string bus_type;        // "canopen", "sim", ...
  std::uint32_t address = 0;   // on its bus (canopen: the node-ID)
  std::string device;
  std::string unit;  // user unit of positions
  core::ModeSet modes;
};

// A generic I/O slave of a bus (core/io.hpp), by global id (index into io_slaves()).
struct IoSlaveInfo {
  std::string name;
  std::string bus;
  std::string bus_type;
  std::size_t bus_index = 0;   // index into the gateway's buses (bus_status())
  std::uint32_t address = 0;   // on its bus (EtherCAT: the 1-based position)
  std::size_t input_size = 0;  // configured sizes (0 with sized false: the device's, known after boot)
  std::size_t output_size = 0;
  bool sized = false;
};

struct BusStatus {
  std::string name;
  std::string type;
  bool running = false;
  bool healthy = false;  // cycle thread alive and keeping its schedule
  std::int64_t period_ns = 0;           // configured
  std::int64_t achieved_period_ns = 0;  // measured mean over the last status interval
  std::int64_t lateness_p50_ns = 0;
  std::int64_t lateness_p99_ns = 0;
  std::int64_t lateness_max_ns = 0;
  std::uint64_t cycles = 0;
  std::uint64_t overruns = 0;
  core::BusCounters counters;
  core::ClockSync clock_sync;  // distributed clocks' figures; valid false on a bus without
};

// Outputs of the cycle threads, with axis ids translated to global ones (index into axes()).
struct GlobalReply {
  std::size_t axis_id = 0;
  core::Reply reply;
};
struct GlobalEvent {
  std::size_t axis_id = SIZE_MAX;  // SIZE_MAX: the event is about a bus, see bus
  std::string bus;
  core::Event event;
};
struct GlobalParamReply {
  std::size_t axis_id = 0;  // SIZE_MAX: a record of an IO device (no axis)
  core::ParamReply reply;
};
struct GlobalIoReply {
  std::size_t io_id = 0;
  core::IoWriteReply reply;
};
struct Outbox {
  std::vector<GlobalReply> replies;
  std::vector<GlobalEvent> events;
  std::vector<GlobalParamReply> param_replies;
  std::vector<GlobalIoReply> io_replies;
  void clear() {
    replies.clear();
    events.clear();
    param_replies.clear();
    io_replies.clear();
  }
};

// The object a client asked for (by name, else by index/sub-index) on one axis, and its type as
// the axis' EDS or the standards give it (Unknown when neither does).
struct ParameterLookup {
  bool ok = false;
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  core::ParamType type = core::ParamType::Unknown;
  std::string type_source;  // "the EDS", "CiA 301", ... (for messages)
  std::string error;        // why not ok, in words
  core::RecordAddress record{};  // valid: a PROFINET record instead of an object
};

class Runtime {
 public:
  virtual ~Runtime() = default;
  [[nodiscard]] virtual const std::string& gateway_name() const noexcept = 0;
  [[nodiscard]] virtual std::span<const AxisInfo> axes() const noexcept = 0;

  // Commands get their reply (Accepted/Rejected, later Completed/Failed) through drain(), with the
  // same command id. Return false when the axis' queue is full (the caller rejects the command).
  virtual bool submit_command(std::size_t axis_id, const core::Command& cmd) = 0;
  virtual bool submit_setpoint(std::size_t axis_id, const core::Setpoint& sp) = 0;
  // A record request (req.record valid) with record.io set goes to that I/O slave's device (its
  // global id here) instead, and `axis_id` is not used.
  virtual bool submit_parameter(std::size_t axis_id, const core::ParamRequest& req) = 0;
  // The object `name` stands for on this axis, or the object index:sub when `name` is empty, with
  // its type (control plane only; may allocate).
  [[nodiscard]] virtual ParameterLookup lookup_parameter(std::size_t axis_id, std::string_view name,
                                                         std::uint16_t index, std::uint8_t sub) const = 0;

  [[nodiscard]] virtual core::AxisSnapshot snapshot(std::size_t axis_id) const = 0;

  // Generic I/O slaves (none by default). A write's reply (with the IoWrite's id) comes through
  // drain(); false when the slave's bus queue is full (the caller retries or answers busy).
  [[nodiscard]] virtual std::span<const IoSlaveInfo> io_slaves() const noexcept { return {}; }
  [[nodiscard]] virtual core::IoSnapshot io_snapshot(std::size_t /*io_id*/) const { return {}; }
  virtual bool submit_io_write(std::size_t /*io_id*/, const core::IoWrite& /*w*/) { return false; }
  [[nodiscard]] virtual std::size_t bus_count() const noexcept = 0;
  [[nodiscard]] virtual BusStatus bus_status(std::size_t bus) const = 0;

  // Appends everything the cycle threads produced since the last call.
  virtual void drain(Outbox& out) = 0;
  // Notified whenever there is something new for drain() (a cycle thread queued replies or events),
  // so the drainer can sleep until then. It may notify others' news too (DDS data arrival).
  [[nodiscard]] virtual WakeSignal& output_signal() noexcept = 0;
};

}  // namespace drivegate::daemon
