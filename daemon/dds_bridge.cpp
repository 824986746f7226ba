#include "daemon/dds_bridge.hpp"

#include <pthread.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <map>
#include <mutex>
#include <optional>
#include <random>
#include <set>
#include <stdexcept>
#include <thread>
#include <utility>

#include <fastdds/dds/core/status/PublicationMatchedStatus.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <spdlog/spdlog.h>

#include "core/param_value.hpp"
#include "core/record_address.hpp"
#include "daemon/log_limiter.hpp"
#include "drivegate.h"
#include "idl/dds_node.hpp"

namespace drivegate::daemon {

namespace dds = eprosima::fastdds::dds;
using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

namespace {

// The bridge sleeps until the Runtime's output signal (replies, events), DDS data or the next
// publication is due. Only while requests wait for room in the Runtime's queues, or replies for
// their client's reader or writer history, does it come back this often to retry.
constexpr auto kBusyPoll = 1ms;
// A request that found no place in the Runtime's queue for this long is answered "busy".
constexpr auto kBusyAfter = 2s;
// Replies for a client wait this long for its reply reader to match before they go out anyway (a
// client may read replies through another participant than the one it writes commands with).
constexpr auto kReplyHold = 1500ms;
// At most this many requests are taken from DDS per pass; more replies than this waiting to be
// written make the bridge stop taking requests until they are out.
constexpr std::size_t kTakePerPass = 256;
constexpr std::size_t kMaxReplyBacklog = 2048;
// A client with this many requests still unanswered gets "busy" for more: its replies then always
// fit the reply topics' history per client (idl/dds_node.cpp), read or not.
constexpr int kClientLimit = 256;
// A reply that waited this long for room in its client's reply history is warned about.
constexpr auto kReplyStall = 5s;
// A summary of the traffic instead of a log line per command.
constexpr auto kSummaryPeriod = 10s;

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

// The participant a writer or reader belongs to: the first 12 bytes (GUID prefix) of its handle.
using Prefix = std::array<std::uint8_t, 12>;
Prefix prefix_of(const dds::InstanceHandle_t& h) {
  Prefix p{};
  for (std::size_t i = 0; i < p.size(); ++i) p[i] = h.value[i];
  return p;
}

// "1008h:00", as the gateway names objects in its messages.
std::string hex_object(std::uint16_t index, std::uint8_t sub) {
  std::array<char, 16> buf{};
  std::snprintf(buf.data(), buf.size(), "%04Xh:%02X", static_cast<unsigned>(index), static_cast<unsigned>(sub));
  return buf.data();
}

// A record address (core/record_address.hpp) for `who` ("axis 'y'") on bus `bus` of type `bus_type`:
// PROFINET only.
ParameterLookup record_lookup(const std::string& name, const std::string& who, const std::string& bus,
                              const std::string& bus_type) {
  ParameterLookup out;
  if (bus_type != "profinet") {
    out.error = who + " is on " + bus_type + " bus '" + bus + "': '" + name + "' is a PROFINET record address (" +
                std::string(core::kRecordSyntax) + "); give an object as INDEX:SUB or by its name";
    return out;
  }
  const core::ParsedRecordAddress parsed = core::parse_record_address(name);
  if (!parsed.address) {
    out.error = parsed.error;
    return out;
  }
  out.ok = true;
  out.record = *parsed.address;
  out.index = out.record.index;
  return out;
}

// The reply topics whose readers the gateway waits for (write_replies()).
enum class ReplyTopic : std::uint8_t { Command, Param, Io };

struct Pending {
  std::string client;
  std::uint64_t client_id = 0;
  std::string axis;
  Prefix prefix{};
  std::uint16_t index = 0;  // parameter requests: the object accessed
  std::uint8_t sub = 0;
};

// A reply (CommandReply or ParameterReply) addressed to the client and request of `p`.
template <typename Reply>
Reply reply_to(const std::string& gateway, const Pending& p) {
  Reply out;
  out.gateway(gateway);
  out.axis(p.axis);
  out.client(p.client);
  out.id(p.client_id);
  return out;
}

// The key of a client's reply instance (gateway, client).
template <typename Reply>
Reply instance_key(const std::string& gateway, const std::string& client) {
  Reply key;
  key.gateway(gateway);
  key.client(client);
  return key;
}

// A request taken from DDS that the Runtime had no room for yet.
template <typename Request>
struct Deferred {
  std::size_t axis_id;
  Request request;
  Pending pending;
  Clock::time_point since;
};

// A reply waiting for its client's reader (or for room in the writer's history).
template <typename Sample>
struct OutReply {
  Sample sample;
  Prefix prefix;
  Clock::time_point since;
};

// Why the bus refused an I/O write, in words.
std::string io_refusal_text(const IoSlaveInfo& io, core::IoWriteStatus status, const core::IoSnapshot& s) {
  const std::string who = "I/O slave '" + io.name + "' on bus " + io.bus;
  switch (status) {
    case core::IoWriteStatus::Ok: return {};
    case core::IoWriteStatus::UnknownSlave: return who + " is not known to its bus";
    case core::IoWriteStatus::OutOfRange:
      return "out of range: " + who + " has " + std::to_string(s.output_size) + " output bytes";
    case core::IoWriteStatus::SlaveLost:
      return who + " is not exchanging process data (booting, lost or recovering): outputs not written";
    case core::IoWriteStatus::Busy: return "busy: " + who + "'s queue stayed full";
  }
  return who + ": refused";
}

std::int64_t wall_clock_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

}  // namespace

class DdsBridge::Impl : private dds::DataWriterListener, private dds::DataReaderListener {
 public:
  Impl(Runtime& runtime, DdsBridgeOptions options) : rt_(runtime), opt_(std::move(options)) {
    std::random_device rd;
    instance_ = (std::uint64_t{rd()} << 32) ^ rd();
    started_ = wall_clock_ns();
  }
  ~Impl() override { stop(); }
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  void start();
  void stop();
  [[nodiscard]] Stats stats() const {
    std::lock_guard lock(stats_mutex_);
    Stats s = stats_;
    s.wakeups = wakeups_.load(std::memory_order_relaxed);
    return s;
  }
  DuplicateGateway duplicate() const {
    std::lock_guard lock(dup_mutex_);
    return duplicate_;
  }
  void let_others_see_us(std::chrono::milliseconds budget) {
    const auto until = Clock::now() + budget;
    // Our own reader is one match; the other instance's reader makes two.
    dds::PublicationMatchedStatus st{};
    while (Clock::now() < until) {
      info_w_->get_publication_matched_status(st);
      if (st.current_count >= 2) break;
      std::this_thread::sleep_for(10ms);
    }
    const auto left = std::chrono::duration_cast<std::chrono::nanoseconds>(until - Clock::now()).count();
    if (left > 0)
      info_w_->wait_for_acknowledgments(eprosima::fastrtps::Duration_t(
          static_cast<std::int32_t>(left / 1'000'000'000), static_cast<std::uint32_t>(left % 1'000'000'000)));
  }
  DuplicateGateway wait_for_duplicate(std::chrono::milliseconds window) const {
    std::unique_lock lock(dup_mutex_);
    dup_cv_.wait_for(lock, window, [&] { return duplicate_.seen; });
    return duplicate_;
  }

