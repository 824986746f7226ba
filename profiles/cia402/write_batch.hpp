#pragma once
// A handful of object writes that must all have landed before a handshake goes on (e.g. pp target,
// velocity and ramps before new set-point bit 4 rises). Mapped objects go into the process image at
// once; the others become acyclic requests, re-submitted while the adapter's queue is full.
// Requests still in flight when the batch is cleared or fails are cancelled, so that an abandoned
// batch never keeps the adapter's request slots. Fixed capacity: no heap.
#include <array>
#include <cstddef>
#include <cstdint>

#include "profiles/cia402/object_access.hpp"

namespace drivegate::cia402 {

class WriteBatch {
 public:
  static constexpr std::size_t kCapacity = 8;
  enum class Status : std::uint8_t { Pending, Done, Failed };

  // Forget the batch, cancelling its requests in flight.
  void clear(ObjectAccess& io) noexcept;
  // False when the batch is full (a programming error: the master never stages more than 6).
  bool add(ObjectDef def, std::int64_t value) noexcept;
  // Advance all writes; Done once every one of them is Done.
  Status run(ObjectAccess& io) noexcept;

  // The write that failed, after run() returned Failed.
  [[nodiscard]] ObjectDef failed_object() const noexcept { return failed_.def; }
  [[nodiscard]] std::int64_t failed_value() const noexcept { return failed_.value; }
  [[nodiscard]] std::uint32_t failed_abort() const noexcept { return failed_abort_; }
  // The first write not done yet, while run() returns Pending (for a timeout message).
  [[nodiscard]] ObjectDef pending_object() const noexcept;
  [[nodiscard]] std::int64_t pending_value() const noexcept;

 private:
  struct Entry {
    ObjectDef def{};
    std::int64_t value = 0;
    RequestId request = kNoRequest;
    bool done = false;
  };
  [[nodiscard]] const Entry* first_pending() const noexcept;

  std::array<Entry, kCapacity> entries_{};
  std::size_t count_ = 0;
  Entry failed_{};
  std::uint32_t failed_abort_ = 0;
};

}  // namespace drivegate::cia402
