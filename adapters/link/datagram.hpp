#pragma once
// UDP datagrams for the engines that talk over IP (PROFINET's DCE/RPC connection management, UDP
// port 34964): a DatagramPort sends a payload to an IPv4 address and port, and hands up what came
// in with the address and port it came from, so that a sans-I/O engine gets bytes and a source and
// never a socket. Implementations: UdpEndpoint (a UDP socket on one named interface's IPv4 address)
// and MemoryDatagramPort (in-process pairs for unit tests).
//
// send_to(), receive_from() and counters() are the cyclic path: non-blocking, no heap allocation,
// no lock, no logging. open() may allocate and throws LinkError (link.hpp) with one line a person
// can act on. One thread uses a port; counters() may be read from any.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "core/counter_cell.hpp"

namespace drivegate::link {

struct Ipv4Endpoint {
  std::array<std::uint8_t, 4> address{};  // in network order: 192.168.0.1 is {192, 168, 0, 1}
  std::uint16_t port = 0;
  bool operator==(const Ipv4Endpoint&) const = default;
};
// "192.168.0.1"
std::string ipv4_text(const std::array<std::uint8_t, 4>& address);
// "192.168.0.1:34964"
std::string to_string(const Ipv4Endpoint& e);

// The longest payload a port sends or hands up. PROFINET's RPC fragments stay below one Ethernet
// frame's 1472 bytes of UDP payload; 4 KiB leaves room for peers that rely on IP fragmentation.
inline constexpr std::size_t kMaxDatagramBytes = 4096;

// One received datagram in memory the caller owns.
struct Datagram {
  std::array<std::uint8_t, kMaxDatagramBytes> bytes{};
  std::size_t size = 0;
  Ipv4Endpoint from{};

  [[nodiscard]] std::span<const std::uint8_t> view() const noexcept { return {bytes.data(), size}; }
};

enum class DatagramStatus : std::uint8_t {
  Sent,     // handed to the kernel (UDP: no word on whether it arrives)
  Invalid,  // empty or longer than kMaxDatagramBytes: not sent
  Busy,     // the send buffer was full: not sent
  Down,     // closed, the interface is down, or no route to the address: not sent
};
const char* to_string(DatagramStatus s) noexcept;

struct DatagramCounters {
  std::uint64_t tx_datagrams = 0;
  std::uint64_t tx_invalid = 0;   // refused by send_to(): empty or too long
  std::uint64_t tx_busy = 0;      // not sent: send buffer full
  std::uint64_t tx_down = 0;      // not sent: closed, interface down, no route
  std::uint64_t rx_datagrams = 0; // handed up by receive_from()
  std::uint64_t rx_too_long = 0;  // dropped: longer than kMaxDatagramBytes
  std::uint64_t rx_overflow = 0;  // dropped before we saw them: receive queue full
};

// DatagramCounters as relaxed atomics: the owning thread writes them, any thread may read them.
struct DatagramCounterCells {
  core::CounterCell tx_datagrams, tx_invalid, tx_busy, tx_down, rx_datagrams, rx_too_long, rx_overflow;
  [[nodiscard]] DatagramCounters snapshot() const noexcept;
};

// Whether a payload may be sent: 1 to kMaxDatagramBytes bytes.
constexpr bool sendable_datagram(std::span<const std::uint8_t> payload) noexcept {
  return !payload.empty() && payload.size() <= kMaxDatagramBytes;
}

class DatagramPort {
 public:
  virtual ~DatagramPort() = default;

  // Opens the port; throws LinkError with one line that says what is wrong and what to do.
  virtual void open() = 0;
  virtual void close() noexcept = 0;
  [[nodiscard]] virtual bool is_open() const noexcept = 0;
  // The address and port datagrams go out from (the port the kernel chose when 0 was asked for);
  // all zero while closed.
  [[nodiscard]] virtual Ipv4Endpoint local() const noexcept = 0;

  // Non-blocking: sends `payload` as one datagram to `to`.
  virtual DatagramStatus send_to(const Ipv4Endpoint& to, std::span<const std::uint8_t> payload) noexcept = 0;
  // Non-blocking: the oldest pending datagram into `out` (true), or false when none is pending.
  // Datagrams too long for `out` are dropped and counted, never handed up cut.
  virtual bool receive_from(Datagram& out) noexcept = 0;

  // A file descriptor that becomes readable when datagrams arrive, or -1.
  [[nodiscard]] virtual int wait_fd() const noexcept = 0;
  [[nodiscard]] virtual DatagramCounters counters() const noexcept = 0;
  // "udp eth1 192.168.0.1:34964", ...
  [[nodiscard]] virtual std::string describe() const = 0;
};

}  // namespace drivegate::link
