#include "profiles/profidrive/fault_buffer.hpp"

#include <algorithm>

namespace drivegate::profidrive {

FaultSnapshot fault_snapshot(std::uint16_t counter_before, std::span<const std::uint16_t> pnu947,
                             std::uint16_t counter_after) noexcept {
  FaultSnapshot s;
  s.consistent = counter_before == counter_after;
  s.counter = counter_after;
  const std::size_t n = std::min(pnu947.size(), kFaultBufferEntries);
  for (std::size_t i = 0; i < n; ++i) {
    if (pnu947[i] == 0) continue;
    FaultSituation& sit = s.situations[i / kFaultsPerSituation];
    sit.faults[sit.count++] = pnu947[i];
  }
  return s;
}

std::optional<std::size_t> u16_values(const ValueBlock& block, std::span<std::uint16_t> out) noexcept {
  if (block.format != format::kWord && block.format != format::kUnsigned16 && block.format != format::kInteger16)
    return std::nullopt;
  const std::size_t n = std::min<std::size_t>(block.count, out.size());
  for (std::size_t i = 0; i < n; ++i) out[i] = static_cast<std::uint16_t>(block.value(i));
  return n;
}

FaultBufferReader::FaultBufferReader(std::uint8_t entries, std::uint8_t max_attempts) noexcept
    : entries_(static_cast<std::uint8_t>(std::clamp<std::size_t>(entries, 1, kFaultBufferEntries))),
      max_attempts_(max_attempts == 0 ? std::uint8_t{1} : max_attempts) {}

std::optional<ParamAddress> FaultBufferReader::next_read() const noexcept {
  if (status_ != Status::Reading) return std::nullopt;
  if (step_ == Step::Buffer) return ParamAddress{Attribute::Value, entries_, kPnuFaultNumbers, 0};
  return ParamAddress{Attribute::Value, 1, kPnuFaultCounter, 0};
}

void FaultBufferReader::on_values(std::span<const std::uint16_t> values) noexcept {
  if (status_ != Status::Reading) return;
  switch (step_) {
    case Step::CounterBefore:
      if (values.size() != 1) {
        status_ = Status::Failed;
        return;
      }
      before_ = values[0];
      step_ = Step::Buffer;
      return;
    case Step::Buffer:
      if (values.size() != entries_) {
        status_ = Status::Failed;
        return;
      }
      std::copy(values.begin(), values.end(), buffer_.begin());
      buffer_count_ = entries_;
      ++attempts_;
      step_ = Step::CounterAfter;
      return;
    case Step::CounterAfter: {
      if (values.size() != 1) {
        status_ = Status::Failed;
        return;
      }
      snapshot_ = fault_snapshot(before_, std::span<const std::uint16_t>(buffer_).first(buffer_count_), values[0]);
      if (snapshot_.consistent) {
        status_ = Status::Consistent;
      } else if (attempts_ >= max_attempts_) {
        status_ = Status::Inconsistent;
      } else {
        before_ = values[0];  // the counter just read is the "before" of the next buffer read
        step_ = Step::Buffer;
      }
      return;
    }
  }
}

}  // namespace drivegate::profidrive
