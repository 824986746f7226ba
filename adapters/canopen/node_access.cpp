#include "adapters/canopen/node_access.hpp"

namespace drivegate::canopen {

NodeAccess::Pending* NodeAccess::slot_for(SdoRequestId id) noexcept {
  for (auto& p : pending_)
    if (p.id == id) return &p;
  return nullptr;
}

cia402::RequestId NodeAccess::track(SdoRequestId id, cia402::DataType type) noexcept {
  if (id == kNoSdoRequest) return cia402::kNoRequest;
  Pending* free = slot_for(kNoSdoRequest);
  if (!free) {  // cannot happen while submit_* check for a free slot first
    sdo_.cancel(id);
    return cia402::kNoRequest;
  }
  *free = {id, type};
  return id;
}

cia402::RequestId NodeAccess::submit_read(cia402::ObjectDef def) noexcept {
  if (!operational_ || !slot_for(kNoSdoRequest)) return cia402::kNoRequest;
  return track(sdo_.read(channel_, def.id, cia402::size_of(def.type)), def.type);
}

cia402::RequestId NodeAccess::submit_write(cia402::ObjectDef def, std::int64_t value) noexcept {
  if (!operational_ || !slot_for(kNoSdoRequest)) return cia402::kNoRequest;
  return track(sdo_.write(channel_, def.id, static_cast<std::uint32_t>(value & 0xFFFFFFFF), cia402::size_of(def.type)),
               def.type);
}

cia402::RequestResult NodeAccess::poll(cia402::RequestId id) noexcept {
  Pending* p = id == cia402::kNoRequest ? nullptr : slot_for(id);
  if (!p) return {cia402::RequestState::Unknown, 0, 0};
  const SdoResult r = sdo_.result(id);
  switch (r.status) {
    case SdoStatus::Queued:
    case SdoStatus::InFlight: return {cia402::RequestState::Pending, 0, 0};
    case SdoStatus::Done: {
      const auto type = p->type;
      sdo_.take(id);
      *p = {};
      return {cia402::RequestState::Done, cia402::normalise(type, r.value), 0};
    }
    case SdoStatus::Failed:
      sdo_.take(id);
      *p = {};
      return {cia402::RequestState::Failed, 0, r.abort_code};
    case SdoStatus::Unknown: break;
  }
  *p = {};
  return {cia402::RequestState::Unknown, 0, 0};
}

void NodeAccess::cancel(cia402::RequestId id) noexcept {
  Pending* p = id == cia402::kNoRequest ? nullptr : slot_for(id);
  if (!p) return;
  sdo_.cancel(id);
  *p = {};
}

cia402::DriveFaultReport NodeAccess::fault_report() const noexcept {
  const EmcyReport* r = emcy_.active(node_);
  if (!r) return {};
  return {true, r->emcy.code, r->text.view()};
}

}  // namespace drivegate::canopen
