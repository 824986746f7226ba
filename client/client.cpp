#include "client/client.hpp"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <condition_variable>
#include <deque>
#include <map>
#include <mutex>
#include <cstdlib>
#include <optional>
#include <random>
#include <set>
#include <stdexcept>
#include <tuple>

#include <fastdds/dds/core/status/PublicationMatchedStatus.hpp>
#include <fastdds/dds/core/status/SubscriptionMatchedStatus.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>

#include "client/settled.hpp"
#include "core/record_address.hpp"
#include "drivegate.h"
#include "idl/dds_node.hpp"

namespace drivegate::client {

namespace dds = eprosima::fastdds::dds;
using SteadyClock = std::chrono::steady_clock;

namespace {

constexpr std::size_t kMaxEvents = 1000;
constexpr Millis kPollSlice{50};
// Gateways on one domain are discovered within a few hundred ms of each other.
constexpr Millis kDiscoveryQuiet{1000};
// How long the first read of a state-like topic waits for its reader to match every known gateway
// and for the data to arrive: endpoint discovery takes some ms, then axis_state (best effort,
// volatile) comes with the next publication (status_rate_hz, 50 Hz by default, 1 Hz and up
// allowed; an unchanged state every status_keepalive, at most 500 ms), the transient-local
// topics with their history.
constexpr Millis kFirstData{1500};
// The event history comes after the match: the first read takes it as complete once no event arrived for
// this long (Fast DDS 2 does not implement DataReader::wait_for_historical_data).
constexpr Millis kHistoryQuiet{300};

std::string default_name() {
  char host[256] = {};
  if (::gethostname(host, sizeof host - 1) != 0) host[0] = '\0';
  std::random_device rd;
  char suffix[16] = {};
  std::snprintf(suffix, sizeof suffix, "%08x", rd());
  return std::string(host[0] != '\0' ? host : "host") + "-" + std::to_string(::getpid()) + "-" + suffix;
}

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) {
    if (!s.empty()) s += ", ";
    s += x;
  }
  return s;
}

// Lets one thread at a time take from a reader and store what it took, so an older sample never
// overwrites a newer one and events keep their order. Without blocking: Fast DDS may call
// on_data_available() with the reader's own lock held, and waiting there for a thread that is inside
// take() (waiting for that lock) would deadlock. A thread that finds another taking leaves a note,
// and the taking thread takes again before it leaves.
class SerialTake {
 public:
  template <typename Take>
  void run(Take&& take) {
    pending_.store(true);
    while (pending_.load()) {
      std::unique_lock lock(mutex_, std::try_to_lock);
      if (!lock.owns_lock()) return;  // the thread that holds it sees pending_ after it unlocked
      pending_.store(false);
      take();
    }
  }

 private:
  std::mutex mutex_;
  std::atomic<bool> pending_{false};
};

// A reader of a state-like topic, made on first use.
struct LazyReader {
  std::atomic<dds::DataReader*> reader{nullptr};
  SerialTake take;
};

struct ReplyRecord {
  std::string gateway;
  std::string status;
  std::string reason;
};

}  // namespace

std::string_view to_string(Outcome o) noexcept {
  switch (o) {
    case Outcome::Accepted: return "accepted";
    case Outcome::Completed: return "completed";
    case Outcome::Rejected: return "rejected";
    case Outcome::Failed: return "failed";
    case Outcome::Timeout: return "timeout";
    case Outcome::NoGateway: return "no_gateway";
    case Outcome::Busy: return "busy";
    case Outcome::Denied: return "denied";
  }
  return "unknown";
}

// A DDS participant's GUID prefix: the gateway's endpoints all carry the prefix of its participant.
using ParticipantKey = std::array<std::uint8_t, 12>;
ParticipantKey participant_of(const eprosima::fastrtps::rtps::GUID_t& guid) {
  ParticipantKey k{};
  std::copy(std::begin(guid.guidPrefix.value), std::end(guid.guidPrefix.value), k.begin());
  return k;
}
ParticipantKey participant_of(const dds::InstanceHandle_t& handle) {
  return participant_of(eprosima::fastrtps::rtps::iHandle2GUID(handle));
}

class Client::Impl : public dds::DataReaderListener, public dds::DataWriterListener {
 public:
  explicit Impl(ClientOptions options) : opt_(std::move(options)) {
    if (opt_.name.empty()) opt_.name = default_name();
    if (opt_.window == 0) opt_.window = 1;
    msg::DdsOptions o;
    o.domain = opt_.domain;
    o.ns = opt_.ns;
    o.participant_name = "drivegate-client/" + opt_.name;
    o.interfaces = opt_.interfaces;
    if (o.interfaces.empty()) o.interfaces = split_list(env("DRIVEGATE_INTERFACES"));
    const std::string identity = opt_.identity.empty() ? env("DRIVEGATE_IDENTITY") : opt_.identity;
    if (!identity.empty()) o.security = msg::security_files_in(identity);
    node_ = std::make_unique<msg::DdsNode>(o);
    // Discovery from the start. Transient-local history can be delivered while create_datareader()
    // is still running, before info_r_ is known to on_data_available(). So: create the reader
    // without a listener, then attach it and take whatever already arrived. The readers of the
    // state-like topics are made on first use (subscribe()): a client that only commands matches
    // no gateway's axis_state writer, which would otherwise send it every state at the status rate.
    info_r_ = &node_->reader(msg::TopicId::GatewayInfo, nullptr, dds::StatusMask::none());
    info_r_->set_listener(this, dds::StatusMask::data_available());
    on_data_available(info_r_);
  }

