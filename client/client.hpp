#pragma once
// drivegate client library: discovers gateways and axes over DDS, keeps the latest state of every
// axis, sends commands and waits for their replies, streams set-points, collects events, reads and
// writes drive parameters. Thread-safe: DDS delivers into internal tables under a mutex, and every
// public call may come from any thread.
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/param_value.hpp"

namespace drivegate::client {

using Millis = std::chrono::milliseconds;

struct ClientOptions {
  std::uint32_t domain = 0;
  std::string ns = "drivegate";
  std::string name;  // empty: "<hostname>-<pid>-<random>"
  // DDS Security identity: a directory as scripts/make-pki.sh writes one (identity_ca.pem,
  // cert.pem, key.pem, permissions_ca.pem, governance.p7s, permissions.p7s). Empty: the
  // DRIVEGATE_IDENTITY environment variable, else no security.
  std::string identity;
  // UDPv4 on these interfaces only (names or IPv4 addresses). Empty: the DRIVEGATE_INTERFACES
  // environment variable (comma-separated), else what the Fast DDS profile says.
  std::vector<std::string> interfaces;
  // Commands and parameter requests of this client that may wait for their first reply at once;
  // send() and param() wait for room beyond that (flow control), up to their timeout.
  std::size_t window = 64;
};

// Options with the domain, namespace and client name set, everything else at its default.
inline ClientOptions options_for(std::uint32_t domain, std::string ns, std::string name) {
  ClientOptions o;
  o.domain = domain;
  o.ns = std::move(ns);
  o.name = std::move(name);
  return o;
}

struct AxisInfo {
  std::string gateway;
  std::string name;
  std::string bus;
  std::string device;
  std::string unit;
  std::vector<std::string> modes;
};

struct GatewayInfo {
  std::string name;
  std::string host;
  std::uint32_t pid = 0;
  std::vector<AxisInfo> axes;
};

struct AxisState {
  std::string gateway;
  std::string axis;
  std::string state;
  std::string link;
  std::string mode;
  double position = 0;
  double velocity = 0;
  double torque = 0;
  std::string unit;
  std::uint32_t fault_code = 0;
  std::string fault_text;
  bool target_reached = false;
  bool homed = false;
  bool warning = false;
  bool stopping = false;
  bool following_error = false;
  std::uint16_t statusword = 0;
  std::uint64_t active_command = 0;
  std::int64_t stamp_ns = 0;
  std::uint64_t seq = 0;
  std::chrono::steady_clock::time_point received;
};

// Where an axis' link stands, why, and since when (topic axis_link, written when it changes).
struct AxisLink {
  std::string gateway;
  std::string axis;
  std::string bus;
  std::string bus_type;       // "canopen", "sim", ...
  std::uint32_t address = 0;  // on its bus (canopen: the node-ID)
  std::string link;
  std::string detail;         // the bus' words ("" when it says nothing)
  std::int64_t since_ns = 0;  // gateway monotonic time the link entered its state (as AxisState::stamp_ns)
};

struct AxisEvent {
  std::string gateway;
  std::string axis;  // empty for bus events
  std::string bus;
  std::string kind;
  std::string state;
  std::uint32_t code = 0;
  std::string text;
  std::int64_t stamp_ns = 0;
};

struct BusStatus {
  std::string gateway;
  std::string bus;
  std::string type;
  bool running = false;
  bool healthy = false;
  std::int64_t period_ns = 0;
  std::int64_t achieved_period_ns = 0;
  std::int64_t lateness_p50_ns = 0;
  std::int64_t lateness_p99_ns = 0;
  std::int64_t lateness_max_ns = 0;
  std::uint64_t cycles = 0;
  std::uint64_t overruns = 0;
  std::uint64_t frames_sent = 0;
  std::uint64_t frames_received = 0;
  std::uint64_t frames_lost = 0;
  std::uint64_t frames_dropped = 0;
  std::uint64_t errors = 0;
  // Distributed clocks (EtherCAT): clock_sync false when the bus reports no figure (no DC, or
  // before the first measurement); then the two figures are 0.
  bool clock_sync = false;
  std::int64_t clock_difference_ns = 0;     // largest |system time difference| of the last round
  std::int64_t clock_master_offset_ns = 0;  // the master's clock minus the reference clock
};

// Mirrors core::Command in user units; kind/mode use the names of core/axis_types.cpp.
struct CommandRequest {
  std::string axis;
  std::string gateway;  // empty: the gateway that owns the axis (from discovery)
  std::string kind;
  std::string mode;
  double position = 0;
  double velocity = 0;
  double acceleration = 0;
  double deceleration = 0;
  double torque = 0;
  bool relative = false;
  bool immediate = true;
  std::int16_t homing_method = 0;
  double home_offset = 0;
  double homing_search_velocity = 0;
  double homing_zero_velocity = 0;
  std::int32_t block = 0;
};

enum class Outcome {
  Accepted,   // accepted, final outcome not awaited
  Completed,
  Rejected,
  Failed,
  Timeout,    // the gateway did not answer in time
  NoGateway,  // no gateway owns the axis (or the named gateway is unknown)
  Busy,       // the command could not be sent in time: the window or DDS flow control stayed full
  Denied,     // this client's DDS identity may not send commands (DDS Security access control)
};
std::string_view to_string(Outcome o) noexcept;

struct CommandResult {
  Outcome outcome = Outcome::Timeout;
  std::string gateway;
  std::string axis;
  std::uint64_t id = 0;
  std::string reason;  // gateway's reason, or ours for Timeout/NoGateway
  [[nodiscard]] bool ok() const noexcept { return outcome == Outcome::Accepted || outcome == Outcome::Completed; }
};

struct ParamRequest {
  std::string axis;
  std::string gateway;  // empty: owner from discovery
  bool write = false;
  std::uint16_t index = 0;
  std::uint8_t subindex = 0;
  std::string name;   // the object by name (EDS ParameterName, SD6 "A83"); replaces index/subindex
  std::string type;   // empty: the type the axis' EDS or the standards give; else u8..u64, i8..i64,
                      // r32, r64, bool, string, unicode, octets, domain (core/param_value.hpp)
  std::string value;  // write: the value as text ("1000", "-5", "0x1F", "2.5", "name", "01 02 0a")
};

struct ParamResult {
  bool ok = false;
  std::string gateway;
  std::uint32_t error_code = 0;
  std::string error;
  std::uint16_t index = 0;  // the object the gateway accessed
  std::uint8_t subindex = 0;
  core::ParamType type = core::ParamType::Unknown;  // what `data` is (Unknown: raw bytes)
  std::vector<std::uint8_t> data;                   // the object's bytes as on the bus (read or written)

