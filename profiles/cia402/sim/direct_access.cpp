#include "profiles/cia402/sim/direct_access.hpp"

#include <algorithm>

namespace drivegate::cia402::sim {

DirectObjectAccess::DirectObjectAccess(DriveModel& drive, std::span<const ObjectId> mapped_objects,
                                       unsigned acyclic_latency_cycles)
    : drive_(drive), latency_(acyclic_latency_cycles) {
  slots_.reserve(mapped_objects.size());
  for (const ObjectId id : mapped_objects) {
    if (std::any_of(slots_.begin(), slots_.end(), [id](const Slot& s) { return s.id == id; })) continue;
    Slot s;
    s.id = id;
    const auto access = drive_.dictionary().access_of(id);
    s.exists = access.has_value();
    s.output = access && *access != Access::ReadOnly;
    mapping_valid_ = mapping_valid_ && s.exists;
    slots_.push_back(s);
  }
  std::sort(slots_.begin(), slots_.end(), [](const Slot& a, const Slot& b) { return a.id.key() < b.id.key(); });
}

ImageRef DirectObjectAccess::resolve(ObjectId id) const noexcept {
  const auto pos = std::lower_bound(slots_.begin(), slots_.end(), id.key(),
                                    [](const Slot& s, std::uint32_t k) { return s.id.key() < k; });
  if (pos == slots_.end() || !(pos->id == id)) return {};
  return ImageRef::at(static_cast<std::uint16_t>(pos - slots_.begin()), 0);
}

std::int64_t DirectObjectAccess::read(ImageRef ref) const noexcept {
  return ref.current(mapping_generation()) && ref.slot() < slots_.size() ? slots_[ref.slot()].input : 0;
}

void DirectObjectAccess::write(ImageRef ref, std::int64_t value) noexcept {
  Slot* s = ref.current(mapping_generation()) && ref.slot() < slots_.size() ? &slots_[ref.slot()] : nullptr;
  if (s == nullptr || !s->output) {
    ++dropped_writes_;
    return;
  }
  s->output_value = value;
  s->written = true;
}

void DirectObjectAccess::begin_cycle() noexcept {
  fresh_ = link_up_;
  if (link_up_) {
    for (Slot& s : slots_) {
      if (!s.exists) continue;
      const ReadResult r = drive_.dictionary().read(s.id);
      if (r.abort_code == abort_code::kNone) s.input = r.value;
    }
  }
  for (Request& r : requests_) {
    if (!r.in_use || r.result.state != RequestState::Pending) continue;
    if (!link_up_) {
      r.result = RequestResult{RequestState::Failed, 0, abort_code::kTimeout, 0, true};
      continue;
    }
    if (r.cycles_left > 0) --r.cycles_left;
    if (r.cycles_left == 0) execute(r);
  }
}

void DirectObjectAccess::end_cycle() noexcept {
  if (!link_up_) return;
  for (const Slot& s : slots_) {
    if (!s.output || !s.written) continue;
    const std::uint32_t code = drive_.write_object(s.id, s.output_value);
    if (code != abort_code::kNone) {
      ++rejected_outputs_;
      last_output_abort_ = code;
    }
  }
}

RequestId DirectObjectAccess::submit_read(ObjectDef def) noexcept { return submit(def, false, 0); }

RequestId DirectObjectAccess::submit_write(ObjectDef def, std::int64_t value) noexcept {
  return submit(def, true, value);
}

RequestId DirectObjectAccess::submit_upload(ObjectId id, std::span<std::uint8_t> into,
                                            std::uint8_t /*expected_size*/) noexcept {
  Request* r = allocate(ObjectDef{id, DataType::U32}, false, 0);
  if (r == nullptr) return kNoRequest;
  r->as_bytes = true;
  r->into = into;
  return start(*r);
}

RequestId DirectObjectAccess::submit_download(ObjectId id, std::span<const std::uint8_t> data) noexcept {
  // Longer than any drive object: refused like a drive would (length too high).
  const bool too_long = data.size() > Request{}.data.size();
  Request* r = allocate(ObjectDef{id, DataType::U32}, true, 0);
  if (r == nullptr) return kNoRequest;
  r->as_bytes = true;
  r->size = too_long ? r->data.size() + 1 : data.size();
  std::copy_n(data.begin(), std::min(data.size(), r->data.size()), r->data.begin());
  return start(*r);
}

RequestId DirectObjectAccess::submit(ObjectDef def, bool is_write, std::int64_t value) noexcept {
  Request* r = allocate(def, is_write, value);
  return r == nullptr ? kNoRequest : start(*r);
}

DirectObjectAccess::Request* DirectObjectAccess::allocate(ObjectDef def, bool is_write, std::int64_t value) noexcept {
  const auto free_slot = std::find_if(requests_.begin(), requests_.end(), [](const Request& r) { return !r.in_use; });
  if (free_slot == requests_.end()) return nullptr;
  Request& r = *free_slot;
  r.in_use = true;
  r.is_write = is_write;
  r.id = next_id_;
  next_id_ = next_id_ == 0xFFFFFFFFU ? 1 : next_id_ + 1;
  r.def = def;
  r.value = value;
  r.cycles_left = latency_;
  r.result = RequestResult{RequestState::Pending, 0, 0, 0, true};
  r.as_bytes = false;
  r.into = {};
  r.size = 0;
  return &r;
}

RequestId DirectObjectAccess::start(Request& r) noexcept {
  if (latency_ == 0) {
    if (link_up_) {
      execute(r);
    } else {
      r.result = RequestResult{RequestState::Failed, 0, abort_code::kTimeout, 0, true};
    }
  }
  return r.id;
}

void DirectObjectAccess::execute(Request& r) noexcept {
  if (r.as_bytes) return execute_bytes(r);
  const auto type = drive_.dictionary().type_of(r.def.id);
  std::uint32_t code = abort_code::kNone;
  std::int64_t value = 0;
  if (!type) {
    code = drive_.dictionary().missing_code(r.def.id);
  } else if (*type != r.def.type) {
    code = abort_code::kTypeMismatch;  // the master's idea of the object disagrees with the drive
  } else if (r.is_write) {
    code = drive_.write_object(r.def.id, r.value);
  } else {
    const ReadResult rr = drive_.read_object(r.def.id);
    code = rr.abort_code;
    value = rr.value;
  }
  r.result = RequestResult{code == abort_code::kNone ? RequestState::Done : RequestState::Failed, value, code, 0, true};
}

void DirectObjectAccess::execute_bytes(Request& r) noexcept {
  const auto type = drive_.dictionary().type_of(r.def.id);
  const auto fail = [&](std::uint32_t code) { r.result = RequestResult{RequestState::Failed, 0, code, 0, true}; };
  if (!type) return fail(drive_.dictionary().missing_code(r.def.id));
  const std::size_t size = size_of(*type);
  if (r.is_write) {
    if (r.size != size) return fail(r.size > size ? abort_code::kTooLong : abort_code::kTooShort);
    std::uint64_t raw = 0;
    for (std::size_t i = size; i-- > 0;) raw = (raw << 8) | r.data[i];
    const std::uint32_t code = drive_.write_object(r.def.id, normalise(*type, static_cast<std::int64_t>(raw)));
    if (code != abort_code::kNone) return fail(code);
    r.result = RequestResult{RequestState::Done, 0, 0, 0, true};
    return;
  }
  const ReadResult rr = drive_.read_object(r.def.id);
  if (rr.abort_code != abort_code::kNone) return fail(rr.abort_code);
  if (size > r.into.size()) return fail(abort_code::kOutOfMemory);
  for (std::size_t i = 0; i < size; ++i) r.into[i] = static_cast<std::uint8_t>(static_cast<std::uint64_t>(rr.value) >> (8 * i));
  r.result = RequestResult{RequestState::Done, 0, 0, static_cast<std::uint32_t>(size), true};
}

RequestResult DirectObjectAccess::poll(RequestId id) noexcept {
  if (id == kNoRequest) return {};
  for (Request& r : requests_) {
    if (!r.in_use || r.id != id) continue;
    const RequestResult result = r.result;
    if (result.state != RequestState::Pending) r.in_use = false;  // reported once
    return result;
  }
  return {};
}

void DirectObjectAccess::cancel(RequestId id) noexcept {
  if (id == kNoRequest) return;
  for (Request& r : requests_) {
    if (r.in_use && r.id == id) r.in_use = false;
  }
}

std::size_t DirectObjectAccess::requests_in_use() const noexcept {
  return static_cast<std::size_t>(std::count_if(requests_.begin(), requests_.end(), [](const Request& r) { return r.in_use; }));
}

}  // namespace drivegate::cia402::sim