  // The endpoints for commands (and set-points) or parameter requests, made on first use: a client
  // that only watches never asks for them, and under DDS Security an identity may lack the right to
  // them (roles observer, operator), which is then reported when they are used.
  void ensure_command_endpoints() {
    std::lock_guard lock(endpoints_mutex_);
    if (command_endpoints_tried_) return;
    command_endpoints_tried_ = true;
    cmd_w_ = optional_writer(msg::TopicId::AxisCommand, command_refusal_);
    if (cmd_w_ != nullptr) sp_w_ = optional_writer(msg::TopicId::Setpoint, command_refusal_);
    if (sp_w_ != nullptr) reply_r_ = listened_reader(msg::TopicId::CommandReply, command_refusal_);
  }
  void ensure_param_endpoints() {
    std::lock_guard lock(endpoints_mutex_);
    if (param_endpoints_tried_) return;
    param_endpoints_tried_ = true;
    param_w_ = optional_writer(msg::TopicId::ParamRequest, parameter_refusal_);
    if (param_w_ != nullptr) param_r_ = listened_reader(msg::TopicId::ParamReply, parameter_refusal_);
  }
  void ensure_io_endpoints() {
    std::lock_guard lock(endpoints_mutex_);
    if (io_endpoints_tried_) return;
    io_endpoints_tried_ = true;
    io_w_ = optional_writer(msg::TopicId::IoWrite, io_refusal_);
    if (io_w_ != nullptr) io_r_ = listened_reader(msg::TopicId::IoWriteReply, io_refusal_);
  }
  std::string io_refusal() {
    ensure_io_endpoints();
    return io_refusal_;
  }
  // A reply reader: its matches are followed from creation on (ensure_matched asks whose writers
  // matched); its data once it is known as reply_r_/param_r_ (replies come only after a request).
  dds::DataReader* listened_reader(msg::TopicId t, std::string& refusal) {
    dds::DataReader* r = optional_reader(t, refusal, this, dds::StatusMask::subscription_matched());
    if (r != nullptr) r->set_listener(this, dds::StatusMask::data_available() << dds::StatusMask::subscription_matched());
    return r;
  }
  // The readers call back into this object: delete them before anything else goes.
  ~Impl() override { node_.reset(); }
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  std::string command_refusal() {
    ensure_command_endpoints();
    return command_refusal_;
  }
  std::string parameter_refusal() {
    ensure_param_endpoints();
    return parameter_refusal_;
  }

  // Called by DDS listener threads, and by the thread that attached the listener for what arrived
  // before (constructor, subscribe()): the readers taken on both take through a SerialTake.
  void on_data_available(dds::DataReader* reader) override {
    if (reader == nullptr) return;
    if (reader == info_r_) info_take_.run([&] { take_infos(); });
    else if (reader == reply_r_) take_replies();
    else if (reader == param_r_) take_param_replies();
    else if (reader == io_r_) take_io_replies();
    else if (reader == io_state_r_.reader.load()) io_state_r_.take.run([&] { take_io_states(*reader); });
    else if (reader == state_r_.reader.load()) state_r_.take.run([&] { take_states(*reader); });
    else if (reader == event_r_.reader.load()) event_r_.take.run([&] { take_events(*reader); });
    else if (reader == bus_r_.reader.load()) bus_r_.take.run([&] { take_buses(*reader); });
    else if (reader == link_r_.reader.load()) link_r_.take.run([&] { take_links(*reader); });
    {
      std::lock_guard lock(mutex_);
      ++generation_;
    }
    cv_.notify_all();
  }

  // Which participants' readers matched our writers and whose writers matched our readers
  // (per endpoint, by participant: a count, since a participant may have several).
  void on_publication_matched(dds::DataWriter* writer, const dds::PublicationMatchedStatus& s) override {
    note_match(writer, participant_of(s.last_subscription_handle), s.current_count_change);
  }
  void on_subscription_matched(dds::DataReader* reader, const dds::SubscriptionMatchedStatus& s) override {
    note_match(reader, participant_of(s.last_publication_handle), s.current_count_change);
  }
  void note_match(const void* endpoint, const ParticipantKey& peer, std::int32_t change) {
    {
      std::lock_guard lock(mutex_);
      auto& peers = matches_[endpoint];
      const int n = (peers[peer] += change);
      if (n <= 0) peers.erase(peer);
      ++generation_;
    }
    cv_.notify_all();
  }
  [[nodiscard]] bool matched_locked(const void* endpoint, const ParticipantKey& peer) const {
    const auto e = matches_.find(endpoint);
    return e != matches_.end() && e->second.count(peer) > 0;
  }

  bool wait_until(const std::function<bool()>& condition, Millis timeout) const {
    const auto deadline = SteadyClock::now() + timeout;
    for (;;) {
      std::uint64_t gen = 0;
      {
        std::lock_guard lock(mutex_);
        gen = generation_;
      }
      if (condition()) return true;
      const auto now = SteadyClock::now();
      if (now >= deadline) return false;
      std::unique_lock lock(mutex_);
      cv_.wait_until(lock, std::min(deadline, now + kPollSlice), [&] { return generation_ != gen; });
    }
  }

