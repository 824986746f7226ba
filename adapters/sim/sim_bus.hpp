#pragma once
// The in-process `sim` bus: each axis is a CiA 402 master profile connected straight to a
// simulated CiA 402 drive in the same process, through an object-access link with the latency of
// a real bus' acyclic channel. It is what the demo runs on until a real bus is configured, and
// what the daemon's integration tests use. Like every bus, it runs on its own cycle thread.
#include <atomic>
#include <memory>
#include <string>
#include <vector>

#include "config/sim/plan.hpp"
#include "core/bus.hpp"
#include "profiles/cia402/cia402_master.hpp"
#include "profiles/cia402/error_codes.hpp"
#include "profiles/cia402/sim/direct_access.hpp"
#include "profiles/cia402/sim/drive_model.hpp"

namespace drivegate::sim {

// The drive model settings for one axis of a compiled plan (units from the device profile, the
// axis' encoder and its `sim:` section).
cia402::sim::DriveModelConfig drive_config_for(const config::AxisPlan& axis);

class SimBus final : public core::Bus {
 public:
  explicit SimBus(const config::BusPlan& plan);
  ~SimBus() override;

  std::string_view name() const noexcept override { return name_; }
  std::string_view type() const noexcept override { return "sim"; }
  void open(core::TimePoint now) override;
  void close() noexcept override;
  std::size_t axis_count() const noexcept override { return nodes_.size(); }
  core::AxisController& controller(std::size_t axis) noexcept override { return *nodes_[axis].master; }
  core::LinkState link_state(std::size_t axis) const noexcept override;
  void receive(core::TimePoint now) noexcept override;
  void transmit(core::TimePoint now) noexcept override;
  core::BusCounters counters() const noexcept override;

  // Direct access to a simulated drive (fault injection in tests; not thread-safe against the
  // cycle thread, so only while the bus is not cycling).
  cia402::sim::DriveModel& drive(std::size_t axis) noexcept { return *nodes_[axis].model; }

 private:
  struct Node {
    std::unique_ptr<cia402::sim::DriveModel> model;
    std::vector<cia402::ObjectId> mapped;
    std::unique_ptr<cia402::sim::DirectObjectAccess> io;
    std::vector<cia402::FaultText> faults;  // views into the plan's device profile
    std::unique_ptr<cia402::Cia402Master> master;
  };

  std::string name_;
  core::Duration cycle_time_;
  std::vector<Node> nodes_;
  bool open_ = false;
  core::TimePoint last_step_{};
  std::atomic<std::uint64_t> exchanges_{0};
};

}  // namespace drivegate::sim
