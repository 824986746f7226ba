// EMCY producer: see emcy_producer.hpp.
#include "adapters/canopen/sim/emcy_producer.hpp"

#include <chrono>

#include "adapters/canopen/wire/can_frame.hpp"

namespace drivegate::canopen::sim {

EmcyProducer::EmcyProducer(EmcyProducerConfig config) noexcept : config_(config), inhibit_(config.inhibit_time) {}

bool EmcyProducer::raise(const Emcy& emcy) noexcept {
  ++counters_.raised;
  if (!enabled_ || config_.node == 0) {
    ++counters_.suppressed;
    return false;
  }
  if (count_ == kQueueCapacity) {
    ++counters_.dropped;
    return false;
  }
  queue_[(head_ + count_) % kQueueCapacity] = emcy;
  ++count_;
  return true;
}

void EmcyProducer::set_enabled(bool enabled) noexcept {
  enabled_ = enabled;
  if (!enabled) count_ = 0;
}

void EmcyProducer::set_inhibit_time(std::uint16_t units_100us) noexcept { inhibit_ = units_100us; }

void EmcyProducer::reset() noexcept {
  inhibit_ = config_.inhibit_time;
  count_ = 0;
  sent_any_ = false;
}

core::TimePoint EmcyProducer::earliest_send() const noexcept {
  if (!sent_any_) return core::TimePoint::min();
  return last_sent_ + std::chrono::microseconds(100) * inhibit_;
}

void EmcyProducer::poll(core::TimePoint now, TxQueue& tx) noexcept {
  while (count_ > 0 && now >= earliest_send()) {
    if (!tx.push(make_frame(cob::emcy(config_.node), encode_emcy(queue_[head_])))) {
      ++counters_.tx_full;
      return;
    }
    head_ = (head_ + 1) % kQueueCapacity;
    --count_;
    ++counters_.sent;
    sent_any_ = true;
    last_sent_ = now;
  }
}

core::TimePoint EmcyProducer::next_deadline() const noexcept {
  return count_ == 0 ? core::TimePoint::max() : earliest_send();
}

}  // namespace drivegate::canopen::sim
