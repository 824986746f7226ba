#pragma once
// The production transport: a Linux SocketCAN raw socket (AF_CAN, CAN_RAW) on a named interface
// (DESIGN.md §5). Kernel receive filters for the COB-IDs the bus wants, error frames enabled and
// turned into the controller state (bus-off detection: AKD part 1 §2.4 and §16 step 14 leave
// detection and recovery to the master's own controller), own frames not looped back, all I/O
// non-blocking. The interface's bit rate and restart-ms are set outside, with `ip link`.
//
// I/O is batched: receive() reads what is pending with recvmmsg (up to kCanBatch frames a call),
// send_batch() writes up to kCanBatch frames with one sendmmsg.
//
// The pieces that do not need a CAN socket (filters, frame mapping, error frame decoding, time
// stamps) are pure functions, so they are tested where the kernel has no CAN support.
#include <linux/can.h>
#include <sys/socket.h>
#include <time.h>

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "adapters/canopen/transport/controller_tracker.hpp"
#include "adapters/canopen/transport/counter_cells.hpp"
#include "adapters/canopen/transport/transport.hpp"

namespace drivegate::canopen {

// Receive frames whose id matches `id` in the bits set in `mask`, in one id format. Data and
// remote frames both pass.
struct CanIdFilter {
  std::uint32_t id = 0;
  std::uint32_t mask = kMaxStandardId;
  bool extended = false;
};

// Frames per recvmmsg / sendmmsg call.
inline constexpr std::size_t kCanBatch = 64;

struct SocketCanOptions {
  std::string interface = "can0";
  std::uint32_t bitrate = 500000;   // for describe() and the hints in error messages
  std::vector<CanIdFilter> filters;  // empty: every frame
};

// The kernel filter list for CAN_RAW_FILTER. Throws TransportError for an id or mask outside its
// format's range.
std::vector<can_filter> build_can_filters(std::span<const CanIdFilter> filters);

// Our frame to the kernel's and back (EFF and RTR flags). from_linux_frame() refuses error frames
// and lengths over 8.
can_frame to_linux_frame(const CanFrame& frame) noexcept;
bool from_linux_frame(const can_frame& in, CanFrame& out) noexcept;

// What an error frame (CAN_ERR_FLAG set; `can_id` its class bits, `data` its 8 bytes) says about
// the controller [linux/can/error.h]: BUSOFF -> BusOff; CRTL with RX/TX passive -> Passive,
// with RX/TX warning -> Warning, with ACTIVE -> Active; RESTARTED -> Active and restarted.
// Other classes (protocol violations, lost arbitration, ACK errors) leave the state as it is.
ErrorFrameEffect decode_error_frame(std::uint32_t can_id, std::span<const std::uint8_t> data) noexcept;

// A frame's reception time on the monotonic (or virtual) time line of `now`, from the kernel's
// SO_TIMESTAMPNS stamp (CLOCK_REALTIME): `now` minus how long ago the kernel received it, as
// measured on the realtime clock. A stamp in the future (clock stepped) gives `now`.
core::TimePoint reception_time(core::TimePoint now, const timespec& realtime_now, const timespec& kernel_stamp) noexcept;

class SocketCanTransport final : public Transport {
 public:
  explicit SocketCanTransport(SocketCanOptions options);
  ~SocketCanTransport() override;
  SocketCanTransport(const SocketCanTransport&) = delete;
  SocketCanTransport& operator=(const SocketCanTransport&) = delete;

  void open() override;
  void close() noexcept override;
  [[nodiscard]] bool is_open() const noexcept override { return fd_ >= 0; }

  std::size_t receive(std::span<CanFrame> out, core::TimePoint now) noexcept override;
  // Down while the controller is bus-off: the kernel would refuse or queue the frame anyway.
  SendResult send(const CanFrame& frame, core::TimePoint now) noexcept override;
  SendBatchResult send_batch(std::span<const CanFrame> frames, core::TimePoint now) noexcept override;

  [[nodiscard]] ControllerState controller_state() const noexcept override { return controller_.state(); }
  [[nodiscard]] TransportCounters counters() const noexcept override { return counters_.snapshot(); }
  [[nodiscard]] std::string describe() const override;
  [[nodiscard]] int wait_fd() const noexcept override { return fd_; }

 private:
  SocketCanOptions options_;
  int fd_ = -1;
  bool kernel_stamps_ = false;  // SO_TIMESTAMPNS accepted
  CounterCells counters_;
  ControllerTracker controller_;
  // Per message of a batch: the kernel's frame and room for one SCM_TIMESTAMPNS control message
  // (CMSG_SPACE(sizeof(timespec)) on 64-bit Linux).
  struct alignas(8) Control {
    std::array<unsigned char, 64> bytes{};
  };
  std::array<can_frame, kCanBatch> rx_frames_{};
  std::array<Control, kCanBatch> rx_control_{};
  std::array<iovec, kCanBatch> rx_iov_{};
  std::array<mmsghdr, kCanBatch> rx_msgs_{};
  std::array<can_frame, kCanBatch> tx_frames_{};
  std::array<iovec, kCanBatch> tx_iov_{};
  std::array<mmsghdr, kCanBatch> tx_msgs_{};
  std::array<std::size_t, kCanBatch> tx_frame_of_{};  // the frame (index into the batch) of each message
};

}  // namespace drivegate::canopen
