#include "profiles/cia402/write_batch.hpp"

namespace drivegate::cia402 {

bool WriteBatch::add(ObjectDef def, std::int64_t value) noexcept {
  if (count_ == kCapacity) return false;
  entries_[count_++] = Entry{def, value, kNoRequest, false};
  return true;
}

WriteBatch::Status WriteBatch::run(ObjectAccess& io) noexcept {
  bool all_done = true;
  for (std::size_t i = 0; i < count_; ++i) {
    Entry& e = entries_[i];
    if (e.done) continue;
    if (io.mapped(e.def.id)) {
      io.write(e.def.id, e.value);
      e.done = true;
      continue;
    }
    if (e.request == kNoRequest) {
      e.request = io.submit_write(e.def, e.value);  // kNoRequest: queue full, try next cycle
      all_done = false;
      continue;
    }
    const RequestResult r = io.poll(e.request);
    if (r.state == RequestState::Done) {
      e.done = true;
    } else if (r.state == RequestState::Failed || r.state == RequestState::Unknown) {
      failed_ = e;
      failed_abort_ = r.abort_code;
      count_ = 0;
      return Status::Failed;
    } else {
      all_done = false;
    }
  }
  return all_done ? Status::Done : Status::Pending;
}

}  // namespace drivegate::cia402
