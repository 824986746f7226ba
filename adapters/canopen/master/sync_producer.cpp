// SYNC producer: deadlines on a fixed grid start + k * period, so the drives' PLLs see a period
// without drift (AKD part 1 §7: the drive locks to SYNC within a ±70 us window; §16 step 9).
#include "adapters/canopen/master/nmt_master.hpp"
#include "adapters/canopen/wire/cob_id.hpp"

namespace drivegate::canopen {

void SyncProducer::start(core::TimePoint now) noexcept {
  if (period_ <= core::Duration::zero()) return;  // no period, no SYNC
  running_ = true;
  next_ = now;  // the first SYNC goes out at the first poll
}

void SyncProducer::stop() noexcept { running_ = false; }

bool SyncProducer::poll(core::TimePoint now, TxQueue& tx) noexcept {
  if (!running_ || now < next_) return false;
  // Grid points passed over while the caller was late are not caught up: a burst of SYNCs would
  // make the drives apply several set-points at once. One goes out, the rest are counted.
  const auto late = (now - next_) / period_;
  skipped_ += static_cast<std::uint64_t>(late);
  next_ += (late + 1) * period_;
  // The reference drives use no SYNC counter: DLC 0 (SD6 digest §6.1, AKD part 1 §7).
  CanFrame sync;
  sync.id = cob_id_ & cob::kIdMask;  // a 1005h value may carry the generate flag in bit 30
  if (!tx.push(sync)) {
    ++skipped_;  // refused by a full queue: lost like one the caller was too late for
    return false;
  }
  ++sent_;
  return true;
}

core::TimePoint SyncProducer::next_deadline() const noexcept {
  return running_ ? next_ : core::TimePoint::max();
}

}  // namespace drivegate::canopen
