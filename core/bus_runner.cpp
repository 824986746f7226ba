#include "core/bus_runner.hpp"

namespace drivegate::core {

BusRunner::BusRunner(Bus& bus, const std::vector<AxisSpec>& specs)
    : bus_(bus),
      snapshots_(std::make_unique<Seqlock<AxisSnapshot>[]>(specs.size())),
      io_count_(bus.io_count()),
      io_snapshots_(std::make_unique<Seqlock<IoSnapshot>[]>(io_count_)) {
  if (specs.size() != bus.axis_count()) throw BusError("bus runner: axis specs do not match the bus' axes");
  axes_.reserve(specs.size());
  for (std::size_t i = 0; i < specs.size(); ++i)
    axes_.emplace_back(static_cast<AxisIndex>(i), specs[i], bus.controller(i));
  reply_headroom_ = 4 * axes_.size() + 16;
  if (reply_headroom_ >= replies_.capacity() / 2) throw BusError("bus runner: too many axes on one bus for its reply queue");
}

bool BusRunner::room_for_command() const noexcept {
  return replies_.capacity() - replies_.size_approx() >= reply_headroom_;
}

bool BusRunner::room_for_parameter() const noexcept {
  return params_in_flight_ + param_replies_.size_approx() < param_replies_.capacity();
}

bool BusRunner::cycle(TimePoint now) noexcept {
  queued_ = false;
  // Snapshots are built and stored once per publish period; in between the cycle skips what only
  // they need (the link detail text, the conversions to user units).
  const bool publish = now >= next_publish_;
  if (publish) next_publish_ = now + publish_period_;
  bus_.receive(now);
  Event bus_event;
  while (bus_.next_event(bus_event)) {
    if (bus_event.axis >= axes_.size())
      bus_event.axis = kNoAxis;
    else
      bus_event.state = axes_[bus_event.axis].state();
    bus_event.stamp_ns = to_ns(now);
    event(bus_event);
  }
  for (std::size_t i = 0; i < axes_.size(); ++i) {
    const LinkState link = bus_.link_state(i);
    if (publish || !axes_[i].link_unchanged(link)) axes_[i].observe_link(now, link, bus_.link_detail(i), *this);
  }
  while (bus_.next_record_reply(record_reply_)) parameter_reply(record_reply_);

  Command cmd;
  for (std::size_t n = 0; n < kMaxCommandsPerCycle && room_for_command() && commands_.pop(cmd); ++n)
    if (cmd.axis < axes_.size()) axes_[cmd.axis].command(cmd, now, *this);
  Setpoint sp;
  for (std::size_t n = 0; n < kMaxSetpointsPerCycle && setpoints_.pop(sp); ++n)
    if (sp.axis < axes_.size()) axes_[sp.axis].setpoint(sp, now, *this);
  for (std::size_t n = 0; n < kMaxParamsPerCycle && room_for_parameter(); ++n) {
    if (!param_held_ && !params_.pop(held_param_)) break;
    param_held_ = false;
    const bool record = held_param_.record.valid;
    if (!record && held_param_.axis >= axes_.size()) continue;  // a record's target is the bus' to judge
    ++params_in_flight_;
    if (record ? !this->record(held_param_, now) : !axes_[held_param_.axis].parameter(held_param_, now, *this)) {
      // Its axis has every request slot in use: it goes first again next cycle, in order.
      --params_in_flight_;
      param_held_ = true;
      break;
    }
  }

  // I/O writes: taken only while their replies have room (one reply each, never dropped).
  IoWrite w;
  for (std::size_t n = 0; n < kMaxIoWritesPerCycle && io_replies_.size_approx() < io_replies_.capacity() &&
                          io_writes_.pop(w);
       ++n) {
    IoWriteReply r;
    r.id = w.id;
    r.slave = w.slave;
    if (w.slave >= io_count_)
      r.status = IoWriteStatus::UnknownSlave;
    else if (w.size == 0 || w.size > w.data.size())
      r.status = IoWriteStatus::OutOfRange;
    else
      r.status = bus_.io_write(w.slave, w.offset, std::span<const std::uint8_t>(w.data.data(), w.size));
    queued_ = true;
    if (!io_replies_.push(r)) dropped_.fetch_add(1, std::memory_order_relaxed);
  }

  for (std::size_t i = 0; i < axes_.size(); ++i) {
    axes_[i].update(now, *this, publish);
    if (publish) snapshots_[i].store(axes_[i].snapshot());
  }
  ++cycles_;
  for (std::size_t k = 0; k < io_count_ && publish; ++k) {
    bus_.io_read(k, io_scratch_);
    io_scratch_.stamp_ns = to_ns(now);
    io_scratch_.cycle = cycles_;
    io_snapshots_[k].store(io_scratch_);
  }
  bus_.transmit(now);
  return queued_;
}

bool BusRunner::record(const ParamRequest& req, TimePoint now) noexcept {
  const Admission adm = bus_.record(req, now);
  if (!adm.accepted && adm.busy) return false;
  if (!adm.accepted) {
    record_reply_ = ParamReply{};
    record_reply_.id = req.id;
    record_reply_.axis = req.axis;
    record_reply_.error = adm.reason;
    parameter_reply(record_reply_);
  }
  return true;
}

void BusRunner::reply(const Reply& r) noexcept {
  queued_ = true;
  if (!replies_.push(r)) dropped_.fetch_add(1, std::memory_order_relaxed);
}
void BusRunner::event(const Event& e) noexcept {
  queued_ = true;
  if (!events_.push(e)) dropped_.fetch_add(1, std::memory_order_relaxed);
}
void BusRunner::parameter_reply(const ParamReply& r) noexcept {
  queued_ = true;
  if (params_in_flight_ > 0) --params_in_flight_;
  if (!param_replies_.push(r)) dropped_.fetch_add(1, std::memory_order_relaxed);
}

}  // namespace drivegate::core
