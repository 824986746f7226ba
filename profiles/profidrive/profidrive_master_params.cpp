// ProfidriveMaster: the record-47 parameter channel [akd-profinet-profidrive.md §5, §18.2]. One
// exchange at a time: the fault buffer read (944 -> 947 -> 944) goes first, then the clients'
// parameter requests in the order they came. Every response is decoded and checked against its
// request before anything of it is believed.
#include <algorithm>

#include "profiles/profidrive/master_helpers.hpp"
#include "profiles/profidrive/profidrive_master.hpp"

namespace drivegate::profidrive {

using core::EventKind;

namespace {

std::uint8_t change_format(std::size_t size) noexcept {
  return size == 1 ? format::kByte : size == 2 ? format::kWord : format::kDWord;
}

// core::ParamRequest/Reply carry values little-endian (core/param_value.hpp).
std::uint32_t from_le(std::span<const std::uint8_t> bytes) noexcept {
  std::uint32_t v = 0;
  for (std::size_t i = bytes.size(); i-- > 0;) v = (v << 8) | bytes[i];
  return v;
}

}  // namespace

void ProfidriveMaster::run_channel(core::TimePoint now, core::ControllerSink& sink) noexcept {
  if (ticket_ != kNoTicket) {
    const ParamResult r = channel_.poll(ticket_);
    if (r.state == ParamState::Pending) {
      if (now - ticket_since_ <= settings_.param_timeout) return;
      channel_.cancel(ticket_);
      core::Text why;
      why.format("no answer on record 47 within %lld ms", ms(settings_.param_timeout));
      on_failure(why.view(), 0, sink);
    } else if (r.state == ParamState::Done) {
      on_response(r.response, sink);
    } else {
      core::Text why;
      if (r.state == ParamState::Failed)
        why.format("record 47 exchange failed: %.*s", static_cast<int>(r.error.size()), r.error.data());
      else
        why.assign("record 47 exchange lost by the bus adapter");
      on_failure(why.view(), 0, sink);
    }
    ticket_ = kNoTicket;
    channel_user_ = ChannelUser::None;
  }
  if (!actual_valid_) return;
  if (fault_read_wanted_) {
    if (const auto next = fault_reader_.next_read(); next && send_read(*next, now)) channel_user_ = ChannelUser::FaultBuffer;
    return;
  }
  if (params_active_ == 0) return;
  for (std::size_t i = 0; i < params_.size(); ++i) {
    PendingParam& p = params_[i];
    if (!p.active) continue;
    const ParamAddress address{Attribute::Value, 1, p.req.index, p.req.sub};
    bool sent = false;
    if (p.req.write) {
      const std::uint32_t value = from_le(p.req.bytes());
      const ParamChange change{address, change_format(p.req.size), std::span<const std::uint32_t>(&value, 1)};
      sent = send_change(change, now);
    } else {
      sent = send_read(address, now);
    }
    if (sent) {
      channel_user_ = ChannelUser::Client;
      channel_client_ = i;
    }
    return;  // the oldest waits for the channel; the others after it
  }
}

bool ProfidriveMaster::send_read(const ParamAddress& address, core::TimePoint now) noexcept {
  const std::uint8_t ref = next_reference();
  const EncodeResult e = encode_read_request(request_buf_, ref, std::span<const ParamAddress>(&address, 1));
  return e.error == ParamError::None && send(ref, RequestId::Read, address, e.size, now);
}

bool ProfidriveMaster::send_change(const ParamChange& change, core::TimePoint now) noexcept {
  const std::uint8_t ref = next_reference();
  const EncodeResult e = encode_change_request(request_buf_, ref, std::span<const ParamChange>(&change, 1));
  return e.error == ParamError::None && send(ref, RequestId::Change, change.address, e.size, now);
}

std::uint8_t ProfidriveMaster::next_reference() noexcept {
  reference_ = static_cast<std::uint8_t>(reference_ % 255U + 1U);  // 1..255, 0 is reserved [§5.2]
  return reference_;
}

bool ProfidriveMaster::send(std::uint8_t reference, RequestId id, const ParamAddress& address, std::size_t size,
                            core::TimePoint now) noexcept {
  const ParamTicket t = channel_.submit(std::span<const std::uint8_t>(request_buf_).first(size));
  if (t == kNoTicket) return false;  // the channel is busy: next cycle
  ticket_ = t;
  ticket_since_ = now;
  expected_.reference = reference;
  expected_.id = id;
  expected_.axis = 0;
  expected_.count = 1;
  expected_.params[0] = address;
  return true;
}

void ProfidriveMaster::on_response(std::span<const std::uint8_t> bytes, core::ControllerSink& sink) noexcept {
  const ResponseResult d = decode_param_response(bytes);
  core::Text why;
  if (d.error != ParamError::None) {
    why.format("malformed parameter response: %s at byte %zu", to_string(d.error).data(), d.at);
    on_failure(why.view(), 0, sink);
    return;
  }
  if (const CheckResult c = check_response(expected_, d.response); c.mismatch != ParamMismatch::None) {
    why.format("parameter response does not answer the request: %s", to_string(c.mismatch).data());
    on_failure(why.view(), 0, sink);
    return;
  }
  const ValueBlock* block = d.response.block_count > 0 ? &d.response.blocks[0] : nullptr;
  if (block != nullptr && block->is_error()) {
    const std::uint16_t number = block->error_number();
    const std::string_view text = param_error_text(number);
    why.format("PNU %u:%u: %.*s (error 0x%02X)", static_cast<unsigned>(expected_.params[0].pnu),
               static_cast<unsigned>(expected_.params[0].subindex), static_cast<int>(text.size()), text.data(),
               static_cast<unsigned>(number));
    on_failure(why.view(), number, sink);
    return;
  }
  if (channel_user_ == ChannelUser::FaultBuffer) {
    std::array<std::uint16_t, kFaultBufferEntries> values{};
    const auto n = block != nullptr ? u16_values(*block, values) : std::nullopt;
    if (!n) {
      fault_read_failed("PNU 944/947 answered without Word values", sink);
      return;
    }
    fault_reader_.on_values(std::span<const std::uint16_t>(values).first(*n));
    if (fault_reader_.status() == FaultBufferReader::Status::Failed)
      fault_read_failed("PNU 944/947 answered with another number of values than asked", sink);
    else if (fault_reader_.status() != FaultBufferReader::Status::Reading)
      finish_fault_read(sink);
    return;
  }
  if (channel_user_ == ChannelUser::Client) client_reply(params_[channel_client_], block, {}, 0, sink);
}

void ProfidriveMaster::on_failure(std::string_view why, std::uint16_t error_number, core::ControllerSink& sink) noexcept {
  if (channel_user_ == ChannelUser::FaultBuffer) fault_read_failed(why, sink);
  else if (channel_user_ == ChannelUser::Client) client_reply(params_[channel_client_], nullptr, why, error_number, sink);
}

void ProfidriveMaster::client_reply(PendingParam& p, const ValueBlock* block, std::string_view error,
                                    std::uint16_t error_number, core::ControllerSink& sink) noexcept {
  if (!p.active) return;
  core::ParamReply reply;
  reply.id = p.req.id;
  reply.axis = p.req.axis;
  reply.type = p.req.type;
  if (!error.empty()) {
    reply.error.assign(error);
    reply.error_code = error_number;
  } else if (p.req.write) {
    reply.ok = true;
    reply.size = p.req.size;
    std::copy_n(p.req.data.begin(), p.req.size, reply.data.begin());
  } else if (block == nullptr) {
    reply.error.format("PNU %u:%u: the drive answered without a value", static_cast<unsigned>(p.req.index),
                       static_cast<unsigned>(p.req.sub));
  } else {
    // check_response saw one value; it goes out little-endian like every parameter value.
    const std::size_t size = format_size(block->format);
    const std::size_t fixed = core::param_type_size(p.req.type);
    if (fixed != 0 && fixed != size) {
      const auto type_name = core::param_type_cia_name(p.req.type);
      reply.error.format("PNU %u:%u: the drive sent %zu bytes (format 0x%02X), a %.*s has %zu",
                         static_cast<unsigned>(p.req.index), static_cast<unsigned>(p.req.sub), size,
                         static_cast<unsigned>(block->format), static_cast<int>(type_name.size()), type_name.data(), fixed);
    } else {
      const std::uint32_t value = block->value(0);
      reply.ok = true;
      reply.size = static_cast<std::uint16_t>(size);
      for (std::size_t i = 0; i < size; ++i) reply.data[i] = static_cast<std::uint8_t>(value >> (8U * i));
    }
  }
  p.active = false;
  --params_active_;
  sink.parameter_done(reply);
}

std::string_view ProfidriveMaster::fault_text(std::uint16_t number) const noexcept {
  for (const FaultText& f : fault_table_) {
    if (f.number == number) return f.text;
  }
  return "no text for it in the device profile";
}

void ProfidriveMaster::finish_fault_read(core::ControllerSink& sink) noexcept {
  fault_read_wanted_ = false;
  const FaultSnapshot& snap = fault_reader_.snapshot();
  // Inconsistent: new fault situations kept arriving while the buffer was read [§18.2]; the last
  // read is still the best there is, and says so.
  const char* note = snap.consistent ? "" : " (the fault buffer changed while it was read)";
  const auto current = snap.current();
  if (current.empty()) {
    fb_.fault_code = 0;
    fb_.fault_text.format("drive fault without a fault number in PNU 947%s", note);
    sink.event(EventKind::Fault, 0, fb_.fault_text.view());
    return;
  }
  for (std::size_t i = 0; i < current.size(); ++i) {
    const std::string_view text = fault_text(current[i]);
    core::Text t;
    t.format("F%u: %.*s%s", static_cast<unsigned>(current[i]), static_cast<int>(text.size()), text.data(), note);
    if (i == 0) {
      fb_.fault_code = current[i];
      fb_.fault_text = t;
    }
    sink.event(EventKind::Fault, current[i], t.view());
  }
}

void ProfidriveMaster::fault_read_failed(std::string_view why, core::ControllerSink& sink) noexcept {
  fault_read_wanted_ = false;
  fault_reader_.on_failed();
  fb_.fault_code = 0;
  fb_.fault_text.format("drive fault (fault buffer unreadable: %.*s)", static_cast<int>(why.size()), why.data());
  sink.event(EventKind::Fault, 0, fb_.fault_text.view());
}

void ProfidriveMaster::cancel_fault_read() noexcept {
  fault_read_wanted_ = false;
  if (channel_user_ != ChannelUser::FaultBuffer) return;
  channel_.cancel(ticket_);
  ticket_ = kNoTicket;
  channel_user_ = ChannelUser::None;
}

void ProfidriveMaster::cancel_channel() noexcept {
  if (ticket_ != kNoTicket) channel_.cancel(ticket_);
  ticket_ = kNoTicket;
  channel_user_ = ChannelUser::None;
}

}  // namespace drivegate::profidrive
