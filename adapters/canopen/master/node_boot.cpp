#include "adapters/canopen/master/node_boot.hpp"

#include "profiles/cia402/sdo_abort.hpp"

namespace drivegate::canopen {
namespace {

bool missing_object(std::uint32_t code) noexcept {
  return code == cia402::sdo_abort_code::kNoObject || code == cia402::sdo_abort_code::kNoSubIndex;
}

}  // namespace

NodeBoot::NodeBoot(int sdo_channel, std::vector<BootStep> steps) : channel_(sdo_channel), steps_(std::move(steps)) {}

void NodeBoot::start() noexcept {
  status_ = steps_.empty() ? Status::Done : Status::Running;
  next_ = 0;
  found_ = 0;
  refusal_ = 0;
  request_ = kNoSdoRequest;
  failure_.assign("");
}

void NodeBoot::abandon(SdoClient& sdo) noexcept {
  if (request_ != kNoSdoRequest) sdo.cancel(request_);
  request_ = kNoSdoRequest;
  status_ = Status::Idle;
}

void NodeBoot::fail_abort(const BootStep& s, std::uint32_t code) noexcept {
  status_ = Status::Failed;
  if (s.kind == BootStep::Kind::Write)
    failure_.format("%s: write %04Xh:%02X := 0x%llX failed: %s (abort 0x%08X)%s%s", s.stage.c_str(), s.def.id.index,
                    s.def.id.sub, static_cast<unsigned long long>(s.value) & 0xFFFFFFFFULL,
                    cia402::sdo_abort_text(code).data(), code, s.why.empty() ? "" : "; ", s.why.c_str());
  else
    failure_.format("%s: read %04Xh:%02X failed: %s (abort 0x%08X)", s.stage.c_str(), s.def.id.index, s.def.id.sub,
                    cia402::sdo_abort_text(code).data(), code);
}

NodeBoot::Status NodeBoot::step(SdoClient& sdo, ProcessImage& image) noexcept {
  // Running means next_ < steps_.size(): start() and the end of every step see to it.
  if (status_ != Status::Running) return status_;
  const BootStep& s = steps_[next_];
  const auto advance = [&] {
    ++next_;
    return status_ = next_ >= steps_.size() ? Status::Done : Status::Running;
  };
  // A step for a drive without what it needs (or with what makes it unnecessary) is skipped.
  if ((found_ & s.if_found) != s.if_found || (found_ & s.if_missing) != 0) return advance();
  if (s.kind == BootStep::Kind::Fail) {
    status_ = Status::Failed;
    if (refusal_ != 0)
      failure_.format("%s: %s (abort 0x%08X)", s.stage.c_str(), s.why.c_str(), refusal_);
    else
      failure_.format("%s: %s", s.stage.c_str(), s.why.c_str());
    return status_;
  }
  const auto size = cia402::size_of(s.def.type);
  if (request_ == kNoSdoRequest) {
    request_ = s.kind == BootStep::Kind::Write
                   ? sdo.write(channel_, s.def.id, static_cast<std::uint32_t>(s.value & 0xFFFFFFFF), size)
                   : sdo.read(channel_, s.def.id, size);
    return status_;  // queue full: kNoSdoRequest, tried again next step()
  }
  const SdoResult r = sdo.result(request_);
  if (r.status == SdoStatus::Queued || r.status == SdoStatus::InFlight) return status_;
  sdo.take(request_);
  request_ = kNoSdoRequest;
  if (r.status == SdoStatus::Unknown) {  // dropped by a channel reset: try the step again
    return status_;
  }
  if (r.status == SdoStatus::Failed) {
    // A seed the drive cannot answer leaves the image value as it is (0 at first).
    const bool missing = missing_object(r.abort_code);
    if (s.kind == BootStep::Kind::Write && s.refused != 0 && r.abort_code != cia402::sdo_abort_code::kTimeout) {
      found_ = static_cast<std::uint8_t>((found_ & ~s.refused) | s.sets);
      refusal_ = r.abort_code;
    } else if (s.kind != BootStep::Kind::Seed && !(s.kind == BootStep::Kind::Probe && missing) &&
               !(s.optional && missing)) {
      fail_abort(s, r.abort_code);
      return status_;
    }
  } else if (s.kind == BootStep::Kind::Probe) {
    found_ = static_cast<std::uint8_t>(found_ | s.sets);
  } else if (s.kind == BootStep::Kind::Seed) {
    image.set(s.def.id, r.value);  // set() takes it to the object's type
  } else if (s.kind == BootStep::Kind::Expect) {
    const auto got = static_cast<std::uint32_t>(cia402::normalise(s.def.type, r.value) & 0xFFFFFFFF);
    const auto want = static_cast<std::uint32_t>(s.value & 0xFFFFFFFF);
    if ((got & s.mask) != (want & s.mask)) {
      status_ = Status::Failed;
      failure_.format("%s: %04Xh:%02X reads 0x%08X, expected 0x%08X%s%s%s", s.stage.c_str(), s.def.id.index,
                      s.def.id.sub, got, want, s.mask != 0xFFFFFFFF ? " (compared under a mask)" : "",
                      s.why.empty() ? "" : "; ", s.why.c_str());
      return status_;
    }
  }
  return advance();
}

}  // namespace drivegate::canopen
