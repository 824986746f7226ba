#pragma once
// Connectionless DCE/RPC for the connection-management engines (CmClient, CmServer), sans I/O:
// datagrams in with the time, datagrams out into a caller-owned CmOutbox [DCE 1.1 RPC ch. 10
// "Connectionless RPC Protocol Machines", ch. 12; IEC 61158-6-10 §4.10.3].
//
//   RpcCall       one outstanding call of a client: the request is sent, sent again after
//                 `timeout` up to `retries` times; a `working` answer means the server has the
//                 call: from then on the client sends `ping` when the timeout runs out instead of
//                 the request, a `nocall` answer to a ping (the server lost it) sends the request
//                 again, and each working answer restores the tries. `call_limit` bounds the call
//                 however long the server keeps working. A response or fault is taken only for the
//                 call's activity and sequence number: a late answer to an earlier sequence number
//                 is counted and ignored. A fragmented response is refused with a clear error (the
//                 requests offer ArgsMaximum so that a response fits one datagram, kMaxPnioArgs).
//   RpcResponder  the server's memory of the last call of one client activity: a new call is
//                 handled, a repeated one (same activity and sequence number, the answer was lost)
//                 is answered from the cache without being run again, an older one ignored; a ping
//                 is answered with the cached response, or `nocall` when the server does not know
//                 the call.
//
// Nothing here allocates: every buffer is a member.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "adapters/profinet/wire/rpc.hpp"
#include "core/clock.hpp"
#include "core/fixed_string.hpp"

namespace drivegate::profinet {

// An IPv4 UDP endpoint; the address in host order (192.168.0.2 = 0xC0A80002).
struct UdpEndpoint {
  std::uint32_t ip = 0;
  std::uint16_t port = 0;
  bool operator==(const UdpEndpoint&) const = default;
};

// Which of an engine's two UDP sockets a datagram leaves from or arrives at: the one it calls
// from (an ephemeral port), or its RPC server port (34964 by default: the device's for the
// controller's calls, the controller's for the device's ApplicationReady).
enum class CmSocket : std::uint8_t { Client, Server };

// One RPC fragment in one Ethernet frame: 1500 - 20 (IPv4) - 8 (UDP). Fragmentation is not spoken.
inline constexpr std::size_t kMaxRpcDatagram = 1472;
// What the requests offer as ArgsMaximum: the largest response args that still fit one datagram.
inline constexpr std::uint32_t kMaxPnioArgs = kMaxRpcDatagram - kPnioBlocksOffset;

struct CmDatagram {
  CmSocket from = CmSocket::Client;
  UdpEndpoint to{};
  std::size_t size = 0;
  std::array<std::uint8_t, kMaxRpcDatagram> bytes{};
  [[nodiscard]] std::span<const std::uint8_t> view() const noexcept { return {bytes.data(), size}; }
};

// The datagrams the engines want sent, in order; the transport drains it. Fixed capacity: a full
// outbox refuses a datagram and counts it, the engine treats that as a lost datagram (the RPC
// retransmission recovers it).
class CmOutbox {
 public:
  static constexpr std::size_t kCapacity = 8;
  bool push(CmSocket from, const UdpEndpoint& to, std::span<const std::uint8_t> bytes) noexcept;
  [[nodiscard]] bool empty() const noexcept { return size_ == 0; }
  [[nodiscard]] std::size_t size() const noexcept { return size_; }
  [[nodiscard]] const CmDatagram& front() const noexcept { return items_[head_]; }
  void pop() noexcept;
  [[nodiscard]] std::uint64_t overflows() const noexcept { return overflows_; }

 private:
  std::array<CmDatagram, kCapacity> items_{};
  std::size_t head_ = 0;
  std::size_t size_ = 0;
  std::uint64_t overflows_ = 0;
};

struct RpcTiming {
  core::Duration timeout = std::chrono::seconds(1);      // wait for an answer before sending again
  int retries = 3;                                        // sends after the first
  core::Duration call_limit = std::chrono::seconds(30);  // a call ends here even while "working"
};

// What the RPC layer of an engine saw; the engines add their own in their counters.
struct RpcCounters {
  std::uint64_t datagrams_in = 0;
  std::uint64_t malformed = 0;      // not decodable (RPC header, NDR, blocks): dropped
  std::uint64_t unexpected = 0;     // well formed, but no call of ours / another activity: dropped
  std::uint64_t stale = 0;          // an answer to an earlier sequence number: dropped
  std::uint64_t retransmissions = 0, pings = 0, working = 0, nocalls = 0, facks = 0;
  std::uint64_t duplicates_answered = 0;  // a repeated request answered from the cache
  std::uint64_t old_requests = 0;         // a request older than the last one: dropped
  std::uint64_t refused = 0;              // answered with reject (fragment, interface, opnum)
  std::uint64_t timeouts = 0;
  std::uint64_t outbox_full = 0;
};

// The sequence number `a` comes before `b` (modulo 2^32, DCE 1.1 RPC §10.2.1).
constexpr bool seq_before(std::uint32_t a, std::uint32_t b) noexcept {
  return static_cast<std::int32_t>(a - b) < 0;
}

// "192.168.0.2:34964" into `out`.
std::string_view format_endpoint(const UdpEndpoint& e, std::span<char> out) noexcept;

class RpcCall {
 public:
  enum class Event : std::uint8_t {
    None,      // nothing for the caller (progress, or a datagram counted and dropped)
    Response,  // the call's response arrived: decode the datagram; the call is over
    Failed,    // timeout, fault, reject or fragment: failure() says why; the call is over
  };

