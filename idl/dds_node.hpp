#pragma once
// One DDS participant with the drivegate topics (idl/drivegate.idl) and their QoS. The bridge and
// the client both build on this so they always agree on names and QoS. Only standard DDS QoS is
// used (reliability, durability, history) so other vendors interoperate (DESIGN.md §6).
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include <fastdds/dds/core/status/StatusMask.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>

namespace eprosima::fastdds::dds {
class DomainParticipant;
class Publisher;
class Subscriber;
class Topic;
class DataWriter;
class DataReaderListener;
class DataWriterListener;
}  // namespace eprosima::fastdds::dds

namespace drivegate::msg {

enum class TopicId : std::uint8_t {
  AxisState,
  AxisCommand,
  CommandReply,
  Setpoint,
  AxisEvent,
  BusStatus,
  ParamRequest,
  ParamReply,
  GatewayInfo,
};
inline constexpr std::size_t kTopicCount = 9;

// "axis_state", "axis_command", ... (the part after "<namespace>/").
std::string_view topic_suffix(TopicId t) noexcept;
std::string topic_name(std::string_view ns, TopicId t);

class DdsNode {
 public:
  // Throws std::runtime_error when the participant cannot be created (bad domain id, ...).
  DdsNode(std::uint32_t domain, std::string ns, const std::string& participant_name);
  ~DdsNode();
  DdsNode(const DdsNode&) = delete;
  DdsNode& operator=(const DdsNode&) = delete;

  // Endpoints with the topic's QoS. Each call creates a new endpoint; they live as long as the node.
  eprosima::fastdds::dds::DataWriter& writer(TopicId t,
                                             eprosima::fastdds::dds::DataWriterListener* listener = nullptr);
  eprosima::fastdds::dds::DataReader& reader(
      TopicId t, eprosima::fastdds::dds::DataReaderListener* listener = nullptr,
      eprosima::fastdds::dds::StatusMask mask = eprosima::fastdds::dds::StatusMask::all());

  [[nodiscard]] const std::string& ns() const noexcept { return ns_; }

 private:
  eprosima::fastdds::dds::Topic& topic(TopicId t);

  std::string ns_;
  eprosima::fastdds::dds::DomainParticipant* participant_ = nullptr;
  eprosima::fastdds::dds::Publisher* publisher_ = nullptr;
  eprosima::fastdds::dds::Subscriber* subscriber_ = nullptr;
  std::array<eprosima::fastdds::dds::Topic*, kTopicCount> topics_{};
};

// Takes every sample waiting in `reader` and hands each one that carries data to `fn`; samples
// that only announce an instance's end (disposed, no writers) are dropped. Readers that must see
// those use take_next_sample themselves.
template <typename T, typename Fn>
void take_valid(eprosima::fastdds::dds::DataReader& reader, Fn&& fn) {
  T sample;
  eprosima::fastdds::dds::SampleInfo info;
  while (reader.take_next_sample(&sample, &info) == eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK)
    if (info.valid_data) fn(static_cast<const T&>(sample));
}

}  // namespace drivegate::msg
