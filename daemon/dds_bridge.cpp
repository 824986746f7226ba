#include "daemon/dds_bridge.hpp"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <stdexcept>
#include <thread>
#include <utility>

#include <fastdds/dds/core/condition/GuardCondition.hpp>
#include <fastdds/dds/core/condition/StatusCondition.hpp>
#include <fastdds/dds/core/condition/WaitSet.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <spdlog/spdlog.h>

#include "drivegate.h"
#include "idl/dds_node.hpp"

namespace drivegate::daemon {

namespace dds = eprosima::fastdds::dds;
using Clock = std::chrono::steady_clock;

namespace {

// Every command gets a final reply, but a gateway that loses replies (its outbound queue full)
// must not make this bookkeeping grow without bound: the oldest entries go beyond this many.
constexpr std::size_t kMaxPending = 4096;
// The Runtime has no wake-up signal, so its outbox is drained at least this often.
constexpr auto kMaxPoll = std::chrono::milliseconds(5);

std::string known_kinds() {
  std::string s;
  for (std::size_t i = 0; i < core::kCommandKindCount; ++i) {
    if (!s.empty()) s += ", ";
    s += core::to_string(static_cast<core::CommandKind>(i));
  }
  return s;
}

std::string known_modes() {
  std::string s;
  for (std::size_t i = 1; i < core::kModeCount; ++i) {
    if (!s.empty()) s += ", ";
    const auto m = static_cast<core::Mode>(i);
    s += core::to_string(m);
    s += " (";
    s += core::mode_short_name(m);
    s += ')';
  }
  return s;
}

std::string host_name() {
  char buf[256] = {};
  if (::gethostname(buf, sizeof buf - 1) != 0) return "unknown";
  return buf;
}

struct Pending {
  std::string client;
  std::uint64_t client_id = 0;
  std::string axis;
  std::uint16_t index = 0;  // parameter requests: the object accessed
  std::uint8_t sub = 0;
};

template <typename T>
void remember(std::map<core::CommandId, T>& pending, core::CommandId id, T value) {
  pending.emplace(id, std::move(value));
  while (pending.size() > kMaxPending) pending.erase(pending.begin());
}

}  // namespace

class DdsBridge::Impl {
 public:
  Impl(Runtime& runtime, DdsBridgeOptions options) : rt_(runtime), opt_(std::move(options)) {}
  ~Impl() { stop(); }
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  void start();
  void stop();
  [[nodiscard]] Stats stats() const {
    std::lock_guard lock(stats_mutex_);
    return stats_;
  }

 private:
  void run();
  void take_commands();
  void handle_command(const msg::AxisCommand& in);
  void reject(const msg::AxisCommand& in, const std::string& reason);
  void take_setpoints();
  void take_params();
  void handle_param(const msg::ParamRequest& in);
  void take_gateway_infos();
  void publish_outbox();
  void publish_states();
  void publish_bus_status();
  void publish_gateway_info();
  [[nodiscard]] std::optional<std::size_t> find_axis(std::string_view name) const;
  [[nodiscard]] std::string axis_list() const;
  template <typename F>
  void count(F&& f) {
    std::lock_guard lock(stats_mutex_);
    f(stats_);
  }

  Runtime& rt_;
  DdsBridgeOptions opt_;
  std::string gateway_;

  std::unique_ptr<msg::DdsNode> node_;
  dds::DataWriter* state_w_ = nullptr;
  dds::DataWriter* reply_w_ = nullptr;
  dds::DataWriter* event_w_ = nullptr;
  dds::DataWriter* bus_w_ = nullptr;
  dds::DataWriter* param_w_ = nullptr;
  dds::DataWriter* info_w_ = nullptr;
  dds::DataReader* cmd_r_ = nullptr;
  dds::DataReader* sp_r_ = nullptr;
  dds::DataReader* param_r_ = nullptr;
  dds::DataReader* info_r_ = nullptr;
  dds::GuardCondition wake_;
  dds::WaitSet waitset_;

  std::thread thread_;
  std::atomic<bool> running_{false};

  // Bridge-thread state.
  core::CommandId next_id_ = 1;
  std::map<core::CommandId, Pending> pending_commands_;
  std::map<core::CommandId, Pending> pending_params_;
  std::set<std::pair<std::string, std::string>> warned_duplicates_;  // (other gateway, axis)
  std::set<std::pair<std::string, std::string>> warned_setpoints_;   // (client, axis)
  Outbox outbox_;
  std::uint64_t state_seq_ = 0;

