#include "adapters/canopen/sim/sdo_server.hpp"

#include <algorithm>

namespace drivegate::canopen::sim {

SdoServer::SdoServer(SdoServerConfig config, SdoBackend& backend) noexcept : config_(config), backend_(backend) {}

bool SdoServer::on_frame(const CanFrame& frame, core::TimePoint now) noexcept {
  if (frame.extended || frame.id != config_.rx_cob) return false;
  if (silent_) {
    ++counters_.ignored_silent;
    return true;
  }
  // An RTR carries no SDO; a DLC above 8 cannot come off a real bus, and payload() would overrun.
  if (frame.remote || frame.dlc > kMaxDlc) {
    ++counters_.malformed;
    return true;
  }
  const SdoDecoded d = decode_sdo_request(frame.payload());
  if (d.error == SdoDecodeError::WrongLength) {
    ++counters_.malformed;
    return true;
  }
  if (d.error != SdoDecodeError::None || d.message.command == SdoCommand::Block) {
    ++counters_.unknown_command;
    abort(state_ != State::Idle ? object_ : d.message.object, cia402::sdo_abort_code::kUnknownCommand);
    return true;
  }
  on_request(d.message, now);
  return true;
}

void SdoServer::on_request(const SdoMessage& m, core::TimePoint now) noexcept {
  switch (m.command) {
    case SdoCommand::InitiateUploadRequest:
    case SdoCommand::InitiateDownloadRequest:
      ++counters_.requests;
      if (state_ != State::Idle) {
        ++counters_.replaced;
        state_ = State::Idle;
        deadline_ = core::TimePoint::max();
      }
      if (take_injected(m.object)) {
        ++counters_.injected;
        abort(m.object, injected_code_);
      } else if (m.command == SdoCommand::InitiateUploadRequest) {
        initiate_upload(m.object, now);
      } else {
        initiate_download(m, now);
      }
      return;
    case SdoCommand::DownloadSegmentRequest:
    case SdoCommand::UploadSegmentRequest: {
      const State wanted = m.command == SdoCommand::DownloadSegmentRequest ? State::Download : State::Upload;
      if (state_ != wanted) {
        // No transfer, or one in the other direction: the specifier does not fit [CiA 301].
        ++counters_.unexpected;
        abort(state_ != State::Idle ? object_ : ObjectId{}, cia402::sdo_abort_code::kUnknownCommand);
      } else if (wanted == State::Download) {
        download_segment(m, now);
      } else {
        upload_segment(m, now);
      }
      return;
    }
    case SdoCommand::Abort:
      ++counters_.aborts_received;
      state_ = State::Idle;
      deadline_ = core::TimePoint::max();
      return;
    default: return;  // server-to-client specifiers: decode_sdo_request never yields them
  }
}

void SdoServer::initiate_upload(ObjectId object, core::TimePoint now) noexcept {
  const SdoReadResult r = backend_.sdo_read(object, buffer_);
  if (r.abort_code != 0) {
    abort(object, r.abort_code);
    return;
  }
  if (r.size > kBufferSize) {
    abort(object, cia402::sdo_abort_code::kOutOfMemory);
    return;
  }
  if (r.size >= 1 && r.size <= 4) {
    const auto n = static_cast<std::uint8_t>(r.size);
    SdoBytes b = sdo_upload_expedited_response(object, get_le(buffer_, 0, n), n);
    // 42h: expedited with s = 0 and n = 0, the form the SD6 manual draws (stoeber-sd6-canopen.md
    // §6.4); the unused bytes stay 0 as the codec wrote them.
    if (config_.upload_without_size) b[0] = static_cast<std::uint8_t>(b[0] & ~0x0DU);
    respond(b);
    ++counters_.completed;
    return;
  }
  state_ = State::Upload;
  object_ = object;
  size_ = r.size;
  offset_ = 0;
  toggle_ = false;
  deadline_ = now + config_.timeout;
  respond(sdo_upload_initiate_response(object, static_cast<std::uint32_t>(r.size)));
}

void SdoServer::initiate_download(const SdoMessage& m, core::TimePoint now) noexcept {
  if (m.expedited) {
    // Without a size indication all four bytes are the value (the codec hands up 4).
    const std::uint32_t code = backend_.sdo_write(m.object, {m.data.data(), m.length});
    if (code != 0) {
      abort(m.object, code);
      return;
    }
    respond(sdo_download_response(m.object));
    ++counters_.completed;
    return;
  }
  if (m.size_indicated && m.size > kBufferSize) {
    abort(m.object, cia402::sdo_abort_code::kOutOfMemory);
    return;
  }
  state_ = State::Download;
  object_ = m.object;
  size_indicated_ = m.size_indicated;
  size_ = m.size;
  offset_ = 0;
  toggle_ = false;
  deadline_ = now + config_.timeout;
  respond(sdo_download_response(m.object));
}

void SdoServer::download_segment(const SdoMessage& m, core::TimePoint now) noexcept {
  if (m.toggle != toggle_) {
    ++counters_.toggle_errors;
    abort(object_, cia402::sdo_abort_code::kToggle);
    return;
  }
  const std::size_t received = offset_ + m.length;
  if (received > kBufferSize) {
    abort(object_, cia402::sdo_abort_code::kOutOfMemory);
    return;
  }
  if (size_indicated_ && received > size_) {
    abort(object_, cia402::sdo_abort_code::kTooLong);
    return;
  }
  std::copy_n(m.data.begin(), m.length, buffer_.begin() + static_cast<std::ptrdiff_t>(offset_));
  offset_ = received;
  if (m.last) {
    if (size_indicated_ && received != size_) {
      abort(object_, cia402::sdo_abort_code::kTooShort);
      return;
    }
    // The object is written before the last segment is confirmed, so that a refused value is
    // reported by an abort in place of the confirmation.
    const std::uint32_t code = backend_.sdo_write(object_, {buffer_.data(), received});
    if (code != 0) {
      abort(object_, code);
      return;
    }
    state_ = State::Idle;
    deadline_ = core::TimePoint::max();
    ++counters_.completed;
  } else {
    deadline_ = now + config_.timeout;
  }
  respond(sdo_download_segment_response(toggle_));
  toggle_ = !toggle_;
}

void SdoServer::upload_segment(const SdoMessage& m, core::TimePoint now) noexcept {
  if (m.toggle != toggle_) {
    ++counters_.toggle_errors;
    abort(object_, cia402::sdo_abort_code::kToggle);
    return;
  }
  const std::size_t n = std::min<std::size_t>(7, size_ - offset_);
  const bool last = offset_ + n == size_;
  respond(sdo_upload_segment(toggle_, {buffer_.data() + offset_, n}, last));
  offset_ += n;
  toggle_ = !toggle_;
  if (last) {
    state_ = State::Idle;
    deadline_ = core::TimePoint::max();
    ++counters_.completed;
  } else {
    deadline_ = now + config_.timeout;
  }
}

bool SdoServer::take_injected(ObjectId object) noexcept {
  if (!injection_armed_ || !(injected_object_ == object)) return false;
  injection_armed_ = false;
  return true;
}

void SdoServer::respond(const SdoBytes& bytes) noexcept {
  if (!outbox_.push(make_frame(config_.tx_cob, bytes))) ++counters_.tx_full;
}

void SdoServer::abort(ObjectId object, std::uint32_t code) noexcept {
  ++counters_.aborts_sent;
  state_ = State::Idle;
  deadline_ = core::TimePoint::max();
  respond(sdo_abort(object, code));
}

void SdoServer::poll(core::TimePoint now, TxQueue& tx) noexcept {
  if (state_ != State::Idle && now >= deadline_) {
    ++counters_.timeouts;
    abort(object_, cia402::sdo_abort_code::kTimeout);
  }
  for (; !outbox_.empty(); outbox_.pop()) {
    if (!tx.push(outbox_.front())) ++counters_.tx_full;
  }
}

core::TimePoint SdoServer::next_deadline() const noexcept {
  return outbox_.empty() ? deadline_ : core::TimePoint::min();
}

void SdoServer::reset() noexcept {
  outbox_.clear();
  state_ = State::Idle;
  deadline_ = core::TimePoint::max();
}

void SdoServer::inject_abort(ObjectId object, std::uint32_t code) noexcept {
  injection_armed_ = true;
  injected_object_ = object;
  injected_code_ = code;
}

void SdoServer::set_silent(bool on) noexcept {
  silent_ = on;
  if (on) reset();
}

}  // namespace drivegate::canopen::sim
