#include "adapters/ethercat/sim/coe_server.hpp"

#include <algorithm>
#include <cstring>

namespace drivegate::ethercat::sim {

// ---- MailboxOutbox ----------------------------------------------------------------------------

MailboxOutbox::MailboxOutbox(std::size_t capacity, std::size_t mailbox_size)
    : slots_(capacity == 0 ? 1 : capacity), mailbox_size_(mailbox_size) {
  for (Slot& s : slots_) s.bytes.assign(mailbox_size, 0);
}

std::span<std::uint8_t> MailboxOutbox::reserve() noexcept {
  if (full() || mailbox_size_ < kMailboxHeaderSize) return {};
  Slot& s = slots_[(head_ + count_) % slots_.size()];
  std::fill(s.bytes.begin(), s.bytes.end(), std::uint8_t{0});
  return {s.bytes.data(), s.bytes.size()};
}

bool MailboxOutbox::commit(std::size_t size) noexcept {
  if (full() || size < kMailboxHeaderSize || size > mailbox_size_) return false;
  Slot& s = slots_[(head_ + count_) % slots_.size()];
  counter_ = next_mailbox_counter(counter_);
  // Mailbox header byte 5: type bits 0-3, counter bits 4-6 [ETG.1000.6 mailbox header].
  s.bytes[5] = static_cast<std::uint8_t>((s.bytes[5] & 0x0F) | (counter_ << 4));
  s.size = size;
  ++count_;
  return true;
}

bool MailboxOutbox::push_front(std::span<const std::uint8_t> msg) noexcept {
  if (full() || msg.size() > mailbox_size_) return false;
  head_ = (head_ + slots_.size() - 1) % slots_.size();
  Slot& s = slots_[head_];
  std::copy(msg.begin(), msg.end(), s.bytes.begin());
  s.size = msg.size();
  ++count_;
  return true;
}

std::span<const std::uint8_t> MailboxOutbox::front() const noexcept {
  if (count_ == 0) return {};
  const Slot& s = slots_[head_];
  return {s.bytes.data(), s.size};
}

void MailboxOutbox::pop() noexcept {
  if (count_ == 0) return;
  head_ = (head_ + 1) % slots_.size();
  --count_;
}

void MailboxOutbox::drop_front() noexcept {
  if (count_ == 0) return;
  pop();
  ++dropped_;
}

void MailboxOutbox::clear() noexcept {
  head_ = 0;
  count_ = 0;
}

// ---- CoeServer --------------------------------------------------------------------------------

CoeServer::CoeServer(ObjectDictionary* od, std::size_t max_object_bytes) : od_(od), buffer_(max_object_bytes, 0) {}

void CoeServer::reset() noexcept {
  transfer_ = Transfer::None;
  size_ = 0;
  done_ = 0;
}

void CoeServer::on_request(std::span<const std::uint8_t> mailbox, AlState state, MailboxOutbox& out) noexcept {
  const CoeView c = decode_coe(mailbox);
  if (c.error != MailboxError::None) {
    // A CoE header cut off: mailbox error "size too short" [ETG.1000.6 mailbox error reply].
    out.emit([](std::span<std::uint8_t> buf) { return encode_mailbox_error(buf, 0, mailbox_error_code::kSizeTooShort); });
    return;
  }
  switch (static_cast<CoeService>(c.service)) {
    case CoeService::SdoRequest: sdo(mailbox, state, out); break;
    case CoeService::SdoInformation: info(mailbox, out); break;
    default: {
      out.emit([](std::span<std::uint8_t> buf) {
        return encode_mailbox_error(buf, 0, mailbox_error_code::kServiceNotSupported);
      });
      break;
    }
  }
}

void CoeServer::abort(MailboxOutbox& out, std::uint16_t index, std::uint8_t subindex, std::uint32_t code) noexcept {
  reset();
  out.emit([&](std::span<std::uint8_t> buf) { return encode_sdo_abort(buf, 0, index, subindex, code); });
}

void CoeServer::upload_segment(bool toggle, MailboxOutbox& out) noexcept {
  // Segment: mailbox header, CoE header, command byte, data [ETG.1000.6 §5.6.2.6].
  const std::size_t room = out.mailbox_size() - kMailboxHeaderSize - kCoeHeaderSize - 1;
  const std::size_t n = std::min(room, size_ - done_);
  const bool last = done_ + n >= size_;
  const std::span<const std::uint8_t> data(buffer_.data() + done_, n);
  if (!out.emit([&](std::span<std::uint8_t> buf) {
        return encode_sdo_upload_segment_response(buf, 0, toggle, last, data);
      })) {
    return;
  }
  done_ += n;
  toggle_ = !toggle;
  if (last) reset();
}

void CoeServer::sdo(std::span<const std::uint8_t> mailbox, AlState state, MailboxOutbox& out) noexcept {
  const SdoView v = decode_sdo_request(mailbox);
  if (v.error != MailboxError::None) {
    // An undecodable command specifier aborts [CiA 301 §7.2.4.3.17 05040001h]; a cut-off SDO
    // cannot name its object.
    abort(out, 0, 0, cia402::sdo_abort_code::kUnknownCommand);
    return;
  }
  const CoeSdo& s = v.sdo;
  if (s.complete_access) {
    abort(out, s.index, s.subindex, cia402::sdo_abort_code::kUnsupportedAccess);
    return;
  }
  switch (s.command) {
    case SdoCommand::UploadInitiateRequest: {
      reset();
      if (od_ == nullptr) return abort(out, s.index, s.subindex, cia402::sdo_abort_code::kNoObject);
      const OdReadResult r = od_->read(s.index, s.subindex, buffer_, state);
      if (r.abort_code != 0) return abort(out, s.index, s.subindex, r.abort_code);
      if (r.size > 0 && r.size <= 4) {
        const std::span<const std::uint8_t> value(buffer_.data(), r.size);
        out.emit([&](std::span<std::uint8_t> buf) {
          return encode_sdo_upload_expedited_response(buf, 0, s.index, s.subindex, value);
        });
        return;
      }
      // Normal upload [ETG.1000.6 §5.6.2.4]: complete size, then what fits after the 16 header bytes.
      const std::size_t room = out.mailbox_size() - kMailboxHeaderSize - kCoeHeaderSize - kSdoHeaderSize - 0;
      const std::size_t n = std::min(room, r.size);
      const std::span<const std::uint8_t> first(buffer_.data(), n);
      if (!out.emit([&](std::span<std::uint8_t> buf) {
            return encode_sdo_upload_normal_response(buf, 0, s.index, s.subindex, static_cast<std::uint32_t>(r.size), first);
          })) {
        return;
      }
      if (n < r.size) {
        transfer_ = Transfer::Upload;
        index_ = s.index;
        subindex_ = s.subindex;
        size_ = r.size;
        done_ = n;
        toggle_ = false;
      }
      return;
    }
    case SdoCommand::UploadSegmentRequest:
      if (transfer_ != Transfer::Upload) return abort(out, 0, 0, cia402::sdo_abort_code::kUnknownCommand);
      if (s.toggle != toggle_) return abort(out, index_, subindex_, cia402::sdo_abort_code::kToggle);
      upload_segment(s.toggle, out);
      return;
    case SdoCommand::DownloadInitiateRequest: {
      reset();
      if (od_ == nullptr) return abort(out, s.index, s.subindex, cia402::sdo_abort_code::kNoObject);
      if (s.expedited || s.data.size() >= s.size) {
        const std::span<const std::uint8_t> value =
            s.expedited ? s.data : s.data.first(std::min<std::size_t>(s.data.size(), s.size));
        const std::uint32_t code = od_->write(s.index, s.subindex, value, state);
        if (code != 0) return abort(out, s.index, s.subindex, code);
        out.emit([&](std::span<std::uint8_t> buf) { return encode_sdo_download_response(buf, 0, s.index, s.subindex); });
        return;
      }
      // Segmented download: collect the segments, write at the last one [ETG.1000.6 §5.6.2.3].
      if (s.size > buffer_.size()) return abort(out, s.index, s.subindex, cia402::sdo_abort_code::kOutOfMemory);
      std::memcpy(buffer_.data(), s.data.data(), s.data.size());
      transfer_ = Transfer::Download;
      index_ = s.index;
      subindex_ = s.subindex;
      size_ = s.size;
      done_ = s.data.size();
      toggle_ = false;
      out.emit([&](std::span<std::uint8_t> buf) { return encode_sdo_download_response(buf, 0, s.index, s.subindex); });
      return;
    }
    case SdoCommand::DownloadSegmentRequest: {
      if (transfer_ != Transfer::Download) return abort(out, 0, 0, cia402::sdo_abort_code::kUnknownCommand);
      if (s.toggle != toggle_) return abort(out, index_, subindex_, cia402::sdo_abort_code::kToggle);
      const std::size_t n = std::min(s.data.size(), size_ - done_);
      // Bytes beyond the announced size are the segment padding (at least 7 bytes), not data.
      std::memcpy(buffer_.data() + done_, s.data.data(), n);
      done_ += n;
      const bool toggle = s.toggle;
      toggle_ = !toggle_;
      if (s.last) {
        const std::uint16_t index = index_;
        const std::uint8_t subindex = subindex_;
        const std::size_t done = done_;
        const std::size_t size = size_;
        reset();
        if (done < size) return abort(out, index, subindex, cia402::sdo_abort_code::kTooShort);
        const std::uint32_t code = od_ == nullptr ? cia402::sdo_abort_code::kNoObject
                                                  : od_->write(index, subindex,
                                                               std::span<const std::uint8_t>(buffer_.data(), size), state);
        if (code != 0) return abort(out, index, subindex, code);
      } else if (done_ >= size_ && s.data.size() > n) {
        return abort(out, index_, subindex_, cia402::sdo_abort_code::kTooLong);
      }
      out.emit([&](std::span<std::uint8_t> buf) { return encode_sdo_download_segment_response(buf, 0, toggle); });
      return;
    }
    case SdoCommand::Abort:
      reset();  // a client abort ends the transfer; no answer [ETG.1000.6 §5.6.2.7]
      return;
    default:
      return abort(out, s.index, s.subindex, cia402::sdo_abort_code::kUnknownCommand);
  }
}

void CoeServer::info(std::span<const std::uint8_t> mailbox, MailboxOutbox& out) noexcept {
  const SdoInfoView v = decode_sdo_info(mailbox);
  auto error = [&](std::uint32_t code) {
    out.emit([&](std::span<std::uint8_t> buf) { return encode_sdo_info_error(buf, 0, code); });
  };
  if (v.error != MailboxError::None || od_ == nullptr) return error(cia402::sdo_abort_code::kUnknownCommand);
  switch (v.opcode) {
    case SdoInfoOpcode::GetOdListRequest: {
      const auto type = static_cast<OdListType>(v.list_type);
      if (v.list_type > static_cast<std::uint16_t>(OdListType::Startup)) return error(cia402::sdo_abort_code::kUnsupportedAccess);
      std::size_t total = 0;
      if (type == OdListType::Lengths) {
        // List type 0: the five list lengths [ETG.1000.6 §5.6.3.3].
        for (std::uint16_t t = 1; t <= 5; ++t) {
          list_[t - 1] = static_cast<std::uint16_t>(od_->list(static_cast<OdListType>(t), {}));
        }
        total = 5;
      } else {
        total = std::min(od_->list(type, list_), list_.size());
      }
      // Fragments [ETG.1000.6 §5.6.3.2]: 12 header bytes, the first also carries the list type.
      const std::size_t room = (out.mailbox_size() - kMailboxHeaderSize - kCoeHeaderSize - 4) / 2;
      std::size_t at = 0;
      bool first = true;
      std::size_t fragments = 1;
      if (total + 1 > room) fragments = (total + 1 + room - 1) / room;
      for (std::size_t f = 0; f < fragments; ++f) {
        const std::size_t cap = first ? room - 1 : room;
        const std::size_t n = std::min(cap, total - at);
        const auto left = static_cast<std::uint16_t>(fragments - 1 - f);
        const std::span<const std::uint16_t> part(list_.data() + at, n);
        if (!out.emit([&](std::span<std::uint8_t> buf) {
              return encode_get_od_list_response(buf, 0, type, first, left, part);
            })) {
          return;
        }
        at += n;
        first = false;
      }
      return;
    }
    case SdoInfoOpcode::GetObjectDescriptionRequest: {
      SdoInfoObjectDescription d;
      if (!od_->describe_object(v.object.index, d)) return error(cia402::sdo_abort_code::kNoObject);
      out.emit([&](std::span<std::uint8_t> buf) { return encode_get_object_description_response(buf, 0, d); });
      return;
    }
    case SdoInfoOpcode::GetEntryDescriptionRequest: {
      SdoInfoEntryDescription d;
      if (!od_->describe_entry(v.entry.index, v.entry.subindex, d)) {
        SdoInfoObjectDescription o;
        return error(od_->describe_object(v.entry.index, o) ? cia402::sdo_abort_code::kNoSubIndex
                                                             : cia402::sdo_abort_code::kNoObject);
      }
      d.value_info = 0;  // no unit/default/min/max offered
      out.emit([&](std::span<std::uint8_t> buf) { return encode_get_entry_description_response(buf, 0, d); });
      return;
    }
    default:
      return error(cia402::sdo_abort_code::kUnknownCommand);
  }
}

}  // namespace drivegate::ethercat::sim
