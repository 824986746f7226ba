#include "core/bus_runner.hpp"

namespace drivegate::core {

BusRunner::BusRunner(Bus& bus, const std::vector<AxisSpec>& specs)
    : bus_(bus), snapshots_(std::make_unique<Seqlock<AxisSnapshot>[]>(specs.size())) {
  if (specs.size() != bus.axis_count()) throw BusError("bus runner: axis specs do not match the bus' axes");
  axes_.reserve(specs.size());
  for (std::size_t i = 0; i < specs.size(); ++i)
    axes_.emplace_back(static_cast<AxisIndex>(i), specs[i], bus.controller(i));
}

void BusRunner::cycle(TimePoint now) noexcept {
  bus_.receive(now);
  for (std::size_t i = 0; i < axes_.size(); ++i) axes_[i].observe_link(now, bus_.link_state(i), bus_.link_detail(i), *this);

  Command cmd;
  for (std::size_t n = 0; n < kMaxCommandsPerCycle && commands_.pop(cmd); ++n)
    if (cmd.axis < axes_.size()) axes_[cmd.axis].command(cmd, now, *this);
  Setpoint sp;
  for (std::size_t n = 0; n < kMaxSetpointsPerCycle && setpoints_.pop(sp); ++n)
    if (sp.axis < axes_.size()) axes_[sp.axis].setpoint(sp, now, *this);
  ParamRequest pr;
  for (std::size_t n = 0; n < kMaxParamsPerCycle && params_.pop(pr); ++n)
    if (pr.axis < axes_.size()) axes_[pr.axis].parameter(pr, now, *this);

  for (std::size_t i = 0; i < axes_.size(); ++i) {
    axes_[i].update(now, *this);
    snapshots_[i].store(axes_[i].snapshot());
  }
  bus_.transmit(now);
}

void BusRunner::reply(const Reply& r) noexcept {
  if (!replies_.push(r)) dropped_.fetch_add(1, std::memory_order_relaxed);
}
void BusRunner::event(const Event& e) noexcept {
  if (!events_.push(e)) dropped_.fetch_add(1, std::memory_order_relaxed);
}
void BusRunner::parameter_reply(const ParamReply& r) noexcept {
  if (!param_replies_.push(r)) dropped_.fetch_add(1, std::memory_order_relaxed);
}

}  // namespace drivegate::core
