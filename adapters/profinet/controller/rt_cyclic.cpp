#include "adapters/profinet/controller/rt_cyclic.hpp"

#include <algorithm>
#include <bit>

namespace drivegate::profinet {

namespace {

constexpr std::uint16_t kMaxSendClockFactor = 128;
constexpr std::uint16_t kMaxReductionRatio = 512;
constexpr std::uint16_t kMaxDataHoldFactor = 7680;  // 1E00h [IEC 61158-6-10, DataHoldFactor]

double ms(core::Duration d) noexcept { return static_cast<double>(d.count()) / 1e6; }

// Shared by both engines: validates the config and lays out its CR.
RtConfigError lay_out(const RtIocrConfig& c, CrDirection direction, CsduLayout& layout,
                      std::array<IoPlacement, kMaxRtSubmodules>& placements, std::size_t& count) noexcept {
  const RtConfigError e = validate(c);
  if (e != RtConfigError::None) return e;
  count = c.submodules.size();
  layout = compute_csdu_layout(direction, c.submodules, std::span(placements).first(count));
  return e;
}

}  // namespace

std::string_view to_string(RtConfigError e) noexcept {
  switch (e) {
    case RtConfigError::None: return "ok";
    case RtConfigError::BadFrameId: return "FrameID is not RT class 1 (8000h-FBFFh)";
    case RtConfigError::BadSendClock: return "SendClockFactor outside 1..128";
    case RtConfigError::BadReductionRatio: return "ReductionRatio is not a power of two in 1..512";
    case RtConfigError::BadPhase: return "Phase outside 1..ReductionRatio";
    case RtConfigError::BadDataHold: return "DataHoldFactor outside 1..7680";
    case RtConfigError::TooManySubmodules: return "more submodules than one AR's cyclic data holds (64)";
    case RtConfigError::DataTooLong: return "one CR's IO data needs more than 1440 octets";
    case RtConfigError::BadSubmodule: return "a submodule has a data length for a direction its kind does not have";
  }
  return "unknown";
}

RtConfigError validate(const RtIocrConfig& c) noexcept {
  if (classify_frame_id(c.frame_id) != FrameClass::RtCyclic) return RtConfigError::BadFrameId;
  if (c.send_clock_factor < 1 || c.send_clock_factor > kMaxSendClockFactor) return RtConfigError::BadSendClock;
  if (c.reduction_ratio > kMaxReductionRatio || !std::has_single_bit(c.reduction_ratio)) {
    return RtConfigError::BadReductionRatio;
  }
  if (c.phase < 1 || c.phase > c.reduction_ratio) return RtConfigError::BadPhase;
  if (c.data_hold_factor < 1 || c.data_hold_factor > kMaxDataHoldFactor) return RtConfigError::BadDataHold;
  if (c.submodules.size() > kMaxRtSubmodules) return RtConfigError::TooManySubmodules;
  std::array<IoPlacement, kMaxRtSubmodules> scratch{};
  for (const CrDirection d : {CrDirection::Input, CrDirection::Output}) {
    switch (compute_csdu_layout(d, c.submodules, std::span(scratch).first(c.submodules.size())).error) {
      case LayoutError::None: break;
      case LayoutError::TooLong: return RtConfigError::DataTooLong;
      case LayoutError::TooFewPlacements:  // cannot happen: the scratch array holds them all
      case LayoutError::BadSubmodule: return RtConfigError::BadSubmodule;
    }
  }
  return RtConfigError::None;
}

// ---- RtProvider -----------------------------------------------------------------------------------

RtProvider::RtProvider(const RtIocrConfig& config, RtSide side) noexcept
    : period_(rt_period(config)), offset_(kSendClockUnit * config.send_clock_factor * (config.phase - 1)) {
  const bool controller = side == RtSide::Controller;
  // In the body: the layout members are initialised after error_.
  error_ = lay_out(config, controller ? CrDirection::Output : CrDirection::Input, layout_, placements_,
                   submodule_count_);
  if (!ok()) return;
  EthernetHeader h;
  h.dst = controller ? config.device_mac : config.controller_mac;
  h.src = controller ? config.controller_mac : config.device_mac;
  h.vlan = true;
  h.priority = kPriorityRtCyclic;
  h.frame_id = config.frame_id;
  pdu_offset_ = encode_ethernet_header(h, frame_);
  frame_size_ = pdu_offset_ + layout_.length + kApduStatusSize;  // over 60: the C_SDU is at least 40
  for (std::size_t i = 0; i < submodule_count_; ++i) {
    (void)set_iops(i, controller ? iox_status::kBadByController : iox_status::kBadByDevice);
    (void)set_iocs(i, iox_status::kGood);
  }
}

std::span<std::uint8_t> RtProvider::data(std::size_t i) noexcept {
  if (i >= submodule_count_ || placements_[i].data_offset == kNoOffset) return {};
  return std::span(frame_).subspan(pdu_offset_ + placements_[i].data_offset, placements_[i].data_length);
}

bool RtProvider::set_iops(std::size_t i, std::uint8_t iops) noexcept {
  if (i >= submodule_count_ || placements_[i].iops_offset == kNoOffset) return false;
  frame_[pdu_offset_ + placements_[i].iops_offset] = iops;
  return true;
}

bool RtProvider::set_iocs(std::size_t i, std::uint8_t iocs) noexcept {
  if (i >= submodule_count_ || placements_[i].iocs_offset == kNoOffset) return false;
  frame_[pdu_offset_ + placements_[i].iocs_offset] = iocs;
  return true;
}

void RtProvider::start(core::TimePoint start) noexcept {
  if (!ok()) return;
  running_ = true;
  next_ = start + offset_;
}

core::TimePoint RtProvider::next_deadline() const noexcept { return running_ ? next_ : core::TimePoint::max(); }

std::size_t RtProvider::poll(core::TimePoint now, std::span<std::uint8_t> out) noexcept {
  if (!running_ || now < next_) return 0;
  const auto late = (now - next_) / period_;  // whole periods behind: slots that passed unsent
  counters_.missed_slots += static_cast<std::uint64_t>(late);
  const core::TimePoint slot = next_ + period_ * late;
  next_ = slot + period_;
  if (out.size() < frame_size_) {
    ++counters_.tx_too_small;
    return 0;
  }
  ApduStatus s;
  s.cycle_counter = cycle_counter_at(static_cast<std::uint64_t>(core::to_ns(slot)));
  s.data_status = run_ ? data_status::kGood : static_cast<std::uint8_t>(data_status::kGood & ~data_status::kProviderRun);
  encode_apdu_status(s, std::span(frame_).subspan(pdu_offset_ + layout_.length).first<kApduStatusSize>());
  std::copy_n(frame_.begin(), frame_size_, out.begin());
  ++counters_.frames_sent;
  return frame_size_;
}

// ---- RtConsumer -----------------------------------------------------------------------------------

std::string_view to_string(RtConsumerState s) noexcept {
  switch (s) {
    case RtConsumerState::Idle: return "idle";
    case RtConsumerState::Waiting: return "waiting for the first frame";
    case RtConsumerState::Running: return "running";
    case RtConsumerState::Timeout: return "data hold timeout";
  }
  return "unknown";
}

RtConsumer::RtConsumer(const RtIocrConfig& config, RtSide side) noexcept
    : side_(side),
      frame_id_(config.frame_id),
      peer_mac_(side == RtSide::Controller ? config.device_mac : config.controller_mac),
      data_hold_(rt_data_hold_time(config)) {
  error_ = lay_out(config, side == RtSide::Controller ? CrDirection::Input : CrDirection::Output, layout_,
                   placements_, submodule_count_);
}

void RtConsumer::arm(core::TimePoint now) noexcept {
  if (!ok()) return;
  state_ = RtConsumerState::Waiting;
  last_valid_ = now;
  has_last_ = false;
  status_ = ApduStatus{};
  c_sdu_.fill(0);
  reason_.assign("");
}

core::TimePoint RtConsumer::next_deadline() const noexcept {
  const bool watching = state_ == RtConsumerState::Waiting || state_ == RtConsumerState::Running;
  return watching ? last_valid_ + data_hold_ : core::TimePoint::max();
}

void RtConsumer::expire(core::TimePoint now) noexcept {
  ++counters_.timeouts;
  const double hold = ms(data_hold_);
  const bool controller = side_ == RtSide::Controller;
  const char* cr = controller ? "input" : "output";
  if (state_ == RtConsumerState::Waiting) {
    reason_.format("no %s frame 0x%04X from the %s within the data hold time (%g ms)", cr, frame_id_,
                   controller ? "device" : "controller", hold);
  } else {
    reason_.format("%s frame 0x%04X silent for %g ms (data hold time %g ms); last valid cycle counter %u", cr,
                   frame_id_, ms(now - last_valid_), hold, static_cast<unsigned>(last_cycle_));
  }
  state_ = RtConsumerState::Timeout;
}

bool RtConsumer::poll(core::TimePoint now) noexcept {
  if (now < next_deadline()) return false;
  expire(now);
  return true;
}

bool RtConsumer::on_frame(std::span<const std::uint8_t> frame, core::TimePoint now) noexcept {
  const EthernetView e = decode_ethernet(frame);
  if (!e.ok()) {
    ++counters_.malformed;
    return false;
  }
  if (e.frame_class != FrameClass::RtCyclic) return false;
  if (e.header.frame_id != frame_id_) {
    ++counters_.wrong_frame_id;
    return false;
  }
  if (e.header.src != peer_mac_) {
    ++counters_.wrong_source;
    return true;
  }
  (void)poll(now);  // a frame at or after the deadline comes too late
  if (state_ == RtConsumerState::Idle || state_ == RtConsumerState::Timeout) {
    ++counters_.inactive;
    return true;
  }
  const RtInputCheck c = check_input_frame(e.header.frame_id, e.pdu, frame_id_, layout_.length, has_last_, last_cycle_);
  switch (c.result) {
    case RtCheck::WrongFrameId: break;  // checked above
    case RtCheck::Truncated: ++counters_.truncated; return true;
    case RtCheck::TransferError: ++counters_.transfer_error; return true;
    case RtCheck::RepeatedCycle: ++counters_.repeated_cycle; return true;
    case RtCheck::OldCycle: ++counters_.old_cycle; return true;
    case RtCheck::Ignore: ++counters_.ignore; break;
    case RtCheck::DataInvalid: ++counters_.data_invalid; break;
    case RtCheck::Backup: ++counters_.backup; break;
    case RtCheck::ProviderStop: ++counters_.provider_stop; break;
    case RtCheck::Ok: break;
  }
  // A new frame: later ones are judged against its cycle counter.
  has_last_ = true;
  last_cycle_ = c.frame.status.cycle_counter;
  if (c.result == RtCheck::Ignore || c.result == RtCheck::DataInvalid) return true;
  last_valid_ = now;
  state_ = RtConsumerState::Running;
  if (c.result == RtCheck::Backup) return true;
  ++counters_.frames;
  if (c.station_problem) ++counters_.station_problem;
  status_ = c.frame.status;
  std::copy(c.frame.c_sdu.begin(), c.frame.c_sdu.end(), c_sdu_.begin());
  return true;
}

std::span<const std::uint8_t> RtConsumer::data(std::size_t i) const noexcept {
  if (i >= submodule_count_ || placements_[i].data_offset == kNoOffset) return {};
  return std::span(c_sdu_).subspan(placements_[i].data_offset, placements_[i].data_length);
}

std::uint8_t RtConsumer::iops(std::size_t i) const noexcept {
  if (i >= submodule_count_ || placements_[i].iops_offset == kNoOffset) return iox_status::kBadBySubslot;
  return c_sdu_[placements_[i].iops_offset];
}

std::uint8_t RtConsumer::iocs(std::size_t i) const noexcept {
  if (i >= submodule_count_ || placements_[i].iocs_offset == kNoOffset) return iox_status::kBadBySubslot;
  return c_sdu_[placements_[i].iocs_offset];
}

bool RtConsumer::all_iops_good() const noexcept {
  for (std::size_t i = 0; i < submodule_count_; ++i) {
    if (placements_[i].iops_offset != kNoOffset && !iox_status::is_good(c_sdu_[placements_[i].iops_offset])) {
      return false;
    }
  }
  return true;
}

}  // namespace drivegate::profinet
