#pragma once
// ObjectAccess for a master and a DriveModel in the same process, as the in-process sim bus uses
// it. Per bus cycle: begin_cycle() (inputs snapshot, acyclic requests that are due complete), the
// master reads/writes/submits/polls, end_cycle() (outputs reach the drive), then drive.step().
//
// The process image holds the mapped objects. Writable ones (RW/WO in the drive's dictionary) are
// outputs: once the master has written one, end_cycle() sends its latest value every cycle, like
// an RPDO. Every mapped object is read back in the snapshot (inputs, and outputs as the drive
// holds them). Acyclic requests behave like SDO: they complete `acyclic_latency_cycles` cycles
// after submission with the drive's abort code, or with 0x05040000 (timeout) while the link is
// down. A cancelled request frees its slot at once; if it was not due yet it never reaches the
// drive. No allocation after construction.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "profiles/cia402/object_access.hpp"
#include "profiles/cia402/sim/drive_model.hpp"

namespace drivegate::cia402::sim {

class DirectObjectAccess final : public ObjectAccess {
 public:
  static constexpr std::size_t kMaxRequests = 16;

  DirectObjectAccess(DriveModel& drive, std::span<const ObjectId> mapped_objects, unsigned acyclic_latency_cycles = 1);

  void begin_cycle() noexcept;
  void end_cycle() noexcept;
  // Link loss: inputs go stale, outputs are not delivered, requests fail with a timeout.
  void set_link_up(bool up) noexcept { link_up_ = up; }

  // References are indexes into the mapped objects, fixed at construction (the generation never
  // changes).
  [[nodiscard]] ImageRef resolve(ObjectId id) const noexcept override;
  [[nodiscard]] std::uint32_t mapping_generation() const noexcept override { return 0; }
  using ObjectAccess::read;
  using ObjectAccess::write;
  [[nodiscard]] std::int64_t read(ImageRef ref) const noexcept override;
  void write(ImageRef ref, std::int64_t value) noexcept override;
  [[nodiscard]] bool inputs_fresh() const noexcept override { return fresh_; }
  RequestId submit_read(ObjectDef def) noexcept override;
  RequestId submit_write(ObjectDef def, std::int64_t value) noexcept override;
  // Byte-level requests see a drive object as the little-endian bytes of its type.
  RequestId submit_upload(ObjectId id, std::span<std::uint8_t> into, std::uint8_t expected_size) noexcept override;
  RequestId submit_download(ObjectId id, std::span<const std::uint8_t> data) noexcept override;
  RequestResult poll(RequestId id) noexcept override;
  void cancel(RequestId id) noexcept override;

  // Requests submitted and neither reported nor cancelled yet (leak checks in tests).
  [[nodiscard]] std::size_t requests_in_use() const noexcept;

  // False when a mapped object does not exist in the drive (a real drive would refuse the map).
  [[nodiscard]] bool mapping_valid() const noexcept { return mapping_valid_; }
  // Counted drops: writes to objects that are not mapped outputs, and outputs the drive refused
  // (e.g. out of range); the abort code of the latest refusal.
  [[nodiscard]] std::uint32_t dropped_writes() const noexcept { return dropped_writes_; }
  [[nodiscard]] std::uint32_t rejected_outputs() const noexcept { return rejected_outputs_; }
  [[nodiscard]] std::uint32_t last_output_abort() const noexcept { return last_output_abort_; }

 private:
  struct Slot {
    ObjectId id;
    bool exists = false;
    bool output = false;
    bool written = false;
    std::int64_t input = 0;
    std::int64_t output_value = 0;
  };
  struct Request {
    bool in_use = false;
    bool is_write = false;
    RequestId id = kNoRequest;
    ObjectDef def{};
    std::int64_t value = 0;
    unsigned cycles_left = 0;
    RequestResult result{};
    bool as_bytes = false;            // submit_upload / submit_download
    std::span<std::uint8_t> into{};   // upload destination
    std::array<std::uint8_t, 8> data{};  // download bytes (no drive object is longer)
    std::size_t size = 0;
  };

  RequestId submit(ObjectDef def, bool is_write, std::int64_t value) noexcept;
  Request* allocate(ObjectDef def, bool is_write, std::int64_t value) noexcept;
  RequestId start(Request& r) noexcept;  // completes at once when the latency is 0
  void execute(Request& r) noexcept;
  void execute_bytes(Request& r) noexcept;

  DriveModel& drive_;
  std::vector<Slot> slots_;  // sorted by key
  std::array<Request, kMaxRequests> requests_{};
  unsigned latency_;
  RequestId next_id_ = 1;
  bool link_up_ = true;
  bool fresh_ = false;
  bool mapping_valid_ = true;
  std::uint32_t dropped_writes_ = 0;
  std::uint32_t rejected_outputs_ = 0;
  std::uint32_t last_output_abort_ = 0;
};

}  // namespace drivegate::cia402::sim
