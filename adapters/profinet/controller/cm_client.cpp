#include "adapters/profinet/controller/cm_client.hpp"

#include <algorithm>
#include <cstdarg>

#include "adapters/profinet/wire/rpc_calls.hpp"

namespace drivegate::profinet {

std::string_view to_string(CmClientState s) noexcept {
  switch (s) {
    case CmClientState::Idle: return "Idle";
    case CmClientState::Connecting: return "Connecting";
    case CmClientState::Parameterising: return "Parameterising";
    case CmClientState::PrmEnd: return "PrmEnd";
    case CmClientState::WaitApplicationReady: return "WaitApplicationReady";
    case CmClientState::DataExchange: return "DataExchange";
    case CmClientState::Releasing: return "Releasing";
    case CmClientState::Released: return "Released";
    case CmClientState::Failed: return "Failed";
  }
  return "unknown";
}

std::string_view to_string(CmRecordOutcome o) noexcept {
  switch (o) {
    case CmRecordOutcome::Done: return "done";
    case CmRecordOutcome::Refused: return "refused";
    case CmRecordOutcome::Failed: return "failed";
    case CmRecordOutcome::Aborted: return "aborted";
  }
  return "unknown";
}

namespace {

int len(std::string_view s) noexcept { return static_cast<int>(s.size()); }

long long to_ms(core::Duration d) noexcept {
  return static_cast<long long>(std::chrono::duration_cast<std::chrono::milliseconds>(d).count());
}

bool rt_class_1(const IocrParams& p) noexcept { return (p.properties & 0x0F) == iocr_properties::kRtClass1; }

// A difference the AR cannot run with: a module that is missing or wrong, a submodule that is
// missing or wrong, or one locked by another AR [IEC 61158-6-10 "ModuleState", "SubmoduleState"].
// Substitutes, "application ready pending" and the diagnosis bits are not in the way.
bool diff_blocks_ar(const ModuleDiffBlockView& v) noexcept {
  ModuleDiffReader reader(v);
  ModuleDiffEntry e;
  while (reader.next(e)) {
    if (e.module_state != static_cast<std::uint16_t>(ModuleState::ProperModule) &&
        e.module_state != static_cast<std::uint16_t>(ModuleState::Substitute)) {
      return true;
    }
    if (!e.has_submodule || (e.submodule.state & submodule_state::kFormatIndicator) == 0) continue;
    const std::uint8_t ident = submodule_state::ident_info(e.submodule.state);
    const std::uint8_t ar = submodule_state::ar_info(e.submodule.state);
    if (ident == submodule_state::kIdentWrong || ident == submodule_state::kIdentNoSubmodule ||
        ar == submodule_state::kArSuperordinatedLocked || ar == submodule_state::kArLockedByController ||
        ar == submodule_state::kArLockedBySupervisor) {
      return true;
    }
  }
  return false;
}

// The multi-line module diff report on one line ("; " between the findings).
core::FixedString<1100> one_line(std::string_view lines) noexcept {
  std::array<char, 1100> buf{};
  std::size_t n = 0;
  while (!lines.empty() && lines.back() == '\n') lines.remove_suffix(1);
  for (const char c : lines) {
    if (c == '\n') {
      if (n + 2 > buf.size()) break;
      buf[n++] = ';';
      buf[n++] = ' ';
    } else {
      if (n == buf.size()) break;
      buf[n++] = c;
    }
  }
  return core::FixedString<1100>(std::string_view(buf.data(), n));
}

}  // namespace

CmClient::CmClient(const CmClientConfig& config, CmRecordListener* listener) noexcept
    : config_(config),
      listener_(listener),
      call_(config_.rpc, counters_.rpc),
      server_(config_.boot_time, counters_.rpc) {}

bool CmClient::start(core::TimePoint now, CmOutbox& out) noexcept {
  if (state_ != CmClientState::Idle) return false;
  state_ = CmClientState::Connecting;
  if (!rt_class_1(config_.connect.input) || !rt_class_1(config_.connect.output)) {
    fail(now, nullptr, "the IOCRs must be RT class 1 (IOCRProperties 0x%08X / 0x%08X): this controller speaks RT "
                       "class 1 only",
         static_cast<unsigned>(config_.connect.input.properties), static_cast<unsigned>(config_.connect.output.properties));
    return false;
  }
  const RpcHeader h = next_request(Opnum::Connect);
  begin(Call::Connect, encode_connect_request(h, kMaxPnioArgs, config_.connect, call_.buffer()), h, now, out);
  return true;
}

void CmClient::release(core::TimePoint now, CmOutbox& out) noexcept {
  switch (state_) {
    case CmClientState::Idle: state_ = CmClientState::Released; return;
    case CmClientState::Releasing:
    case CmClientState::Released:
    case CmClientState::Failed: return;
    default: break;
  }
  call_.cancel();
  fail_after_release_ = false;
  state_ = CmClientState::Releasing;
  abort_records("aborted: the AR is being released");
  send_control(Call::Release, now, out);
}

RpcHeader CmClient::next_request(Opnum op) noexcept {
  RpcHeader h = pnio_request_header(make_pnio_object_uuid(config_.device_object), kPnioDeviceInterface,
                                    config_.activity, sequence_++, op, config_.order);
  h.server_boot_time = call_.server_boot_time();
  return h;
}

void CmClient::begin(Call call, std::size_t size, const RpcHeader& h, core::TimePoint now, CmOutbox& out) noexcept {
  calling_ = call;
  if (call_.start(size, h, config_.device, CmSocket::Client, now, out) == RpcCall::Event::Failed) {
    on_call_failed(now, out);
  }
}

void CmClient::send_record(bool write, std::uint32_t api, std::uint16_t slot, std::uint16_t subslot,
                           std::uint16_t index, std::span<const std::uint8_t> data, std::size_t read_length,
                           core::TimePoint now, CmOutbox& out) noexcept {
  RecordReqHeader& rh = record_request_;
  rh = {};
  rh.type = write ? block_type::kWriteReqHeader : block_type::kReadReqHeader;
  rh.sequence_number = record_sequence_++;
  rh.ar_uuid = config_.connect.ar.ar_uuid;
  rh.api = api;
  rh.slot = slot;
  rh.subslot = subslot;
  rh.index = index;
  const RpcHeader h = next_request(write ? Opnum::Write : Opnum::Read);
  std::size_t n = 0;
  if (write) {
    n = encode_write_request(h, kMaxPnioArgs, rh, data, call_.buffer());
    rh.record_data_length = static_cast<std::uint32_t>(data.size());
  } else {
    rh.record_data_length = static_cast<std::uint32_t>(read_length);
    n = encode_read_request(h, kMaxPnioArgs, rh, call_.buffer());
  }
  begin(state_ == CmClientState::Parameterising ? Call::ParameterWrite : Call::Record, n, h, now, out);
}

void CmClient::send_control(Call call, core::TimePoint now, CmOutbox& out) noexcept {
  const bool release = call == Call::Release;
  const ControlBlock b{release ? block_type::kReleaseReq : block_type::kPrmEndReq,
                       config_.connect.ar.ar_uuid,
                       config_.connect.ar.session_key,
                       0,
                       release ? control_command::kRelease : control_command::kPrmEnd,
                       0};
  const RpcHeader h = next_request(release ? Opnum::Release : Opnum::Control);
  begin(call, encode_control_request(h, kMaxPnioArgs, b, call_.buffer()), h, now, out);
}

void CmClient::next_parameter(core::TimePoint now, CmOutbox& out) noexcept {
  if (next_parameter_ < config_.parameters.size()) {
    const CmRecordWrite& p = config_.parameters[next_parameter_];
    send_record(true, p.api, p.slot, p.subslot, p.index, p.data, 0, now, out);
    return;
  }
  state_ = CmClientState::PrmEnd;
  send_control(Call::PrmEnd, now, out);
}

void CmClient::enter_data_exchange(core::TimePoint now, CmOutbox& out) noexcept {
  state_ = CmClientState::DataExchange;
  start_next_record(now, out);
}

void CmClient::start_next_record(core::TimePoint now, CmOutbox& out) noexcept {
  if (state_ != CmClientState::DataExchange || record_running_ || record_count_ == 0 || call_.busy()) return;
  record_running_ = true;
  const Record& r = records_[record_head_];
  send_record(r.write, r.api, r.slot, r.subslot, r.index, std::span<const std::uint8_t>(r.data).first(r.write ? r.length : 0),
              r.length, now, out);
}

CmRecordId CmClient::submit(bool write, std::uint32_t api, std::uint16_t slot, std::uint16_t subslot,
                            std::uint16_t index, std::size_t length) noexcept {
  if (state_ < CmClientState::Connecting || state_ > CmClientState::DataExchange || length > kMaxRecordData) return 0;
  if (record_count_ == kRecordQueueDepth) {
    ++counters_.queue_full;
    return 0;
  }
  Record& r = records_[(record_head_ + record_count_) % kRecordQueueDepth];
  r.id = next_record_id_++;
  if (next_record_id_ == 0) next_record_id_ = 1;
  r.write = write;
  r.api = api;
  r.slot = slot;
  r.subslot = subslot;
  r.index = index;
  r.length = length;
  ++record_count_;
  ++counters_.records_submitted;
  return r.id;
}

CmRecordId CmClient::submit_read(std::uint32_t api, std::uint16_t slot, std::uint16_t subslot, std::uint16_t index,
                                 std::size_t max_length) noexcept {
  return submit(false, api, slot, subslot, index, max_length);
}

CmRecordId CmClient::submit_write(std::uint32_t api, std::uint16_t slot, std::uint16_t subslot, std::uint16_t index,
                                  std::span<const std::uint8_t> data) noexcept {
  const CmRecordId id = submit(true, api, slot, subslot, index, data.size());
  if (id != 0) {
    Record& r = records_[(record_head_ + record_count_ - 1) % kRecordQueueDepth];
    std::copy(data.begin(), data.end(), r.data.begin());
  }
  return id;
}

void CmClient::reply_record(const Record& r, CmRecordOutcome outcome, const PnioStatus& status,
                            std::span<const std::uint8_t> data, std::string_view text, std::uint16_t add1,
                            std::uint16_t add2) noexcept {
  switch (outcome) {
    case CmRecordOutcome::Done: ++counters_.records_done; break;
    case CmRecordOutcome::Refused: ++counters_.records_refused; break;
    case CmRecordOutcome::Failed: ++counters_.records_failed; break;
    case CmRecordOutcome::Aborted: ++counters_.records_aborted; break;
  }
  if (listener_ == nullptr) return;
  CmRecordReply reply;
  reply.id = r.id;
  reply.write = r.write;
  reply.outcome = outcome;
  reply.status = status;
  reply.additional_value1 = add1;
  reply.additional_value2 = add2;
  reply.data = data;
  reply.text = text;
  listener_->on_record_reply(reply);
}

void CmClient::abort_records(std::string_view why) noexcept {
  // Taken off the queue before each reply: a listener that submits again is refused (the state
  // has already left the running ones) and does not see a record twice.
  while (record_count_ > 0) {
    const Record r = records_[record_head_];
    record_head_ = (record_head_ + 1) % kRecordQueueDepth;
    --record_count_;
    reply_record(r, CmRecordOutcome::Aborted, {}, {}, why);
  }
  record_running_ = false;
}

void CmClient::fail(core::TimePoint now, CmOutbox* release_out, const char* fmt, ...) noexcept {
  core::FixedString<1300> what;
  va_list args;
  va_start(args, fmt);
  what.vformat(fmt, args);
  va_end(args);
  failed_in_ = state_;
  const std::string_view in = to_string(state_);
  reason_.format("%.*s: %.*s", len(in), in.data(), len(what.view()), what.view().data());
  call_.cancel();
  state_ = release_out != nullptr ? CmClientState::Releasing : CmClientState::Failed;
  abort_records("aborted: the AR failed");
  if (release_out != nullptr) {
    fail_after_release_ = true;
    send_control(Call::Release, now, *release_out);
  }
}

void CmClient::poll(core::TimePoint now, CmOutbox& out) noexcept {
  if (call_.poll(now, out) == RpcCall::Event::Failed) on_call_failed(now, out);
  if (state_ == CmClientState::WaitApplicationReady && now >= ready_deadline_) {
    fail(now, &out, "no ApplicationReady from the device within %lld ms after PrmEnd",
         to_ms(config_.application_ready_timeout));
  }
  start_next_record(now, out);
}

void CmClient::on_datagram(std::span<const std::uint8_t> datagram, const UdpEndpoint& from, CmSocket socket,
                           core::TimePoint now, CmOutbox& out) noexcept {
  ++counters_.rpc.datagrams_in;
  if (socket == CmSocket::Server) {
    on_server_datagram(datagram, from, now, out);
    return;
  }
  const RpcView rpc = decode_rpc(datagram);
  if (rpc.error != WireError::None) {
    ++counters_.rpc.malformed;
    return;
  }
  switch (call_.on_datagram(rpc, now, out)) {
    case RpcCall::Event::Response: on_response(datagram, now, out); break;
    case RpcCall::Event::Failed: on_call_failed(now, out); break;
    case RpcCall::Event::None: break;
  }
}

void CmClient::on_response(std::span<const std::uint8_t> datagram, core::TimePoint now, CmOutbox& out) noexcept {
  switch (calling_) {
    case Call::Connect: on_connect_response(datagram, now, out); return;
    case Call::PrmEnd:
    case Call::Release: on_control_response(datagram, now, out); return;
    case Call::ParameterWrite:
    case Call::Record: break;
    case Call::None: return;
  }
  std::span<const std::uint8_t> data;
  PnioStatus status;
  RecordResHeader header;
  const bool ok = check_record_response(datagram, data, status, header);
  if (calling_ == Call::ParameterWrite) {
    const CmRecordWrite& p = config_.parameters[next_parameter_];
    if (!ok) {
      fail(now, &out, "write API 0x%X slot %u subslot %u index %u (0x%04X) %s: %.*s", static_cast<unsigned>(p.api),
           unsigned{p.slot}, unsigned{p.subslot}, unsigned{p.index}, unsigned{p.index},
           status.ok() ? "failed" : "refused", len(scratch_.view()), scratch_.view().data());
      return;
    }
    ++next_parameter_;
    next_parameter(now, out);
    return;
  }
  const Record r = records_[record_head_];
  record_head_ = (record_head_ + 1) % kRecordQueueDepth;
  --record_count_;
  record_running_ = false;
  calling_ = Call::None;
  if (ok) {
    reply_record(r, CmRecordOutcome::Done, {}, data, {}, header.additional_value1, header.additional_value2);
  } else {
    reply_record(r, status.ok() ? CmRecordOutcome::Failed : CmRecordOutcome::Refused, status, {}, scratch_.view(),
                 header.additional_value1, header.additional_value2);
  }
  start_next_record(now, out);
}

bool CmClient::check_record_response(std::span<const std::uint8_t> datagram, std::span<const std::uint8_t>& data,
                                     PnioStatus& status, RecordResHeader& header) noexcept {
  std::array<char, 200> text{};
  const PnioResponseView r = decode_pnio_response(datagram);
  if (r.error != WireError::None) {
    ++counters_.rpc.malformed;
    const std::string_view e = to_string(r.error);
    scratch_.format("malformed response: %.*s", len(e), e.data());
    return false;
  }
  const RecordResView v = decode_record_response(r.ndr.blocks);
  header = v.header;
  // A refusal carries the PNIOStatus in the NDR part, and for a write in the header too.
  status = !r.ndr.status.ok() ? r.ndr.status : (v.error == WireError::None ? v.header.status : PnioStatus{});
  if (!status.ok()) {
    const std::string_view d = describe(status, text);
    scratch_.assign(d);
    return false;
  }
  const RecordReqHeader& q = record_request_;
  if (v.error != WireError::None) {
    ++counters_.rpc.malformed;
    const std::string_view e = to_string(v.error);
    scratch_.format("malformed record response: %.*s", len(e), e.data());
    return false;
  }
  if (v.header.type != (q.type | 0x8000) || v.header.ar_uuid != q.ar_uuid || v.header.api != q.api ||
      v.header.slot != q.slot || v.header.subslot != q.subslot || v.header.index != q.index) {
    ++counters_.rpc.malformed;
    scratch_.format("the response names another record (API 0x%X slot %u subslot %u index 0x%04X)",
                    static_cast<unsigned>(v.header.api), unsigned{v.header.slot}, unsigned{v.header.subslot},
                    unsigned{v.header.index});
    return false;
  }
  if (q.type == block_type::kReadReqHeader && v.data.size() > q.record_data_length) {
    ++counters_.rpc.malformed;
    scratch_.format("the device sent %zu bytes, %u were asked for", v.data.size(),
                    static_cast<unsigned>(q.record_data_length));
    return false;
  }
  data = v.data;
  return true;
}

void CmClient::on_connect_response(std::span<const std::uint8_t> datagram, core::TimePoint now,
                                   CmOutbox& out) noexcept {
  const ConnectResponseView v = decode_connect_response(datagram);
  const ConnectRequest& c = config_.connect;
  if (v.has_module_diff) {
    std::array<char, 1024> report{};
    module_diff_.assign(module_diff_report(v.module_diff, c.expected, report));
  }
  const core::FixedString<1100> diff = one_line(module_diff_.view());
  if (v.error != WireError::None) {
    // A refusal's blocks may be absent, but its NDR part still names the status.
    if (v.error != WireError::MissingBlock) ++counters_.rpc.malformed;
    if (!v.status.ok()) {
      std::array<char, 200> text{};
      const std::string_view d = describe(v.status, text);
      fail(now, nullptr, "Connect refused: %.*s", len(d), d.data());
      return;
    }
    const std::string_view e = to_string(v.error);
    fail(now, &out, "malformed Connect response: %.*s", len(e), e.data());
    return;
  }
  if (!v.status.ok()) {
    std::array<char, 200> text{};
    const std::string_view d = describe(v.status, text);
    fail(now, nullptr, "Connect refused: %.*s%s%.*s", len(d), d.data(), diff.empty() ? "" : "; ", len(diff.view()),
         diff.view().data());
    return;
  }
  if (v.ar.ar_uuid != c.ar.ar_uuid || v.ar.session_key != c.ar.session_key) {
    ++counters_.rpc.malformed;
    fail(now, &out, "the Connect response names another AR (session key %u, expected %u, or another AR UUID)",
         unsigned{v.ar.session_key}, unsigned{c.ar.session_key});
    return;
  }
  const IocrBlockRes* in = v.iocr(iocr_type::kInput, c.input.reference);
  const IocrBlockRes* outcr = v.iocr(iocr_type::kOutput, c.output.reference);
  if (in == nullptr || outcr == nullptr || !v.has_alarm_cr) {
    ++counters_.rpc.malformed;
    fail(now, &out, "the Connect response lacks the %s", in == nullptr ? "input IOCRBlockRes"
                                                          : outcr == nullptr ? "output IOCRBlockRes"
                                                                             : "AlarmCRBlockRes");
    return;
  }
  input_frame_id_ = in->frame_id;
  output_frame_id_ = outcr->frame_id;
  ar_res_ = v.ar;
  alarm_res_ = v.alarm_cr;
  if (v.has_module_diff && !config_.accept_module_diff && diff_blocks_ar(v.module_diff)) {
    fail(now, &out, "the device's modules differ from the expected ones: %.*s", len(diff.view()), diff.view().data());
    return;
  }
  state_ = CmClientState::Parameterising;
  next_parameter_ = 0;
  next_parameter(now, out);
}

void CmClient::on_control_response(std::span<const std::uint8_t> datagram, core::TimePoint now,
                                   CmOutbox& out) noexcept {
  const bool release = calling_ == Call::Release;
  calling_ = Call::None;
  const PnioResponseView r = decode_pnio_response(datagram);
  std::array<char, 200> text{};
  std::string_view problem;
  if (r.error != WireError::None) {
    ++counters_.rpc.malformed;
    problem = to_string(r.error);
  } else if (!r.ndr.status.ok()) {
    problem = describe(r.ndr.status, text);
  } else {
    const ControlBlockView b = decode_control_block(r.ndr.blocks);
    const std::uint16_t expected = release ? block_type::kReleaseRes : block_type::kPrmEndRes;
    if (b.error != WireError::None || b.block.type != expected || b.block.ar_uuid != config_.connect.ar.ar_uuid ||
        b.block.session_key != config_.connect.ar.session_key ||
        (b.block.command & control_command::kDone) == 0) {
      ++counters_.rpc.malformed;
      problem = b.error != WireError::None ? to_string(b.error) : "the response block is not the Done of our AR";
    }
  }
  if (release) {
    if (fail_after_release_) {
      state_ = CmClientState::Failed;
    } else if (problem.empty()) {
      state_ = CmClientState::Released;
    } else {
      fail(now, nullptr, "Release refused: %.*s", len(problem), problem.data());
    }
    return;
  }
  if (!problem.empty()) {
    fail(now, &out, "PrmEnd refused: %.*s", len(problem), problem.data());
    return;
  }
  if (application_ready_seen_) {
    enter_data_exchange(now, out);
    return;
  }
  state_ = CmClientState::WaitApplicationReady;
  ready_deadline_ = now + config_.application_ready_timeout;
}

void CmClient::on_call_failed(core::TimePoint now, CmOutbox& out) noexcept {
  const Call call = calling_;
  calling_ = Call::None;
  const std::string_view why = call_.failure();
  // After a refusal the device may hold the AR: release it. Without an answer there is nobody to
  // release it with (the device drops the AR after its CM activity timeout).
  CmOutbox* release_out = call_.timed_out() ? nullptr : &out;
  switch (call) {
    case Call::Record: {
      const Record r = records_[record_head_];
      record_head_ = (record_head_ + 1) % kRecordQueueDepth;
      --record_count_;
      record_running_ = false;
      reply_record(r, CmRecordOutcome::Failed, {}, {}, why);
      start_next_record(now, out);
      return;
    }
    case Call::Release:
      if (fail_after_release_) {
        state_ = CmClientState::Failed;
      } else {
        fail(now, nullptr, "%.*s", len(why), why.data());
      }
      return;
    case Call::Connect: fail(now, nullptr, "%.*s", len(why), why.data()); return;
    case Call::ParameterWrite:
    case Call::PrmEnd: fail(now, release_out, "%.*s", len(why), why.data()); return;
    case Call::None: return;
  }
}

void CmClient::on_server_datagram(std::span<const std::uint8_t> datagram, const UdpEndpoint& from,
                                  core::TimePoint now, CmOutbox& out) noexcept {
  const RpcView rpc = decode_rpc(datagram);
  if (rpc.error != WireError::None) {
    ++counters_.rpc.malformed;
    return;
  }
  const auto type = static_cast<PacketType>(rpc.header.packet_type);
  if (type == PacketType::Ping) {
    server_.on_ping(rpc.header, from, CmSocket::Server, out);
    return;
  }
  if (type != PacketType::Request) {
    ++counters_.rpc.unexpected;
    return;
  }
  const PnioRequestView r = decode_pnio_request(datagram);
  const bool fragment = (rpc.header.flags1 & rpc_flag1::kFragment) != 0;
  const bool foreign = r.error == WireError::UnexpectedInterface || rpc.header.interface != kPnioControllerInterface;
  const bool bad_op = r.error == WireError::UnexpectedOpnum || rpc.header.opnum != static_cast<std::uint16_t>(Opnum::Control);
  if (!fragment && !foreign && !bad_op && r.error != WireError::None) {
    ++counters_.rpc.malformed;
    return;
  }
  if (server_.on_request(rpc.header, from, CmSocket::Server, out) != RpcResponder::Verdict::New) return;
  if (fragment || foreign || bad_op) {
    server_.reject(fragment ? nca_status::kProtoError : foreign ? nca_status::kUnknownInterface : nca_status::kOpRangeError,
                   out);
    return;
  }
  const ControlBlockView b = decode_control_block(r.ndr.blocks);
  ControlBlock request = b.block;
  PnioStatus status{};
  if (b.error != WireError::None || b.block.type != block_type::kApplicationReadyReq ||
      (b.block.command & control_command::kApplicationReady) == 0) {
    ++counters_.rpc.malformed;
    // "Faulty ControlBlockConnect: Error in Parameter BlockType" / "... ControlCommand"
    status = {pnio_error_code::kControl, pnio_error_decode::kPnio, pnio_error_code1::kControlBlockConnect,
              static_cast<std::uint8_t>(b.error != WireError::None || b.block.type != block_type::kApplicationReadyReq ? 0 : 8)};
    request.type = block_type::kApplicationReadyReq;
  } else if (b.block.ar_uuid != config_.connect.ar.ar_uuid || b.block.session_key != config_.connect.ar.session_key) {
    status = {pnio_error_code::kControl, pnio_error_decode::kPnio, pnio_error_code1::kCmrpc, 5};  // AR UUID unknown
  } else if (state_ != CmClientState::PrmEnd && state_ != CmClientState::WaitApplicationReady) {
    status = {pnio_error_code::kControl, pnio_error_decode::kPnio, pnio_error_code1::kCmctl, 0};  // State conflict
  }
  const std::size_t n = encode_control_response(server_.response_header(rpc.header), status, r.ndr.args_maximum,
                                                control_response_for(request), server_.buffer());
  server_.answer(n, out);
  if (!status.ok()) return;
  ++counters_.application_ready;
  if (state_ == CmClientState::WaitApplicationReady) {
    enter_data_exchange(now, out);
  } else {
    application_ready_seen_ = true;
  }
}

}  // namespace drivegate::profinet
