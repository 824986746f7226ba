#pragma once
// The CiA 402 profile's view of one CANopen node (profiles/cia402/object_access.hpp): mapped
// objects live in the node's PDO process image, everything else goes through the node's SDO
// channel, and faults the drive announced by EMCY are handed to the profile with their text.
// Requests are refused (the profile retries next cycle) while the node is not operational, so the
// profile never competes with the boot sequence for the SDO channel.
#include <array>
#include <cstdint>

#include "adapters/canopen/master/emcy_consumer.hpp"
#include "adapters/canopen/master/pdo.hpp"
#include "adapters/canopen/master/sdo_client.hpp"
#include "profiles/cia402/object_access.hpp"

namespace drivegate::canopen {

class NodeAccess final : public cia402::ObjectAccess {
 public:
  NodeAccess(NodeId node, int sdo_channel, NodePdos& pdos, SdoClient& sdo, const EmcyConsumer& emcy) noexcept
      : node_(node), channel_(sdo_channel), pdos_(pdos), sdo_(sdo), emcy_(emcy) {}

  // Called by the bus at the start of each cycle.
  void begin_cycle(core::TimePoint now, bool operational) noexcept {
    now_ = now;
    operational_ = operational;
  }
  // The node went away or rebooted: every request is forgotten (the SDO channel was reset).
  void forget_requests() noexcept { pending_.fill({}); }

  [[nodiscard]] bool mapped(cia402::ObjectId id) const noexcept override { return pdos_.image().contains(id); }
  [[nodiscard]] std::int64_t read(cia402::ObjectId id) const noexcept override { return pdos_.image().get(id); }
  void write(cia402::ObjectId id, std::int64_t value) noexcept override { pdos_.image().set(id, value); }
  [[nodiscard]] bool inputs_fresh() const noexcept override { return operational_ && pdos_.inputs_fresh(now_); }

  cia402::RequestId submit_read(cia402::ObjectDef def) noexcept override;
  cia402::RequestId submit_write(cia402::ObjectDef def, std::int64_t value) noexcept override;
  cia402::RequestResult poll(cia402::RequestId id) noexcept override;
  void cancel(cia402::RequestId id) noexcept override;
  [[nodiscard]] cia402::DriveFaultReport fault_report() const noexcept override;

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
};

}  // namespace drivegate::canopen