  Route route(std::string_view axis, std::string_view gateway) const {
    std::lock_guard lock(mutex_);
    if (!gateway.empty()) {
      const auto it = gateways_.find(std::string(gateway));
      if (it == gateways_.end())
        return {{}, "gateway '" + std::string(gateway) + "' is not known; known gateways: " + known_gateways_locked()};
      // A named gateway is asked even when discovery does not list the axis there: the gateway's
      // own answer is authoritative (and says which axes it has) where discovery may be stale.
      return {std::string(gateway), {}};
    }
    std::vector<std::string> owners;
    for (const auto& [name, g] : gateways_)
      for (const auto& a : g.axes)
        if (a.name == axis) owners.push_back(name);
    if (owners.size() == 1) return {owners.front(), {}};
    if (owners.empty())
      return {{}, "no gateway owns axis '" + std::string(axis) + "'; known axes: " + known_axes_locked()};
    return {{}, "axis '" + std::string(axis) + "' is claimed by several gateways (" + join(owners) +
                    "); name one with --gateway"};
  }

  CommandResult send(const CommandRequest& req, bool wait_final, Millis timeout) {
    const auto deadline = SteadyClock::now() + timeout;
    CommandResult result;
    result.axis = req.axis;
    ensure_command_endpoints();
    if (cmd_w_ == nullptr || reply_r_ == nullptr) {
      result.outcome = Outcome::Denied;
      result.reason = command_refusal_;
      return result;
    }
    const Route r = wait_route(req.axis, req.gateway, timeout);
    if (!r.error.empty()) {
      result.outcome = Outcome::NoGateway;
      result.reason = r.error;
      return result;
    }
    result.gateway = r.gateway;
    ensure_matched(deadline, r.gateway, *cmd_w_, *reply_r_);

    msg::AxisCommand out;
    out.gateway(r.gateway);
    out.axis(req.axis);
    out.client(opt_.name);
    result.id = next_id_++;
    out.id(result.id);
    out.kind(req.kind);
    out.mode(req.mode);
    out.position(req.position);
    out.velocity(req.velocity);
    out.acceleration(req.acceleration);
    out.deceleration(req.deceleration);
    out.torque(req.torque);
    out.relative(req.relative);
    out.immediate(req.immediate);
    out.homing_method(req.homing_method);
    out.home_offset(req.home_offset);
    out.homing_search_velocity(req.homing_search_velocity);
    out.homing_zero_velocity(req.homing_zero_velocity);
    out.block(req.block);
    {
      std::lock_guard lock(mutex_);
      replies_[result.id];  // from now on, replies with this id are kept
    }
    if (const auto busy = write_in_window(*cmd_w_, &out, deadline)) {
      std::lock_guard lock(mutex_);
      replies_.erase(result.id);
      result.outcome = Outcome::Busy;
      result.reason = *busy;
      return result;
    }

    std::unique_lock lock(mutex_);
    bool accepted = false;
    const auto first_reply = [&] {
      if (!accepted) release_window_locked();
    };
    for (;;) {
      auto& queue = replies_[result.id];
      while (!queue.empty()) {
        ReplyRecord rec = std::move(queue.front());
        queue.pop_front();
        if (rec.status == "accepted") {
          first_reply();
          accepted = true;
          result.outcome = Outcome::Accepted;
          result.reason = rec.reason;
          if (!wait_final) {
            replies_.erase(result.id);
            return result;
          }
          continue;
        }
        first_reply();
        result.outcome = rec.status == "completed" ? Outcome::Completed
                         : rec.status == "rejected" ? Outcome::Rejected
                                                    : Outcome::Failed;
        result.reason = rec.reason;
        replies_.erase(result.id);
        return result;
      }
      if (cv_.wait_until(lock, deadline) == std::cv_status::timeout && replies_[result.id].empty()) {
        first_reply();
        replies_.erase(result.id);
        result.outcome = Outcome::Timeout;
        result.reason = accepted ? "gateway '" + r.gateway + "' accepted the command but did not finish it in time"
                                 : "no reply from gateway '" + r.gateway + "' in time";
        return result;
      }
    }
  }

  std::string stream_setpoint(std::string_view axis, std::string_view gateway, double position, double velocity,
                              double torque) {
    ensure_command_endpoints();
    if (sp_w_ == nullptr) return command_refusal_;
    const Route r = route(axis, gateway);
    if (!r.error.empty()) return r.error;
    msg::Setpoint out;
    out.gateway(r.gateway);
    out.axis(std::string(axis));
    out.client(opt_.name);
    out.position(position);
    out.velocity(velocity);
    out.torque(torque);
    out.seq(++setpoint_seq_);
    if (!sp_w_->write(&out)) return "set-point could not be written";
    return {};
  }