 private:
  void run();
  // Each returns true when it stopped at kTakePerPass with more possibly waiting.
  bool take_commands(Clock::time_point now);
  void handle_command(const msg::AxisCommand& in, const Prefix& from, Clock::time_point now);
  void reject(const msg::AxisCommand& in, const Prefix& from, const std::string& reason, Clock::time_point now);
  void take_setpoints();
  bool take_params(Clock::time_point now);
  void handle_param(const msg::ParameterRequest& in, const Prefix& from, Clock::time_point now);
  void fail_param(const msg::ParameterRequest& in, const Prefix& from, const std::string& error, Clock::time_point now);
  void retry_deferred(Clock::time_point now);
  void take_gateway_infos();
  void collect_outbox(Clock::time_point now);
  void write_replies(Clock::time_point now);
  void publish_states(Clock::time_point now);
  // axis_link of the axis whose snapshot is `s`, when its link state or detail changed.
  void publish_link(std::size_t axis_id, const core::AxisSnapshot& s);
  void publish_bus_status();
  // io_state of every I/O slave whose bytes or validity changed, or whose keep-alive is due.
  void publish_io_states(Clock::time_point now);
  bool take_io_writes(Clock::time_point now);
  void handle_io_write(const msg::IoWrite& in, const Prefix& from, Clock::time_point now);
  void refuse_io(const msg::IoWrite& in, const Prefix& from, core::IoWriteStatus status, const std::string& reason,
                 Clock::time_point now);
  void retry_io(Clock::time_point now);
  [[nodiscard]] std::string io_list() const;
  [[nodiscard]] msg::IoWriteReply io_reply(const Pending& p, std::size_t io_id) const {
    msg::IoWriteReply out;
    out.gateway(gateway_);
    out.bus(rt_.io_slaves()[io_id].bus);
    out.slave(p.axis);
    out.client(p.client);
    out.id(p.client_id);
    return out;
  }
  void publish_gateway_info();
  // An event of this gateway (not of a bus); `axis` when it is about one of its axes.
  void publish_gateway_event(core::EventKind kind, const std::string& text, const std::string& axis = {});
  void log_summary(Clock::time_point now);
  // A request of `client` was answered for good (bookkeeping of kClientLimit).
  void answered(const std::string& client);
  // Instances of clients whose reply readers went away are unregistered (the history per client
  // would otherwise grow with every client that ever connected).
  void forget_gone_clients();
  [[nodiscard]] bool busy() const noexcept {
    return !deferred_commands_.empty() || !deferred_params_.empty() || !deferred_io_.empty() ||
           replies_.size() + param_replies_.size() + io_replies_.size() >= kMaxReplyBacklog;
  }
  [[nodiscard]] std::optional<std::size_t> find_axis(std::string_view name) const;
  [[nodiscard]] std::string axis_list() const;
  [[nodiscard]] bool reader_matched(const Prefix& p, ReplyTopic topic) const;
  template <typename F>
  void count(F&& f) {
    std::lock_guard lock(stats_mutex_);
    f(stats_);
  }

  // DataWriterListener of the two reply writers: which participants have a matched reply reader.
  void on_publication_matched(dds::DataWriter* writer, const dds::PublicationMatchedStatus& info) override;
  // DataReaderListener of the four readers (DDS threads): wakes the bridge.
  void on_data_available(dds::DataReader* /*reader*/) override { rt_.output_signal().notify(); }

  Runtime& rt_;
  DdsBridgeOptions opt_;
  std::string gateway_;
  std::uint64_t instance_ = 0;
  std::int64_t started_ = 0;

  std::unique_ptr<msg::DdsNode> node_;
  dds::DataWriter* state_w_ = nullptr;
  dds::DataWriter* reply_w_ = nullptr;
  dds::DataWriter* event_w_ = nullptr;
  dds::DataWriter* bus_w_ = nullptr;
  dds::DataWriter* param_w_ = nullptr;
  dds::DataWriter* info_w_ = nullptr;
  dds::DataWriter* link_w_ = nullptr;  // null: DDS access control refused it (older permissions)
  dds::DataReader* cmd_r_ = nullptr;
  dds::DataReader* sp_r_ = nullptr;
  dds::DataReader* param_r_ = nullptr;
  dds::DataReader* info_r_ = nullptr;
  // The I/O topics; null when DDS access control refused them (permissions older than the topics).
  dds::DataWriter* io_state_w_ = nullptr;
  dds::DataWriter* io_reply_w_ = nullptr;
  dds::DataReader* io_write_r_ = nullptr;

  std::thread thread_;
  std::atomic<bool> running_{false};
  std::atomic<std::uint64_t> wakeups_{0};

  // Bridge-thread state.
  core::CommandId next_id_ = 1;
  std::map<core::CommandId, Pending> pending_commands_;
  std::map<core::CommandId, Pending> pending_params_;
  std::deque<Deferred<core::Command>> deferred_commands_;
  std::deque<Deferred<core::ParamRequest>> deferred_params_;
  std::deque<OutReply<msg::CommandReply>> replies_;
  std::deque<OutReply<msg::ParameterReply>> param_replies_;
  std::set<std::pair<std::string, std::string>> warned_duplicates_;  // (other gateway, axis)
  std::set<std::pair<std::string, std::string>> warned_setpoints_;   // (client, axis)
  std::set<std::uint64_t> warned_instances_;                         // other instances of this gateway
  Outbox outbox_;
  std::uint64_t state_seq_ = 0;
  // What axis_state last carried per axis, and when (status_keepalive).
  struct PublishedState {
    bool written = false;
    core::AxisSnapshot snapshot;
    Clock::time_point at{};
  };
  std::vector<PublishedState> states_;
  // The link state and detail last written on axis_link, per axis.
  struct PublishedLink {
    bool written = false;
    core::LinkState link = core::LinkState::Offline;
    core::LinkDetail detail;
  };
  std::vector<PublishedLink> links_;
  // I/O slaves: writes in flight, waiting for room, replies waiting; what io_state last carried.
  // (Pending::axis holds the slave's name, Deferred::axis_id its I/O id.)
  std::map<core::CommandId, std::pair<std::size_t, Pending>> pending_io_;
  std::deque<Deferred<core::IoWrite>> deferred_io_;
  std::deque<OutReply<msg::IoWriteReply>> io_replies_;
  struct PublishedIo {
    bool written = false;
    core::IoSnapshot snapshot;
    Clock::time_point at{};
  };
  std::vector<PublishedIo> io_states_;

