#pragma once
// The send_batch() loop of the socket transports (SocketCAN, UDP multicast): the frames are staged
// into up to N message slots, each batch goes out with one sendmmsg, a partial send is resumed, and
// a full transmit queue ends the call (counted once, reported busy). Cyclic path: no allocation.
#include <sys/socket.h>

#include <array>
#include <cerrno>
#include <cstddef>
#include <span>

#include "adapters/canopen/transport/counter_cells.hpp"
#include "adapters/canopen/transport/transport.hpp"

namespace drivegate::canopen {

// `stage(slot, frame)` puts a valid frame into message slot `slot` of `msgs`; invalid frames are
// refused here and never reach the socket. `frame_of` remembers which frame each slot carries.
template <std::size_t N, typename Stage>
SendBatchResult send_in_batches(int fd, std::span<const CanFrame> frames, std::array<mmsghdr, N>& msgs,
                                std::array<std::size_t, N>& frame_of, CounterCells& counters,
                                Stage&& stage) noexcept {
  SendBatchResult r;
  while (r.taken < frames.size()) {
    std::size_t count = 0;
    std::size_t next = r.taken;
    for (; next < frames.size() && count < N; ++next) {
      if (!frames[next].valid()) continue;
      stage(count, frames[next]);
      frame_of[count] = next;
      ++count;
    }
    for (std::size_t done = 0; done < count;) {
      const int sent = ::sendmmsg(fd, msgs.data() + done, static_cast<unsigned>(count - done), MSG_DONTWAIT);
      if (sent > 0) {
        done += static_cast<std::size_t>(sent);
        r.sent += static_cast<std::size_t>(sent);
        counters.tx_frames.add(static_cast<std::uint64_t>(sent));
        continue;
      }
      if (errno == EINTR) continue;
      // A full transmit queue: EAGAIN, or ENOBUFS (what SocketCAN reports).
      if (errno == EAGAIN || errno == EWOULDBLOCK || errno == ENOBUFS) {
        counters.tx_overflows.add();
        r.taken = frame_of[done];
        r.busy = true;
        return r;
      }
      ++done;  // ENETDOWN, ENETUNREACH, interface gone: this frame is refused (Down); retrying fixes nothing
    }
    r.taken = next;
  }
  return r;
}

}  // namespace drivegate::canopen