  ParamResult param(const ParamRequest& req, Millis timeout) {
    const auto deadline = SteadyClock::now() + timeout;
    ParamResult result;
    ensure_param_endpoints();
    if (param_w_ == nullptr || param_r_ == nullptr) {
      result.error = parameter_refusal_;
      return result;
    }
    Route r = wait_route(req.axis, req.gateway, timeout);
    // A record may go to an IO device (no axis): the gateway that publishes it.
    if (!r.error.empty() && core::is_record_address(req.name)) {
      const Route io = io_owner(req.axis, {}, deadline);
      if (io.error.empty()) r = io;
    }
    if (!r.error.empty()) {
      result.error = r.error;
      return result;
    }
    result.gateway = r.gateway;
    ensure_matched(deadline, r.gateway, *param_w_, *param_r_);
    msg::ParameterRequest out;
    out.gateway(r.gateway);
    out.axis(req.axis);
    out.client(opt_.name);
    const std::uint64_t id = next_id_++;
    out.id(id);
    out.write(req.write);
    out.index(req.index);
    out.subindex(req.subindex);
    out.name(req.name);
    out.type(req.type);
    out.value(req.value);
    {
      std::lock_guard lock(mutex_);
      param_replies_[id];
    }
    if (const auto busy = write_in_window(*param_w_, &out, deadline)) {
      std::lock_guard lock(mutex_);
      param_replies_.erase(id);
      result.error = *busy;
      return result;
    }
    std::unique_lock lock(mutex_);
    const bool got = cv_.wait_until(lock, deadline, [&] { return param_replies_[id].has_value(); });
    release_window_locked();
    if (!got) {
      param_replies_.erase(id);
      result.error = "no parameter reply from gateway '" + r.gateway + "' in time";
      return result;
    }
    const ParamResult reply = *param_replies_[id];
    param_replies_.erase(id);
    return reply;
  }

  // io_state: gateways that have no I/O slaves publish none, and nobody says how many a gateway
  // has. So the first read waits until every known gateway's states came and no new slave showed
  // up for 100 ms (a gateway writes all of its slaves together, daemon/dds_bridge.cpp), or for
  // 600 ms (a keep-alive period, 250 ms by default, past the match), whichever comes first.
  void subscribe_io() {
    const auto start = SteadyClock::now();
    subscribe(io_state_r_, msg::TopicId::IoState, [&] {
      std::set<std::string> seen;
      for (const auto& [key, st] : io_states_) seen.insert(st.gateway);
      const auto now = SteadyClock::now();
      return (seen.size() >= gateways_.size() && now - last_io_instance_ > std::chrono::milliseconds(100)) ||
             now - start > std::chrono::milliseconds(600);
    });
  }
  std::vector<IoState> io_states() {
    subscribe_io();
    std::lock_guard lock(mutex_);
    std::vector<IoState> v;
    for (const auto& [key, st] : io_states_) v.push_back(st);
    return v;
  }
  std::optional<IoState> io_state(std::string_view slave, std::string_view bus, std::string_view gateway) {
    subscribe_io();
    std::lock_guard lock(mutex_);
    for (const auto& [key, st] : io_states_)
      if (st.slave == slave && (bus.empty() || st.bus == bus) && (gateway.empty() || st.gateway == gateway)) return st;
    return std::nullopt;
  }

  IoWriteResult io_write(const IoWriteRequest& req, Millis timeout) {
    const auto deadline = SteadyClock::now() + timeout;
    IoWriteResult result;
    ensure_io_endpoints();
    if (io_w_ == nullptr || io_r_ == nullptr) {
      result.error = io_refusal_;
      return result;
    }
    // The owner: the gateway named, else the one whose io_state names the slave (on the bus).
    std::string gateway = req.gateway;
    if (gateway.empty()) {
      const Route owner = io_owner(req.slave, req.bus, deadline);
      if (!owner.error.empty()) {
        result.error = owner.error;
        return result;
      }
      gateway = owner.gateway;
    }
    result.gateway = gateway;
    result.bus = req.bus;
    ensure_matched(deadline, gateway, *io_w_, *io_r_);
    msg::IoWrite out;
    out.gateway(gateway);
    out.bus(req.bus);
    out.slave(req.slave);
    out.client(opt_.name);
    const std::uint64_t id = next_id_++;
    out.id(id);
    out.offset(req.offset);
    out.data(req.data);
    {
      std::lock_guard lock(mutex_);
      io_replies_[id];
    }
    if (const auto busy = write_in_window(*io_w_, &out, deadline)) {
      std::lock_guard lock(mutex_);
      io_replies_.erase(id);
      result.status = "busy";
      result.error = *busy;
      return result;
    }
    std::unique_lock lock(mutex_);
    const bool got = cv_.wait_until(lock, deadline, [&] { return io_replies_[id].has_value(); });
    release_window_locked();
    if (!got) {
      io_replies_.erase(id);
      result.error = "no I/O write reply from gateway '" + gateway + "' in time";
      return result;
    }
    const IoWriteResult reply = *io_replies_[id];
    io_replies_.erase(id);
    return reply;
  }

