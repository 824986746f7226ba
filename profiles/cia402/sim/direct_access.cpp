#include "profiles/cia402/sim/direct_access.hpp"

#include <algorithm>
#include <utility>

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

const DirectObjectAccess::Slot* DirectObjectAccess::find(ObjectId id) const noexcept {
  const auto pos = std::lower_bound(slots_.begin(), slots_.end(), id.key(),
                                    [](const Slot& s, std::uint32_t k) { return s.id.key() < k; });
  return (pos != slots_.end() && pos->id == id) ? &*pos : nullptr;
}

DirectObjectAccess::Slot* DirectObjectAccess::find(ObjectId id) noexcept {
  return const_cast<Slot*>(std::as_const(*this).find(id));
}

bool DirectObjectAccess::mapped(ObjectId id) const noexcept { return find(id) != nullptr; }

std::int64_t DirectObjectAccess::read(ObjectId id) const noexcept {
  const Slot* s = find(id);
  return s != nullptr ? s->input : 0;
}

void DirectObjectAccess::write(ObjectId id, std::int64_t value) noexcept {
  Slot* s = find(id);
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
      r.result = RequestResult{RequestState::Failed, 0, abort_code::kTimeout};
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

RequestId DirectObjectAccess::submit(ObjectDef def, bool is_write, std::int64_t value) noexcept {
  const auto free_slot = std::find_if(requests_.begin(), requests_.end(), [](const Request& r) { return !r.in_use; });
  if (free_slot == requests_.end()) return kNoRequest;
  Request& r = *free_slot;
  r.in_use = true;
  r.is_write = is_write;
  r.id = next_id_;
  next_id_ = next_id_ == 0xFFFFFFFFU ? 1 : next_id_ + 1;
  r.def = def;
  r.value = value;
  r.cycles_left = latency_;
  r.result = RequestResult{RequestState::Pending, 0, 0};
  if (latency_ == 0) {
    if (link_up_) {
      execute(r);
    } else {
      r.result = RequestResult{RequestState::Failed, 0, abort_code::kTimeout};
    }
  }
  return r.id;
}

void DirectObjectAccess::execute(Request& r) noexcept {
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
  r.result = RequestResult{code == abort_code::kNone ? RequestState::Done : RequestState::Failed, value, code};
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
