#pragma once
// One DDS participant with the drivegate topics (idl/drivegate.idl) and their QoS. The bridge and
// the client both build on this so they always agree on names and QoS. Only standard DDS QoS is
// used (reliability, durability, history, resource limits) so other vendors interoperate
// (DESIGN.md §6); qos_table() is the one statement of it, and the README's table is tested
// against it.
//
// The participant starts from Fast DDS's default participant QoS, so a standard XML profile
// (FASTRTPS_DEFAULT_PROFILES_FILE, which Fast DDS 2.9 reads; DEFAULT_FASTRTPS_PROFILES.xml in the
// working directory; or DdsOptions::profiles_file with the profile named) applies: interfaces,
// transports, discovery servers, security properties. DdsOptions then narrows what drivegate is
// told to.
#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <fastdds/dds/core/status/StatusMask.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>

#include "idl/dds_security.hpp"

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
  AxisLink,
  IoState,
  IoWrite,
  IoWriteReply,
};
inline constexpr std::size_t kTopicCount = 13;

// "axis_state", "axis_command", ... (the part after "<namespace>/").
std::string_view topic_suffix(TopicId t) noexcept;
std::string topic_name(std::string_view ns, TopicId t);

// The QoS of one topic, the same for its writers and readers.
struct TopicQos {
  TopicId topic;
  bool reliable;
  bool transient_local;
  // Keep-all topics are flow-controlled end to end: a reader whose history is full leaves samples
  // unacknowledged, so the writer keeps them and blocks (a client's write() waits, then says busy)
  // instead of dropping. `depth` is then the history's resource limit in samples; for keep-last it
  // is the depth per instance.
  bool keep_all;
  std::int32_t depth;
  std::string_view key;  // key fields, "" for an unkeyed topic
};
const std::array<TopicQos, kTopicCount>& qos_table() noexcept;
const TopicQos& qos_of(TopicId t) noexcept;
// "reliable" / "best effort", "transient local" / "volatile", "keep all (up to 1024)" /
// "keep last 1 per instance": the words of the README's table.
std::string reliability_text(const TopicQos& q);
std::string durability_text(const TopicQos& q);
std::string history_text(const TopicQos& q);

struct DdsOptions {
  std::uint32_t domain = 0;
  std::string ns = "drivegate";
  std::string participant_name;
  // A Fast DDS XML profiles file loaded before the participant is made, and the participant
  // profile in it that is the starting point (Fast DDS 2.9 does not make a later file's default
  // profile the default).
  std::string profiles_file;
  std::string profile;
  // UDPv4 on these interfaces only (names such as "lo" or IPv4 addresses), no shared memory: the
  // participant announces only their addresses. Empty: whatever the profile says.
  std::vector<std::string> interfaces;
  // DDS Security with these files (checked before the participant is made).
  std::optional<SecurityFiles> security;
};

// The IPv4 addresses of `interfaces` (names or addresses) on this machine; throws
// std::runtime_error naming an unknown interface or one without an IPv4 address.
std::vector<std::string> resolve_interfaces(const std::vector<std::string>& interfaces);

class DdsNode {
 public:
  // Throws std::runtime_error when the participant cannot be created, with what to check.
  explicit DdsNode(const DdsOptions& options);
  ~DdsNode();
  DdsNode(const DdsNode&) = delete;
  DdsNode& operator=(const DdsNode&) = delete;

  // Endpoints with the topic's QoS. Each call creates a new endpoint; they live as long as the node.
  // Throw std::runtime_error when the endpoint cannot be made; under DDS Security that is access
  // control refusing it (the message says so).
  // `max_blocking`: how long write() may wait while a keep-all history is full of samples not yet
  // acknowledged by every matched reader, before it returns RETCODE_TIMEOUT.
  eprosima::fastdds::dds::DataWriter& writer(TopicId t,
                                             eprosima::fastdds::dds::DataWriterListener* listener = nullptr,
                                             eprosima::fastdds::dds::StatusMask mask =
                                                 eprosima::fastdds::dds::StatusMask::all(),
                                             std::chrono::milliseconds max_blocking = std::chrono::milliseconds(100));
  eprosima::fastdds::dds::DataReader& reader(
      TopicId t, eprosima::fastdds::dds::DataReaderListener* listener = nullptr,
      eprosima::fastdds::dds::StatusMask mask = eprosima::fastdds::dds::StatusMask::all());

  [[nodiscard]] const std::string& ns() const noexcept { return ns_; }
  [[nodiscard]] bool secure() const noexcept { return secure_; }
  [[nodiscard]] eprosima::fastdds::dds::DomainParticipant& participant() noexcept { return *participant_; }

 private:
  eprosima::fastdds::dds::Topic& topic(TopicId t);
  [[nodiscard]] std::string refusal(TopicId t, const char* what) const;

  std::string ns_;
  bool secure_ = false;
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
