#include "adapters/profinet/controller/cm_rpc.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>

namespace drivegate::profinet {

bool CmOutbox::push(CmSocket from, const UdpEndpoint& to, std::span<const std::uint8_t> bytes) noexcept {
  if (size_ == kCapacity || bytes.size() > kMaxRpcDatagram) {
    ++overflows_;
    return false;
  }
  CmDatagram& d = items_[(head_ + size_) % kCapacity];
  d.from = from;
  d.to = to;
  d.size = bytes.size();
  std::copy(bytes.begin(), bytes.end(), d.bytes.begin());
  ++size_;
  return true;
}

void CmOutbox::pop() noexcept {
  if (size_ == 0) return;
  head_ = (head_ + 1) % kCapacity;
  --size_;
}

std::string_view format_endpoint(const UdpEndpoint& e, std::span<char> out) noexcept {
  if (out.empty()) return {};
  const int n = std::snprintf(out.data(), out.size(), "%u.%u.%u.%u:%u", (e.ip >> 24) & 0xFFU, (e.ip >> 16) & 0xFFU,
                              (e.ip >> 8) & 0xFFU, e.ip & 0xFFU, unsigned{e.port});
  return {out.data(), n < 0 ? 0 : std::min(static_cast<std::size_t>(n), out.size() - 1)};
}

namespace {

long long to_ms(core::Duration d) noexcept {
  return static_cast<long long>(std::chrono::duration_cast<std::chrono::milliseconds>(d).count());
}

// For "%.*s".
int len(std::string_view s) noexcept { return static_cast<int>(s.size()); }

}  // namespace

RpcCall::Event RpcCall::start(std::size_t size, const RpcHeader& h, const UdpEndpoint& to, CmSocket from,
                              core::TimePoint now, CmOutbox& out) noexcept {
  header_ = h;
  to_ = to;
  from_ = from;
  size_ = size;
  busy_ = true;
  working_ = false;
  tries_left_ = timing_.retries;
  sends_ = 0;
  attempts_ = 0;
  limit_ = now + timing_.call_limit;
  if (size == 0) return fail("request does not encode (a value out of range, or larger than one datagram)");
  send(now, out, false);
  return Event::None;
}

void RpcCall::send(core::TimePoint now, CmOutbox& out, bool ping) noexcept {
  next_ = now + timing_.timeout;
  ++attempts_;
  if (ping) {
    // A ping names the call by activity and sequence number; it has no body [DCE 1.1 RPC §12.5.3.5].
    RpcHeader p = header_;
    p.packet_type = static_cast<std::uint8_t>(PacketType::Ping);
    p.fragment_length = 0;
    std::array<std::uint8_t, kRpcHeaderSize> bytes{};
    if (encode_rpc_header(p, bytes) != 0 && !out.push(from_, to_, bytes)) ++counters_.outbox_full;
    ++counters_.pings;
    return;
  }
  if (sends_++ > 0) ++counters_.retransmissions;
  if (!out.push(from_, to_, std::span<const std::uint8_t>(buffer_).first(size_))) ++counters_.outbox_full;
}

RpcCall::Event RpcCall::fail(const char* what) noexcept {
  busy_ = false;
  timed_out_ = false;
  failure_.assign(what);
  return Event::Failed;
}

RpcCall::Event RpcCall::poll(core::TimePoint now, CmOutbox& out) noexcept {
  if (!busy_ || now < next_) return Event::None;
  if (now >= limit_ || tries_left_ == 0) {
    ++counters_.timeouts;
    std::array<char, 32> peer{};
    busy_ = false;
    timed_out_ = true;
    const std::string_view op = to_string(static_cast<Opnum>(header_.opnum));
    const std::string_view peer_text = format_endpoint(to_, peer);
    failure_.format("%.*s: no response from %.*s after %d sends, %lld ms apart%s", len(op), op.data(),
                    len(peer_text), peer_text.data(), attempts_, to_ms(timing_.timeout),
                    now >= limit_ ? " (call limit reached while the device was working)" : "");
    return Event::Failed;
  }
  --tries_left_;
  send(now, out, working_);
  return Event::None;
}

RpcCall::Event RpcCall::on_datagram(const RpcView& rpc, core::TimePoint now, CmOutbox& out) noexcept {
  const RpcHeader& h = rpc.header;
  const auto type = static_cast<PacketType>(h.packet_type);
  if (type == PacketType::Request || type == PacketType::Ping || type == PacketType::Ack ||
      type == PacketType::ClCancel || h.activity != header_.activity) {
    ++counters_.unexpected;
    return Event::None;
  }
  if (!busy_ || h.sequence_number != header_.sequence_number) {
    if (seq_before(h.sequence_number, header_.sequence_number) ||
        (!busy_ && h.sequence_number == header_.sequence_number)) {
      ++counters_.stale;
    } else {
      ++counters_.unexpected;
    }
    return Event::None;
  }
  switch (type) {
    case PacketType::Response:
      server_boot_time_ = h.server_boot_time;
      timed_out_ = false;
      if ((h.flags1 & rpc_flag1::kFragment) != 0) {
        const std::string_view op = to_string(static_cast<Opnum>(header_.opnum));
        failure_.format("%.*s: the peer answered with a fragmented response (fragment %u): RPC fragmentation is "
                        "not supported",
                        len(op), op.data(), unsigned{h.fragment_number});
        busy_ = false;
        ++counters_.refused;
        return Event::Failed;
      }
      busy_ = false;
      return Event::Response;
    case PacketType::Fault:
    case PacketType::Reject: {
      const RpcFaultView f = decode_rpc_fault(rpc.body, h.order);
      if (f.error != WireError::None) {
        ++counters_.malformed;
        return Event::None;
      }
      const std::string_view op = to_string(static_cast<Opnum>(header_.opnum));
      const std::string_view kind = to_string(type);
      const std::string_view text = nca_status_text(f.status);
      failure_.format("%.*s: RPC %.*s 0x%08X %.*s", len(op), op.data(), len(kind), kind.data(),
                      static_cast<unsigned>(f.status), len(text), text.data());
      busy_ = false;
      timed_out_ = false;
      return Event::Failed;
    }
    case PacketType::Working:
      // The server has the call and works on it: ping from now on, and the tries start over.
      ++counters_.working;
      working_ = true;
      tries_left_ = timing_.retries;
      next_ = now + timing_.timeout;
      return Event::None;
    case PacketType::Nocall:
      // The server does not know the call (the request was lost): send it again now, as one try.
      ++counters_.nocalls;
      working_ = false;
      if (tries_left_ > 0) {
        --tries_left_;
        send(now, out, false);
      }
      return Event::None;
    case PacketType::Fack: ++counters_.facks; return Event::None;
    default: ++counters_.unexpected; return Event::None;
  }
}

RpcResponder::Verdict RpcResponder::on_request(const RpcHeader& h, const UdpEndpoint& from, CmSocket socket,
                                               CmOutbox& out) noexcept {
  if (known_ && h.activity == last_.activity) {
    if (h.sequence_number == last_.sequence_number) {
      // The client did not get the answer: the same one again, the call is not run twice.
      from_ = from;
      socket_ = socket;
      ++counters_.duplicates_answered;
      send(out);
      return Verdict::Answered;
    }
    if (seq_before(h.sequence_number, last_.sequence_number)) {
      ++counters_.old_requests;
      return Verdict::Dropped;
    }
  }
  known_ = true;
  last_ = h;
  from_ = from;
  socket_ = socket;
  reply_size_ = 0;
  return Verdict::New;
}

void RpcResponder::on_ping(const RpcHeader& h, const UdpEndpoint& from, CmSocket socket, CmOutbox& out) noexcept {
  if (known_ && reply_size_ != 0 && h.activity == last_.activity && h.sequence_number == last_.sequence_number) {
    from_ = from;
    socket_ = socket;
    send(out);
    return;
  }
  RpcHeader n = response_header_for(h, boot_time_);
  n.packet_type = static_cast<std::uint8_t>(PacketType::Nocall);
  n.flags1 = 0;
  std::array<std::uint8_t, kRpcHeaderSize> bytes{};
  if (encode_rpc_header(n, bytes) != 0 && !out.push(socket, from, bytes)) ++counters_.outbox_full;
}

void RpcResponder::answer(std::size_t size, CmOutbox& out) noexcept {
  reply_size_ = size;
  send(out);
}

void RpcResponder::reject(std::uint32_t nca_status, CmOutbox& out) noexcept {
  ++counters_.refused;
  reply_size_ = encode_rpc_fault(response_header_for(last_, boot_time_), PacketType::Reject, nca_status, reply_);
  send(out);
}

void RpcResponder::send(CmOutbox& out) noexcept {
  if (reply_size_ == 0) return;
  if (!out.push(socket_, from_, std::span<const std::uint8_t>(reply_).first(reply_size_))) ++counters_.outbox_full;
}

}  // namespace drivegate::profinet
