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

cia402::RequestId NodeAccess::submit_upload(cia402::ObjectId id, std::span<std::uint8_t> into,
                                            std::uint8_t expected_size) noexcept {
  if (!operational_ || !slot_for(kNoSdoRequest)) return cia402::kNoRequest;
  return track(sdo_.read_into(channel_, id, into, expected_size), cia402::DataType::U32);
}

cia402::RequestId NodeAccess::submit_download(cia402::ObjectId id, std::span<const std::uint8_t> data) noexcept {
  if (!operational_ || !slot_for(kNoSdoRequest)) return cia402::kNoRequest;
  return track(sdo_.write_from(channel_, id, data), cia402::DataType::U32);
}

cia402::RequestResult NodeAccess::poll(cia402::RequestId id) noexcept {
  Pending* p = id == cia402::kNoRequest ? nullptr : slot_for(id);
  if (!p) return {};
  const SdoResult r = sdo_.result(id);
  switch (r.status) {
    case SdoStatus::Queued:
    case SdoStatus::InFlight: return {cia402::RequestState::Pending, 0, 0, 0, true};
    case SdoStatus::Done: {
      const auto type = p->type;
      sdo_.take(id);
      *p = {};
      return {cia402::RequestState::Done, cia402::normalise(type, r.value), 0, r.size, r.size_indicated};
    }
    case SdoStatus::Failed:
      sdo_.take(id);
      *p = {};
      return {cia402::RequestState::Failed, 0, r.abort_code, 0, true};
    case SdoStatus::Unknown: break;
  }
  *p = {};
  return {};
}

void NodeAccess::cancel(cia402::RequestId id) noexcept {
  Pending* p = id == cia402::kNoRequest ? nullptr : slot_for(id);
  if (!p) return;
  sdo_.cancel(id);
  *p = {};
}

void NodeAccess::cancel_requests() noexcept {
  for (auto& p : pending_) {
    if (p.id != kNoSdoRequest) sdo_.cancel(p.id);
    p = {};
  }
}

cia402::DriveFaultReport NodeAccess::fault_report() const noexcept {
  const EmcyReport* r = emcy_.active(node_);
  if (!r) return {};
  return {true, r->emcy.code, r->text.view()};
}

// The communication profile's objects the gateway configures and relies on [CiA 301 §7.5]. Unused
// PDOs count too: the gateway disabled them, and enabling one would put frames on the bus that
// nothing planned for.
std::string_view NodeAccess::owner_of(cia402::ObjectId id) const noexcept {
  const auto in = [&](unsigned lo, unsigned hi) { return id.index >= lo && id.index <= hi; };
  if (id.index == 0x1005 || id.index == 0x1006 || id.index == 0x1007)
    return "owned by the CANopen bus (SYNC)";
  if (id.index == 0x100C || id.index == 0x100D)
    return "owned by the CANopen bus (node guarding)";
  if (id.index == 0x1014) return "owned by the CANopen bus (EMCY COB-ID)";
  if (id.index == 0x1016) return "owned by the CANopen bus (heartbeat consumer)";
  if (id.index == 0x1017) return "owned by the CANopen bus (heartbeat producer)";
  if (in(0x1200, 0x12FF)) return "owned by the CANopen bus (SDO channel)";
  if (in(0x1400, 0x15FF)) return "owned by the CANopen bus (RPDO communication parameter)";
  if (in(0x1600, 0x17FF)) return "owned by the CANopen bus (RPDO mapping)";
  if (in(0x1800, 0x19FF)) return "owned by the CANopen bus (TPDO communication parameter)";
  if (in(0x1A00, 0x1BFF)) return "owned by the CANopen bus (TPDO mapping)";
  for (const auto& o : owned_)
    if (o.id.index == id.index && o.id.sub == id.sub) return o.what;
  return {};
}

void NodeAccess::control_lost(std::string_view why) noexcept {
  control_lost_ = true;
  lost_why_.assign(why);
}

}  // namespace drivegate::canopen
