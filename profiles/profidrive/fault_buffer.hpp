#pragma once
// Reading the fault buffer consistently [akd-profinet-profidrive.md §18.2, §24 step 12]: PNU 944
// (fault message counter, U16), then PNU 947 (fault numbers: 8 fault situations x 8 entries, U16,
// subindex 0..7 the current situation [STD]), then PNU 944 again. The snapshot is consistent when
// both counter reads agree: no new fault situation arrived while the buffer was read.
// Sans-I/O: FaultBufferReader says which parameter to read next and takes the values read; the
// caller sends the requests over record 47 (param_access.hpp). No allocation.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

#include "profiles/profidrive/param_access.hpp"

namespace drivegate::profidrive {

inline constexpr std::uint16_t kPnuFaultCounter = 944;
inline constexpr std::uint16_t kPnuFaultNumbers = 947;
inline constexpr std::size_t kFaultSituations = 8;
inline constexpr std::size_t kFaultsPerSituation = 8;
inline constexpr std::size_t kFaultBufferEntries = kFaultSituations * kFaultsPerSituation;  // 64

struct FaultSituation {
  std::array<std::uint16_t, kFaultsPerSituation> faults{};  // the non-zero entries, in order
  std::uint8_t count = 0;
  [[nodiscard]] std::span<const std::uint16_t> numbers() const noexcept {
    return std::span<const std::uint16_t>(faults).first(count);
  }
};

struct FaultSnapshot {
  bool consistent = false;    // counter before == counter after
  std::uint16_t counter = 0;  // PNU 944 (the second read)
  // situations[0] is the current (not yet acknowledged) one; acknowledged situations move up by
  // one, 8 entries at a time [§18.2]. Empty situations have count 0.
  std::array<FaultSituation, kFaultSituations> situations{};
  [[nodiscard]] std::span<const std::uint16_t> current() const noexcept { return situations[0].numbers(); }
};

// The snapshot from the three reads. `pnu947` holds the entries from subindex 0 (up to 64; extra
// entries are ignored); 0 entries are empty slots.
FaultSnapshot fault_snapshot(std::uint16_t counter_before, std::span<const std::uint16_t> pnu947,
                             std::uint16_t counter_after) noexcept;

// U16 values of a value block (formats 42h, 06h, 03h), at most out.size(); nullopt for other formats.
std::optional<std::size_t> u16_values(const ValueBlock& block, std::span<std::uint16_t> out) noexcept;

// Drives the 944 -> 947 -> 944 sequence. When the counters differ, the buffer and the counter are
// read again (the second counter becomes the new "before"), up to `max_attempts` buffer reads.
class FaultBufferReader {
 public:
  enum class Status : std::uint8_t { Reading, Consistent, Inconsistent, Failed };

  explicit FaultBufferReader(std::uint8_t entries = kFaultBufferEntries, std::uint8_t max_attempts = 3) noexcept;

  // The parameter to read now; nullopt once the status is no longer Reading.
  [[nodiscard]] std::optional<ParamAddress> next_read() const noexcept;
  // The values of the positive answer to next_read().
  void on_values(std::span<const std::uint16_t> values) noexcept;
  // The read failed (negative response, timeout): the snapshot is not available.
  void on_failed() noexcept { status_ = Status::Failed; }

  [[nodiscard]] Status status() const noexcept { return status_; }
  [[nodiscard]] std::uint8_t attempts() const noexcept { return attempts_; }
  // Meaningful once the status is Consistent (or Inconsistent: the last attempt's data).
  [[nodiscard]] const FaultSnapshot& snapshot() const noexcept { return snapshot_; }

 private:
  enum class Step : std::uint8_t { CounterBefore, Buffer, CounterAfter };
  std::uint8_t entries_;
  std::uint8_t max_attempts_;
  std::uint8_t attempts_ = 0;
  Step step_ = Step::CounterBefore;
  Status status_ = Status::Reading;
  std::uint16_t before_ = 0;
  std::array<std::uint16_t, kFaultBufferEntries> buffer_{};
  std::uint8_t buffer_count_ = 0;
  FaultSnapshot snapshot_;
};

}  // namespace drivegate::profidrive
