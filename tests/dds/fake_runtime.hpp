#pragma once
// An in-test daemon::Runtime: named axes, a recorded command log, scripted replies, an in-memory
// object dictionary for parameter requests and synthetic snapshots. The bridge thread calls it;
// the test thread inspects it, hence the mutex.
#include <map>
#include <mutex>
#include <string>
#include <tuple>
#include <vector>

#include "daemon/runtime.hpp"

namespace drivegate::dds_test {

class FakeRuntime final : public daemon::Runtime {
 public:
  FakeRuntime(std::string gateway, std::vector<std::string> axis_names);

  [[nodiscard]] const std::string& gateway_name() const noexcept override { return gateway_; }
  [[nodiscard]] std::span<const daemon::AxisInfo> axes() const noexcept override { return axes_; }
  bool submit_command(std::size_t axis_id, const core::Command& cmd) override;
  bool submit_setpoint(std::size_t axis_id, const core::Setpoint& sp) override;
  bool submit_parameter(std::size_t axis_id, const core::ParamRequest& req) override;
  [[nodiscard]] daemon::ParameterLookup lookup_parameter(std::size_t axis_id, std::string_view name,
                                                         std::uint16_t index, std::uint8_t sub) const override;
  [[nodiscard]] core::AxisSnapshot snapshot(std::size_t axis_id) const override;
  [[nodiscard]] std::size_t bus_count() const noexcept override { return 1 + extra_buses_.size(); }
  [[nodiscard]] daemon::BusStatus bus_status(std::size_t bus) const override;
  void drain(daemon::Outbox& out) override;
  [[nodiscard]] std::span<const daemon::IoSlaveInfo> io_slaves() const noexcept override { return io_; }
  [[nodiscard]] core::IoSnapshot io_snapshot(std::size_t io_id) const override;
  bool submit_io_write(std::size_t io_id, const core::IoWrite& w) override;
  [[nodiscard]] daemon::WakeSignal& output_signal() noexcept override { return signal_; }

  // Test controls and observations.
  // An I/O slave on bus "ec0" with these sizes, inputs zero, outputs zero, valid (before start()).
  void add_io(std::string name, std::size_t inputs, std::size_t outputs);
  void set_io_inputs(std::size_t io_id, std::vector<std::uint8_t> inputs);
  // A lost slave: inputs stale, writes refused with slave_lost (as the EtherCAT bus does).
  void set_io_lost(std::size_t io_id, bool lost);
  [[nodiscard]] std::vector<std::uint8_t> io_outputs(std::size_t io_id) const;
  // The axis on another bus than can0 (canopen), e.g. "pn0" of type "profinet" (before start()).
  void put_on_bus(std::size_t axis_id, std::string bus, std::string bus_type);
  // A bus after the default can0 (canopen, no clock figures), reported as given (before start()).
  void add_bus(daemon::BusStatus status);
  void set_busy(bool busy);
  void set_complete_commands(bool complete);  // false: reply Accepted only
  // An object and its type as the axis' EDS would give it (Unknown: the gateway would not know it);
  // `value` as drivegatectl takes it.
  void set_object(std::size_t axis_id, std::uint16_t index, std::uint8_t sub, core::ParamType type,
                  std::string_view value);
  // Parameter names lookup_parameter() knows (for every axis).
  void add_name(std::string name, daemon::ParameterLookup object);
  void push_event(std::size_t axis_id, core::EventKind kind, std::string_view text);
  // The axis' link from now on (default: operational, no detail, since 0 = not known).
  void set_link(std::size_t axis_id, core::LinkState link, std::string_view detail, std::int64_t since_ns);
  // The axis' position from now on (default: 10 * axis id + 1.5).
  void set_position(std::size_t axis_id, double position);
  // The stamp of every snapshot: 100 s of gateway monotonic time.
  static constexpr std::int64_t kStampNs = 100'000'000'000;
  struct Received {
    std::size_t axis_id;
    core::Command command;
  };
  [[nodiscard]] std::vector<Received> commands() const;
  [[nodiscard]] std::vector<std::pair<std::size_t, core::Setpoint>> setpoints() const;
  // The object's bytes (empty when it does not exist).
  [[nodiscard]] std::vector<std::uint8_t> object(std::size_t axis_id, std::uint16_t index, std::uint8_t sub) const;

 private:
  std::string gateway_;
  std::vector<daemon::AxisInfo> axes_;
  mutable std::mutex mutex_;
  std::map<std::string, daemon::ParameterLookup> names_;
  bool busy_ = false;
  bool complete_ = true;
  std::vector<Received> commands_;
  std::vector<std::pair<std::size_t, core::Setpoint>> setpoints_;
  struct Object {
    core::ParamType type = core::ParamType::Unknown;
    std::vector<std::uint8_t> bytes;
  };
  std::map<std::tuple<std::size_t, std::uint16_t, std::uint8_t>, Object> objects_;
  daemon::Outbox pending_;
  daemon::WakeSignal signal_;  // notified whenever pending_ grows, as the gateway's cycle threads do
  std::map<std::size_t, core::AxisSnapshot> links_;  // link, link_detail, link_since_ns per axis
  std::map<std::size_t, double> positions_;
  std::vector<daemon::IoSlaveInfo> io_;
  std::vector<daemon::BusStatus> extra_buses_;
  std::vector<core::IoSnapshot> io_data_;
};

}  // namespace drivegate::dds_test