  // Traffic summary (instead of a line per command) and rate-limited warnings.
  LogLimiter warn_limit_;
  Clock::time_point next_summary_{};
  std::set<std::string> summary_clients_;
  std::uint64_t summary_commands_ = 0;
  std::uint64_t summary_rejected_ = 0;
  std::uint64_t summary_params_ = 0;

  // Matched reply readers per participant, from the writers' listener (DDS threads).
  mutable std::mutex match_mutex_;
  std::map<Prefix, int> reply_readers_;
  std::map<Prefix, int> param_reply_readers_;
  std::map<Prefix, int> io_reply_readers_;
  std::vector<std::pair<Prefix, ReplyTopic>> gone_;  // (participant, reply topic) whose last reader left

  // Bridge thread: requests per client without a final reply, and the clients of each participant.
  std::map<std::string, int> unanswered_;
  std::map<Prefix, std::set<std::string>> clients_of_;

  mutable std::mutex dup_mutex_;
  mutable std::condition_variable dup_cv_;
  DuplicateGateway duplicate_;

  mutable std::mutex stats_mutex_;
  Stats stats_;
};

void DdsBridge::Impl::start() {
  if (running_) return;
  if (!std::isfinite(opt_.status_rate_hz) || opt_.status_rate_hz <= 0 || opt_.status_rate_hz > 1000)
    throw std::invalid_argument("DDS status rate must be in (0, 1000] Hz, got " + std::to_string(opt_.status_rate_hz));
  gateway_ = rt_.gateway_name();
  msg::DdsOptions o;
  o.domain = opt_.domain;
  o.ns = opt_.ns;
  o.participant_name = "drivegated/" + gateway_;
  o.profiles_file = opt_.profiles_file;
  o.profile = opt_.profile;
  o.interfaces = opt_.interfaces;
  o.security = opt_.security;
  node_ = std::make_unique<msg::DdsNode>(o);
  state_w_ = &node_->writer(msg::TopicId::AxisState);
  // Reply writers never block the bridge: a client's full history refuses at once and the reply waits here.
  reply_w_ = &node_->writer(msg::TopicId::CommandReply, this, dds::StatusMask::publication_matched(), 0ms);
  event_w_ = &node_->writer(msg::TopicId::AxisEvent);
  bus_w_ = &node_->writer(msg::TopicId::BusStatus);
  param_w_ = &node_->writer(msg::TopicId::ParamReply, this, dds::StatusMask::publication_matched(), 0ms);
  info_w_ = &node_->writer(msg::TopicId::GatewayInfo);
  try {
    link_w_ = &node_->writer(msg::TopicId::AxisLink);
  } catch (const std::runtime_error& e) {
    // Permissions made before axis_link existed: the gateway runs, without link details.
    if (!node_->secure()) throw;
    spdlog::warn("dds: axis_link is not published ({}); scripts/make-pki.sh makes permissions that allow it",
                 e.what());
  }
  try {
    io_state_w_ = &node_->writer(msg::TopicId::IoState);
    io_reply_w_ = &node_->writer(msg::TopicId::IoWriteReply, this, dds::StatusMask::publication_matched(), 0ms);
    io_write_r_ = &node_->reader(msg::TopicId::IoWrite, this, dds::StatusMask::data_available());
  } catch (const std::runtime_error& e) {
    // Permissions made before the I/O topics existed: the gateway runs, without them.
    if (!node_->secure()) throw;
    io_state_w_ = nullptr;
    io_reply_w_ = nullptr;
    io_write_r_ = nullptr;
    spdlog::warn("dds: the I/O topics are not served ({}); scripts/make-pki.sh makes permissions that allow them",
                 e.what());
  }
  io_states_.assign(rt_.io_slaves().size(), PublishedIo{});
  links_.assign(rt_.axes().size(), PublishedLink{});
  states_.assign(rt_.axes().size(), PublishedState{});
  const auto arrival = dds::StatusMask::data_available();
  cmd_r_ = &node_->reader(msg::TopicId::AxisCommand, this, arrival);
  sp_r_ = &node_->reader(msg::TopicId::Setpoint, this, arrival);
  param_r_ = &node_->reader(msg::TopicId::ParamRequest, this, arrival);
  info_r_ = &node_->reader(msg::TopicId::GatewayInfo, this, arrival);

  publish_gateway_info();
  spdlog::info("dds: gateway '{}' on domain {} namespace '{}'{}{}, {} axes, state at {} Hz", gateway_, opt_.domain,
               opt_.ns, node_->secure() ? ", DDS Security on" : "",
               opt_.interfaces.empty() ? std::string{} : ", interfaces " + std::to_string(opt_.interfaces.size()),
               rt_.axes().size(), opt_.status_rate_hz);
  running_ = true;
  thread_ = std::thread([this] {
    ::pthread_setname_np(::pthread_self(), "dg-dds");  // top -H shows who uses what
    run();
  });
}

void DdsBridge::Impl::stop() {
  if (!running_.exchange(false)) return;
  rt_.output_signal().notify();
  thread_.join();
  node_.reset();
  spdlog::info("dds: bridge of gateway '{}' stopped", gateway_);
}

void DdsBridge::Impl::on_publication_matched(dds::DataWriter* writer, const dds::PublicationMatchedStatus& info) {
  std::lock_guard lock(match_mutex_);
  const ReplyTopic topic = writer == param_w_     ? ReplyTopic::Param
                           : writer == io_reply_w_ ? ReplyTopic::Io
                                                   : ReplyTopic::Command;
  auto& readers = topic == ReplyTopic::Param ? param_reply_readers_
                  : topic == ReplyTopic::Io  ? io_reply_readers_
                                             : reply_readers_;
  const Prefix p = prefix_of(info.last_subscription_handle);
  if (info.current_count_change > 0) {
    ++readers[p];
  } else if (info.current_count_change < 0) {
    const auto it = readers.find(p);
    if (it != readers.end() && --it->second <= 0) {
      readers.erase(it);
      gone_.emplace_back(p, topic);
    }
  }
  rt_.output_signal().notify();  // replies may wait for this reader
}

bool DdsBridge::Impl::reader_matched(const Prefix& p, ReplyTopic topic) const {
  std::lock_guard lock(match_mutex_);
  const auto& readers = topic == ReplyTopic::Param ? param_reply_readers_
                        : topic == ReplyTopic::Io  ? io_reply_readers_
                                                   : reply_readers_;
  return readers.count(p) > 0;
}

void DdsBridge::Impl::run() {
  const auto state_period =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / opt_.status_rate_hz));
  const auto bus_period = std::max<Clock::duration>(state_period, std::chrono::seconds(1));
  auto next_state = Clock::now();
  auto next_bus = Clock::now();
  next_summary_ = Clock::now() + kSummaryPeriod;
  bool more = false;  // requests may still wait in DDS: no sleep
  while (running_) {
    auto until = std::min({next_state, next_bus, next_summary_});
    if (more) {
      until = Clock::now();
    } else if (busy() || !replies_.empty() || !param_replies_.empty() || !io_replies_.empty()) {
      until = std::min(until, Clock::now() + kBusyPoll);
    }
    rt_.output_signal().wait_until(until);
    wakeups_.fetch_add(1, std::memory_order_relaxed);
    if (!running_) break;
    const auto t = Clock::now();
    retry_deferred(t);
    more = take_commands(t);
    take_setpoints();
    more = take_params(t) || more;
    retry_io(t);
    more = take_io_writes(t) || more;
    take_gateway_infos();
    collect_outbox(t);
    write_replies(t);
    forget_gone_clients();
    if (t >= next_state) {
      publish_states(t);
      publish_io_states(t);
      next_state += state_period;
      if (next_state < t) next_state = t + state_period;  // fell behind: do not burst to catch up
    }
    if (t >= next_bus) {
      publish_bus_status();
      next_bus = t + bus_period;
    }
    log_summary(t);
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

bool DdsBridge::Impl::take_commands(Clock::time_point now) {
  msg::AxisCommand in;
  dds::SampleInfo info;
  // While requests wait for the Runtime the rest stay in DDS: the keep-all reader fills and the
  // clients' writers wait, instead of anything being dropped.
  for (std::size_t n = 0; n < kTakePerPass; ++n) {
    if (busy() || cmd_r_->take_next_sample(&in, &info) != ReturnCode_t::RETCODE_OK) return false;
    if (!info.valid_data) continue;
    if (in.gateway() != gateway_) {
      // Another gateway's axis: the owner answers, we stay silent.
      count([](Stats& s) { ++s.commands_ignored; });
      continue;
    }
    handle_command(in, prefix_of(info.publication_handle), now);
  }
  return true;
}

void DdsBridge::Impl::reject(const msg::AxisCommand& in, const Prefix& from, const std::string& reason,
                             Clock::time_point now) {
  if (warn_limit_.allow(now))
    spdlog::warn("dds: rejected {} for axis '{}' from '{}' id {}: {}", in.kind(), in.axis(), in.client(), in.id(),
                 reason);
  auto out = reply_to<msg::CommandReply>(gateway_, Pending{in.client(), in.id(), in.axis(), from, 0, 0});
  out.status(std::string(core::to_string(core::ReplyStatus::Rejected)));
  out.reason(reason);
  replies_.push_back({std::move(out), from, now});
  ++summary_rejected_;
  count([](Stats& s) { ++s.commands_rejected; });
}

void DdsBridge::Impl::handle_command(const msg::AxisCommand& in, const Prefix& from, Clock::time_point now) {
  ++summary_commands_;
  summary_clients_.insert(in.client());
  if (in.client().empty()) return reject(in, from, "command without a client id (field 'client')", now);
  const auto axis = find_axis(in.axis());
  if (!axis)
    return reject(in, from, "unknown axis '" + in.axis() + "' on gateway '" + gateway_ + "'; axes here: " + axis_list(),
                  now);
  const auto kind = core::parse_command_kind(in.kind());
  if (!kind) return reject(in, from, "unknown command kind '" + in.kind() + "'; known: " + known_kinds(), now);
  core::Mode mode = core::Mode::None;
  if (!in.mode().empty()) {
    const auto m = core::parse_mode(in.mode());
    if (!m) return reject(in, from, "unknown mode '" + in.mode() + "'; known: " + known_modes(), now);
    mode = *m;
  }
  if (*kind == core::CommandKind::SetMode && mode == core::Mode::None)
    return reject(in, from, "set_mode needs a mode; known: " + known_modes(), now);

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
  if (unanswered_[in.client()] >= kClientLimit)
    return reject(in, from,
                  "busy: client '" + in.client() + "' has " + std::to_string(kClientLimit) +
                      " requests without a final reply; wait for replies before sending more",
                  now);
  ++unanswered_[in.client()];
  clients_of_[from].insert(in.client());
  Pending p{in.client(), in.id(), in.axis(), from, 0, 0};
  spdlog::debug("dds: {} for axis '{}' from '{}' id {} -> command {}", in.kind(), in.axis(), in.client(), in.id(),
                cmd.id);
  if (!rt_.submit_command(*axis, cmd)) {
    deferred_commands_.push_back({*axis, cmd, std::move(p), now});
    return;
  }
  pending_commands_.emplace(cmd.id, std::move(p));
  count([](Stats& s) { ++s.commands_routed; });
}

// Offers the requests that found no room in the Runtime again, in order; one that has waited
// kBusyAfter is answered "busy".
void DdsBridge::Impl::retry_deferred(Clock::time_point now) {
  const auto retry = [&](auto& queue, auto& pending, auto& replies, auto submit, auto busy_reply, bool param) {
    while (!queue.empty()) {
      auto& d = queue.front();
      if (submit(d)) {
        pending.emplace(d.request.id, std::move(d.pending));
        count([&](Stats& s) { ++(param ? s.params_routed : s.commands_routed); });
      } else if (now - d.since >= kBusyAfter) {
        replies.push_back({busy_reply(d.pending), d.pending.prefix, now});
        answered(d.pending.client);
        summary_rejected_ += param ? 0 : 1;
        count([](Stats& s) { ++s.commands_busy; });
      } else {
        break;
      }
      queue.pop_front();
    }
  };
  const std::string waited =
      std::to_string(std::chrono::duration_cast<std::chrono::milliseconds>(kBusyAfter).count()) + " ms";
  retry(
      deferred_commands_, pending_commands_, replies_,
      [&](const Deferred<core::Command>& d) { return rt_.submit_command(d.axis_id, d.request); },
      [&](const Pending& p) {
        auto out = reply_to<msg::CommandReply>(gateway_, p);
        out.status(std::string(core::to_string(core::ReplyStatus::Rejected)));
        out.reason("busy: the gateway's command queue for axis '" + p.axis + "' stayed full for " + waited +
                   "; send it again");
        return out;
      },
      false);
  retry(
      deferred_params_, pending_params_, param_replies_,
      [&](const Deferred<core::ParamRequest>& d) { return rt_.submit_parameter(d.axis_id, d.request); },
      [&](const Pending& p) {
        auto out = reply_to<msg::ParameterReply>(gateway_, p);
        out.ok(false);
        out.error("busy: the gateway's parameter queue for axis '" + p.axis + "' stayed full for " + waited +
                  "; send it again");
        out.index(p.index);
        out.subindex(p.sub);
        return out;
      },
      true);
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
    if (warned_setpoints_.size() < 1000 && warned_setpoints_.emplace(in.client(), in.axis()).second)
      spdlog::warn("dds: dropping set-points from '{}' for axis '{}': {}", in.client(), in.axis(),
                   axis ? "queue full" : "unknown axis; axes here: " + axis_list());
  });
}

