#pragma once
// The interface a bus adapter implements (CANopen, EtherCAT, PROFINET, the in-process sim bus).
// A Bus owns its transport and its protocol engines and exposes one AxisController per axis.
// The cycle thread calls receive() at the start of a cycle, lets the controllers run, then calls
// transmit(). Those two calls are the cyclic path: no heap allocation, lock, logging or blocking.
// Between two cycles it calls serve_until(), where a bus may do acyclic work (an SDO exchange) as
// its frames arrive, under the same rules; it blocks only waiting for frames, never past the
// deadline.
#include <cstddef>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>

#include "core/axis_controller.hpp"
#include "core/command.hpp"
#include "core/clock.hpp"
#include "core/io.hpp"
#include "core/param_value.hpp"

namespace drivegate::core {

// Raised by open() (never by the cyclic calls) with a message a person can act on.
class BusError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct BusCounters {
  std::uint64_t frames_sent = 0;
  std::uint64_t frames_received = 0;
  std::uint64_t frames_lost = 0;     // expected but not received in time
  std::uint64_t frames_dropped = 0;  // malformed or unexpected, counted and ignored
  std::uint64_t errors = 0;          // bus errors (error frames, working-counter errors, ...)
};

// How closely the bus holds its devices' clocks together (EtherCAT distributed clocks: the system
// time difference register 092Ch, ETG.1000.4 §9.2.3). `valid` is false on a bus that does not
// synchronise clocks, and before its first complete measurement, so a client tells "no figure"
// from "0 ns".
struct ClockSync {
  bool valid = false;
  std::int64_t max_difference_ns = 0;          // largest |device - reference clock| of the last round
  std::int64_t master_minus_reference_ns = 0;  // the master's clock minus the reference clock
};

// A parameter named by the device itself (EtherCAT: its object dictionary read over SDO
// Information), for a name the axis' configuration files do not know.
struct NamedObject {
  bool found = false;
  std::uint16_t index = 0;  // as the axis numbers it (a multi-axis slave's offset taken off)
  std::uint8_t sub = 0;
  ParamType type = ParamType::Unknown;
  std::string source;  // where the name came from, for messages
  // Not found: why, in words a person can act on; empty when the bus keeps no names for the axis.
  std::string error;
};

class Bus {
 public:
  virtual ~Bus() = default;

  [[nodiscard]] virtual std::string_view name() const noexcept = 0;
  [[nodiscard]] virtual std::string_view type() const noexcept = 0;

  // Open the transport and prepare the engines. May throw BusError.
  virtual void open(TimePoint now) = 0;
  // Release the transport. Called after the axes have been disabled.
  virtual void close() noexcept = 0;

  [[nodiscard]] virtual std::size_t axis_count() const noexcept = 0;
  [[nodiscard]] virtual AxisController& controller(std::size_t axis) noexcept = 0;
  [[nodiscard]] virtual LinkState link_state(std::size_t axis) const noexcept = 0;
  // What brought the link to its present state, in words (e.g. "boot failed at identity: 1018h:01
  // reads ..."): set by the latest transition itself, never the reason of an earlier one, since
  // the axis' link_changed event quotes it. Valid until the next cycle.
  [[nodiscard]] virtual std::string_view link_detail(std::size_t /*axis*/) const noexcept { return {}; }

  // Cyclic path.
  virtual void receive(TimePoint now) noexcept = 0;
  virtual void transmit(TimePoint now) noexcept = 0;
  // Between cycles, on the cycle thread: acyclic work until at most `deadline` (the next cycle's
  // start on the monotonic clock), then return; the caller sleeps the rest precisely. The default
  // has none and returns at once.
  virtual void serve_until(TimePoint /*deadline*/) noexcept {}
  // Events the bus itself reports, taken after receive(); false when there is none. With `axis`
  // kNoAxis (or out of range) the event is about the bus (another master on the wire, ...); with
  // an axis index it is about that axis' device (a CANopen EMCY) and the runner adds the axis'
  // state. The runner stamps them with the cycle's time. A bus bounds how many it holds.
  virtual bool next_event(Event& /*out*/) noexcept { return false; }

  // Generic I/O slaves (core/io.hpp); the default has none. io_count() and io_info() are fixed
  // from construction on and may be called from any thread. io_read() and io_write() are the
  // cyclic path (the runner calls them between receive() and transmit()): io_read() fills `out`
  // with the slave's inputs, its outputs and whether the inputs are fresh (the runner stamps it);
  // io_write() changes the outputs the bus sends from now on.
  [[nodiscard]] virtual std::size_t io_count() const noexcept { return 0; }
  [[nodiscard]] virtual IoInfo io_info(std::size_t /*k*/) const noexcept { return {}; }
  virtual void io_read(std::size_t /*k*/, IoSnapshot& out) noexcept { out = IoSnapshot{}; }
  virtual IoWriteStatus io_write(std::size_t /*k*/, std::size_t /*offset*/,
                                 std::span<const std::uint8_t> /*bytes*/) noexcept {
    return IoWriteStatus::UnknownSlave;
  }

  // Record access (a ParamRequest with `record` valid: PROFINET's IODReadReq/IODWriteReq) to the
  // device of the request's axis or of I/O device `record.io`; the cyclic path (the runner calls
  // it after receive()). An accepted request gets exactly one reply from next_record_reply(); a
  // busy refusal is offered again later. The default: the bus has no records.
  virtual Admission record(const ParamRequest& /*req*/, TimePoint /*now*/) noexcept {
    return Admission::reject("this bus has no records (rec:SLOT:SUBSLOT:INDEX is PROFINET's record access)");
  }
  virtual bool next_record_reply(ParamReply& /*out*/) noexcept { return false; }

  // May be called from any thread while the bus runs (implementations keep relaxed atomics).
  [[nodiscard]] virtual BusCounters counters() const noexcept = 0;
  // Same threading as counters(). The default: the bus synchronises no clocks.
  [[nodiscard]] virtual ClockSync clock_sync() const noexcept { return {}; }
  // The object the device names `name` (control plane, any thread, may allocate; safe while the
  // bus runs). The default: the bus keeps no names of its own.
  [[nodiscard]] virtual NamedObject find_object(std::size_t /*axis*/, std::string_view /*name*/) const { return {}; }
};

}  // namespace drivegate::core
