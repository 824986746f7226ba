#pragma once
// The slave side of EMCY [CiA 301 §7.2.7]: the owner (a simulated drive) raises an EMCY for each
// fault it enters or leaves (code, error register, five vendor bytes: SD6 E82/E43 in bytes 3/4,
// stoeber-sd6-canopen.md §6.9; AKD category in byte 3, part 1 §9.1); the producer sends them on
// 080h+n in order, no two closer than the inhibit time 1015h (100 us units), holding up to
// kQueueCapacity waiting frames.
//
// EMCY is served only in Pre-operational and Operational (SD6 §6.7): the owner passes
// NmtSlave::serves(NmtService::Emcy) to set_enabled(). With node-ID 0 EMCY is off for good, so
// that it cannot collide with SYNC on 080h (SD6 §6.9).
#include <array>
#include <cstddef>
#include <cstdint>

#include "adapters/canopen/master/tx_queue.hpp"
#include "adapters/canopen/wire/cob_id.hpp"
#include "adapters/canopen/wire/emcy_codec.hpp"
#include "core/clock.hpp"

namespace drivegate::canopen::sim {

struct EmcyProducerConfig {
  NodeId node = 1;
  std::uint16_t inhibit_time = 0;  // 1015h power-on value, 100 us units; 0 = none
};

struct EmcyProducerCounters {
  std::uint64_t raised = 0;
  std::uint64_t sent = 0;
  std::uint64_t dropped = 0;     // queue full: the EMCY is lost (the fault itself stays in 1001h/603Fh)
  std::uint64_t suppressed = 0;  // raised while EMCY is not served (NMT state, node-ID 0)
  std::uint64_t tx_full = 0;     // TxQueue refused; retried at the next poll
};

class EmcyProducer {
 public:
  static constexpr std::size_t kQueueCapacity = 8;

  explicit EmcyProducer(EmcyProducerConfig config) noexcept;

  // Queue one EMCY; false when it is suppressed or the queue is full (both counted).
  bool raise(const Emcy& emcy) noexcept;
  // Whether the NMT state serves EMCY now; turning it off discards the queue, since a stopped
  // node does not send stale EMCYs when it is started again.
  void set_enabled(bool enabled) noexcept;
  void set_inhibit_time(std::uint16_t units_100us) noexcept;  // 1015h written by the SDO server
  [[nodiscard]] std::uint16_t inhibit_time() const noexcept { return inhibit_; }
  // Reset Node / Reset Communication: 1015h back to its power-on value, nothing waiting.
  void reset() noexcept;

  void poll(core::TimePoint now, TxQueue& tx) noexcept;
  [[nodiscard]] core::TimePoint next_deadline() const noexcept;

  [[nodiscard]] std::size_t pending() const noexcept { return count_; }
  [[nodiscard]] const EmcyProducerCounters& counters() const noexcept { return counters_; }

 private:
  [[nodiscard]] core::TimePoint earliest_send() const noexcept;

  EmcyProducerConfig config_;
  std::uint16_t inhibit_ = 0;
  bool enabled_ = false;
  bool sent_any_ = false;
  core::TimePoint last_sent_{};
  std::array<Emcy, kQueueCapacity> queue_{};
  std::size_t head_ = 0;
  std::size_t count_ = 0;
  EmcyProducerCounters counters_;
};

}  // namespace drivegate::canopen::sim