  mutable std::mutex stats_mutex_;
  Stats stats_;
};

void DdsBridge::Impl::start() {
  if (running_) return;
  if (!std::isfinite(opt_.status_rate_hz) || opt_.status_rate_hz <= 0 || opt_.status_rate_hz > 1000)
    throw std::invalid_argument("DDS status rate must be in (0, 1000] Hz, got " + std::to_string(opt_.status_rate_hz));
  gateway_ = rt_.gateway_name();
  node_ = std::make_unique<msg::DdsNode>(opt_.domain, opt_.ns, "drivegated/" + gateway_);
  state_w_ = &node_->writer(msg::TopicId::AxisState);
  reply_w_ = &node_->writer(msg::TopicId::CommandReply);
  event_w_ = &node_->writer(msg::TopicId::AxisEvent);
  bus_w_ = &node_->writer(msg::TopicId::BusStatus);
  param_w_ = &node_->writer(msg::TopicId::ParamReply);
  info_w_ = &node_->writer(msg::TopicId::GatewayInfo);
  cmd_r_ = &node_->reader(msg::TopicId::AxisCommand);
  sp_r_ = &node_->reader(msg::TopicId::Setpoint);
  param_r_ = &node_->reader(msg::TopicId::ParamRequest);
  info_r_ = &node_->reader(msg::TopicId::GatewayInfo);
  for (dds::DataReader* r : {cmd_r_, sp_r_, param_r_, info_r_}) {
    r->get_statuscondition().set_enabled_statuses(dds::StatusMask::data_available());
    waitset_.attach_condition(r->get_statuscondition());
  }
  wake_.set_trigger_value(false);
  waitset_.attach_condition(wake_);

  publish_gateway_info();
  spdlog::info("dds: gateway '{}' on domain {} namespace '{}', {} axes, state at {} Hz", gateway_, opt_.domain,
               opt_.ns, rt_.axes().size(), opt_.status_rate_hz);
  running_ = true;
  thread_ = std::thread([this] { run(); });
}

void DdsBridge::Impl::stop() {
  if (!running_.exchange(false)) return;
  wake_.set_trigger_value(true);
  thread_.join();
  for (dds::DataReader* r : {cmd_r_, sp_r_, param_r_, info_r_}) waitset_.detach_condition(r->get_statuscondition());
  waitset_.detach_condition(wake_);
  node_.reset();
  spdlog::info("dds: bridge of gateway '{}' stopped", gateway_);
}

void DdsBridge::Impl::run() {
  const auto state_period =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / opt_.status_rate_hz));
  const auto bus_period = std::max<Clock::duration>(state_period, std::chrono::seconds(1));
  auto next_state = Clock::now();
  auto next_bus = Clock::now();
  dds::ConditionSeq active;
  while (running_) {
    const auto now = Clock::now();
    const auto wait = std::clamp<Clock::duration>(next_state - now, Clock::duration::zero(), kMaxPoll);
    const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(wait).count();
    waitset_.wait(active, eprosima::fastrtps::Duration_t(static_cast<std::int32_t>(ns / 1'000'000'000),
                                                         static_cast<std::uint32_t>(ns % 1'000'000'000)));
    if (!running_) break;
    take_commands();
    take_setpoints();
    take_params();
    take_gateway_infos();
    publish_outbox();
    const auto t = Clock::now();
    if (t >= next_state) {
      publish_states();
      next_state += state_period;
      if (next_state < t) next_state = t + state_period;  // fell behind: do not burst to catch up
    }
    if (t >= next_bus) {
      publish_bus_status();
      next_bus = t + bus_period;
    }
  }
}

std::optional<std::size_t> DdsBridge::Impl::find_axis(std::string_view name) const {
  const auto axes = rt_.axes();
  for (std::size_t i = 0; i < axes.size(); ++i)
    if (axes[i].name == name) return i;
  return std::nullopt;
}

std::string DdsBridge::Impl::axis_list() const {
  std::string s;
  for (const auto& a : rt_.axes()) {
    if (!s.empty()) s += ", ";
    s += a.name;
  }
  return s.empty() ? "(none)" : s;
}

void DdsBridge::Impl::take_commands() {
  msg::take_valid<msg::AxisCommand>(*cmd_r_, [&](const msg::AxisCommand& in) {
    if (in.gateway() != gateway_) {
      // Another gateway's axis: the owner answers, we stay silent.
      spdlog::debug("dds: ignoring {} for {}/{} from '{}' (not our gateway)", in.kind(), in.gateway(), in.axis(),
                    in.client());
      count([](Stats& s) { ++s.commands_ignored; });
      return;
    }
    handle_command(in);
  });
}

void DdsBridge::Impl::reject(const msg::AxisCommand& in, const std::string& reason) {
  spdlog::warn("dds: rejected {} for axis '{}' from '{}' id {}: {}", in.kind(), in.axis(), in.client(), in.id(),
               reason);
  msg::CommandReply out;
  out.gateway(gateway_);
  out.axis(in.axis());
  out.client(in.client());
  out.id(in.id());
  out.status(std::string(core::to_string(core::ReplyStatus::Rejected)));
  out.reason(reason);
  reply_w_->write(&out);
  count([](Stats& s) { ++s.commands_rejected; });
}

void DdsBridge::Impl::handle_command(const msg::AxisCommand& in) {
  if (in.client().empty()) return reject(in, "command without a client id (field 'client')");
  const auto axis = find_axis(in.axis());
  if (!axis)
    return reject(in, "unknown axis '" + in.axis() + "' on gateway '" + gateway_ + "'; axes here: " + axis_list());
  const auto kind = core::parse_command_kind(in.kind());
  if (!kind) return reject(in, "unknown command kind '" + in.kind() + "'; known: " + known_kinds());
  core::Mode mode = core::Mode::None;
  if (!in.mode().empty()) {
    const auto m = core::parse_mode(in.mode());
    if (!m) return reject(in, "unknown mode '" + in.mode() + "'; known: " + known_modes());
    mode = *m;
  }
  if (*kind == core::CommandKind::SetMode && mode == core::Mode::None)
    return reject(in, "set_mode needs a mode; known: " + known_modes());

  core::Command cmd;
  cmd.id = next_id_++;
  cmd.kind = *kind;
  cmd.mode = mode;
  cmd.position = in.position();
  cmd.velocity = in.velocity();
  cmd.acceleration = in.acceleration();
  cmd.deceleration = in.deceleration();
  cmd.torque = in.torque();
  cmd.relative = in.relative();
  cmd.immediate = in.immediate();
  cmd.homing_method = in.homing_method();
  cmd.home_offset = in.home_offset();
  cmd.homing_search_velocity = in.homing_search_velocity();
  cmd.homing_zero_velocity = in.homing_zero_velocity();
  cmd.block = in.block();
  if (!rt_.submit_command(*axis, cmd))
    return reject(in, "gateway busy: the command queue of axis '" + in.axis() + "' is full");
  remember(pending_commands_, cmd.id, Pending{in.client(), in.id(), in.axis()});
  spdlog::info("dds: {} for axis '{}' from '{}' id {} -> command {}", in.kind(), in.axis(), in.client(), in.id(),
               cmd.id);
  count([](Stats& s) { ++s.commands_routed; });
}

void DdsBridge::Impl::take_setpoints() {
  msg::take_valid<msg::Setpoint>(*sp_r_, [&](const msg::Setpoint& in) {
    if (in.gateway() != gateway_) return;
    const auto axis = find_axis(in.axis());
    core::Setpoint sp;
    sp.position = in.position();
    sp.velocity = in.velocity();
    sp.torque = in.torque();
    if (axis && rt_.submit_setpoint(*axis, sp)) {
      count([](Stats& s) { ++s.setpoints_routed; });
      return;
    }
    count([](Stats& s) { ++s.setpoints_dropped; });
    // Set-points stream at high rate: log the first drop per client and axis only.
    if (warned_setpoints_.emplace(in.client(), in.axis()).second)
      spdlog::warn("dds: dropping set-points from '{}' for axis '{}': {}", in.client(), in.axis(),
                   axis ? "queue full" : "unknown axis; axes here: " + axis_list());
  });
}

void DdsBridge::Impl::take_params() {
  msg::take_valid<msg::ParamRequest>(*param_r_, [&](const msg::ParamRequest& in) {
    if (in.gateway() != gateway_) return;
    handle_param(in);
  });
}

void DdsBridge::Impl::handle_param(const msg::ParamRequest& in) {
  auto fail = [&](const std::string& error) {
    spdlog::warn("dds: parameter request {:04X}:{} for axis '{}' from '{}' failed: {}", in.index(), in.subindex(),
                 in.axis(), in.client(), error);
    msg::ParamReply out;
    out.gateway(gateway_);
    out.axis(in.axis());
    out.client(in.client());
    out.id(in.id());
    out.ok(false);
    out.error(error);
    out.index(in.index());
    out.subindex(in.subindex());
    param_w_->write(&out);
  };
  const auto axis = find_axis(in.axis());
  if (!axis) return fail("unknown axis '" + in.axis() + "' on gateway '" + gateway_ + "'; axes here: " + axis_list());
  core::ParamRequest req;
  req.id = next_id_++;
  req.write = in.write();
  req.index = in.index();
  req.sub = in.subindex();
  req.size = in.size();
  req.is_signed = in.is_signed();
  req.value = in.value();
  if (!in.name().empty()) {
    const ParameterLookup p = rt_.lookup_parameter(*axis, in.name());
    if (!p.ok) return fail(p.error);
    req.index = p.index;
    req.sub = p.sub;
    if (p.size != 0) {
      req.size = p.size;
      req.is_signed = p.is_signed;
    }
  }
  if (req.size != 1 && req.size != 2 && req.size != 4)
    return fail("parameter size must be 1, 2 or 4 bytes, got " + std::to_string(req.size));
  if (!rt_.submit_parameter(*axis, req))
    return fail("gateway busy: the parameter queue of axis '" + in.axis() + "' is full");
  remember(pending_params_, req.id, Pending{in.client(), in.id(), in.axis(), req.index, req.sub});
  spdlog::info("dds: parameter {} {:04X}:{} for axis '{}' from '{}' id {} -> request {}", in.write() ? "write" : "read",
               req.index, req.sub, in.axis(), in.client(), in.id(), req.id);
  count([](Stats& s) { ++s.params_routed; });
}

void DdsBridge::Impl::take_gateway_infos() {
  msg::take_valid<msg::GatewayInfo>(*info_r_, [&](const msg::GatewayInfo& in) {
    if (in.gateway() == gateway_) return;
    spdlog::info("dds: gateway '{}' on {} (pid {}) owns {} axes", in.gateway(), in.host(), in.pid(), in.axes().size());
    for (const auto& other : in.axes()) {
      if (!find_axis(other.name())) return;
      if (!warned_duplicates_.emplace(in.gateway(), other.name()).second) return;
      const std::string text = "axis '" + other.name() + "' is claimed by gateway '" + gateway_ + "' and by gateway '" +
                               in.gateway() + "'; clients must name the gateway for this axis";
      spdlog::warn("dds: {}", text);
      msg::AxisEvent ev;
      ev.gateway(gateway_);
      ev.axis(other.name());
      ev.kind(std::string(core::to_string(core::EventKind::Warning)));
      ev.state(std::string(core::to_string(core::AxisState::Unknown)));
      ev.text(text);
      ev.stamp(std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch()).count());
      event_w_->write(&ev);
    }
  });
}

void DdsBridge::Impl::publish_outbox() {
  outbox_.clear();
  rt_.drain(outbox_);
  const auto axes = rt_.axes();
  auto axis_name = [&](std::size_t id) -> std::string { return id < axes.size() ? axes[id].name : std::string(); };

  for (const auto& r : outbox_.replies) {
    const auto it = pending_commands_.find(r.reply.id);
    if (it == pending_commands_.end()) {
      spdlog::debug("dds: reply {} for command {} of no DDS client", core::to_string(r.reply.status), r.reply.id);
      continue;
    }
    msg::CommandReply out;
    out.gateway(gateway_);
    out.axis(it->second.axis);
    out.client(it->second.client);
    out.id(it->second.client_id);
    out.status(std::string(core::to_string(r.reply.status)));
    out.reason(r.reply.reason.str());
    reply_w_->write(&out);
    spdlog::info("dds: command {} ('{}' id {} on '{}'): {}{}{}", r.reply.id, out.client(), out.id(), out.axis(),
                 out.status(), out.reason().empty() ? "" : ": ", out.reason());
    if (r.reply.status != core::ReplyStatus::Accepted) pending_commands_.erase(it);
  }

  for (const auto& e : outbox_.events) {
    msg::AxisEvent out;
    out.gateway(gateway_);
    out.axis(e.axis_id == SIZE_MAX ? std::string() : axis_name(e.axis_id));
    out.bus(e.bus);
    out.kind(std::string(core::to_string(e.event.kind)));
    out.state(std::string(core::to_string(e.event.state)));
    out.code(e.event.code);
    out.text(e.event.text.str());
    out.stamp(e.event.stamp_ns);
    // The gateway logs every event once when it drains it; here only the publication is traced.
    event_w_->write(&out);
    spdlog::trace("dds: published event {} on '{}'", out.kind(), out.axis().empty() ? out.bus() : out.axis());
  }

  for (const auto& p : outbox_.param_replies) {
    const auto it = pending_params_.find(p.reply.id);
    if (it == pending_params_.end()) {
      spdlog::debug("dds: parameter reply {} of no DDS client", p.reply.id);
      continue;
    }
    msg::ParamReply out;
    out.gateway(gateway_);
    out.axis(it->second.axis);
    out.client(it->second.client);
    out.id(it->second.client_id);
    out.ok(p.reply.ok);
    out.value(p.reply.value);
    out.error_code(p.reply.error_code);
    out.error(p.reply.error.str());
    out.index(it->second.index);
    out.subindex(it->second.sub);
    param_w_->write(&out);
    spdlog::info("dds: parameter request {} ('{}' id {}): {}", p.reply.id, out.client(), out.id(),
                 out.ok() ? "ok" : "error: " + out.error());
    pending_params_.erase(it);
  }
}

void DdsBridge::Impl::publish_states() {
  const auto axes = rt_.axes();
  msg::AxisState out;
  out.gateway(gateway_);
  ++state_seq_;
  for (std::size_t i = 0; i < axes.size(); ++i) {
    const core::AxisSnapshot s = rt_.snapshot(i);
    out.axis(axes[i].name);
    out.state(std::string(core::to_string(s.state)));
    out.link(std::string(core::to_string(s.link)));
    out.mode(std::string(core::to_string(s.mode)));
    out.position(s.position);
    out.velocity(s.velocity);
    out.torque(s.torque);
    out.unit(axes[i].unit);
    out.fault_code(s.fault_code);
    out.fault_text(s.fault_text.str());
    out.target_reached(s.target_reached);
    out.homed(s.homed);
    out.warning(s.warning);
    out.stopping(s.stopping);
    out.following_error(s.following_error);
    out.statusword(s.statusword);
    out.active_command(s.active_command);
    out.stamp(s.stamp_ns);
    out.seq(state_seq_);
    state_w_->write(&out);
  }
  count([&](Stats& st) { st.states_published += axes.size(); });
}

void DdsBridge::Impl::publish_bus_status() {
  msg::BusStatus out;
  out.gateway(gateway_);
  for (std::size_t b = 0; b < rt_.bus_count(); ++b) {
    const BusStatus s = rt_.bus_status(b);
    out.bus(s.name);
    out.type(s.type);
    out.running(s.running);
    out.healthy(s.healthy);
    out.period_ns(s.period_ns);
    out.achieved_period_ns(s.achieved_period_ns);
    out.lateness_p50_ns(s.lateness_p50_ns);
    out.lateness_p99_ns(s.lateness_p99_ns);
    out.lateness_max_ns(s.lateness_max_ns);
    out.cycles(s.cycles);
    out.overruns(s.overruns);
    out.frames_sent(s.counters.frames_sent);
    out.frames_received(s.counters.frames_received);
    out.frames_lost(s.counters.frames_lost);
    out.frames_dropped(s.counters.frames_dropped);
    out.errors(s.counters.errors);
    bus_w_->write(&out);
  }
}

void DdsBridge::Impl::publish_gateway_info() {
  msg::GatewayInfo out;
  out.gateway(gateway_);
  out.host(host_name());
  out.pid(static_cast<std::uint32_t>(::getpid()));
  for (const auto& a : rt_.axes()) {
    msg::AxisDescription d;
    d.name(a.name);
    d.bus(a.bus);
    d.device(a.device);
    d.unit(a.unit);
    for (std::size_t i = 1; i < core::kModeCount; ++i) {
      const auto m = static_cast<core::Mode>(i);
      if (a.modes.contains(m)) d.modes().emplace_back(core::to_string(m));
    }
    out.axes().push_back(std::move(d));
  }
  info_w_->write(&out);
}

DdsBridge::DdsBridge(Runtime& runtime, DdsBridgeOptions options)
    : impl_(std::make_unique<Impl>(runtime, std::move(options))) {}
DdsBridge::~DdsBridge() = default;
void DdsBridge::start() { impl_->start(); }
void DdsBridge::stop() { impl_->stop(); }
DdsBridge::Stats DdsBridge::stats() const { return impl_->stats(); }

}  // namespace drivegate::daemon