  RpcCall(const RpcTiming& timing, RpcCounters& counters) noexcept : timing_(timing), counters_(counters) {}

  // Where the request is composed (kMaxRpcDatagram bytes).
  [[nodiscard]] std::span<std::uint8_t> buffer() noexcept { return buffer_; }
  // Sends the `size` bytes of buffer() (a request with header `h`) to `to` from `from`. `size` 0
  // (the composer refused) fails the call at once ("request does not encode").
  Event start(std::size_t size, const RpcHeader& h, const UdpEndpoint& to, CmSocket from, core::TimePoint now,
              CmOutbox& out) noexcept;
  // Stops waiting (a late answer is then counted stale).
  void cancel() noexcept { busy_ = false; }
  [[nodiscard]] bool busy() const noexcept { return busy_; }
  [[nodiscard]] const RpcHeader& request() const noexcept { return header_; }
  // When poll() sends again or gives up; TimePoint::max() while no call runs.
  [[nodiscard]] core::TimePoint next_deadline() const noexcept { return busy_ ? next_ : core::TimePoint::max(); }

  Event poll(core::TimePoint now, CmOutbox& out) noexcept;
  // A decoded datagram from the call's peer socket. Answers to another activity count as
  // unexpected, answers to earlier sequence numbers as stale.
  Event on_datagram(const RpcView& rpc, core::TimePoint now, CmOutbox& out) noexcept;

  [[nodiscard]] std::string_view failure() const noexcept { return failure_.view(); }
  // The last failure was a timeout (no answer), not a refusal.
  [[nodiscard]] bool timed_out() const noexcept { return timed_out_; }
  // The server boot time its last response named (0 before one came).
  [[nodiscard]] std::uint32_t server_boot_time() const noexcept { return server_boot_time_; }

 private:
  Event fail(const char* what) noexcept;
  void send(core::TimePoint now, CmOutbox& out, bool ping) noexcept;

  const RpcTiming& timing_;
  RpcCounters& counters_;
  std::array<std::uint8_t, kMaxRpcDatagram> buffer_{};
  std::size_t size_ = 0;
  RpcHeader header_{};
  UdpEndpoint to_{};
  CmSocket from_ = CmSocket::Client;
  bool busy_ = false;
  bool working_ = false;
  bool timed_out_ = false;  // the server said "working": ping instead of sending the request again
  int tries_left_ = 0;
  int sends_ = 0;     // of the request
  int attempts_ = 0;  // requests and pings
  core::TimePoint next_{};
  core::TimePoint limit_{};
  std::uint32_t server_boot_time_ = 0;
  core::FixedString<200> failure_{};
};

class RpcResponder {
 public:
  enum class Verdict : std::uint8_t { New, Answered, Dropped };

  RpcResponder(std::uint32_t boot_time, RpcCounters& counters) noexcept : boot_time_(boot_time), counters_(counters) {}

  // A request `h` from `from`: New when it is to be handled (answer() then sends the reply), else
  // it was answered from the cache (Answered) or dropped as older than the last call (Dropped).
  Verdict on_request(const RpcHeader& h, const UdpEndpoint& from, CmSocket socket, CmOutbox& out) noexcept;
  // A ping: the cached response when it names the last call, else nocall.
  void on_ping(const RpcHeader& h, const UdpEndpoint& from, CmSocket socket, CmOutbox& out) noexcept;
  // Where the reply to the call on_request() returned New for is composed.
  [[nodiscard]] std::span<std::uint8_t> buffer() noexcept { return reply_; }
  [[nodiscard]] RpcHeader response_header(const RpcHeader& request) const noexcept {
    return response_header_for(request, boot_time_);
  }
  // Sends and keeps the `size` bytes of buffer() as the answer to the last call (size 0: nothing).
  void answer(std::size_t size, CmOutbox& out) noexcept;
  // Answers the last call with a reject and keeps that as its answer.
  void reject(std::uint32_t nca_status, CmOutbox& out) noexcept;
  // Forgets the calls (a new client activity starts from scratch).
  void reset() noexcept { known_ = false; }

 private:
  void send(CmOutbox& out) noexcept;

  std::uint32_t boot_time_;
  RpcCounters& counters_;
  bool known_ = false;
  RpcHeader last_{};
  UdpEndpoint from_{};
  CmSocket socket_ = CmSocket::Server;
  std::array<std::uint8_t, kMaxRpcDatagram> reply_{};
  std::size_t reply_size_ = 0;
};

}  // namespace drivegate::profinet