  std::vector<GatewayInfo> gateways() const {
    std::lock_guard lock(mutex_);
    std::vector<GatewayInfo> v;
    for (const auto& [name, g] : gateways_) v.push_back(g);
    return v;
  }
  std::vector<AxisState> states() {
    subscribe_states();
    std::lock_guard lock(mutex_);
    std::vector<AxisState> v;
    for (const auto& [key, s] : states_) v.push_back(s);
    return v;
  }
  std::optional<AxisState> state(std::string_view axis, std::string_view gateway) {
    subscribe_states();
    std::lock_guard lock(mutex_);
    for (const auto& [key, s] : states_)
      if (s.axis == axis && (gateway.empty() || s.gateway == gateway)) return s;
    return std::nullopt;
  }
  std::vector<BusStatus> buses() {
    subscribe(bus_r_, msg::TopicId::BusStatus, [&] {
      return every_axis_has([&](const std::string& g, const AxisInfo& a) { return buses_.count({g, a.bus}) > 0; });
    });
    std::lock_guard lock(mutex_);
    std::vector<BusStatus> v;
    for (const auto& [key, b] : buses_) v.push_back(b);
    return v;
  }
  std::vector<AxisLink> links() {
    subscribe_links();
    std::lock_guard lock(mutex_);
    std::vector<AxisLink> v;
    for (const auto& [key, l] : links_) v.push_back(l);
    return v;
  }
  std::optional<AxisLink> link(std::string_view axis, std::string_view gateway) {
    subscribe_links();
    std::lock_guard lock(mutex_);
    for (const auto& [key, l] : links_)
      if (l.axis == axis && (gateway.empty() || l.gateway == gateway)) return l;
    return std::nullopt;
  }
  std::size_t link_writers() {
    subscribe_links();
    const dds::DataReader* r = link_r_.reader.load();
    if (r == nullptr) return 0;
    dds::SubscriptionMatchedStatus m{};
    r->get_subscription_matched_status(m);
    return static_cast<std::size_t>(std::max(m.current_count, 0));
  }
  std::vector<AxisEvent> events_since(std::uint64_t& cursor) {
    // The gateways' event history (transient local) reaches the reader after it matched their
    // writers: wait until it stopped growing (called under mutex_, once the reader matched).
    Settled settled(kHistoryQuiet);
    subscribe(event_r_, msg::TopicId::AxisEvent, [&] { return settled(events_end_); });
    std::lock_guard lock(mutex_);
    std::vector<AxisEvent> v;
    const std::uint64_t first = events_end_ - events_.size();
    for (std::uint64_t i = std::max(cursor, first); i < events_end_; ++i) v.push_back(events_[i - first]);
    cursor = events_end_;
    return v;
  }
  const std::string& name() const noexcept { return opt_.name; }

 private:
  static std::string env(const char* name) {
    const char* v = std::getenv(name);
    return v == nullptr ? std::string{} : std::string{v};
  }
  static std::vector<std::string> split_list(const std::string& text) {
    std::vector<std::string> out;
    std::size_t at = 0;
    while (at <= text.size()) {
      const auto comma = text.find(',', at);
      const auto item = text.substr(at, comma == std::string::npos ? std::string::npos : comma - at);
      if (!item.empty()) out.push_back(item);
      if (comma == std::string::npos) break;
      at = comma + 1;
    }
    return out;
  }

  dds::DataWriter* optional_writer(msg::TopicId t, std::string& refusal) {
    try {
      // Matches are followed from creation on (ensure_matched asks whose readers matched).
      return &node_->writer(t, this, dds::StatusMask::publication_matched());
    } catch (const std::runtime_error& e) {
      if (!node_->secure()) throw;  // without access control a refusal is a real failure
      if (refusal.empty()) refusal = std::string(e.what()) + " (client '" + opt_.name + "')";
      return nullptr;
    }
  }
  dds::DataReader* optional_reader(msg::TopicId t, std::string& refusal, dds::DataReaderListener* listener = nullptr,
                                   dds::StatusMask mask = dds::StatusMask::none()) {
    try {
      return &node_->reader(t, listener, mask);
    } catch (const std::runtime_error& e) {
      if (!node_->secure()) throw;
      if (refusal.empty()) refusal = std::string(e.what()) + " (client '" + opt_.name + "')";
      return nullptr;
    }
  }

  void subscribe_states() {
    subscribe(state_r_, msg::TopicId::AxisState,
              [&] { return every_axis_has([&](const std::string& g, const AxisInfo& a) { return states_.count({g, a.name}) > 0; }); });
  }
  void subscribe_links() {
    subscribe(link_r_, msg::TopicId::AxisLink,
              [&] { return every_axis_has([&](const std::string& g, const AxisInfo& a) { return links_.count({g, a.name}) > 0; }); });
  }

  // Makes the reader of a state-like topic on the first call (the later ones return at once) and
  // waits, up to kFirstData, until it matched every known gateway and `arrived` says the gateways'
  // present data is in, so that the first read after subscribing is not silently empty. When no
  // gateway is known yet (a read right after construction), it first waits, within the same budget,
  // for discovery: a gateway, then none new for kDiscoveryQuiet (as wait_route()). Readers
  // the DDS identity may not have (permissions made before axis_link existed, say) stay absent:
  // their data is then empty. The mutex makes concurrent first calls wait for the same reader; the
  // reader is published (slot) before the listener is attached, as in the constructor.
  void subscribe(LazyReader& slot, msg::TopicId topic, const std::function<bool()>& arrived) {
    if (subscribed_.load(std::memory_order_acquire) & bit(topic)) return;
    std::lock_guard lock(subscribe_mutex_);
    if (subscribed_.load(std::memory_order_relaxed) & bit(topic)) return;
    std::string refusal;
    dds::DataReader* r = optional_reader(topic, refusal);
    if (r != nullptr) {
      slot.reader.store(r);
      r->set_listener(this, dds::StatusMask::data_available());
      on_data_available(r);
      bool discovering = false;
      {
        std::lock_guard data_lock(mutex_);
        discovering = gateways_.empty();
      }
      wait_until(
          [&] {
            dds::SubscriptionMatchedStatus m{};
            r->get_subscription_matched_status(m);
            std::lock_guard data_lock(mutex_);
            if (discovering && (gateways_.empty() || SteadyClock::now() - last_info_change_ < kDiscoveryQuiet))
              return false;
            return m.current_count >= static_cast<std::int32_t>(gateways_.size()) && arrived();
          },
          kFirstData);
    }
    subscribed_.fetch_or(bit(topic), std::memory_order_release);
  }
  static unsigned bit(msg::TopicId t) { return 1U << static_cast<unsigned>(t); }
  // Under mutex_: whether `has(gateway, axis)` holds for every discovered axis.
  template <typename Has>
  bool every_axis_has(Has&& has) const {
    for (const auto& [name, g] : gateways_)
      for (const auto& a : g.axes)
        if (!has(name, a)) return false;
    return true;
  }