bool DdsBridge::Impl::take_params(Clock::time_point now) {
  msg::ParameterRequest in;
  dds::SampleInfo info;
  for (std::size_t n = 0; n < kTakePerPass; ++n) {
    if (busy() || param_r_->take_next_sample(&in, &info) != ReturnCode_t::RETCODE_OK) return false;
    if (!info.valid_data || in.gateway() != gateway_) continue;
    handle_param(in, prefix_of(info.publication_handle), now);
  }
  return true;
}

void DdsBridge::Impl::fail_param(const msg::ParameterRequest& in, const Prefix& from, const std::string& error,
                                 Clock::time_point now) {
  if (warn_limit_.allow(now))
    spdlog::warn("dds: parameter request {:04X}:{} for axis '{}' from '{}' failed: {}", in.index(), in.subindex(),
                 in.axis(), in.client(), error);
  auto out = reply_to<msg::ParameterReply>(gateway_, Pending{in.client(), in.id(), in.axis(), from, 0, 0});
  out.ok(false);
  out.error(error);
  out.index(in.index());
  out.subindex(in.subindex());
  param_replies_.push_back({std::move(out), from, now});
}

void DdsBridge::Impl::handle_param(const msg::ParameterRequest& in, const Prefix& from, Clock::time_point now) {
  ++summary_params_;
  summary_clients_.insert(in.client());
  const bool record = core::is_record_address(in.name());
  const auto axis = find_axis(in.axis());
  // A record may go to an IO device (which has no axis) too: by its name.
  std::optional<std::size_t> io;
  const auto ios = rt_.io_slaves();
  for (std::size_t i = 0; !axis && record && i < ios.size(); ++i)
    if (ios[i].name == in.axis()) {
      if (io)
        return fail_param(in, from,
                          "IO device '" + in.axis() + "' is on more than one bus of gateway '" + gateway_ +
                              "': its records cannot be told apart",
                          now);
      io = i;
    }
  if (!axis && !io)
    return fail_param(in, from,
                      "unknown axis '" + in.axis() + "' on gateway '" + gateway_ + "'; axes here: " + axis_list() +
                          (record ? "; IO devices: " + io_list() : std::string{}),
                      now);
  ParameterLookup p;
  if (axis && !record) {
    p = rt_.lookup_parameter(*axis, in.name(), in.index(), in.subindex());
  } else if (axis) {
    const AxisInfo& a = rt_.axes()[*axis];
    p = record_lookup(in.name(), "axis '" + a.name + "'", a.bus, a.bus_type);
  } else {
    p = record_lookup(in.name(), "IO device '" + ios[*io].name + "'", ios[*io].bus, ios[*io].bus_type);
    p.record.io = static_cast<std::uint16_t>(*io);
  }
  if (!p.ok) return fail_param(in, from, p.error, now);
  const std::string where = p.record.valid ? core::format_record_address(p.record) : hex_object(p.index, p.sub);
  core::ParamType type = p.type;
  if (!in.type().empty()) {
    const auto asked = core::param_type_from_name(in.type());
    if (!asked)
      return fail_param(in, from,
                        "unknown type '" + in.type() +
                            "': use u8, u16, u24, u32, u40, u48, u56, u64, i8 .. i64, r32, r64, bool, string, "
                            "unicode, octets, domain, time_of_day or time_difference",
                        now);
    const auto size_text = [](core::ParamType t) {
      const std::size_t n = core::param_type_size(t);
      return n == 0 ? std::string("any length") : std::to_string(n) + (n == 1 ? " byte" : " bytes");
    };
    if (p.type != core::ParamType::Unknown && *asked != p.type)
      return fail_param(in, from,
                        where + " is a " + std::string(core::param_type_cia_name(p.type)) + " (" + size_text(p.type) +
                            ", per " + p.type_source + "), not a " + std::string(core::param_type_cia_name(*asked)) +
                            " (" + size_text(*asked) + ")",
                        now);
    type = *asked;
  }
  if (p.record.valid && type == core::ParamType::Unknown) type = core::ParamType::OctetString;  // a record's bytes
  core::ParamRequest req;
  req.id = next_id_++;
  req.write = in.write();
  req.index = p.index;
  req.sub = p.sub;
  req.record = p.record;
  req.type = type;
  if (in.write()) {
    if (type == core::ParamType::Unknown)
      return fail_param(in, from,
                        "the type of " + where +
                            " is not known (not in the axis' EDS nor in CiA 301/402): give it (--type u16, string, "
                            "domain, ...)",
                        now);
    const core::EncodedParam value = core::encode_param(type, in.value());
    if (!value.error.empty()) return fail_param(in, from, where + ": " + value.error, now);
    req.size = static_cast<std::uint16_t>(value.bytes.size());
    std::copy(value.bytes.begin(), value.bytes.end(), req.data.begin());
  }
  if (unanswered_[in.client()] >= kClientLimit)
    return fail_param(in, from,
                      "busy: client '" + in.client() + "' has " + std::to_string(kClientLimit) +
                          " requests without a final reply; wait for replies before sending more",
                      now);
  ++unanswered_[in.client()];
  clients_of_[from].insert(in.client());
  Pending pending{in.client(), in.id(), in.axis(), from, req.index, req.sub};
  spdlog::debug("dds: parameter {} {:04X}:{} for axis '{}' from '{}' id {} -> request {}",
                in.write() ? "write" : "read", req.index, req.sub, in.axis(), in.client(), in.id(), req.id);
  if (!rt_.submit_parameter(axis.value_or(0), req)) {
    deferred_params_.push_back({axis.value_or(0), req, std::move(pending), now});
    return;
  }
  pending_params_.emplace(req.id, std::move(pending));
  count([](Stats& s) { ++s.params_routed; });
}

