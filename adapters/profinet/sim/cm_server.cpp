#include "adapters/profinet/sim/cm_server.hpp"

#include <algorithm>

#include "adapters/profinet/wire/rpc_calls.hpp"

namespace drivegate::profinet {

std::string_view to_string(CmServerState s) noexcept {
  switch (s) {
    case CmServerState::NoAr: return "NoAr";
    case CmServerState::Parameterising: return "Parameterising";
    case CmServerState::ApplicationReady: return "ApplicationReady";
    case CmServerState::DataExchange: return "DataExchange";
  }
  return "unknown";
}

namespace {

constexpr PnioStatus pnio(std::uint8_t code, std::uint8_t code1, std::uint8_t code2) noexcept {
  return {code, pnio_error_decode::kPnio, code1, code2};
}
// CMRPC "AR UUID unknown" for the call's ErrorCode.
constexpr PnioStatus ar_unknown(std::uint8_t code) noexcept { return pnio(code, pnio_error_code1::kCmrpc, 5); }

constexpr std::uint16_t submodule_ident_state(std::uint8_t ident_info) noexcept {
  return static_cast<std::uint16_t>(submodule_state::kFormatIndicator | (ident_info << 11));
}

int len(std::string_view s) noexcept { return static_cast<int>(s.size()); }

}  // namespace

CmServer::CmServer(const CmServerConfig& config, CmServerApp& app) noexcept
    : config_(config), app_(app), responder_(config_.boot_time, counters_.rpc), ready_call_(config_.rpc, counters_.rpc) {}

void CmServer::set_state(CmServerState s, std::string_view why) noexcept {
  state_ = s;
  app_.on_ar_state(s, why);
}

void CmServer::abort(std::string_view why) noexcept {
  ++counters_.aborts;
  abort_reason_.assign(why);
  ready_call_.cancel();
  ar_ = {};
  set_state(CmServerState::NoAr, why);
}

void CmServer::abort_ar(std::string_view why) noexcept {
  if (state_ != CmServerState::NoAr) abort(why);
}

void CmServer::poll(core::TimePoint now, CmOutbox& out) noexcept {
  if (ready_call_.poll(now, out) == RpcCall::Event::Failed) abort(ready_call_.failure());
}

void CmServer::on_datagram(std::span<const std::uint8_t> datagram, const UdpEndpoint& from, CmSocket socket,
                           core::TimePoint now, CmOutbox& out) noexcept {
  ++counters_.rpc.datagrams_in;
  const RpcView rpc = decode_rpc(datagram);
  if (rpc.error != WireError::None) {
    ++counters_.rpc.malformed;
    return;
  }
  if (socket == CmSocket::Client) {
    switch (ready_call_.on_datagram(rpc, now, out)) {
      case RpcCall::Event::Response: on_ready_response(datagram); break;
      case RpcCall::Event::Failed: abort(ready_call_.failure()); break;
      case RpcCall::Event::None: break;
    }
    return;
  }
  switch (static_cast<PacketType>(rpc.header.packet_type)) {
    case PacketType::Ping: responder_.on_ping(rpc.header, from, CmSocket::Server, out); return;
    case PacketType::Request: on_request(datagram, from, now, out); return;
    default: ++counters_.rpc.unexpected; return;
  }
}

void CmServer::on_request(std::span<const std::uint8_t> datagram, const UdpEndpoint& from, core::TimePoint now,
                          CmOutbox& out) noexcept {
  const PnioRequestView r = decode_pnio_request(datagram);
  const RpcHeader& h = r.header;
  const bool fragment = (h.flags1 & rpc_flag1::kFragment) != 0;
  const bool foreign = r.error == WireError::UnexpectedInterface || h.interface != kPnioDeviceInterface;
  const bool bad_op = r.error == WireError::UnexpectedOpnum || h.opnum == static_cast<std::uint16_t>(Opnum::ReadImplicit);
  if (!fragment && !foreign && !bad_op && r.error != WireError::None) {
    ++counters_.rpc.malformed;
    return;
  }
  if (responder_.on_request(h, from, CmSocket::Server, out) != RpcResponder::Verdict::New) return;
  if (fragment || foreign || bad_op) {
    responder_.reject(fragment  ? nca_status::kProtoError
                      : foreign ? nca_status::kUnknownInterface
                                : nca_status::kOpRangeError,
                      out);
    return;
  }
  switch (static_cast<Opnum>(h.opnum)) {
    case Opnum::Connect: on_connect(datagram, from, out); return;
    case Opnum::Read:
    case Opnum::Write: on_record(h, r.ndr, out); return;
    case Opnum::Control:
    case Opnum::Release: on_control(h, r.ndr, now, out); return;
    case Opnum::ReadImplicit: return;
  }
}

const CmModelSlot* CmServer::find_slot(std::uint32_t api, std::uint16_t slot) const noexcept {
  for (const CmModelSlot& s : config_.slots) {
    if (s.api == api && s.slot == slot) return &s;
  }
  return nullptr;
}

bool CmServer::has_subslot(std::uint32_t api, std::uint16_t slot, std::uint16_t subslot) const noexcept {
  const CmModelSlot* s = find_slot(api, slot);
  if (s == nullptr) return false;
  return std::any_of(s->submodules.begin(), s->submodules.end(),
                     [subslot](const CmModelSubmodule& m) { return m.subslot == subslot; });
}

void CmServer::compare(const ConnectRequestView& c) noexcept {
  diff_module_count_ = diff_submodule_count_ = diff_api_count_ = 0;
  for (std::size_t b = 0; b < c.expected_count; ++b) {
    ExpectedSubmoduleReader reader(c.expected[b]);
    ExpectedEntry e;
    bool in_slot = false;
    std::uint32_t api = 0;
    std::uint16_t slot = 0;
    const CmModelSlot* model = nullptr;
    ModuleDiffModule* module = nullptr;  // this slot's entry in the diff, once it has one
    std::size_t first_sub = 0;
    while (reader.next(e)) {
      if (!in_slot || e.api != api || e.slot != slot) {
        in_slot = true;
        api = e.api;
        slot = e.slot;
        model = find_slot(api, slot);
        module = nullptr;
        if ((model == nullptr || model->module_ident != e.module_ident) && diff_module_count_ < kMaxDiffModules) {
          module = &diff_modules_[diff_module_count_];
          *module = {slot, model == nullptr ? 0 : model->module_ident,
                     model == nullptr ? ModuleState::NoModule : ModuleState::WrongModule, {}};
          diff_module_api_[diff_module_count_++] = api;
        }
      }
      // A wrong or missing module says it all; the submodules are compared in proper modules.
      if (model == nullptr || model->module_ident != e.module_ident || !e.has_submodule) continue;
      const auto sub = std::find_if(model->submodules.begin(), model->submodules.end(),
                                    [&e](const CmModelSubmodule& m) { return m.subslot == e.submodule.subslot; });
      if (sub != model->submodules.end() && sub->ident == e.submodule.ident) continue;
      if (diff_submodule_count_ == kMaxDiffSubmodules) continue;
      if (module == nullptr) {
        if (diff_module_count_ == kMaxDiffModules) continue;
        module = &diff_modules_[diff_module_count_];
        *module = {slot, model->module_ident, ModuleState::ProperModule, {}};
        diff_module_api_[diff_module_count_++] = api;
        first_sub = diff_submodule_count_;
      }
      diff_submodules_[diff_submodule_count_++] =
          sub == model->submodules.end()
              ? ModuleDiffSubmodule{e.submodule.subslot, 0, submodule_ident_state(submodule_state::kIdentNoSubmodule)}
              : ModuleDiffSubmodule{e.submodule.subslot, sub->ident, submodule_ident_state(submodule_state::kIdentWrong)};
      module->submodules = std::span<const ModuleDiffSubmodule>(&diff_submodules_[first_sub], diff_submodule_count_ - first_sub);
    }
  }
  // One ModuleDiffBlock API entry per API: group the modules by API, keeping their order
  // (insertion sort: stable, and it does not allocate).
  for (std::size_t i = 1; i < diff_module_count_; ++i) {
    for (std::size_t j = i; j > 0 && diff_module_api_[j - 1] > diff_module_api_[j]; --j) {
      std::swap(diff_module_api_[j - 1], diff_module_api_[j]);
      std::swap(diff_modules_[j - 1], diff_modules_[j]);
    }
  }
  for (std::size_t i = 0; i < diff_module_count_;) {
    std::size_t k = i;
    while (k < diff_module_count_ && diff_module_api_[k] == diff_module_api_[i]) ++k;
    diff_apis_[diff_api_count_++] = {diff_module_api_[i], std::span<const ModuleDiffModule>(&diff_modules_[i], k - i)};
    i = k;
  }
}

void CmServer::on_connect(std::span<const std::uint8_t> datagram, const UdpEndpoint& from, CmOutbox& out) noexcept {
  const ConnectRequestView c = decode_connect_request(datagram);
  const RpcHeader rh = responder_.response_header(c.header);
  const std::span<std::uint8_t> buf = responder_.buffer();
  const std::uint32_t max = c.args_maximum;
  auto refuse = [&](const PnioStatus& s) {
    ++counters_.connects_refused;
    responder_.answer(finish_pnio_response(rh, s, max, 0, buf), out);
  };
  if (c.error != WireError::None) {
    ++counters_.rpc.malformed;
    if (c.error == WireError::MissingBlock && c.iocr_count == 0) {
      refuse(pnio(pnio_error_code::kConnect, pnio_error_code1::kCmrpc, 2));  // IOCR Missing
    } else if (c.error == WireError::MissingBlock && c.alarm_cr.size == 0) {
      refuse(pnio(pnio_error_code::kConnect, pnio_error_code1::kCmrpc, 3));  // Wrong AlarmCRBlock count
    } else {
      refuse(pnio(pnio_error_code::kConnect, pnio_error_code1::kCmrpc, 1));  // Unknown Blocks
    }
    return;
  }
  if (c.ar.block.ar_type != ar_type::kIocarSingle) {
    refuse(pnio(pnio_error_code::kConnect, pnio_error_code1::kArBlockReq, 4));  // ARType
    return;
  }
  const IocrBlockReqView* in = nullptr;
  const IocrBlockReqView* outcr = nullptr;
  for (std::size_t i = 0; i < c.iocr_count; ++i) {
    const IocrParams& p = c.iocrs[i].params;
    if ((p.properties & 0x0F) != iocr_properties::kRtClass1) {
      refuse(pnio(pnio_error_code::kConnect, pnio_error_code1::kIocrBlockReq, 7));  // IOCRProperties
      return;
    }
    const IocrBlockReqView*& slot = p.type == iocr_type::kInput ? in : outcr;
    if ((p.type != iocr_type::kInput && p.type != iocr_type::kOutput) || slot != nullptr) {
      refuse(pnio(pnio_error_code::kConnect, pnio_error_code1::kIocrBlockReq, 4));  // IOCRType
      return;
    }
    slot = &c.iocrs[i];
  }
  if (in == nullptr || outcr == nullptr) {
    refuse(pnio(pnio_error_code::kConnect, pnio_error_code1::kCmrpc, 2));  // IOCR Missing
    return;
  }
  if (state_ != CmServerState::NoAr) {
    if (c.ar.block.ar_uuid != ar_.ar_uuid) {
      refuse(pnio(pnio_error_code::kConnect, pnio_error_code1::kCmrpc, 4));  // Out of AR Resources
      return;
    }
    abort("a new Connect for the running AR");
  }
  // RT class 1: the controller may leave the FrameIDs to the device (FFFFh); then the device
  // numbers them from C000h by IOCR reference.
  auto frame_id = [](const IocrParams& p) {
    return p.frame_id != 0xFFFF ? p.frame_id : static_cast<std::uint16_t>(0xC000 + p.reference);
  };
  const std::array<IocrBlockRes, 2> iocrs{{{iocr_type::kInput, in->params.reference, frame_id(in->params)},
                                           {iocr_type::kOutput, outcr->params.reference, frame_id(outcr->params)}}};
  const PnioStatus app_status = app_.on_connect({c, *in, *outcr, iocrs[0].frame_id, iocrs[1].frame_id});
  if (!app_status.ok()) {
    refuse(app_status);
    return;
  }
  ++counters_.connects;
  ar_.ar_uuid = c.ar.block.ar_uuid;
  ar_.session_key = c.ar.block.session_key;
  ar_.initiator_object = c.ar.block.initiator_object_uuid;
  ar_.controller = {from.ip, config_.controller_port};
  compare(c);
  ConnectResponse res;
  res.ar = {ar_type::kIocarSingle, ar_.ar_uuid, ar_.session_key, config_.mac, kEtherTypePnio};
  res.iocrs = iocrs;
  res.alarm_cr = {1, kDeviceAlarmReference, std::min<std::uint16_t>(c.alarm_cr.block.max_alarm_data_length, 200)};
  res.module_diff = std::span<const ModuleDiffApi>(diff_apis_.data(), diff_api_count_);
  responder_.answer(encode_connect_response(rh, PnioStatus{}, max, res, buf), out);
  set_state(CmServerState::Parameterising);
}

void CmServer::on_record(const RpcHeader& h, const NdrRequest& ndr, CmOutbox& out) noexcept {
  const bool write = h.opnum == static_cast<std::uint16_t>(Opnum::Write);
  const std::uint8_t code = write ? pnio_error_code::kWrite : pnio_error_code::kRead;
  const RecordReqView v = decode_record_request(ndr.blocks);
  const RpcHeader rh = responder_.response_header(h);
  PnioStatus status{};
  std::size_t length = 0;
  if (v.error != WireError::None || v.header.type != (write ? block_type::kWriteReqHeader : block_type::kReadReqHeader)) {
    ++counters_.rpc.malformed;
    status = pnio(code, pnio_error_code1::kRecord, 0);  // Error in Parameter BlockType
  } else if (state_ == CmServerState::NoAr || v.header.ar_uuid != ar_.ar_uuid) {
    status = ar_unknown(code);
  } else if (!has_subslot(v.header.api, v.header.slot, v.header.subslot)) {
    status = {code, pnio_error_decode::kPniorw, pniorw_error::kInvalidSlot, 0};
  } else if (write) {
    ++counters_.writes;
    status = app_.on_record_write(v.header, v.data);
  } else {
    ++counters_.reads;
    // What fits the controller's ArgsMaximum after the header, and its RecordDataLength.
    const std::size_t room = ndr.args_maximum > kRecordHeaderSize ? ndr.args_maximum - kRecordHeaderSize : 0;
    const std::size_t most = std::min({room, record_.size(), std::size_t{v.header.record_data_length}});
    status = app_.on_record_read(v.header, std::span<std::uint8_t>(record_).first(most), length);
    length = std::min(length, most);
  }
  if (!status.ok()) {
    ++counters_.records_refused;
    length = 0;
  }
  std::size_t n = 0;
  if (write) {
    n = encode_write_response(rh, status, ndr.args_maximum,
                              record_response_for(v.header, v.header.record_data_length, status), responder_.buffer());
  } else {
    n = encode_read_response(rh, status, ndr.args_maximum, record_response_for(v.header, 0),
                             std::span<const std::uint8_t>(record_).first(length), responder_.buffer());
  }
  responder_.answer(n, out);
}

void CmServer::on_control(const RpcHeader& h, const NdrRequest& ndr, core::TimePoint now, CmOutbox& out) noexcept {
  const bool release = h.opnum == static_cast<std::uint16_t>(Opnum::Release);
  const std::uint8_t code = release ? pnio_error_code::kRelease : pnio_error_code::kControl;
  const std::uint16_t wanted = release ? block_type::kReleaseReq : block_type::kPrmEndReq;
  const ControlBlockView b = decode_control_block(ndr.blocks);
  ControlBlock request = b.block;
  PnioStatus status{};
  if (b.error != WireError::None || b.block.type != wanted) {
    ++counters_.rpc.malformed;
    request.type = wanted;
    // Faulty ControlBlockConnect / ReleaseBlock: Error in Parameter BlockType
    status = pnio(code, release ? pnio_error_code1::kReleaseBlock : pnio_error_code1::kControlBlockConnect, 0);
  } else if (state_ == CmServerState::NoAr || b.block.ar_uuid != ar_.ar_uuid || b.block.session_key != ar_.session_key) {
    status = ar_unknown(code);
  } else if (!release && state_ != CmServerState::Parameterising) {
    status = pnio(code, pnio_error_code1::kCmdev, 0);  // CMDEV State Conflict
  }
  responder_.answer(encode_control_response(responder_.response_header(h), status, ndr.args_maximum,
                                            control_response_for(request), responder_.buffer()),
                    out);
  if (!status.ok()) return;
  if (release) {
    ++counters_.releases;
    abort_reason_.clear();
    ready_call_.cancel();
    ar_ = {};
    set_state(CmServerState::NoAr);
    return;
  }
  set_state(CmServerState::ApplicationReady);
  const ControlBlock ready{block_type::kApplicationReadyReq, ar_.ar_uuid, ar_.session_key, 0,
                           control_command::kApplicationReady, 0};
  const RpcHeader rh = pnio_request_header(ar_.initiator_object, kPnioControllerInterface, config_.activity,
                                           sequence_++, Opnum::Control, config_.order);
  const std::size_t n = encode_control_request(rh, kMaxPnioArgs, ready, ready_call_.buffer());
  if (ready_call_.start(n, rh, ar_.controller, CmSocket::Client, now, out) == RpcCall::Event::Failed) {
    abort(ready_call_.failure());
  }
}

void CmServer::on_ready_response(std::span<const std::uint8_t> datagram) noexcept {
  const PnioResponseView r = decode_pnio_response(datagram);
  if (r.error != WireError::None) {
    ++counters_.rpc.malformed;
    const std::string_view e = to_string(r.error);
    core::FixedString<200> why;
    why.format("ApplicationReady: malformed response: %.*s", len(e), e.data());
    abort(why.view());
    return;
  }
  if (!r.ndr.status.ok()) {
    std::array<char, 160> text{};
    const std::string_view d = describe(r.ndr.status, text);
    core::FixedString<200> why;
    why.format("ApplicationReady refused: %.*s", len(d), d.data());
    abort(why.view());
    return;
  }
  const ControlBlockView b = decode_control_block(r.ndr.blocks);
  if (b.error != WireError::None || b.block.type != block_type::kApplicationReadyRes || b.block.ar_uuid != ar_.ar_uuid) {
    ++counters_.rpc.malformed;
    abort("ApplicationReady: the response block is not the Done of this AR");
    return;
  }
  set_state(CmServerState::DataExchange);
}

}  // namespace drivegate::profinet