  // Flow control: at most opt_.window requests of this client wait for their first reply; then
  // the write, which waits while the gateway's keep-all history is full. Returns why it could not
  // be sent before `deadline`, or nothing once it was written.
  template <typename Sample>
  std::optional<std::string> write_in_window(dds::DataWriter& writer, Sample* sample, SteadyClock::time_point deadline) {
    {
      std::unique_lock lock(mutex_);
      if (!cv_.wait_until(lock, deadline, [&] { return in_flight_ < opt_.window; }))
        return "busy: " + std::to_string(in_flight_) + " requests of this client still wait for their first reply";
      ++in_flight_;
    }
    for (;;) {
      const ReturnCode_t rc = writer.write(sample, dds::HANDLE_NIL);
      if (rc == ReturnCode_t::RETCODE_OK) return std::nullopt;
      if (rc != ReturnCode_t::RETCODE_TIMEOUT || SteadyClock::now() >= deadline) {
        std::lock_guard lock(mutex_);
        release_window_locked();
        return rc == ReturnCode_t::RETCODE_TIMEOUT
                   ? std::string("busy: the gateway did not take the request in time (DDS flow control)")
                   : "the request could not be written (DDS error " + std::to_string(rc()) + ")";
      }
    }
  }
  void release_window_locked() {
    if (in_flight_ > 0) --in_flight_;
    cv_.notify_all();
  }

  // The route for an axis, waiting for discovery: until the axis has an owner, or gateways are known
  // and none appeared for a while (then the axis really is unknown and waiting longer is pointless).
  // The gateway whose io_state names the I/O slave (on `bus` when given), waiting until `deadline`.
  Route io_owner(const std::string& slave, const std::string& bus, SteadyClock::time_point deadline) {
    subscribe_io();
    std::set<std::string> owners;
    std::string list;
    {
      std::unique_lock lock(mutex_);
      cv_.wait_until(lock, deadline, [&] {
        owners.clear();
        for (const auto& [key, st] : io_states_)
          if (st.slave == slave && (bus.empty() || st.bus == bus)) owners.insert(st.gateway);
        return !owners.empty();
      });
      for (const auto& [key, st] : io_states_) list += (list.empty() ? "" : ", ") + st.slave + " (" + st.gateway + "/" + st.bus + ")";
    }
    if (owners.empty())
      return {{}, "no gateway publishes an I/O slave '" + slave + "'" + (bus.empty() ? std::string() : " on bus " + bus) +
                      "; I/O slaves: " + (list.empty() ? "(none)" : list)};
    if (owners.size() > 1) return {{}, "I/O slave '" + slave + "' is on more than one gateway: name the gateway"};
    return {*owners.begin(), {}};
  }

  Route wait_route(std::string_view axis, std::string_view gateway, Millis timeout) const {
    Route r;
    wait_until(
        [&] {
          r = route(axis, gateway);
          if (r.error.empty()) return true;
          std::lock_guard lock(mutex_);
          return !gateways_.empty() && SteadyClock::now() - last_info_change_ >= kDiscoveryQuiet;
        },
        timeout);
    return r;
  }

  // A reliable volatile sample written before the gateway's reader matched us would be lost, and so
  // would a reply written before our reply reader matched. Wait (bounded) until the gateway's own
  // participant matched both: another participant's reader of the topic (a monitor, a recorder)
  // does not count.
  void ensure_matched(SteadyClock::time_point deadline, const std::string& gateway, const dds::DataWriter& writer,
                      const dds::DataReader& reader) const {
    wait_until(
        [&] {
          std::lock_guard lock(mutex_);
          const auto g = gateways_.find(gateway);
          if (g == gateways_.end()) return false;
          const auto peer = gateway_participants_.find(gateway);
          return peer != gateway_participants_.end() && matched_locked(&writer, peer->second) &&
                 matched_locked(&reader, peer->second);
        },
        std::chrono::duration_cast<Millis>(deadline - SteadyClock::now()));
  }

  std::string known_gateways_locked() const {
    std::vector<std::string> v;
    for (const auto& [name, g] : gateways_) v.push_back(name);
    return v.empty() ? "(none discovered)" : join(v);
  }
  std::string known_axes_locked() const {
    std::vector<std::string> v;
    for (const auto& [name, g] : gateways_)
      for (const auto& a : g.axes) v.push_back(name + "/" + a.name);
    return v.empty() ? "(no gateway discovered)" : join(v);
  }

