#include "adapters/profinet/sim/pn_device.hpp"

#include <algorithm>

#include "adapters/profinet/wire/blocks_submodule.hpp"
#include "adapters/profinet/wire/byte_order.hpp"

namespace drivegate::profinet {

namespace {

// Refusals of a Connect the device cannot run. ErrorCode2 numbers the faulty field in the block's
// field order [IEC 61158-6-10, PNIOStatus ErrorCode2 for the connect blocks]: IOCRBlockReq 8
// DataLength, 10 SendClockFactor, 11 ReductionRatio, 12 Phase, 16 DataHoldFactor, 24 the
// IODataObject / IOCS FrameOffset; ExpectedSubmoduleBlockReq 14 SubmoduleDataLength.
constexpr PnioStatus connect_error(std::uint8_t code1, std::uint8_t code2) noexcept {
  return {pnio_error_code::kConnect, pnio_error_decode::kPnio, code1, code2};
}
constexpr std::uint8_t kFieldDataLength = 8;
constexpr std::uint8_t kFieldReductionRatio = 11;
constexpr std::uint8_t kFieldFrameOffset = 24;
constexpr std::uint8_t kFieldSubmoduleDataLength = 14;
// AlarmCRBlockReq: 7 RTATimeoutFactor, 8 RTARetries.
constexpr std::uint8_t kFieldRtaTimeoutFactor = 7;
constexpr std::uint8_t kFieldRtaRetries = 8;

std::uint8_t iocr_field(RtConfigError e) noexcept {
  switch (e) {
    case RtConfigError::BadSendClock: return 10;
    case RtConfigError::BadReductionRatio: return kFieldReductionRatio;
    case RtConfigError::BadPhase: return 12;
    case RtConfigError::BadDataHold: return 16;
    case RtConfigError::BadFrameId: return 9;
    case RtConfigError::None:
    case RtConfigError::TooManySubmodules:
    case RtConfigError::DataTooLong:
    case RtConfigError::BadSubmodule: break;
  }
  return kFieldDataLength;
}

IoKind kind_of(SubmoduleType t) noexcept {
  switch (t) {
    case SubmoduleType::NoIo: return IoKind::NoIo;
    case SubmoduleType::Input: return IoKind::Input;
    case SubmoduleType::Output: return IoKind::Output;
    case SubmoduleType::InputOutput: return IoKind::InputOutput;
  }
  return IoKind::NoIo;
}

}  // namespace

PnDevice::PnDevice(const PnDeviceConfig& config, PnPersona& persona)
    : config_(config), persona_(persona), dcp_(config.dcp) {
  cm_.emplace(cm_config(), static_cast<CmServerApp&>(*this));
}

CmServerConfig PnDevice::cm_config() const noexcept {
  CmServerConfig c;
  c.object = {config_.dcp.instance_low, config_.dcp.device_id, config_.dcp.vendor_id};
  c.mac = config_.dcp.mac;
  c.activity = config_.activity;
  c.slots = persona_.slots();
  c.rpc = config_.rpc;
  c.boot_time = boot_time_;
  return c;
}

std::uint32_t PnDevice::ip() const noexcept { return get_be32(dcp_.ip().address, 0); }

// ---- frames and datagrams -------------------------------------------------------------------------

bool PnDevice::on_frame(std::span<const std::uint8_t> frame, core::TimePoint now) noexcept {
  if (!powered_) {
    ++counters_.rx_powered_off;
    return false;
  }
  // The AR's engines exist together (from the Connect to the AR's end).
  if (consumer_ && alarms_) {
    const EthernetView e = decode_ethernet(frame);
    if (e.ok() && e.frame_class == FrameClass::RtCyclic) {
      if (lose_rx_ > 0) {
        --lose_rx_;
        ++counters_.rx_lost;
        return true;
      }
      return consumer_->on_frame(frame, now);
    }
    if (e.ok() && (e.frame_class == FrameClass::AlarmHigh || e.frame_class == FrameClass::AlarmLow)) {
      return alarms_->on_frame(frame, now);
    }
  }
  return dcp_.on_frame(frame, now);
}

void PnDevice::on_datagram(std::span<const std::uint8_t> datagram, const UdpEndpoint& from, CmSocket socket,
                           core::TimePoint now, CmOutbox& out) noexcept {
  if (!powered_) {
    ++counters_.rx_powered_off;
    return;
  }
  now_ = now;
  cm_->on_datagram(datagram, from, socket, now, out);
}

std::size_t PnDevice::poll(core::TimePoint now, std::span<std::uint8_t> frame, CmOutbox& out) noexcept {
  if (!powered_) return 0;
  now_ = now;
  cm_->poll(now, out);
  // The watchdog expires here or in on_frame() (a frame at the deadline is late).
  if (consumer_ && (consumer_->poll(now) || consumer_->state() == RtConsumerState::Timeout)) {
    ++counters_.watchdog_aborts;
    core::FixedString<200> why;
    why.format("output CR watchdog: %.*s", static_cast<int>(consumer_->reason().size()), consumer_->reason().data());
    cm_->abort_ar(why.view());
  }
  // An alarm CR that aborted (its ERR-RTA-PDU went out with the previous poll) ends the AR.
  if (alarms_ && alarms_->state() == AlarmSenderState::Aborted) {
    ++counters_.alarm_cr_aborts;
    core::FixedString<200> why;
    why.format("alarm CR: %.*s", static_cast<int>(alarms_->reason().size()), alarms_->reason().data());
    cm_->abort_ar(why.view());
  }
  if (const std::size_t n = dcp_.poll(now, frame)) return n;
  if (alarms_) {
    if (const std::size_t n = alarms_->poll(now, frame)) return n;
  }
  if (provider_) {
    if (now < provider_->next_deadline()) return 0;
    run_cycle(provider_->period());
    const std::size_t n = provider_->poll(now, frame);
    if (n > 0 && lose_tx_ > 0) {
      --lose_tx_;
      ++counters_.tx_lost;
      return 0;
    }
    return n;
  }
  if (!idle_started_) {
    idle_started_ = true;
    idle_next_ = now;
  }
  if (now >= idle_next_) {
    persona_.cycle(config_.idle_period, {});
    idle_next_ += config_.idle_period * (1 + (now - idle_next_) / config_.idle_period);
  }
  return 0;
}

core::TimePoint PnDevice::next_deadline() const noexcept {
  if (!powered_) return core::TimePoint::max();
  core::TimePoint t = std::min(dcp_.next_deadline(), cm_->next_deadline());
  if (consumer_) t = std::min(t, consumer_->next_deadline());
  if (alarms_) t = std::min(t, alarms_->next_deadline());
  if (provider_) return std::min(t, provider_->next_deadline());
  return std::min(t, idle_started_ ? idle_next_ : core::TimePoint::min());
}

void PnDevice::run_cycle(core::Duration dt) noexcept {
  ++counters_.cycles;
  const RtConsumerState state = consumer_->state();
  for (std::size_t i = 0; i < submodule_count_; ++i) {
    PnSubmoduleIo& s = io_[i];
    if (state == RtConsumerState::Waiting) {
      s.outputs = PnOutputs::NotYet;
    } else if (state != RtConsumerState::Running) {
      s.outputs = PnOutputs::Lost;
    } else {
      const bool good = consumer_->provider_run() && (s.output.empty() || iox_status::is_good(consumer_->iops(i)));
      s.outputs = good ? PnOutputs::Valid : PnOutputs::Stop;
    }
  }
  persona_.cycle(dt, std::span<const PnSubmoduleIo>(io_).first(submodule_count_));
}

// ---- the AR ---------------------------------------------------------------------------------------

PnioStatus PnDevice::on_connect(const CmArSetup& setup) noexcept {
  // A modular device plugs what the controller expects where it can; then the lengths must fit.
  for (std::size_t b = 0; b < setup.request.expected_count; ++b) {
    ExpectedSubmoduleReader reader(setup.request.expected[b]);
    ExpectedEntry e;
    while (reader.next(e)) {
      if (e.has_submodule) persona_.fit(e.api, e.slot, e.module_ident, e.submodule.subslot, e.submodule.ident);
    }
  }
  // The alarm CR's transport values, before anything is set up [IEC 61158-6-10, AlarmCRBlockReq].
  const AlarmCrBlockReq& alarm_cr = setup.request.alarm_cr.block;
  PnioStatus s;
  switch (validate_alarm_cr(alarm_cr)) {
    case AlarmCrError::None: s = set_up_cyclic(setup); break;
    case AlarmCrError::BadTimeoutFactor: s = connect_error(pnio_error_code1::kAlarmCrBlockReq, kFieldRtaTimeoutFactor); break;
    case AlarmCrError::BadRetries: s = connect_error(pnio_error_code1::kAlarmCrBlockReq, kFieldRtaRetries); break;
  }
  if (!s.ok()) {
    ++counters_.connects_refused;
    return s;
  }
  alarms_.emplace(AlarmSenderConfig{config_.dcp.mac, setup.request.ar.block.initiator_mac, alarm_cr, kDeviceAlarmReference});
  alarms_->open();
  return s;
}

PnioStatus PnDevice::set_up_cyclic(const CmArSetup& setup) noexcept {
  stop_ar_engines();
  const std::span<const CmModelSlot> model = persona_.slots();
  auto matches = [&model](const ExpectedEntry& e) {
    const auto slot = std::find_if(model.begin(), model.end(), [&e](const CmModelSlot& m) {
      return m.api == e.api && m.slot == e.slot && m.module_ident == e.module_ident;
    });
    return slot != model.end() && std::any_of(slot->submodules.begin(), slot->submodules.end(), [&e](const CmModelSubmodule& m) {
             return m.subslot == e.submodule.subslot && m.ident == e.submodule.ident;
           });
  };
  std::size_t n = 0;
  for (std::size_t b = 0; b < setup.request.expected_count; ++b) {
    ExpectedSubmoduleReader reader(setup.request.expected[b]);
    ExpectedEntry e;
    while (reader.next(e)) {
      if (!e.has_submodule) continue;
      if (n == kMaxRtSubmodules) return connect_error(pnio_error_code1::kIocrBlockReq, kFieldDataLength);
      const ExpectedSubmodule& m = e.submodule;
      const IoKind kind = kind_of(m.type());
      const bool in = kind != IoKind::Output;
      const bool out = kind == IoKind::Output || kind == IoKind::InputOutput;
      submodules_[n] = {kind, in ? m.input.length : std::uint16_t{0}, out ? m.output.length : std::uint16_t{0}};
      proper_[n] = matches(e);
      if (proper_[n]) {
        const PnPersona::IoLengths l = persona_.lengths(e.api, e.slot, m.subslot);
        if (l.input != submodules_[n].input_length || l.output != submodules_[n].output_length) {
          return connect_error(pnio_error_code1::kExpectedSubmoduleBlockReq, kFieldSubmoduleDataLength);
        }
      }
      io_[n] = {e.api, e.slot, m.subslot, {}, PnOutputs::Lost, {}};
      ++n;
    }
  }
  RtIocrConfig in;
  in.frame_id = setup.input_frame_id;
  in.controller_mac = setup.request.ar.block.initiator_mac;
  in.device_mac = config_.dcp.mac;
  in.send_clock_factor = setup.input.params.send_clock_factor;
  in.reduction_ratio = setup.input.params.reduction_ratio;
  in.phase = setup.input.params.phase;
  in.data_hold_factor = setup.input.params.data_hold_factor;
  in.submodules = std::span<const IoSubmodule>(submodules_).first(n);
  RtIocrConfig out = in;
  out.frame_id = setup.output_frame_id;
  out.send_clock_factor = setup.output.params.send_clock_factor;
  out.reduction_ratio = setup.output.params.reduction_ratio;
  out.phase = setup.output.params.phase;
  out.data_hold_factor = setup.output.params.data_hold_factor;
  for (const RtIocrConfig* c : {&in, &out}) {
    const RtConfigError e = validate(*c);
    if (e != RtConfigError::None) return connect_error(pnio_error_code1::kIocrBlockReq, iocr_field(e));
    if (rt_period(*c) < persona_.min_update_time()) return connect_error(pnio_error_code1::kIocrBlockReq, kFieldReductionRatio);
  }
  provider_.emplace(in, RtSide::Device);
  consumer_.emplace(out, RtSide::Device);
  std::uint8_t field = iocr_mismatch(setup.input, provider_->placements());
  if (field == 0) field = iocr_mismatch(setup.output, consumer_->placements());
  if (field != 0) {
    stop_ar_engines();
    return connect_error(pnio_error_code1::kIocrBlockReq, field);
  }
  submodule_count_ = n;
  for (std::size_t i = 0; i < n; ++i) {
    if (!proper_[i]) continue;
    io_[i].input = provider_->data(i);
    io_[i].output = consumer_->data(i);
  }
  provider_->start(now_);
  consumer_->arm(now_);
  persona_.on_ar_start(consumer_->data_hold_time());
  return {};
}

std::uint8_t PnDevice::iocr_mismatch(const IocrBlockReqView& v, std::span<const IoPlacement> placements) const noexcept {
  std::uint16_t used = 0;
  for (const IoPlacement& q : placements) {
    if (q.data_offset != kNoOffset) used = std::max<std::uint16_t>(used, static_cast<std::uint16_t>(q.data_offset + q.data_length));
    for (const std::uint16_t at : {q.iops_offset, q.iocs_offset}) {
      if (at != kNoOffset) used = std::max<std::uint16_t>(used, static_cast<std::uint16_t>(at + 1));
    }
  }
  if (v.params.data_length != std::max(used, kMinCsduLength)) return kFieldDataLength;
  IocrEntryReader r(v);
  IocrEntry e;
  std::size_t entries = 0;
  while (r.next(e)) {
    ++entries;
    const auto it = std::find_if(io_.begin(), io_.begin() + static_cast<std::ptrdiff_t>(placements.size()),
                                 [&e](const PnSubmoduleIo& s) {
                                   return s.api == e.api && s.slot == e.ref.slot && s.subslot == e.ref.subslot;
                                 });
    if (it == io_.begin() + static_cast<std::ptrdiff_t>(placements.size())) return kFieldFrameOffset;
    const IoPlacement& q = placements[static_cast<std::size_t>(it - io_.begin())];
    if (e.ref.frame_offset != (e.iocs ? q.iocs_offset : q.data_offset)) return kFieldFrameOffset;
  }
  // Every object the layout has must be in the IOCR (a data object per provided submodule, an
  // IOCS per consumed one).
  std::size_t expected = 0;
  for (const IoPlacement& q : placements) expected += (q.iops_offset != kNoOffset ? 1U : 0U) + (q.iocs_offset != kNoOffset ? 1U : 0U);
  return entries == expected ? 0 : kFieldFrameOffset;
}

void PnDevice::stop_ar_engines() noexcept {
  provider_.reset();
  consumer_.reset();
  alarms_.reset();
  submodule_count_ = 0;
}

PnioStatus PnDevice::on_record_write(const RecordReqHeader& h, std::span<const std::uint8_t> data) noexcept {
  return persona_.write_record(h, data);
}

PnioStatus PnDevice::on_record_read(const RecordReqHeader& h, std::span<std::uint8_t> into, std::size_t& length) noexcept {
  return persona_.read_record(h, into, length);
}

void PnDevice::on_ar_state(CmServerState state, std::string_view) noexcept {
  switch (state) {
    case CmServerState::NoAr:
      stop_ar_engines();
      dcp_.set_in_operation(false);
      break;
    case CmServerState::Parameterising: dcp_.set_in_operation(true); break;
    case CmServerState::ApplicationReady: break;
    case CmServerState::DataExchange:
      for (std::size_t i = 0; i < submodule_count_; ++i) {
        if (proper_[i]) (void)provider_->set_iops(i, iox_status::kGood);
      }
      break;
  }
}

void PnDevice::abort_ar(std::string_view why) noexcept { cm_->abort_ar(why); }

void PnDevice::power_loss() noexcept {
  powered_ = false;
  stop_ar_engines();
}

void PnDevice::power_return(core::TimePoint now) noexcept {
  if (powered_) return;
  powered_ = true;
  dcp_.power_cycle();
  dcp_.set_in_operation(false);
  persona_.power_cycle();
  ++boot_time_;
  cm_.emplace(cm_config(), static_cast<CmServerApp&>(*this));
  idle_started_ = true;
  idle_next_ = now;
}

}  // namespace drivegate::profinet