void DdsBridge::Impl::take_gateway_infos() {
  msg::take_valid<msg::GatewayInfo>(*info_r_, [&](const msg::GatewayInfo& in) {
    if (in.gateway() == gateway_) {
      if (in.instance() == instance_ || !warned_instances_.insert(in.instance()).second) return;
      // Two masters on one set of drives: both say so loudly, the one that started later stops.
      const bool this_one_later = started_ > in.started() || (started_ == in.started() && instance_ > in.instance());
      const std::string text = "another drivegated runs as gateway '" + gateway_ + "' on this DDS domain (host " +
                               in.host() + ", pid " + std::to_string(in.pid()) + "): two gateways would command the "
                               "same axes; " +
                               (this_one_later ? "this one started later and stops" : "that one started later and must stop");
      spdlog::critical("dds: {}", text);
      publish_gateway_event(core::EventKind::DuplicateGateway, text);
      {
        std::lock_guard lock(dup_mutex_);
        duplicate_ = {true, this_one_later || duplicate_.this_one_stops, text};
      }
      dup_cv_.notify_all();
      return;
    }
    spdlog::info("dds: gateway '{}' on {} (pid {}) owns {} axes", in.gateway(), in.host(), in.pid(), in.axes().size());
    for (const auto& other : in.axes()) {
      if (!find_axis(other.name())) continue;
      if (!warned_duplicates_.emplace(in.gateway(), other.name()).second) continue;
      const std::string text = "axis '" + other.name() + "' is claimed by gateway '" + gateway_ + "' and by gateway '" +
                               in.gateway() + "'; clients must name the gateway for this axis";
      spdlog::warn("dds: {}", text);
      publish_gateway_event(core::EventKind::Warning, text, other.name());
    }
  });
}