  void take_infos() {
    msg::GatewayInfo in;
    dds::SampleInfo si;
    while (info_r_->take_next_sample(&in, &si) == ReturnCode_t::RETCODE_OK) {
      std::lock_guard lock(mutex_);
      if (!si.valid_data) {
        // The gateway went away (disposed or no writers left): forget what it owned.
        if (si.instance_state != dds::ALIVE_INSTANCE_STATE) {
          const auto it = info_handles_.find(si.instance_handle);
          if (it != info_handles_.end()) {
            gateways_.erase(it->second);
            gateway_participants_.erase(it->second);
            info_handles_.erase(it);
            last_info_change_ = SteadyClock::now();
          }
        }
        continue;
      }
      GatewayInfo g;
      g.name = in.gateway();
      g.host = in.host();
      g.pid = in.pid();
      for (const auto& a : in.axes())
        g.axes.push_back({in.gateway(), a.name(), a.bus(), a.device(), a.unit(), a.modes()});
      info_handles_[si.instance_handle] = g.name;
      gateway_participants_[g.name] = participant_of(si.sample_identity.writer_guid());
      gateways_[g.name] = std::move(g);
      last_info_change_ = SteadyClock::now();
    }
  }

  void take_states(dds::DataReader& reader) {
    msg::take_valid<msg::AxisState>(reader, [&](const msg::AxisState& in) {
      AxisState s;
      s.gateway = in.gateway();
      s.axis = in.axis();
      s.state = in.state();
      s.link = in.link();
      s.mode = in.mode();
      s.position = in.position();
      s.velocity = in.velocity();
      s.torque = in.torque();
      s.unit = in.unit();
      s.fault_code = in.fault_code();
      s.fault_text = in.fault_text();
      s.target_reached = in.target_reached();
      s.homed = in.homed();
      s.warning = in.warning();
      s.stopping = in.stopping();
      s.following_error = in.following_error();
      s.statusword = in.statusword();
      s.active_command = in.active_command();
      s.stamp_ns = in.stamp();
      s.seq = in.seq();
      s.received = SteadyClock::now();
      std::lock_guard lock(mutex_);
      states_[{s.gateway, s.axis}] = std::move(s);
    });
  }

  void take_replies() {
    msg::take_valid<msg::CommandReply>(*reply_r_, [&](const msg::CommandReply& in) {
      if (in.client() != opt_.name) return;
      std::lock_guard lock(mutex_);
      const auto it = replies_.find(in.id());
      if (it != replies_.end()) it->second.push_back({in.gateway(), in.status(), in.reason()});
    });
  }

  void take_events(dds::DataReader& reader) {
    msg::take_valid<msg::AxisEvent>(reader, [&](const msg::AxisEvent& in) {
      std::lock_guard lock(mutex_);
      events_.push_back({in.gateway(), in.axis(), in.bus(), in.kind(), in.state(), in.code(), in.text(), in.stamp()});
      ++events_end_;
      if (events_.size() > kMaxEvents) events_.pop_front();
    });
  }

  void take_buses(dds::DataReader& reader) {
    msg::take_valid<msg::BusStatus>(reader, [&](const msg::BusStatus& in) {
      BusStatus b{in.gateway(),        in.bus(),         in.type(),
                  in.running(),        in.healthy(),     in.period_ns(),
                  in.achieved_period_ns(), in.lateness_p50_ns(), in.lateness_p99_ns(),
                  in.lateness_max_ns(), in.cycles(),      in.overruns(),
                  in.frames_sent(),    in.frames_received(), in.frames_lost(),
                  in.frames_dropped(), in.errors(),  in.clock_sync(),
                  in.clock_difference_ns(), in.clock_master_offset_ns()};
      std::lock_guard lock(mutex_);
      buses_[{b.gateway, b.bus}] = std::move(b);
    });
  }

  void take_links(dds::DataReader& reader) {
    msg::take_valid<msg::AxisLink>(reader, [&](const msg::AxisLink& in) {
      AxisLink l{in.gateway(), in.axis(), in.bus(), in.bus_type(), in.address(), in.link(), in.detail(), in.since()};
      std::lock_guard lock(mutex_);
      links_[{l.gateway, l.axis}] = std::move(l);
    });
  }

  void take_io_states(dds::DataReader& reader) {
    const auto now = SteadyClock::now();
    msg::take_valid<msg::IoState>(reader, [&](const msg::IoState& in) {
      IoState st{in.gateway(), in.bus(), in.slave(), in.address(), in.inputs(), in.outputs(), in.valid(),
                 in.stamp(), in.seq(), now};
      std::lock_guard lock(mutex_);
      const bool added = io_states_.insert_or_assign({st.gateway, st.bus, st.slave}, st).second;
      if (added) last_io_instance_ = now;
    });
  }

  void take_io_replies() {
    msg::take_valid<msg::IoWriteReply>(*io_r_, [&](const msg::IoWriteReply& in) {
      if (in.client() != opt_.name) return;
      std::lock_guard lock(mutex_);
      const auto it = io_replies_.find(in.id());
      if (it == io_replies_.end()) return;
      IoWriteResult r;
      r.ok = in.ok();
      r.gateway = in.gateway();
      r.bus = in.bus();
      r.status = in.status();
      r.error = in.reason();
      it->second = std::move(r);
    });
  }

