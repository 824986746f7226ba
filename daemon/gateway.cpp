#include "daemon/gateway.hpp"

#include <spdlog/spdlog.h>

#include <chrono>
#include <sstream>
#include <thread>

#include "config/bus_types.hpp"
#include "daemon/bus_factory.hpp"
#include "profiles/cia402/standard_types.hpp"

namespace drivegate::daemon {

using namespace std::chrono_literals;

namespace {
// States in which the power stage is off and stays off without a new command.
bool is_disabled(core::AxisState s) noexcept {
  return s == core::AxisState::SwitchOnDisabled || s == core::AxisState::NotReadyToSwitchOn ||
         s == core::AxisState::Fault;
}
std::string_view severity_of(const core::Event& e) {
  switch (e.kind) {
    case core::EventKind::Fault:
    case core::EventKind::ControlLost:
    case core::EventKind::DuplicateGateway:
    case core::EventKind::CommandTimeout: return "error";
    case core::EventKind::Warning: return "warning";
    case core::EventKind::Emcy: return e.code == 0 ? "info" : "warning";  // 0000h: error reset / no error
    default: return "info";
  }
}
}  // namespace

Gateway::Gateway(const config::Plan& plan) : name_(plan.gateway.name) {
  buses_.reserve(plan.buses.size());
  for (const auto& bp : plan.buses) {
    BusSlot slot;
    slot.plan = &bp;
    slot.first_axis = axes_.size();
    for (const auto& ap : bp.axes) {
      slot.specs.push_back(ap.spec);
      AxisInfo info;
      info.name = ap.spec.name;
      info.bus = bp.name;
      info.bus_type = bp.type;
      info.address = static_cast<std::uint32_t>(ap.address);
      info.device = ap.device.name;
      info.unit = ap.spec.user_unit;
      info.modes = ap.spec.modes;
      axes_.push_back(std::move(info));
      refs_.push_back({buses_.size(), static_cast<core::AxisIndex>(refs_.size() - slot.first_axis)});
    }
    slot.bus = make_bus(bp);
    slot.runner = std::make_unique<core::BusRunner>(*slot.bus, slot.specs);
    // The bridge samples the snapshots at the status rate: stored four times per status period,
    // a published state is at most a quarter period older than its sample.
    slot.runner->set_publish_period(std::chrono::duration_cast<core::Duration>(
        std::chrono::duration<double>(0.25 / plan.gateway.status_rate_hz)));
    slot.first_io = io_.size();
    for (std::size_t k = 0; k < slot.bus->io_count(); ++k) {
      const core::IoInfo i = slot.bus->io_info(k);
      io_.push_back(IoSlaveInfo{std::string(i.name), bp.name, bp.type, buses_.size(), i.address, i.input_size,
                                i.output_size, i.sized});
    }
    buses_.push_back(std::move(slot));
  }
}

Gateway::~Gateway() {
  for (auto& b : buses_) {
    if (b.thread) b.thread->stop();
    if (b.open) b.bus->close();
  }
}

void Gateway::start() {
  for (auto& b : buses_) {
    const auto now = core::SteadyClock{}.now();
    try {
      if (const auto resource = bus_resource(*b.plan); !resource.empty()) b.lock = std::make_unique<BusLock>(resource);
      b.bus->open(now);
    } catch (const core::BusError& e) {
      throw core::BusError("bus '" + b.plan->name + "' (" + b.plan->type + "): " + e.what());
    }
    b.open = true;
    CycleThread::Schedule sched;
    sched.period = b.plan->cycle_time;
    sched.priority = b.plan->priority;
    sched.cpu = b.plan->cpu;
    sched.name = "dg-cycle-" + b.plan->name;  // "dg-cycle-sim0" (the kernel keeps 15 characters)
    core::BusRunner* runner = b.runner.get();
    core::Bus* bus = b.bus.get();
    b.thread = std::make_unique<CycleThread>(
        sched,
        [runner, signal = &output_signal_](core::TimePoint t, std::uint64_t) {
          if (runner->cycle(t)) signal->notify();
        },
        [bus](core::TimePoint deadline) { bus->serve_until(deadline); });
    if (!b.thread->start()) throw core::BusError("bus '" + b.plan->name + "': could not start its cycle thread");
    spdlog::info("bus {}: {} with {} axes, cycle {} us", b.plan->name, b.plan->type, b.specs.size(),
                 std::chrono::duration_cast<std::chrono::microseconds>(b.plan->cycle_time).count());
  }
}

bool Gateway::submit_command(std::size_t axis_id, const core::Command& cmd) {
  if (axis_id >= refs_.size()) return false;
  std::lock_guard lock(submit_mutex_);
  if (shutting_down_.load() && !core::is_internal(cmd.id)) {
    GlobalReply r;
    r.axis_id = axis_id;
    r.reply.id = cmd.id;
    r.reply.axis = refs_[axis_id].axis;
    r.reply.status = core::ReplyStatus::Rejected;
    r.reply.reason.assign("gateway is shutting down: every axis is being stopped and disabled");
    local_replies_.push_back(r);
    output_signal_.notify();
    return true;
  }
  core::Command c = cmd;
  c.axis = refs_[axis_id].axis;
  return buses_[refs_[axis_id].bus].runner->push_command(c);
}

bool Gateway::submit_setpoint(std::size_t axis_id, const core::Setpoint& sp) {
  if (axis_id >= refs_.size() || shutting_down_.load()) return false;
  std::lock_guard lock(submit_mutex_);
  core::Setpoint s = sp;
  s.axis = refs_[axis_id].axis;
  return buses_[refs_[axis_id].bus].runner->push_setpoint(s);
}

bool Gateway::submit_parameter(std::size_t axis_id, const core::ParamRequest& req) {
  const bool to_io = req.record.valid && req.record.io != core::kNoIo;
  if (to_io ? req.record.io >= io_.size() : axis_id >= refs_.size()) return false;
  std::lock_guard lock(submit_mutex_);
  if (shutting_down_.load()) {
    GlobalParamReply r;
    r.axis_id = axis_id;
    r.reply.id = req.id;
    r.reply.axis = to_io ? core::kNoAxis : refs_[axis_id].axis;
    r.reply.ok = false;
    r.reply.error.assign("gateway is shutting down: no parameter access while axes are being disabled");
    local_param_replies_.push_back(r);
    output_signal_.notify();
    return true;
  }
  core::ParamRequest r = req;
  if (to_io) {
    BusSlot& b = buses_[io_[req.record.io].bus_index];
    r.axis = core::kNoAxis;
    r.record.io = static_cast<std::uint16_t>(req.record.io - b.first_io);
    return b.runner->push_parameter(r);
  }
  r.axis = refs_[axis_id].axis;
  return buses_[refs_[axis_id].bus].runner->push_parameter(r);
}

core::AxisSnapshot Gateway::snapshot(std::size_t axis_id) const {
  if (axis_id >= refs_.size()) return {};
  return buses_[refs_[axis_id].bus].runner->snapshot(refs_[axis_id].axis);
}

core::IoSnapshot Gateway::io_snapshot(std::size_t io_id) const {
  if (io_id >= io_.size()) return {};
  const auto& b = buses_[io_[io_id].bus_index];
  return b.runner->io_snapshot(io_id - b.first_io);
}

bool Gateway::submit_io_write(std::size_t io_id, const core::IoWrite& w) {
  if (io_id >= io_.size()) return false;
  std::lock_guard lock(submit_mutex_);
  auto& b = buses_[io_[io_id].bus_index];
  core::IoWrite local = w;
  local.slave = static_cast<std::uint16_t>(io_id - b.first_io);
  return b.runner->push_io_write(local);
}

BusStatus Gateway::bus_status(std::size_t bus) const {
  BusStatus s;
  if (bus >= buses_.size()) return s;
  const auto& b = buses_[bus];
  s.name = b.plan->name;
  s.type = b.plan->type;
  s.period_ns = b.plan->cycle_time.count();
  if (b.thread) {
    const auto t = b.thread->timing();
    s.running = b.thread->running();
    s.healthy = b.thread->healthy(core::SteadyClock{}.now());
    s.achieved_period_ns = t.achieved_period_ns;
    s.lateness_p50_ns = t.lateness_p50_ns;
    s.lateness_p99_ns = t.lateness_p99_ns;
    s.lateness_max_ns = t.lateness_max_ns;
    s.cycles = t.cycles;
    s.overruns = t.overruns;
  }
  s.counters = b.bus->counters();
  s.counters.frames_dropped += b.runner->dropped_outputs();
  s.clock_sync = b.bus->clock_sync();
  return s;
}

void Gateway::drain(Outbox& out) {
  for (const auto& b : buses_) {
    GlobalReply r;
    while (b.runner->pop_reply(r.reply)) {
      r.axis_id = b.first_axis + r.reply.axis;
      out.replies.push_back(r);
    }
    GlobalEvent e;
    while (b.runner->pop_event(e.event)) {
      e.bus = b.plan->name;
      e.axis_id = e.event.axis == core::kNoAxis ? SIZE_MAX : b.first_axis + e.event.axis;
      const std::string who = e.axis_id == SIZE_MAX ? "bus " + e.bus : "axis " + axes_[e.axis_id].name;
      const auto sev = severity_of(e.event);
      const auto level = sev == "error" ? spdlog::level::err : sev == "warning" ? spdlog::level::warn : spdlog::level::info;
      // Codes are drive error codes for faults and warnings; other events use them internally.
      const bool has_code = e.event.kind == core::EventKind::Fault || e.event.kind == core::EventKind::Warning ||
                            e.event.kind == core::EventKind::FaultCleared;
      if (has_code && e.event.code != 0)
        spdlog::log(level, "{}: {} 0x{:04X}: {}", who, core::to_string(e.event.kind), e.event.code, e.event.text.view());
      else
        spdlog::log(level, "{}: {}: {}", who, core::to_string(e.event.kind), e.event.text.view());
      out.events.push_back(e);
    }
    GlobalParamReply p;
    while (b.runner->pop_parameter_reply(p.reply)) {
      p.axis_id = p.reply.axis == core::kNoAxis ? SIZE_MAX : b.first_axis + p.reply.axis;  // an IO device's record
      out.param_replies.push_back(p);
    }
    GlobalIoReply io;
    while (b.runner->pop_io_reply(io.reply)) {
      io.io_id = b.first_io + io.reply.slave;
      out.io_replies.push_back(io);
    }
  }
  std::lock_guard lock(submit_mutex_);
  out.replies.insert(out.replies.end(), local_replies_.begin(), local_replies_.end());
  local_replies_.clear();
  out.param_replies.insert(out.param_replies.end(), local_param_replies_.begin(), local_param_replies_.end());
  local_param_replies_.clear();
}

void Gateway::submit_internal(std::size_t axis_id, core::CommandKind kind) {
  core::Command c;
  {
    std::lock_guard lock(submit_mutex_);
    c.id = next_internal_++;
  }
  c.kind = kind;
  // The queue may be momentarily full of client commands; the cycle thread empties it every cycle.
  for (int attempt = 0; attempt < 100 && !submit_command(axis_id, c); ++attempt) std::this_thread::sleep_for(1ms);
}

template <typename Pred>
bool Gateway::wait_all(Pred pred, core::Duration budget) const {
  const auto deadline = std::chrono::steady_clock::now() + budget;
  for (;;) {
    bool all = true;
    for (std::size_t i = 0; i < refs_.size() && all; ++i) all = pred(i, snapshot(i));
    if (all) return true;
    if (std::chrono::steady_clock::now() >= deadline) return false;
    // Polling the seqlocked snapshots: the cycle threads must not be made to signal anyone.
    std::this_thread::sleep_for(2ms);
  }
}

ShutdownReport Gateway::shutdown(core::Duration phase_budget) {
  ShutdownReport report;
  {
    // From here on client commands are refused; what was queued before is still handled, in
    // order, ahead of the stop and disable below.
    std::lock_guard lock(submit_mutex_);
    shutting_down_ = true;
  }
  const auto reachable = [](const core::AxisSnapshot& s) { return s.link == core::LinkState::Operational; };
  // A snapshot taken before a command was handled says nothing about its effect: wait for a
  // cycle that started after the submission.
  std::vector<std::uint64_t> submitted_at(refs_.size(), 0);
  const auto fresh = [&](std::size_t i, const core::AxisSnapshot& s) { return s.cycle > submitted_at[i] + 1; };

  bool any_thread = false;
  for (const auto& b : buses_) any_thread = any_thread || (b.thread && b.thread->running());
  if (any_thread) {
    // Phase 1: brake every enabled axis on its quick-stop ramp.
    for (std::size_t i = 0; i < refs_.size(); ++i) {
      const auto s = snapshot(i);
      submitted_at[i] = s.cycle;
      if (reachable(s) && s.state == core::AxisState::OperationEnabled) {
        submit_internal(i, core::CommandKind::QuickStop);
        ++report.stopped;
      }
    }
    if (report.stopped > 0)
      wait_all(
          [&](std::size_t i, const core::AxisSnapshot& s) {
            return !reachable(s) || (fresh(i, s) && s.state != core::AxisState::OperationEnabled);
          },
          phase_budget);
    // Phase 2: disable every reachable axis, whatever state it showed: one that is half-way
    // through an enable walk may still show switch_on_disabled. A disable of a disabled axis
    // completes at once.
    for (std::size_t i = 0; i < refs_.size(); ++i) {
      const auto s = snapshot(i);
      submitted_at[i] = s.cycle;
      if (reachable(s)) submit_internal(i, core::CommandKind::Disable);
    }
    wait_all([&](std::size_t i, const core::AxisSnapshot& s) { return !reachable(s) || (fresh(i, s) && is_disabled(s.state)); },
             phase_budget);
    // An axis whose drive stopped following the gateway is being stopped over the acyclic channel
    // by its bus (link degraded): the bus must not be released before that is done.
    const auto degraded = [](const core::AxisSnapshot& s) { return s.link == core::LinkState::Degraded; };
    wait_all([&](std::size_t, const core::AxisSnapshot& s) { return !degraded(s); }, phase_budget);
    for (std::size_t i = 0; i < refs_.size(); ++i) {
      const auto s = snapshot(i);
      if (degraded(s))
        report.unconfirmed.push_back(axes_[i].name + " (out of the gateway's control, still being stopped)");
      else if (!reachable(s) || is_disabled(s.state))
        ++report.disabled;
      else
        report.unconfirmed.push_back(axes_[i].name + " (" + std::string(core::to_string(s.state)) + ")");
    }
  }
  for (auto& b : buses_) {
    if (b.thread) b.thread->stop();
    if (b.open) {
      b.bus->close();
      b.open = false;
    }
    b.lock.reset();
  }
  return report;
}

bool Gateway::healthy() const noexcept {
  const auto now = core::SteadyClock{}.now();
  for (const auto& b : buses_)
    if (!b.thread || !b.thread->healthy(now)) return false;
  return true;
}

std::string Gateway::status_line() const {
  std::size_t enabled = 0, faulted = 0, lost = 0;
  for (std::size_t i = 0; i < refs_.size(); ++i) {
    const auto s = snapshot(i);
    enabled += s.state == core::AxisState::OperationEnabled ? 1 : 0;
    faulted += s.state == core::AxisState::Fault ? 1 : 0;
    lost += s.link != core::LinkState::Operational ? 1 : 0;
  }
  std::ostringstream o;
  o << buses_.size() << (buses_.size() == 1 ? " bus, " : " buses, ") << refs_.size() << " axes: " << enabled
    << " enabled, " << faulted << " in fault, " << lost << " not operational";
  if (!healthy()) o << "; a cycle thread is late";
  return o.str();
}

std::vector<std::string> Gateway::scheduling_notes() const {
  std::vector<std::string> notes;
  for (const auto& b : buses_)
    if (b.thread && !b.thread->scheduling_note().empty())
      notes.push_back("bus " + b.plan->name + ": " + b.thread->scheduling_note());
  return notes;
}

// The axis' bus type resolves names and knows types from its own files (canopen: EDS, device
// profile; ethercat: ESI); a name they do not know is asked of the bus (the device's own
// dictionary, ethercat); else the standards give the type. Without names: INDEX:SUB. A PROFIdrive
// axis takes PNUs (config/profinet/parameters.hpp).
ParameterLookup Gateway::lookup_parameter(std::size_t axis_id, std::string_view name, std::uint16_t index,
                                          std::uint8_t sub) const {
  ParameterLookup out;
  if (axis_id >= refs_.size()) {
    out.error = "unknown axis";
    return out;
  }
  const AxisRef ref = refs_[axis_id];
  const config::BusPlan& bus = *buses_[ref.bus].plan;
  const config::AxisPlan& axis = bus.axes[ref.axis];
  config::ParameterRef p;
  if (bus.type_info && bus.type_info->find_parameter)
    p = bus.type_info->find_parameter(axis, name, cia402::ObjectId{index, sub});
  else if (name.empty())
    p.id = cia402::ObjectId{index, sub};
  else
    p.error = "axis '" + axis.spec.name + "' has no object named '" + std::string(name) +
              "' (give the axis an EDS file to use names, or use INDEX:SUB)";
  if (!p.id && !name.empty() && (p.name_unknown || !bus.type_info || !bus.type_info->find_parameter)) {
    // The device's own names (EtherCAT: its dictionary read over SDO Information).
    core::NamedObject named = buses_[ref.bus].bus->find_object(ref.axis, name);
    if (named.found) {
      p.id = cia402::ObjectId{named.index, named.sub};
      p.type = named.type;
      p.type_source = std::move(named.source);
    } else if (!named.error.empty()) {
      p.error = "axis '" + axis.spec.name + "': " + named.error;
    }
  }
  if (!p.id) {
    out.error = std::move(p.error);
    return out;
  }
  out.ok = true;
  out.index = p.id->index;
  out.sub = p.id->sub;
  if (p.type != core::ParamType::Unknown) {
    out.type = p.type;
    out.type_source = std::move(p.type_source);
  } else if (const auto t = bus.type_info && !bus.type_info->cia402_device ? core::ParamType::Unknown
                                                                           : cia402::standard_param_type(*p.id);
             t != core::ParamType::Unknown) {
    // Only a CiA 402 drive's objects have the standards' types (a PROFIdrive PNU is no object index).
    out.type = t;
    out.type_source = out.index < 0x2000 ? "CiA 301" : "CiA 402";
  }
  return out;
}

}  // namespace drivegate::daemon
