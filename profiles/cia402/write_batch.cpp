#include "profiles/cia402/write_batch.hpp"

namespace drivegate::cia402 {

void WriteBatch::clear(ObjectAccess& io) noexcept {
  for (std::size_t i = 0; i < count_; ++i) {
    if (!entries_[i].done) io.cancel(entries_[i].request);
  }
  count_ = 0;
}

const WriteBatch::Entry* WriteBatch::first_pending() const noexcept {
  for (std::size_t i = 0; i < count_; ++i) {
    if (!entries_[i].done) return &entries_[i];
  }
  return nullptr;
}

ObjectDef WriteBatch::pending_object() const noexcept {
  const Entry* e = first_pending();
  return e != nullptr ? e->def : ObjectDef{};
}

std::int64_t WriteBatch::pending_value() const noexcept {
  const Entry* e = first_pending();
  return e != nullptr ? e->value : 0;
}

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
      e.request = kNoRequest;  // already reported: nothing to cancel
      e.done = true;
      clear(io);  // the other writes are moot now
      return Status::Failed;
    } else {
      all_done = false;
    }
  }
  return all_done ? Status::Done : Status::Pending;
}

}  // namespace drivegate::cia402
