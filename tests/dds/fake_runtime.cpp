#include "fake_runtime.hpp"

#include <algorithm>
#include <stdexcept>

namespace drivegate::dds_test {

FakeRuntime::FakeRuntime(std::string gateway, std::vector<std::string> axis_names) : gateway_(std::move(gateway)) {
  for (auto& name : axis_names) {
    daemon::AxisInfo a;
    a.name = std::move(name);
    a.bus = "can0";
    a.bus_type = "canopen";
    a.address = static_cast<std::uint32_t>(35 + axes_.size());  // x: node 35 (0x23), y: 36 (0x24)
    a.device = "sim";
    a.unit = "mm";
    a.modes.add(core::Mode::ProfilePosition);
    a.modes.add(core::Mode::ProfileVelocity);
    a.modes.add(core::Mode::Homing);
    axes_.push_back(std::move(a));
  }
}

bool FakeRuntime::submit_command(std::size_t axis_id, const core::Command& cmd) {
  std::lock_guard lock(mutex_);
  if (busy_) return false;
  commands_.push_back({axis_id, cmd});
  daemon::GlobalReply r;
  r.axis_id = axis_id;
  r.reply.id = cmd.id;
  r.reply.axis = static_cast<core::AxisIndex>(axis_id);
  r.reply.status = core::ReplyStatus::Accepted;
  pending_.replies.push_back(r);
  if (complete_) {
    r.reply.status = core::ReplyStatus::Completed;
    r.reply.reason.assign("target reached");
    pending_.replies.push_back(r);
  }
  signal_.notify();
  return true;
}

void FakeRuntime::add_io(std::string name, std::size_t inputs, std::size_t outputs) {
  std::lock_guard lock(mutex_);
  io_.push_back(daemon::IoSlaveInfo{std::move(name), "ec0", "ethercat", 0, static_cast<std::uint32_t>(2 + io_.size()),
                                    inputs, outputs, true});
  core::IoSnapshot s;
  s.valid = true;
  s.input_size = static_cast<std::uint16_t>(inputs);
  s.output_size = static_cast<std::uint16_t>(outputs);
  s.stamp_ns = kStampNs;
  io_data_.push_back(s);
}

void FakeRuntime::set_io_inputs(std::size_t io_id, std::vector<std::uint8_t> inputs) {
  std::lock_guard lock(mutex_);
  std::copy(inputs.begin(), inputs.end(), io_data_.at(io_id).inputs.begin());
}

void FakeRuntime::set_io_lost(std::size_t io_id, bool lost) {
  std::lock_guard lock(mutex_);
  io_data_.at(io_id).valid = !lost;
}

std::vector<std::uint8_t> FakeRuntime::io_outputs(std::size_t io_id) const {
  std::lock_guard lock(mutex_);
  const auto& s = io_data_.at(io_id);
  return {s.outputs.begin(), s.outputs.begin() + s.output_size};
}

core::IoSnapshot FakeRuntime::io_snapshot(std::size_t io_id) const {
  std::lock_guard lock(mutex_);
  return io_id < io_data_.size() ? io_data_[io_id] : core::IoSnapshot{};
}

bool FakeRuntime::submit_io_write(std::size_t io_id, const core::IoWrite& w) {
  std::lock_guard lock(mutex_);
  if (busy_) return false;
  daemon::GlobalIoReply r;
  r.io_id = io_id;
  r.reply.id = w.id;
  r.reply.slave = static_cast<std::uint16_t>(io_id);
  auto& s = io_data_.at(io_id);
  if (!s.valid)
    r.reply.status = core::IoWriteStatus::SlaveLost;
  else if (w.size == 0 || w.offset + w.size > s.output_size)
    r.reply.status = core::IoWriteStatus::OutOfRange;
  else
    std::copy_n(w.data.begin(), w.size, s.outputs.begin() + w.offset);
  pending_.io_replies.push_back(r);
  signal_.notify();
  return true;
}

bool FakeRuntime::submit_setpoint(std::size_t axis_id, const core::Setpoint& sp) {
  std::lock_guard lock(mutex_);
  if (busy_) return false;
  setpoints_.emplace_back(axis_id, sp);
  return true;
}

void FakeRuntime::add_name(std::string name, daemon::ParameterLookup object) {
  std::lock_guard lock(mutex_);
  object.ok = true;
  names_[std::move(name)] = object;
}

daemon::ParameterLookup FakeRuntime::lookup_parameter(std::size_t axis_id, std::string_view name,
                                                      std::uint16_t index, std::uint8_t sub) const {
  std::lock_guard lock(mutex_);
  daemon::ParameterLookup out;
  if (!name.empty()) {
    const auto it = names_.find(std::string(name));
    if (it == names_.end()) {
      out.error = "no object named '" + std::string(name) + "'";
      return out;
    }
    out = it->second;
  } else {
    out.ok = true;
    out.index = index;
    out.sub = sub;
  }
  if (const auto it = objects_.find(std::make_tuple(axis_id, out.index, out.sub)); it != objects_.end()) {
    out.type = it->second.type;
    out.type_source = "the test's dictionary";
  }
  return out;
}

bool FakeRuntime::submit_parameter(std::size_t axis_id, const core::ParamRequest& req) {
  std::lock_guard lock(mutex_);
  if (busy_) return false;
  core::ParamReply r;
  r.id = req.id;
  r.axis = static_cast<core::AxisIndex>(axis_id);
  r.type = req.type;
  const auto key = std::make_tuple(axis_id, req.index, req.sub);
  const auto it = objects_.find(key);
  if (req.write) {
    auto& o = objects_[key];
    o.bytes.assign(req.bytes().begin(), req.bytes().end());
    if (o.type == core::ParamType::Unknown) o.type = req.type;
    r.ok = true;
    r.size = req.size;
    std::copy_n(req.data.begin(), req.size, r.data.begin());
  } else if (it != objects_.end()) {
    r.ok = true;
    r.size = static_cast<std::uint16_t>(it->second.bytes.size());
    std::copy(it->second.bytes.begin(), it->second.bytes.end(), r.data.begin());
  } else {
    r.error_code = 0x06020000;  // CiA 301 SDO abort: object does not exist
    r.error.assign("object does not exist in the object dictionary");
  }
  pending_.param_replies.push_back({axis_id, r});
  signal_.notify();
  return true;
}

core::AxisSnapshot FakeRuntime::snapshot(std::size_t axis_id) const {
  core::AxisSnapshot s;
  s.axis = static_cast<core::AxisIndex>(axis_id);
  s.state = core::AxisState::SwitchOnDisabled;
  s.mode = core::Mode::ProfilePosition;
  s.position = 10.0 * static_cast<double>(axis_id) + 1.5;
  s.stamp_ns = kStampNs;
  std::lock_guard lock(mutex_);
  if (const auto p = positions_.find(axis_id); p != positions_.end()) s.position = p->second;
  const auto it = links_.find(axis_id);
  if (it == links_.end()) {
    s.link = core::LinkState::Operational;
  } else {
    s.link = it->second.link;
    s.link_detail = it->second.link_detail;
    s.link_since_ns = it->second.link_since_ns;
  }
  return s;
}

void FakeRuntime::set_position(std::size_t axis_id, double position) {
  std::lock_guard lock(mutex_);
  positions_[axis_id] = position;
}

void FakeRuntime::set_link(std::size_t axis_id, core::LinkState link, std::string_view detail, std::int64_t since_ns) {
  std::lock_guard lock(mutex_);
  core::AxisSnapshot& s = links_[axis_id];
  s.link = link;
  s.link_detail.assign(detail);
  s.link_since_ns = since_ns;
}

void FakeRuntime::put_on_bus(std::size_t axis_id, std::string bus, std::string bus_type) {
  axes_.at(axis_id).bus = std::move(bus);
  axes_.at(axis_id).bus_type = std::move(bus_type);
}

void FakeRuntime::add_bus(daemon::BusStatus status) { extra_buses_.push_back(std::move(status)); }

daemon::BusStatus FakeRuntime::bus_status(std::size_t bus) const {
  if (bus >= 1 && bus - 1 < extra_buses_.size()) return extra_buses_[bus - 1];
  daemon::BusStatus b;
  b.name = "can0";
  b.type = "canopen";
  b.running = true;
  b.healthy = true;
  b.period_ns = 1'000'000;
  b.cycles = 42;
  return b;
}

void FakeRuntime::drain(daemon::Outbox& out) {
  std::lock_guard lock(mutex_);
  out.replies.insert(out.replies.end(), pending_.replies.begin(), pending_.replies.end());
  out.events.insert(out.events.end(), pending_.events.begin(), pending_.events.end());
  out.param_replies.insert(out.param_replies.end(), pending_.param_replies.begin(), pending_.param_replies.end());
  out.io_replies.insert(out.io_replies.end(), pending_.io_replies.begin(), pending_.io_replies.end());
  pending_.clear();
}

void FakeRuntime::set_busy(bool busy) {
  std::lock_guard lock(mutex_);
  busy_ = busy;
}

void FakeRuntime::set_complete_commands(bool complete) {
  std::lock_guard lock(mutex_);
  complete_ = complete;
}

void FakeRuntime::set_object(std::size_t axis_id, std::uint16_t index, std::uint8_t sub, core::ParamType type,
                             std::string_view value) {
  const core::EncodedParam e = core::encode_param(type == core::ParamType::Unknown ? core::ParamType::Domain : type, value);
  if (!e.error.empty()) throw std::invalid_argument("set_object: " + e.error);
  std::lock_guard lock(mutex_);
  objects_[std::make_tuple(axis_id, index, sub)] = Object{type, e.bytes};
}

void FakeRuntime::push_event(std::size_t axis_id, core::EventKind kind, std::string_view text) {
  std::lock_guard lock(mutex_);
  daemon::GlobalEvent e;
  e.axis_id = axis_id;
  e.bus = "can0";
  e.event.kind = kind;
  e.event.text.assign(text);
  pending_.events.push_back(e);
  signal_.notify();
}

std::vector<FakeRuntime::Received> FakeRuntime::commands() const {
  std::lock_guard lock(mutex_);
  return commands_;
}

std::vector<std::pair<std::size_t, core::Setpoint>> FakeRuntime::setpoints() const {
  std::lock_guard lock(mutex_);
  return setpoints_;
}

std::vector<std::uint8_t> FakeRuntime::object(std::size_t axis_id, std::uint16_t index, std::uint8_t sub) const {
  std::lock_guard lock(mutex_);
  const auto it = objects_.find(std::make_tuple(axis_id, index, sub));
  return it == objects_.end() ? std::vector<std::uint8_t>{} : it->second.bytes;
}

}  // namespace drivegate::dds_test