  // The value as text: decimal integers, reals, strings, else hex bytes (core::format_param).
  [[nodiscard]] std::string text() const { return core::format_param(type, data); }
  // An integer object's value; nullopt for other types.
  [[nodiscard]] std::optional<std::int64_t> integer() const noexcept { return core::param_as_signed(type, data); }
};

// A bus' generic I/O slave (topic io_state; an EtherCAT bus' `io:` slaves).
struct IoState {
  std::string gateway;
  std::string bus;
  std::string slave;
  std::uint32_t address = 0;          // on its bus (EtherCAT: the 1-based position)
  std::vector<std::uint8_t> inputs;   // the last good inputs
  std::vector<std::uint8_t> outputs;  // the outputs the gateway holds for the slave
  bool valid = false;                 // false: the inputs are stale (the slave is not exchanging)
  std::int64_t stamp_ns = 0;
  std::uint64_t seq = 0;
  std::chrono::steady_clock::time_point received;
};

struct IoWriteRequest {
  std::string slave;
  std::string bus;      // empty: the one bus with an I/O slave of that name
  std::string gateway;  // empty: the gateway that publishes the slave
  std::uint32_t offset = 0;
  std::vector<std::uint8_t> data;
};

struct IoWriteResult {
  bool ok = false;
  std::string gateway;
  std::string bus;
  std::string status;  // ok, unknown_slave, out_of_range, slave_lost, busy; "" when no gateway answered
  std::string error;   // the gateway's reason, or ours (no gateway, timeout, denied)
};

// Which gateway a request goes to, or why none.
struct Route {
  std::string gateway;
  std::string error;  // non-empty: no route
};

class Client {
 public:
  // Throws std::runtime_error when DDS cannot be set up.
  explicit Client(ClientOptions options);
  ~Client();
  Client(const Client&) = delete;
  Client& operator=(const Client&) = delete;