void DdsBridge::Impl::publish_gateway_event(core::EventKind kind, const std::string& text, const std::string& axis) {
  msg::AxisEvent ev;
  ev.gateway(gateway_);
  ev.axis(axis);
  ev.kind(std::string(core::to_string(kind)));
  ev.state(std::string(core::to_string(core::AxisState::Unknown)));
  ev.text(text);
  ev.stamp(std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch()).count());
  event_w_->write(&ev);
}

void DdsBridge::Impl::collect_outbox(Clock::time_point now) {
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
    auto out = reply_to<msg::CommandReply>(gateway_, it->second);
    out.status(std::string(core::to_string(r.reply.status)));
    out.reason(r.reply.reason.str());
    spdlog::debug("dds: command {} ('{}' id {} on '{}'): {}{}{}", r.reply.id, out.client(), out.id(), out.axis(),
                  out.status(), out.reason().empty() ? "" : ": ", out.reason());
    replies_.push_back({std::move(out), it->second.prefix, now});
    if (r.reply.status != core::ReplyStatus::Accepted) {
      answered(it->second.client);
      pending_commands_.erase(it);
    }
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
  }

  for (const auto& r : outbox_.io_replies) {
    const auto it = pending_io_.find(r.reply.id);
    if (it == pending_io_.end()) continue;
    const auto& [io_id, pending] = it->second;
    auto out = io_reply(pending, io_id);
    const auto ios = rt_.io_slaves();
    out.ok(r.reply.status == core::IoWriteStatus::Ok);
    out.status(std::string(core::to_string(r.reply.status)));
    if (!out.ok()) out.reason(io_refusal_text(ios[io_id], r.reply.status, rt_.io_snapshot(io_id)));
    io_replies_.push_back({std::move(out), pending.prefix, now});
    answered(pending.client);
    pending_io_.erase(it);
  }

  for (const auto& p : outbox_.param_replies) {
    const auto it = pending_params_.find(p.reply.id);
    if (it == pending_params_.end()) {
      spdlog::debug("dds: parameter reply {} of no DDS client", p.reply.id);
      continue;
    }
    auto out = reply_to<msg::ParameterReply>(gateway_, it->second);
    out.ok(p.reply.ok);
    out.type(std::string(core::param_type_name(p.reply.type)));
    const auto bytes = p.reply.bytes();
    out.data(std::vector<std::uint8_t>(bytes.begin(), bytes.end()));
    out.error_code(p.reply.error_code);
    out.error(p.reply.error.str());
    out.index(it->second.index);
    out.subindex(it->second.sub);
    spdlog::debug("dds: parameter request {} ('{}' id {}): {}", p.reply.id, out.client(), out.id(),
                  out.ok() ? "ok" : "error: " + out.error());
    param_replies_.push_back({std::move(out), it->second.prefix, now});
    answered(it->second.client);
    pending_params_.erase(it);
  }
}

// Replies go out in order per client once that client's reply reader is matched (or after the hold
// time).
void DdsBridge::Impl::write_replies(Clock::time_point now) {
  const auto flush = [&](auto& queue, dds::DataWriter* writer, ReplyTopic topic) {
    std::set<Prefix> blocked;  // clients whose earlier reply is still waiting: keep their order
    for (auto it = queue.begin(); it != queue.end();) {
      if (blocked.count(it->prefix) > 0) {
        ++it;
        continue;
      }
      const bool matched = reader_matched(it->prefix, topic);
      if (!matched && now - it->since < kReplyHold) {
        blocked.insert(it->prefix);
        ++it;
        continue;
      }
      if (!writer->write(&it->sample)) {
        // The client's history is full of replies not yet acknowledged by every reader that gets
        // them (idl/dds_node.cpp): this one and the client's later ones wait, in order.
        count([](Stats& s) { ++s.replies_held; });
        if (now - it->since >= kReplyStall && warn_limit_.allow(now))
          spdlog::warn("dds: replies to client '{}' have waited {} s for its readers' acknowledgements",
                       it->sample.client(), std::chrono::duration_cast<std::chrono::seconds>(now - it->since).count());
        blocked.insert(it->prefix);
        ++it;
        continue;
      }
      count([&](Stats& s) {
        ++s.replies_written;
        if (!matched) ++s.replies_unmatched;
      });
      it = queue.erase(it);
    }
  };
  flush(replies_, reply_w_, ReplyTopic::Command);
  flush(param_replies_, param_w_, ReplyTopic::Param);
  if (io_reply_w_ != nullptr) flush(io_replies_, io_reply_w_, ReplyTopic::Io);
}

void DdsBridge::Impl::answered(const std::string& client) {
  const auto it = unanswered_.find(client);
  if (it != unanswered_.end() && --it->second <= 0) unanswered_.erase(it);
}

