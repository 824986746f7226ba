#pragma once
// The CiA 402 profile's view of one CANopen node (profiles/cia402/object_access.hpp): mapped
// objects live in the node's PDO process image, everything else goes through the node's SDO
// channel, and faults the drive announced by EMCY are handed to the profile with their text.
// Requests are refused (the profile retries next cycle) while the node is not operational, so the
// profile never competes with the boot sequence for the SDO channel.
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "adapters/canopen/master/emcy_consumer.hpp"
#include "core/fixed_string.hpp"
#include "adapters/canopen/master/pdo.hpp"
#include "adapters/canopen/master/sdo_client.hpp"
#include "profiles/cia402/object_access.hpp"

namespace drivegate::canopen {

// An object the gateway writes when it configures the node, and what it is (for the refusal).
struct OwnedObject {
  cia402::ObjectId id;
  std::string what;  // "set by the gateway at every boot (start-up write)"
};

class NodeAccess final : public cia402::ObjectAccess {
 public:
  // `owned`: the objects the node's boot writes besides the communication profile's ranges.
  NodeAccess(NodeId node, int sdo_channel, NodePdos& pdos, SdoClient& sdo, const EmcyConsumer& emcy,
             std::vector<OwnedObject> owned = {})
      : node_(node), channel_(sdo_channel), pdos_(pdos), sdo_(sdo), emcy_(emcy), owned_(std::move(owned)) {}

  // Called by the bus at the start of each cycle.
  void begin_cycle(core::TimePoint now, bool operational) noexcept {
    now_ = now;
    operational_ = operational;
  }
  // The node went away or rebooted: every request is forgotten (the SDO channel was reset).
  void forget_requests() noexcept { pending_.fill({}); }
  // The bus is closing: every request is given up (SdoClient::cancel), so a transfer through the
  // profile's buffer is aborted on the wire and frees the channel at once.
  void cancel_requests() noexcept;

  // A reference is the object's index in the node's process image, valid until NodePdos::configure()
  // replaces the image (a reboot with another mapping): the image's generation is the mapping's.
  [[nodiscard]] cia402::ImageRef resolve(cia402::ObjectId id) const noexcept override {
    const std::size_t i = pdos_.image().index_of(id);
    if (i == ProcessImage::kNotFound) return {};
    return cia402::ImageRef::at(static_cast<std::uint16_t>(i), pdos_.image_generation());
  }
  [[nodiscard]] std::uint32_t mapping_generation() const noexcept override { return pdos_.image_generation(); }
  using cia402::ObjectAccess::read;
  using cia402::ObjectAccess::write;
  [[nodiscard]] std::int64_t read(cia402::ImageRef ref) const noexcept override {
    return ref.current(pdos_.image_generation()) ? pdos_.image().get_at(ref.slot()) : 0;
  }
  void write(cia402::ImageRef ref, std::int64_t value) noexcept override {
    if (ref.current(pdos_.image_generation())) pdos_.image().set_at(ref.slot(), value);
  }
  [[nodiscard]] bool inputs_fresh() const noexcept override { return operational_ && pdos_.inputs_fresh(now_); }

  cia402::RequestId submit_read(cia402::ObjectDef def) noexcept override;
  cia402::RequestId submit_write(cia402::ObjectDef def, std::int64_t value) noexcept override;
  cia402::RequestId submit_upload(cia402::ObjectId id, std::span<std::uint8_t> into,
                                  std::uint8_t expected_size) noexcept override;
  cia402::RequestId submit_download(cia402::ObjectId id, std::span<const std::uint8_t> data) noexcept override;
  cia402::RequestResult poll(cia402::RequestId id) noexcept override;
  void cancel(cia402::RequestId id) noexcept override;
  [[nodiscard]] cia402::DriveFaultReport fault_report() const noexcept override;
  [[nodiscard]] std::string_view owner_of(cia402::ObjectId id) const noexcept override;
  void control_lost(std::string_view why) noexcept override;

  // The bus takes a loss the profile reported (once): true and the reason, then cleared.
  bool take_control_lost(core::FixedString<200>& why) noexcept {
    if (!control_lost_) return false;
    control_lost_ = false;
    why = lost_why_;
    return true;
  }

 private:
  struct Pending {
    SdoRequestId id = kNoSdoRequest;
    cia402::DataType type = cia402::DataType::U32;
  };
  Pending* slot_for(SdoRequestId id) noexcept;
  cia402::RequestId track(SdoRequestId id, cia402::DataType type) noexcept;

  NodeId node_;
  int channel_;
  NodePdos& pdos_;
  SdoClient& sdo_;
  const EmcyConsumer& emcy_;
  core::TimePoint now_{};
  bool operational_ = false;
  std::array<Pending, 16> pending_{};
  std::vector<OwnedObject> owned_;
  bool control_lost_ = false;
  core::FixedString<200> lost_why_;
};

}  // namespace drivegate::canopen
