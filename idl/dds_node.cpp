#include "idl/dds_node.hpp"

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

#include "drivegatePubSubTypes.h"

namespace drivegate::msg {

namespace dds = eprosima::fastdds::dds;

namespace {

struct TopicQos {
  dds::ReliabilityQosPolicyKind reliability;
  dds::DurabilityQosPolicyKind durability;
  std::int32_t depth;  // keep-last depth (per instance for keyed topics)
};

// Per DESIGN.md §6: commands and parameter requests reliable + volatile with a deep history so a
// burst is not lost, and so that a gateway that starts late never acts on old commands. Their
// replies are reliable + transient-local: a reply writer may match a client's reader only after it
// wrote the reply (discovery is asymmetric: the client sees its reader matched before the gateway's
// writer has matched it), and with volatile durability that reply would be lost; transient-local
// hands the recent replies to the late match and the client picks its own by client name and id.
// State and set-points are best effort, newest only; events transient-local so a late joiner sees
// recent faults; gateway_info and bus_status transient-local so a CLI started now sees them at once.
TopicQos qos_of(TopicId t) noexcept {
  switch (t) {
    case TopicId::AxisState: return {dds::BEST_EFFORT_RELIABILITY_QOS, dds::VOLATILE_DURABILITY_QOS, 1};
    case TopicId::Setpoint: return {dds::BEST_EFFORT_RELIABILITY_QOS, dds::VOLATILE_DURABILITY_QOS, 1};
    case TopicId::AxisCommand:
    case TopicId::ParamRequest: return {dds::RELIABLE_RELIABILITY_QOS, dds::VOLATILE_DURABILITY_QOS, 64};
    case TopicId::CommandReply:
    case TopicId::ParamReply: return {dds::RELIABLE_RELIABILITY_QOS, dds::TRANSIENT_LOCAL_DURABILITY_QOS, 64};
    case TopicId::AxisEvent: return {dds::RELIABLE_RELIABILITY_QOS, dds::TRANSIENT_LOCAL_DURABILITY_QOS, 100};
    case TopicId::BusStatus: return {dds::RELIABLE_RELIABILITY_QOS, dds::TRANSIENT_LOCAL_DURABILITY_QOS, 1};
    case TopicId::GatewayInfo: return {dds::RELIABLE_RELIABILITY_QOS, dds::TRANSIENT_LOCAL_DURABILITY_QOS, 1};
  }
  return {dds::RELIABLE_RELIABILITY_QOS, dds::VOLATILE_DURABILITY_QOS, 64};
}

dds::TopicDataType* make_type(TopicId t) {
  switch (t) {
    case TopicId::AxisState: return new AxisStatePubSubType();
    case TopicId::AxisCommand: return new AxisCommandPubSubType();
    case TopicId::CommandReply: return new CommandReplyPubSubType();
    case TopicId::Setpoint: return new SetpointPubSubType();
    case TopicId::AxisEvent: return new AxisEventPubSubType();
    case TopicId::BusStatus: return new BusStatusPubSubType();
    case TopicId::ParamRequest: return new ParamRequestPubSubType();
    case TopicId::ParamReply: return new ParamReplyPubSubType();
    case TopicId::GatewayInfo: return new GatewayInfoPubSubType();
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
  }
  return "unknown";
}

std::string topic_name(std::string_view ns, TopicId t) {
  std::string name(ns);
  if (!name.empty()) name += '/';
  name += topic_suffix(t);
  return name;
}

DdsNode::DdsNode(std::uint32_t domain, std::string ns, const std::string& participant_name)
    : ns_(std::move(ns)) {
  // Standard domain ids for the default RTPS port mapping are 0..232.
  if (domain > 232) throw std::runtime_error("DDS domain id " + std::to_string(domain) + " is out of range 0..232");
  dds::DomainParticipantQos pqos = dds::PARTICIPANT_QOS_DEFAULT;
  pqos.name(participant_name);
  participant_ = dds::DomainParticipantFactory::get_instance()->create_participant(
      static_cast<dds::DomainId_t>(domain), pqos);
  if (participant_ == nullptr)
    throw std::runtime_error("cannot create DDS participant on domain " + std::to_string(domain));
  publisher_ = participant_->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
  subscriber_ = participant_->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
  if (publisher_ == nullptr || subscriber_ == nullptr) {
    participant_->delete_contained_entities();
    dds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
    throw std::runtime_error("cannot create DDS publisher/subscriber");
  }
}

DdsNode::~DdsNode() {
  participant_->delete_contained_entities();
  dds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
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

dds::DataWriter& DdsNode::writer(TopicId t, dds::DataWriterListener* listener) {
  const TopicQos q = qos_of(t);
  dds::DataWriterQos qos = dds::DATAWRITER_QOS_DEFAULT;
  qos.reliability().kind = q.reliability;
  qos.durability().kind = q.durability;
  qos.history().kind = dds::KEEP_LAST_HISTORY_QOS;
  qos.history().depth = q.depth;
  auto* w = publisher_->create_datawriter(&topic(t), qos, listener);
  if (w == nullptr) throw std::runtime_error("cannot create DDS writer for " + topic_name(ns_, t));
  return *w;
}

dds::DataReader& DdsNode::reader(TopicId t, dds::DataReaderListener* listener, dds::StatusMask mask) {
  const TopicQos q = qos_of(t);
  dds::DataReaderQos qos = dds::DATAREADER_QOS_DEFAULT;
  qos.reliability().kind = q.reliability;
  qos.durability().kind = q.durability;
  qos.history().kind = dds::KEEP_LAST_HISTORY_QOS;
  qos.history().depth = q.depth;
  auto* r = subscriber_->create_datareader(&topic(t), qos, listener, mask);
  if (r == nullptr) throw std::runtime_error("cannot create DDS reader for " + topic_name(ns_, t));
  return *r;
}

}  // namespace drivegate::msg