void DdsBridge::Impl::forget_gone_clients() {
  std::vector<std::pair<Prefix, ReplyTopic>> gone;
  {
    std::lock_guard lock(match_mutex_);
    gone.swap(gone_);
  }
  for (const auto& [prefix, topic] : gone) {
    const auto it = clients_of_.find(prefix);
    if (it == clients_of_.end()) continue;
    for (const auto& name : it->second) {
      if (topic == ReplyTopic::Param) {
        auto key = instance_key<msg::ParameterReply>(gateway_, name);
        param_w_->unregister_instance(&key, dds::HANDLE_NIL);
      } else if (topic == ReplyTopic::Io) {
        auto key = instance_key<msg::IoWriteReply>(gateway_, name);
        io_reply_w_->unregister_instance(&key, dds::HANDLE_NIL);
      } else {
        auto key = instance_key<msg::CommandReply>(gateway_, name);
        reply_w_->unregister_instance(&key, dds::HANDLE_NIL);
      }
    }
    // Both reply readers gone: the participant is done with this gateway.
    std::lock_guard lock(match_mutex_);
    if (reply_readers_.count(prefix) == 0 && param_reply_readers_.count(prefix) == 0 &&
        io_reply_readers_.count(prefix) == 0)
      clients_of_.erase(it);
  }
}

void DdsBridge::Impl::log_summary(Clock::time_point now) {
  if (now < next_summary_) return;
  next_summary_ = now + kSummaryPeriod;
  const auto suppressed = warn_limit_.take_suppressed();
  if (summary_commands_ == 0 && summary_params_ == 0 && suppressed == 0) return;
  spdlog::info("dds: in the last {} s: {} commands ({} rejected or busy) and {} parameter requests from {} client(s){}",
               std::chrono::duration_cast<std::chrono::seconds>(kSummaryPeriod).count(), summary_commands_,
               summary_rejected_, summary_params_, summary_clients_.size(),
               suppressed == 0 ? std::string{} : "; " + std::to_string(suppressed) + " similar warnings not logged");
  summary_commands_ = summary_rejected_ = summary_params_ = 0;
  summary_clients_.clear();
}

namespace {
// What a client sees of a state on axis_state: everything but the stamp and the cycle.
bool same_published_state(const core::AxisSnapshot& a, const core::AxisSnapshot& b) {
  return a.state == b.state && a.link == b.link && a.mode == b.mode && a.position == b.position &&
         a.velocity == b.velocity && a.torque == b.torque && a.fault_code == b.fault_code &&
         a.fault_text.view() == b.fault_text.view() && a.target_reached == b.target_reached && a.homed == b.homed &&
         a.warning == b.warning && a.stopping == b.stopping && a.following_error == b.following_error &&
         a.statusword == b.statusword && a.active_command == b.active_command;
}
}  // namespace

void DdsBridge::Impl::publish_states(Clock::time_point now) {
  const auto axes = rt_.axes();
  msg::AxisState out;
  out.gateway(gateway_);
  ++state_seq_;
  std::size_t written = 0;
  for (std::size_t i = 0; i < axes.size(); ++i) {
    const core::AxisSnapshot s = rt_.snapshot(i);
    publish_link(i, s);
    // An unchanged state waits for its keep-alive (a new client's first read waits for it too).
    PublishedState& last = states_[i];
    if (last.written && now - last.at < opt_.status_keepalive && same_published_state(last.snapshot, s)) continue;
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
    if (!state_w_->write(&out)) continue;
    last = {true, s, now};
    ++written;
  }
  count([&](Stats& st) { st.states_published += written; });
}

void DdsBridge::Impl::publish_link(std::size_t axis_id, const core::AxisSnapshot& s) {
  PublishedLink& last = links_[axis_id];
  if (link_w_ == nullptr || (last.written && last.link == s.link && last.detail == s.link_detail.view())) return;
  const AxisInfo& a = rt_.axes()[axis_id];
  msg::AxisLink out;
  out.gateway(gateway_);
  out.axis(a.name);
  out.bus(a.bus);
  out.bus_type(a.bus_type);
  out.address(a.address);
  out.link(std::string(core::to_string(s.link)));
  out.detail(s.link_detail.str());
  out.since(s.link_since_ns);
  if (link_w_->write(&out)) last = {true, s.link, s.link_detail};
}

std::string DdsBridge::Impl::io_list() const {
  std::string s;
  for (const auto& io : rt_.io_slaves()) {
    if (!s.empty()) s += ", ";
    s += io.name + " (bus " + io.bus + ")";
  }
  return s.empty() ? "(none)" : s;
}

bool DdsBridge::Impl::take_io_writes(Clock::time_point now) {
  if (io_write_r_ == nullptr) return false;
  msg::IoWrite in;
  dds::SampleInfo info;
  for (std::size_t n = 0; n < kTakePerPass; ++n) {
    if (busy() || io_write_r_->take_next_sample(&in, &info) != ReturnCode_t::RETCODE_OK) return false;
    if (!info.valid_data || in.gateway() != gateway_) continue;
    handle_io_write(in, prefix_of(info.publication_handle), now);
  }
  return true;
}

void DdsBridge::Impl::refuse_io(const msg::IoWrite& in, const Prefix& from, core::IoWriteStatus status,
                                const std::string& reason, Clock::time_point now) {
  if (warn_limit_.allow(now))
    spdlog::warn("dds: I/O write to '{}' from '{}' id {} refused: {}", in.slave(), in.client(), in.id(), reason);
  msg::IoWriteReply out;
  out.gateway(gateway_);
  out.bus(in.bus());
  out.slave(in.slave());
  out.client(in.client());
  out.id(in.id());
  out.ok(false);
  out.status(std::string(core::to_string(status)));
  out.reason(reason);
  io_replies_.push_back({std::move(out), from, now});
}

