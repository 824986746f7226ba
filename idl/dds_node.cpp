#include "idl/dds_node.hpp"

#include <arpa/inet.h>
#include <ifaddrs.h>
#include <netinet/in.h>

#include <algorithm>
#include <memory>
#include <stdexcept>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>

#include "drivegatePubSubTypes.h"

namespace drivegate::msg {

namespace dds = eprosima::fastdds::dds;

namespace {

// Per DESIGN.md §6. Commands and parameter requests are reliable, volatile and keep-all: nothing
// is overwritten before the gateway acknowledged it, a burst is flow-controlled instead of
// dropped, and a gateway that starts late never acts on old commands. Their replies are reliable
// and volatile, keyed by client with a deep history per client: one client that stops reading
// cannot hold up the replies to every other (which a shared keep-all history would), and the
// gateway keeps each client's unanswered requests well below that depth (daemon/dds_bridge.cpp).
// The gateway's reply writers keep all, up to that depth per client (see DdsNode::writer).
// A reply written before the gateway's writer knew a client's reader would be lost to volatile
// durability, so the gateway holds a client's replies until its reader is matched. State and
// set-points are best effort, newest only; events transient-local so a late joiner sees recent
// faults; gateway_info, bus_status and axis_link transient-local so a CLI started now sees them at
// once. The I/O topics go as their axis counterparts: io_state as axis_state, io_write as the
// parameter requests, io_write_reply as their replies.
constexpr std::array<TopicQos, kTopicCount> kQos{{
    {TopicId::AxisState, false, false, false, 1, "gateway, axis"},
    {TopicId::AxisCommand, true, false, true, 1024, ""},
    {TopicId::CommandReply, true, false, false, 1024, "gateway, client"},
    {TopicId::Setpoint, false, false, false, 1, "gateway, axis"},
    {TopicId::AxisEvent, true, true, false, 100, ""},
    {TopicId::BusStatus, true, true, false, 1, "gateway, bus"},
    {TopicId::ParamRequest, true, false, true, 1024, ""},
    {TopicId::ParamReply, true, false, false, 1024, "gateway, client"},
    {TopicId::GatewayInfo, true, true, false, 1, "gateway"},
    {TopicId::AxisLink, true, true, false, 1, "gateway, axis"},
    {TopicId::IoState, false, false, false, 1, "gateway, bus, slave"},
    {TopicId::IoWrite, true, false, true, 1024, ""},
    {TopicId::IoWriteReply, true, false, false, 1024, "gateway, client"},
}};

// Instances (axes, buses, clients) a topic keeps apart at once; memory grows with use, not up front.
constexpr std::int32_t kMaxInstances = 1000;

template <typename Qos>
void apply(const TopicQos& q, Qos& qos) {
  qos.reliability().kind = q.reliable ? dds::RELIABLE_RELIABILITY_QOS : dds::BEST_EFFORT_RELIABILITY_QOS;
  qos.durability().kind = q.transient_local ? dds::TRANSIENT_LOCAL_DURABILITY_QOS : dds::VOLATILE_DURABILITY_QOS;
  if (q.keep_all) {
    qos.history().kind = dds::KEEP_ALL_HISTORY_QOS;
    // Unkeyed: one instance holds every sample. Memory grows with use, not up front.
    qos.resource_limits().max_samples = q.depth;
    qos.resource_limits().max_instances = 1;
    qos.resource_limits().max_samples_per_instance = q.depth;
    qos.resource_limits().allocated_samples = std::min<std::int32_t>(q.depth, 64);
  } else {
    qos.history().kind = dds::KEEP_LAST_HISTORY_QOS;
    qos.history().depth = q.depth;
    if (!q.key.empty()) {
      // One instance per axis, bus or client: Fast DDS's default limits (10 instances, 400
      // samples each) would refuse the eleventh axis' state, and a client's replies come and go
      // with clients (the gateway unregisters a client's when it leaves).
      qos.resource_limits().max_instances = kMaxInstances;
      qos.resource_limits().max_samples_per_instance = q.depth;
      qos.resource_limits().max_samples = kMaxInstances * q.depth;
      qos.resource_limits().allocated_samples = std::min<std::int32_t>(q.depth, 64);
    }
  }
}

// Why a participant could not be made, with what to check: Fast DDS logs little for most of these.
std::string participant_failure(const DdsOptions& o) {
  std::string s = "cannot create the DDS participant on domain " + std::to_string(o.domain);
  if (!o.profiles_file.empty()) s += " (check the Fast DDS profile in " + o.profiles_file + ")";
  if (o.security)
    s += "; with DDS Security on, check that the certificate is valid now (not expired) and signed by identity_ca, "
         "that the permissions' subject names the certificate's subject exactly, and that governance and "
         "permissions are signed by permissions_ca (scripts/make-pki.sh makes a consistent set)";
  return s;
}

dds::TopicDataType* make_type(TopicId t) {
  switch (t) {
    case TopicId::AxisState: return new AxisStatePubSubType();
    case TopicId::AxisCommand: return new AxisCommandPubSubType();
    case TopicId::CommandReply: return new CommandReplyPubSubType();
    case TopicId::Setpoint: return new SetpointPubSubType();
    case TopicId::AxisEvent: return new AxisEventPubSubType();
    case TopicId::BusStatus: return new BusStatusPubSubType();
    case TopicId::ParamRequest: return new ParameterRequestPubSubType();
    case TopicId::ParamReply: return new ParameterReplyPubSubType();
    case TopicId::GatewayInfo: return new GatewayInfoPubSubType();
    case TopicId::AxisLink: return new AxisLinkPubSubType();
    case TopicId::IoState: return new IoStatePubSubType();
    case TopicId::IoWrite: return new IoWritePubSubType();
    case TopicId::IoWriteReply: return new IoWriteReplyPubSubType();
  }
  return nullptr;
}

}  // namespace

std::string_view topic_suffix(TopicId t) noexcept {
  switch (t) {
    case TopicId::AxisState: return "axis_state";
    case TopicId::AxisCommand: return "axis_command";
    case TopicId::CommandReply: return "command_reply";
    case TopicId::Setpoint: return "setpoint";
    case TopicId::AxisEvent: return "axis_event";
    case TopicId::BusStatus: return "bus_status";
    case TopicId::ParamRequest: return "param_request";
    case TopicId::ParamReply: return "param_reply";
    case TopicId::GatewayInfo: return "gateway_info";
    case TopicId::AxisLink: return "axis_link";
    case TopicId::IoState: return "io_state";
    case TopicId::IoWrite: return "io_write";
    case TopicId::IoWriteReply: return "io_write_reply";
  }
  return "unknown";
}

std::string topic_name(std::string_view ns, TopicId t) {
  std::string name(ns);
  if (!name.empty()) name += '/';
  name += topic_suffix(t);
  return name;
}

const std::array<TopicQos, kTopicCount>& qos_table() noexcept { return kQos; }

const TopicQos& qos_of(TopicId t) noexcept { return kQos[static_cast<std::size_t>(t)]; }

std::string reliability_text(const TopicQos& q) { return q.reliable ? "reliable" : "best effort"; }
std::string durability_text(const TopicQos& q) { return q.transient_local ? "transient local" : "volatile"; }
std::string history_text(const TopicQos& q) {
  if (q.keep_all) return "keep all (up to " + std::to_string(q.depth) + ")";
  return "keep last " + std::to_string(q.depth) + (q.key.empty() ? "" : " per instance");
}

std::vector<std::string> resolve_interfaces(const std::vector<std::string>& interfaces) {
  std::vector<std::string> out;
  ifaddrs* list = nullptr;
  if (::getifaddrs(&list) != 0) throw std::runtime_error("cannot list network interfaces");
  std::unique_ptr<ifaddrs, void (*)(ifaddrs*)> guard(list, ::freeifaddrs);
  for (const auto& want : interfaces) {
    in_addr literal{};
    if (::inet_pton(AF_INET, want.c_str(), &literal) == 1) {
      bool local = false;
      for (const ifaddrs* a = list; a != nullptr; a = a->ifa_next)
        local = local || (a->ifa_addr != nullptr && a->ifa_addr->sa_family == AF_INET &&
                          reinterpret_cast<const sockaddr_in*>(a->ifa_addr)->sin_addr.s_addr == literal.s_addr);
      if (!local) throw std::runtime_error("DDS interface " + want + " is not an address of this machine");
      out.push_back(want);
      continue;
    }
    bool named = false;
    std::size_t found = 0;
    for (const ifaddrs* a = list; a != nullptr; a = a->ifa_next) {
      if (a->ifa_name == nullptr || want != a->ifa_name) continue;
      named = true;
      if (a->ifa_addr == nullptr || a->ifa_addr->sa_family != AF_INET) continue;
      char text[INET_ADDRSTRLEN] = {};
      ::inet_ntop(AF_INET, &reinterpret_cast<const sockaddr_in*>(a->ifa_addr)->sin_addr, text, sizeof text);
      out.emplace_back(text);
      ++found;
    }
    if (!named) throw std::runtime_error("DDS interface " + want + " does not exist on this machine");
    if (found == 0) throw std::runtime_error("DDS interface " + want + " has no IPv4 address");
  }
  return out;
}

DdsNode::DdsNode(const DdsOptions& options) : ns_(options.ns) {
  // Standard domain ids for the default RTPS port mapping are 0..232.
  if (options.domain > 232)
    throw std::runtime_error("DDS domain id " + std::to_string(options.domain) + " is out of range 0..232");
  auto* factory = dds::DomainParticipantFactory::get_instance();
  // The XML defaults (FASTRTPS_DEFAULT_PROFILES_FILE, DEFAULT_FASTRTPS_PROFILES.xml) first, then the
  // file given here; the participant starts from the resulting default QoS (or the named profile),
  // never from the compiled-in PARTICIPANT_QOS_DEFAULT that would bypass them.
  factory->load_profiles();
  if (!options.profiles_file.empty() &&
      factory->load_XML_profiles_file(options.profiles_file) != ReturnCode_t::RETCODE_OK)
    throw std::runtime_error("cannot load the Fast DDS XML profiles in " + options.profiles_file);
  dds::DomainParticipantQos pqos = factory->get_default_participant_qos();
  if (!options.profile.empty() &&
      factory->get_participant_qos_from_profile(options.profile, pqos) != ReturnCode_t::RETCODE_OK)
    throw std::runtime_error("no participant profile named '" + options.profile + "'" +
                             (options.profiles_file.empty() ? std::string{} : " in " + options.profiles_file));
  if (!options.participant_name.empty()) pqos.name(options.participant_name);
  // Participant announcements every second instead of every 3 s (unless a profile chose): a
  // participant that joins learns of the others sooner, which a CLI call and the gateway's
  // start-up check for another instance of itself both wait for.
  auto& discovery = pqos.wire_protocol().builtin.discovery_config;
  if (discovery.leaseDuration_announcementperiod == eprosima::fastrtps::Duration_t(3, 0))
    discovery.leaseDuration_announcementperiod = eprosima::fastrtps::Duration_t(1, 0);
  if (!options.interfaces.empty()) {
    auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
    udp->interfaceWhiteList = resolve_interfaces(options.interfaces);
    pqos.transport().use_builtin_transports = false;
    pqos.transport().user_transports.clear();
    pqos.transport().user_transports.push_back(udp);
  }
  if (options.security) {
    if (const auto problem = check_security_files(*options.security); !problem.empty())
      throw std::runtime_error(problem);
    apply_security(pqos, *options.security);
    secure_ = true;
  }
  participant_ = factory->create_participant(static_cast<dds::DomainId_t>(options.domain), pqos);
  if (participant_ == nullptr) throw std::runtime_error(participant_failure(options));
  publisher_ = participant_->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
  subscriber_ = participant_->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
  if (publisher_ == nullptr || subscriber_ == nullptr) {
    participant_->delete_contained_entities();
    factory->delete_participant(participant_);
    throw std::runtime_error("cannot create DDS publisher/subscriber");
  }
}

DdsNode::~DdsNode() {
  participant_->delete_contained_entities();
  dds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
}

std::string DdsNode::refusal(TopicId t, const char* what) const {
  std::string s = std::string("cannot create DDS ") + what + " for " + topic_name(ns_, t);
  if (secure_)
    s += ": DDS access control refused it (this identity's permissions do not allow " +
         std::string(what[0] == 'w' ? "publishing" : "subscribing to") + " " + std::string(topic_suffix(t)) + ")";
  return s;
}

dds::Topic& DdsNode::topic(TopicId t) {
  auto& slot = topics_[static_cast<std::size_t>(t)];
  if (slot == nullptr) {
    dds::TypeSupport type(make_type(t));
    const std::string type_name = type.get_type_name();
    if (type.register_type(participant_) != ReturnCode_t::RETCODE_OK)
      throw std::runtime_error("cannot register DDS type " + type_name);
    const std::string name = topic_name(ns_, t);
    slot = participant_->create_topic(name, type_name, dds::TOPIC_QOS_DEFAULT);
    if (slot == nullptr) throw std::runtime_error("cannot create DDS topic " + name);
  }
  return *slot;
}

dds::DataWriter& DdsNode::writer(TopicId t, dds::DataWriterListener* listener, dds::StatusMask mask,
                                 std::chrono::milliseconds max_blocking) {
  dds::DataWriterQos qos = dds::DATAWRITER_QOS_DEFAULT;
  apply(qos_of(t), qos);
  // A reply writer keeps all, up to the topic's depth per client, and is transient local: a reply
  // is then never dropped before every reader that gets it has acknowledged it. Keep-last (and
  // Fast DDS's volatile keep-all, which drops the oldest when full) lost replies on a loaded
  // machine: a reader whose receive buffer overflowed asked again for a reply already overwritten.
  // A client's full instance refuses the write after `max_blocking` and the gateway holds the
  // reply (daemon/dds_bridge.cpp). Readers keep the table's QoS (volatile, keep-last): a volatile
  // reader gets nothing written before it matched, and a reader acknowledges whatever it receives,
  // so a client that does not take its replies cannot hold up the writer. No limit on instances:
  // a client name that was never seen before is never refused.
  if (t == TopicId::CommandReply || t == TopicId::ParamReply || t == TopicId::IoWriteReply) {
    qos.history().kind = dds::KEEP_ALL_HISTORY_QOS;
    qos.durability().kind = dds::TRANSIENT_LOCAL_DURABILITY_QOS;
    qos.resource_limits().max_instances = 0;  // unlimited
    qos.resource_limits().max_samples = 0;    // unlimited; max_samples_per_instance stays the depth
  }
  const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(max_blocking).count();
  qos.reliability().max_blocking_time = eprosima::fastrtps::Duration_t(
      static_cast<std::int32_t>(ns / 1'000'000'000), static_cast<std::uint32_t>(ns % 1'000'000'000));
  // Heartbeats every 100 ms instead of Fast DDS's 3 s: readers acknowledge (and ask for what got
  // lost in a burst) while the samples are still in the history, which for the keep-last reply
  // topics is what makes a burst lossless (RTPS heartbeat period; not visible to other vendors).
  qos.reliable_writer_qos().times.heartbeatPeriod = eprosima::fastrtps::Duration_t(0, 100'000'000);
  auto* w = publisher_->create_datawriter(&topic(t), qos, listener, mask);
  if (w == nullptr) throw std::runtime_error(refusal(t, "writer"));
  return *w;
}

dds::DataReader& DdsNode::reader(TopicId t, dds::DataReaderListener* listener, dds::StatusMask mask) {
  dds::DataReaderQos qos = dds::DATAREADER_QOS_DEFAULT;
  apply(qos_of(t), qos);
  auto* r = subscriber_->create_datareader(&topic(t), qos, listener, mask);
  if (r == nullptr) throw std::runtime_error(refusal(t, "reader"));
  return *r;
}

}  // namespace drivegate::msg
