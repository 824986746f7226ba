#include "adapters/sim/sim_bus.hpp"

#include <algorithm>

#include "profiles/cia402/master_settings.hpp"
#include "profiles/cia402/op_modes.hpp"

namespace drivegate::sim {

cia402::sim::DriveModelConfig drive_config_for(const config::AxisPlan& axis) {
  cia402::sim::DriveModelConfig c;
  c.supported_modes.clear();
  for (std::size_t i = 1; i < core::kModeCount; ++i) {
    const auto m = static_cast<core::Mode>(i);
    if (!axis.device.modes.contains(m)) continue;
    if (const auto v = cia402::to_op_mode(m)) c.supported_modes.push_back(*v);
  }
  c.homing_methods.clear();
  for (auto m : axis.device.homing_methods)
    if (m >= -128 && m <= 127) c.homing_methods.push_back(static_cast<std::int8_t>(m));
  if (axis.device.identity.vendor_id) c.identity.vendor_id = *axis.device.identity.vendor_id;
  if (axis.device.identity.product_code) c.identity.product_code = *axis.device.identity.product_code;
  c.identity.serial = static_cast<std::uint32_t>(axis.address);
  c.position_units_per_rev = axis.native.position_per_rev;
  // The model takes velocities in position units per second unless told otherwise.
  c.velocity_units_per_rps =
      axis.native.velocity_per_rps == axis.native.position_per_rev ? 0.0 : axis.native.velocity_per_rps;
  const auto& sim = axis.section<config::SimAxisOptions>();
  if (sim.max_velocity > 0) c.max_velocity_rps = sim.max_velocity / axis.native.velocity_per_rps;
  // The motor's acceleration capability is what it reaches at rated torque.
  if (sim.max_acceleration > 0) c.torque_acceleration_rps2 = sim.max_acceleration / axis.native.acceleration_per_rps2;
  // Following-error window: a tenth of a motor revolution.
  c.following_error_window = static_cast<std::uint32_t>(std::max(1.0, axis.native.position_per_rev / 10));
  c.position_window = static_cast<std::uint32_t>(std::max(1.0, axis.native.position_per_rev / 10000));
  c.velocity_window = static_cast<std::uint16_t>(std::clamp(axis.native.velocity_per_rps / 100, 1.0, 65535.0));
  c.start_position = sim.start_position;
  c.home_switch_position = sim.home_switch_position;
  c.negative_limit_position = sim.negative_limit_switch_position;
  c.positive_limit_position = sim.positive_limit_switch_position;
  return c;
}

SimBus::SimBus(const config::BusPlan& plan) : name_(plan.name), cycle_time_(plan.cycle_time) {
  nodes_.reserve(plan.axes.size());
  for (const auto& axis : plan.axes) {
    Node n;
    n.model = std::make_unique<cia402::sim::DriveModel>(drive_config_for(axis));
    n.mapped = axis.device.cyclic_objects;
    n.io = std::make_unique<cia402::sim::DirectObjectAccess>(
        *n.model, n.mapped, static_cast<unsigned>(plan.section<config::SimBusOptions>().acyclic_latency_cycles));
    for (const auto& [code, text] : axis.device.fault_texts)
      n.faults.push_back({static_cast<std::uint16_t>(code), text});
    n.master = std::make_unique<cia402::Cia402Master>(*n.io, cia402::settings_from(axis.spec));
    n.master->set_fault_table(n.faults);
    nodes_.push_back(std::move(n));
  }
}

SimBus::~SimBus() = default;

void SimBus::open(core::TimePoint now) {
  last_step_ = now;
  open_ = true;
}

void SimBus::close() noexcept { open_ = false; }

core::LinkState SimBus::link_state(std::size_t) const noexcept {
  return open_ ? core::LinkState::Operational : core::LinkState::Offline;
}

void SimBus::receive(core::TimePoint) noexcept {
  for (auto& n : nodes_) n.io->begin_cycle();
}

void SimBus::transmit(core::TimePoint now) noexcept {
  for (auto& n : nodes_) n.io->end_cycle();
  // The drives run in real time: a late cycle advances them by the time that really passed, but
  // never by more than a few cycles at once so a stall does not make the model jump.
  const auto dt = std::clamp(now - last_step_, core::Duration::zero(), 5 * cycle_time_);
  last_step_ = now;
  if (dt > core::Duration::zero())
    for (auto& n : nodes_) n.model->step(dt);
  exchanges_.fetch_add(1, std::memory_order_relaxed);
}

core::BusCounters SimBus::counters() const noexcept {
  core::BusCounters c;
  const auto n = exchanges_.load(std::memory_order_relaxed) * nodes_.size();
  c.frames_sent = n;
  c.frames_received = n;
  return c;
}

}  // namespace drivegate::sim