void DdsBridge::Impl::handle_io_write(const msg::IoWrite& in, const Prefix& from, Clock::time_point now) {
  summary_clients_.insert(in.client());
  const auto ios = rt_.io_slaves();
  std::optional<std::size_t> found;
  std::size_t matches = 0;
  for (std::size_t i = 0; i < ios.size(); ++i)
    if (ios[i].name == in.slave() && (in.bus().empty() || ios[i].bus == in.bus())) {
      found = i;
      ++matches;
    }
  if (!found)
    return refuse_io(in, from, core::IoWriteStatus::UnknownSlave,
                     "unknown I/O slave '" + in.slave() + "'" + (in.bus().empty() ? "" : " on bus " + in.bus()) +
                         " on gateway '" + gateway_ + "'; I/O slaves here: " + io_list(),
                     now);
  if (matches > 1)
    return refuse_io(in, from, core::IoWriteStatus::UnknownSlave,
                     "I/O slave '" + in.slave() + "' is on more than one bus of gateway '" + gateway_ +
                         "': name the bus; I/O slaves here: " + io_list(),
                     now);
  const IoSlaveInfo& io = ios[*found];
  // The bus checks the range against the slave's actual image; the size known here (from the
  // latest snapshot, else the configuration) gives the early answer.
  const core::IoSnapshot snap = rt_.io_snapshot(*found);
  const std::size_t outputs = snap.output_size != 0 ? snap.output_size : io.output_size;
  const std::size_t n = in.data().size();
  if (n == 0 || n > core::kMaxIoBytes || in.offset() > core::kMaxIoBytes ||
      ((snap.output_size != 0 || io.sized) && (in.offset() > outputs || n > outputs - in.offset())))
    return refuse_io(in, from, core::IoWriteStatus::OutOfRange,
                     n == 0 ? "nothing to write (no bytes)"
                            : "out of range: " + std::to_string(n) + " byte(s) at offset " +
                                  std::to_string(in.offset()) + ", but I/O slave '" + io.name + "' on bus " + io.bus +
                                  " has " + std::to_string(outputs) + " output bytes",
                     now);
  if (unanswered_[in.client()] >= kClientLimit)
    return refuse_io(in, from, core::IoWriteStatus::Busy,
                     "busy: client '" + in.client() + "' has " + std::to_string(kClientLimit) +
                         " requests without a final reply; wait for replies before sending more",
                     now);
  core::IoWrite w;
  w.id = next_id_++;
  w.offset = static_cast<std::uint16_t>(in.offset());
  w.size = static_cast<std::uint16_t>(n);
  std::copy(in.data().begin(), in.data().end(), w.data.begin());
  ++unanswered_[in.client()];
  clients_of_[from].insert(in.client());
  Pending p{in.client(), in.id(), in.slave(), from, 0, 0};
  spdlog::debug("dds: I/O write of {} byte(s) at {} to '{}' from '{}' id {} -> request {}", n, in.offset(),
                in.slave(), in.client(), in.id(), w.id);
  if (!rt_.submit_io_write(*found, w)) {
    deferred_io_.push_back({*found, w, std::move(p), now});
    return;
  }
  pending_io_.emplace(w.id, std::make_pair(*found, std::move(p)));
  count([](Stats& s) { ++s.io_writes_routed; });
}

void DdsBridge::Impl::retry_io(Clock::time_point now) {
  while (!deferred_io_.empty()) {
    auto& d = deferred_io_.front();
    if (rt_.submit_io_write(d.axis_id, d.request)) {
      pending_io_.emplace(d.request.id, std::make_pair(d.axis_id, std::move(d.pending)));
      count([](Stats& s) { ++s.io_writes_routed; });
    } else if (now - d.since >= kBusyAfter) {
      auto out = io_reply(d.pending, d.axis_id);
      out.ok(false);
      out.status(std::string(core::to_string(core::IoWriteStatus::Busy)));
      out.reason("busy: the gateway's I/O queue of bus " + rt_.io_slaves()[d.axis_id].bus + " stayed full for " +
                 std::to_string(std::chrono::duration_cast<std::chrono::milliseconds>(kBusyAfter).count()) +
                 " ms; send it again");
      io_replies_.push_back({std::move(out), d.pending.prefix, now});
      answered(d.pending.client);
    } else {
      break;
    }
    deferred_io_.pop_front();
  }
}

void DdsBridge::Impl::publish_io_states(Clock::time_point now) {
  if (io_state_w_ == nullptr) return;
  const auto ios = rt_.io_slaves();
  msg::IoState out;
  out.gateway(gateway_);
  std::size_t written = 0;
  // Every slave goes out whenever one changed or the keep-alive is due: a reader that got one of
  // this gateway's slaves has them all (the client's first read relies on it), and the samples
  // are small.
  std::vector<core::IoSnapshot> snaps;
  snaps.reserve(ios.size());
  bool due = false;
  for (std::size_t i = 0; i < ios.size() && i < io_states_.size(); ++i) {
    snaps.push_back(rt_.io_snapshot(i));
    const core::IoSnapshot& s = snaps.back();
    const PublishedIo& last = io_states_[i];
    const auto& a = last.snapshot;
    const bool same = a.valid == s.valid && a.input_size == s.input_size && a.output_size == s.output_size &&
                      std::equal(a.inputs.begin(), a.inputs.begin() + a.input_size, s.inputs.begin()) &&
                      std::equal(a.outputs.begin(), a.outputs.begin() + a.output_size, s.outputs.begin());
    due = due || !last.written || now - last.at >= opt_.status_keepalive || !same;
  }
  if (!due) return;
  for (std::size_t i = 0; i < snaps.size(); ++i) {
    const core::IoSnapshot& s = snaps[i];
    PublishedIo& last = io_states_[i];
    out.bus(ios[i].bus);
    out.slave(ios[i].name);
    out.address(ios[i].address);
    out.inputs(std::vector<std::uint8_t>(s.inputs.begin(), s.inputs.begin() + s.input_size));
    out.outputs(std::vector<std::uint8_t>(s.outputs.begin(), s.outputs.begin() + s.output_size));
    out.valid(s.valid);
    out.stamp(s.stamp_ns);
    out.seq(state_seq_);
    if (!io_state_w_->write(&out)) continue;
    last = {true, s, now};
    ++written;
  }
  count([&](Stats& st) { st.io_states_published += written; });
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
    out.clock_sync(s.clock_sync.valid);
    out.clock_difference_ns(s.clock_sync.valid ? s.clock_sync.max_difference_ns : 0);
    out.clock_master_offset_ns(s.clock_sync.valid ? s.clock_sync.master_minus_reference_ns : 0);
    bus_w_->write(&out);
  }
}

void DdsBridge::Impl::publish_gateway_info() {
  msg::GatewayInfo out;
  out.gateway(gateway_);
  out.host(host_name());
  out.pid(static_cast<std::uint32_t>(::getpid()));
  out.instance(instance_);
  out.started(started_);
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
DuplicateGateway DdsBridge::wait_for_duplicate(std::chrono::milliseconds window) const {
  return impl_->wait_for_duplicate(window);
}
DuplicateGateway DdsBridge::duplicate() const { return impl_->duplicate(); }
void DdsBridge::let_others_see_us(std::chrono::milliseconds budget) { impl_->let_others_see_us(budget); }
DdsBridge::Stats DdsBridge::stats() const { return impl_->stats(); }

}  // namespace drivegate::daemon
