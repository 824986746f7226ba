#pragma once
// A CAN transport moves frames and reports the controller's error state; it does not interpret
// frames (DESIGN.md §2 rule 5). Implementations: SocketCAN (production), UDP multicast (a virtual
// bus shared by processes, python-can compatible) and the in-process bus (tests, benchmarks).
//
// send(), send_batch() and receive() are the cyclic path: non-blocking, no allocation, no lock, no
// logging.
// open() may allocate and throws TransportError with one line a person can act on.
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>

#include "adapters/canopen/wire/can_frame.hpp"
#include "core/clock.hpp"

namespace drivegate::canopen {

class TransportError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The CAN controller's fault confinement state [ISO 11898-1 §12.1.4], from error frames.
enum class ControllerState : std::uint8_t { Active, Warning, Passive, BusOff };
const char* to_string(ControllerState s) noexcept;

enum class SendResult : std::uint8_t {
  Sent,
  Busy,     // transmit queue full; try again later (counted as tx_overflows)
  Invalid,  // frame cannot exist on the bus (dlc > 8, id too large)
  Down,     // transport not open, or the controller is bus-off
};

// What send_batch() did with its frames, front first: `taken` frames were handled (sent, or refused
// for good as send() would return Invalid or Down), `sent` of them went out. With `busy` the frame
// at `taken` met a full transmit queue (counted once in tx_overflows) and neither it nor the ones
// after it were sent; otherwise taken is the number of frames given.
struct SendBatchResult {
  std::size_t taken = 0;
  std::size_t sent = 0;
  bool busy = false;
};

struct TransportCounters {
  std::uint64_t rx_frames = 0;
  std::uint64_t tx_frames = 0;
  std::uint64_t rx_malformed = 0;   // datagrams/frames that could not be decoded (dropped)
  std::uint64_t rx_filtered = 0;    // well-formed but not for us (own echo, other ids)
  std::uint64_t tx_overflows = 0;   // send() returned Busy
  std::uint64_t error_frames = 0;   // controller error reports
  std::uint64_t bus_off = 0;        // transitions into bus-off
  std::uint64_t restarts = 0;       // recoveries from bus-off
};

class Transport {
 public:
  virtual ~Transport() = default;

  // Open the transport; throws TransportError with a clear, single-line reason.
  virtual void open() = 0;
  virtual void close() noexcept = 0;
  [[nodiscard]] virtual bool is_open() const noexcept = 0;

  // Non-blocking: copies up to out.size() received frames (oldest first), stamping each with its
  // reception time (the transport's time stamp when it has one, else `now`). Error frames are not
  // returned; they update controller_state() and the counters.
  virtual std::size_t receive(std::span<CanFrame> out, core::TimePoint now) noexcept = 0;
  // Non-blocking send of one frame.
  virtual SendResult send(const CanFrame& frame, core::TimePoint now) noexcept = 0;
  // Non-blocking send of frames in order, in as few system calls as the transport allows (SocketCAN
  // and UDP multicast: one sendmmsg per batch); the result and the counters are what send() per
  // frame, stopping at the first Busy, would give. This default does exactly that.
  virtual SendBatchResult send_batch(std::span<const CanFrame> frames, core::TimePoint now) noexcept {
    SendBatchResult r;
    for (const CanFrame& f : frames) {
      const SendResult s = send(f, now);
      if (s == SendResult::Busy) {
        r.busy = true;
        break;
      }
      ++r.taken;
      if (s == SendResult::Sent) ++r.sent;
    }
    return r;
  }

  [[nodiscard]] virtual ControllerState controller_state() const noexcept = 0;
  // Safe to call from any thread (relaxed atomics inside).
  [[nodiscard]] virtual TransportCounters counters() const noexcept = 0;
  // "socketcan can0 @ 500 kbit/s", "udp-multicast 239.74.163.2:43113 on lo", ...
  [[nodiscard]] virtual std::string describe() const = 0;
  // A file descriptor that becomes readable when frames arrive, or -1 (for processes that wait
  // in poll(); the daemon's cycle thread does not).
  [[nodiscard]] virtual int wait_fd() const noexcept { return -1; }
};

}  // namespace drivegate::canopen