  [[nodiscard]] const std::string& name() const noexcept;
  // Why this client may not send commands, set-points or parameter requests (its DDS identity's
  // permissions refused the writer); empty when it may. The endpoints are made on first use.
  [[nodiscard]] std::string command_refusal();
  [[nodiscard]] std::string parameter_refusal();

  // Discovery and latest data (copies, sorted by gateway then axis). Gateways are discovered from
  // construction on. The states, bus statuses, links and events are subscribed to on the first call
  // that reads them (a client that only commands receives none of them); that first call waits
  // (up to 1.5 s) until the gateways discovered so far have delivered what they have: a state and
  // a link per axis, a status per bus, the event history. When no gateway is discovered yet (a read
  // right after construction) it first waits, within the same 1.5 s, for the gateways to appear.
  [[nodiscard]] std::vector<GatewayInfo> gateways() const;
  [[nodiscard]] std::vector<AxisState> states() const;
  [[nodiscard]] std::optional<AxisState> state(std::string_view axis, std::string_view gateway = {}) const;
  [[nodiscard]] std::vector<BusStatus> buses() const;
  // Empty when no gateway published the axis' link (or this identity may not read axis_link).
  [[nodiscard]] std::vector<AxisLink> links() const;
  [[nodiscard]] std::optional<AxisLink> link(std::string_view axis, std::string_view gateway = {}) const;
  // How many axis_link writers (one per gateway that publishes links) the link reader matched; 0
  // when this identity may not read axis_link. Fewer than gateways(): some gateway publishes no links
  // (its permissions predate the topic), so waiting for its axes' links is pointless.
  [[nodiscard]] std::size_t link_writers() const;

  // Events in arrival order. `cursor` starts at 0 and is advanced past the returned events; at most
  // the newest 1000 are kept.
  [[nodiscard]] std::vector<AxisEvent> events_since(std::uint64_t& cursor) const;

  // Polls `condition` whenever new data arrives (and at least every 50 ms) until it holds or the
  // timeout passes. `condition` may call this client's other methods.
  bool wait_until(const std::function<bool()>& condition, Millis timeout) const;

  // The gateway for `axis`: `gateway` if given and known, else the one gateway that owns it.
  [[nodiscard]] Route route(std::string_view axis, std::string_view gateway = {}) const;

  // Sends a command and waits for Accepted/Rejected, then (wait_final) for Completed/Failed, all
  // within `timeout`. Waits for discovery of the axis' owner within the same budget (less when gateways are known
  // and none has appeared for a second: then the axis is unknown).
  CommandResult send(const CommandRequest& request, bool wait_final, Millis timeout);

  // Best-effort set-point (also the keep-alive of velocity/torque/cyclic commands). Returns an
  // error text, empty on success.
  std::string stream_setpoint(std::string_view axis, std::string_view gateway, double position, double velocity,
                              double torque);

  ParamResult param(const ParamRequest& request, Millis timeout);

  // I/O slaves, sorted by gateway, bus, slave. The io_state reader is made on the first call,
  // which waits (up to 1.5 s) for the gateways' next publication.
  [[nodiscard]] std::vector<IoState> io_states() const;
  [[nodiscard]] std::optional<IoState> io_state(std::string_view slave, std::string_view bus = {},
                                                std::string_view gateway = {}) const;
  // Why this client may not write I/O outputs (DDS access control); empty when it may.
  [[nodiscard]] std::string io_refusal();
  // Writes output bytes at an offset and waits for the gateway's reply, within `timeout`.
  IoWriteResult io_write(const IoWriteRequest& request, Millis timeout);

  class Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace drivegate::client