  void take_param_replies() {
    msg::take_valid<msg::ParameterReply>(*param_r_, [&](const msg::ParameterReply& in) {
      if (in.client() != opt_.name) return;
      std::lock_guard lock(mutex_);
      const auto it = param_replies_.find(in.id());
      if (it == param_replies_.end()) return;
      ParamResult r;
      r.ok = in.ok();
      r.gateway = in.gateway();
      r.error_code = in.error_code();
      r.error = in.error();
      r.index = in.index();
      r.subindex = in.subindex();
      // A type this client does not know (a newer gateway's) shows as raw bytes.
      r.type = core::param_type_from_name(in.type()).value_or(core::ParamType::Unknown);
      r.data = in.data();
      it->second = std::move(r);
    });
  }

  ClientOptions opt_;
  std::unique_ptr<msg::DdsNode> node_;
  dds::DataWriter* cmd_w_ = nullptr;
  dds::DataWriter* sp_w_ = nullptr;
  dds::DataWriter* param_w_ = nullptr;
  dds::DataReader* info_r_ = nullptr;
  dds::DataReader* reply_r_ = nullptr;
  dds::DataReader* param_r_ = nullptr;
  dds::DataWriter* io_w_ = nullptr;
  dds::DataReader* io_r_ = nullptr;
  SerialTake info_take_;
  // Made on first use (subscribe()); read by the listener thread.
  LazyReader state_r_;
  LazyReader event_r_;
  LazyReader bus_r_;
  LazyReader link_r_;
  LazyReader io_state_r_;
  std::mutex subscribe_mutex_;
  std::atomic<unsigned> subscribed_{0};  // bit(topic): subscribe() done for that topic

  std::mutex endpoints_mutex_;
  bool command_endpoints_tried_ = false;
  bool param_endpoints_tried_ = false;
  bool io_endpoints_tried_ = false;
  std::string io_refusal_;
  std::string command_refusal_;    // why this identity may not command (empty: it may)
  std::string parameter_refusal_;  // likewise for parameter requests
  std::size_t in_flight_ = 0;      // requests written and waiting for their first reply (mutex_)

  std::atomic<std::uint64_t> next_id_{1};
  std::atomic<std::uint64_t> setpoint_seq_{0};

  mutable std::mutex mutex_;
  mutable std::condition_variable cv_;
  std::uint64_t generation_ = 0;
  std::map<std::string, GatewayInfo> gateways_;
  std::map<dds::InstanceHandle_t, std::string> info_handles_;
  std::map<std::string, ParticipantKey> gateway_participants_;  // gateway name -> its participant
  std::map<const void*, std::map<ParticipantKey, int>> matches_;  // endpoint -> matched peers
  SteadyClock::time_point last_info_change_;
  std::map<std::pair<std::string, std::string>, AxisState> states_;
  std::map<std::pair<std::string, std::string>, BusStatus> buses_;
  std::map<std::pair<std::string, std::string>, AxisLink> links_;
  std::deque<AxisEvent> events_;
  std::uint64_t events_end_ = 0;  // number of events ever received
  std::map<std::uint64_t, std::deque<ReplyRecord>> replies_;
  std::map<std::uint64_t, std::optional<ParamResult>> param_replies_;
  std::map<std::tuple<std::string, std::string, std::string>, IoState> io_states_;
  std::map<std::uint64_t, std::optional<IoWriteResult>> io_replies_;
  SteadyClock::time_point last_io_instance_{};  // a new I/O slave's first state arrived
};

Client::Client(ClientOptions options) : impl_(std::make_unique<Impl>(std::move(options))) {}
Client::~Client() = default;
const std::string& Client::name() const noexcept { return impl_->name(); }
std::string Client::command_refusal() { return impl_->command_refusal(); }
std::string Client::parameter_refusal() { return impl_->parameter_refusal(); }
std::vector<GatewayInfo> Client::gateways() const { return impl_->gateways(); }
std::vector<AxisState> Client::states() const { return impl_->states(); }
std::optional<AxisState> Client::state(std::string_view axis, std::string_view gateway) const {
  return impl_->state(axis, gateway);
}
std::vector<BusStatus> Client::buses() const { return impl_->buses(); }
std::vector<AxisLink> Client::links() const { return impl_->links(); }
std::optional<AxisLink> Client::link(std::string_view axis, std::string_view gateway) const {
  return impl_->link(axis, gateway);
}
std::size_t Client::link_writers() const { return impl_->link_writers(); }
std::vector<AxisEvent> Client::events_since(std::uint64_t& cursor) const { return impl_->events_since(cursor); }
bool Client::wait_until(const std::function<bool()>& condition, Millis timeout) const {
  return impl_->wait_until(condition, timeout);
}
Route Client::route(std::string_view axis, std::string_view gateway) const { return impl_->route(axis, gateway); }
CommandResult Client::send(const CommandRequest& request, bool wait_final, Millis timeout) {
  return impl_->send(request, wait_final, timeout);
}
std::string Client::stream_setpoint(std::string_view axis, std::string_view gateway, double position,
                                    double velocity, double torque) {
  return impl_->stream_setpoint(axis, gateway, position, velocity, torque);
}
ParamResult Client::param(const ParamRequest& request, Millis timeout) { return impl_->param(request, timeout); }
std::vector<IoState> Client::io_states() const { return impl_->io_states(); }
std::optional<IoState> Client::io_state(std::string_view slave, std::string_view bus, std::string_view gateway) const {
  return impl_->io_state(slave, bus, gateway);
}
std::string Client::io_refusal() { return impl_->io_refusal(); }
IoWriteResult Client::io_write(const IoWriteRequest& request, Millis timeout) { return impl_->io_write(request, timeout); }

}  // namespace drivegate::client
