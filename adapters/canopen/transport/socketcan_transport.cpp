#include "adapters/canopen/transport/socketcan_transport.hpp"

#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <utility>

#include "adapters/canopen/transport/batch_send.hpp"
#include "core/errno_text.hpp"
#include "core/fd_guard.hpp"

namespace drivegate::canopen {
namespace {

constexpr std::int64_t kNsPerSecond = 1'000'000'000;

using core::errno_text;

[[noreturn]] void fail(const std::string& what) { throw TransportError("socketcan: " + what); }

std::string hex(std::uint32_t v) {
  static constexpr char kDigits[] = "0123456789ABCDEF";
  std::string s;
  do {
    s.insert(s.begin(), kDigits[v & 0xFU]);
    v >>= 4;
  } while (v != 0);
  return s + "h";
}

std::int64_t ns_of(const timespec& t) noexcept { return std::int64_t{t.tv_sec} * kNsPerSecond + t.tv_nsec; }

template <typename T>
void set_option(int fd, int level, int name, const T& value, const char* name_text) {
  if (::setsockopt(fd, level, name, &value, sizeof value) != 0) {
    fail(std::string("cannot configure the CAN socket (") + name_text + ": " + errno_text(errno) + ")");
  }
}

}  // namespace

std::vector<can_filter> build_can_filters(std::span<const CanIdFilter> filters) {
  std::vector<can_filter> out;
  out.reserve(filters.size());
  for (const auto& f : filters) {
    const std::uint32_t max = f.extended ? kMaxExtendedId : kMaxStandardId;
    if (f.id > max || f.mask > max) {
      fail("receive filter " + hex(f.id) + "/" + hex(f.mask) + " is outside the " +
           (f.extended ? "29" : "11") + "-bit identifier range");
    }
    // EFF in the mask makes the id format part of the match; RTR is left out so that data and
    // remote frames both pass.
    can_filter k{};
    k.can_id = f.id | (f.extended ? CAN_EFF_FLAG : 0U);
    k.can_mask = f.mask | CAN_EFF_FLAG;
    out.push_back(k);
  }
  return out;
}

can_frame to_linux_frame(const CanFrame& frame) noexcept {
  can_frame k{};
  k.can_id = frame.id | (frame.extended ? CAN_EFF_FLAG : 0U) | (frame.remote ? CAN_RTR_FLAG : 0U);
  k.len = frame.dlc;  // for a remote frame: the requested length
  if (!frame.remote) std::memcpy(k.data, frame.data.data(), frame.dlc);
  return k;
}

bool from_linux_frame(const can_frame& in, CanFrame& out) noexcept {
  if ((in.can_id & CAN_ERR_FLAG) != 0 || in.len > kMaxDlc) return false;
  out = CanFrame{};
  out.extended = (in.can_id & CAN_EFF_FLAG) != 0;
  out.remote = (in.can_id & CAN_RTR_FLAG) != 0;
  out.id = in.can_id & (out.extended ? CAN_EFF_MASK : CAN_SFF_MASK);
  out.dlc = in.len;
  if (!out.remote) std::memcpy(out.data.data(), in.data, in.len);
  return true;
}

ErrorFrameEffect decode_error_frame(std::uint32_t can_id, std::span<const std::uint8_t> data) noexcept {
  ErrorFrameEffect e;
  if ((can_id & CAN_ERR_RESTARTED) != 0) {
    e.state = ControllerState::Active;
    e.restarted = true;
  }
  if ((can_id & CAN_ERR_CRTL) != 0 && data.size() > 1) {
    const std::uint8_t status = data[1];  // data[1]: controller status [linux/can/error.h]
    if ((status & (CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE)) != 0) {
      e.state = ControllerState::Passive;
    } else if ((status & (CAN_ERR_CRTL_RX_WARNING | CAN_ERR_CRTL_TX_WARNING)) != 0) {
      e.state = ControllerState::Warning;
    } else if ((status & CAN_ERR_CRTL_ACTIVE) != 0) {
      e.state = ControllerState::Active;
    }
  }
  if ((can_id & CAN_ERR_BUSOFF) != 0) e.state = ControllerState::BusOff;
  return e;
}

core::TimePoint reception_time(core::TimePoint now, const timespec& realtime_now, const timespec& kernel_stamp) noexcept {
  const std::int64_t age = ns_of(realtime_now) - ns_of(kernel_stamp);
  return age > 0 ? now - core::Duration(age) : now;
}

SocketCanTransport::SocketCanTransport(SocketCanOptions options) : options_(std::move(options)) {
  // The message headers point into this object's own buffers for its whole life.
  for (std::size_t i = 0; i < kCanBatch; ++i) {
    rx_iov_[i] = iovec{&rx_frames_[i], sizeof(can_frame)};
    rx_msgs_[i].msg_hdr.msg_iov = &rx_iov_[i];
    rx_msgs_[i].msg_hdr.msg_iovlen = 1;
    tx_iov_[i] = iovec{&tx_frames_[i], sizeof(can_frame)};
    tx_msgs_[i].msg_hdr.msg_iov = &tx_iov_[i];
    tx_msgs_[i].msg_hdr.msg_iovlen = 1;
  }
}

SocketCanTransport::~SocketCanTransport() { close(); }

void SocketCanTransport::open() {
  if (is_open()) return;
  const std::string& name = options_.interface;
  const std::string bring_up = "ip link set " + name + " up type can bitrate " + std::to_string(options_.bitrate);

  core::FdGuard fd(::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW));
  if (fd.get() < 0) {
    const int e = errno;
    if (e == EAFNOSUPPORT) {
      fail("this kernel has no CAN support (socket(AF_CAN): " + errno_text(e) +
           "); load the can and can_raw modules, or use transport udp-multicast (a virtual bus) or sim");
    }
    if (e == EPROTONOSUPPORT) {
      fail("this kernel has no raw CAN sockets (socket(AF_CAN, CAN_RAW): " + errno_text(e) +
           "); load the can_raw module, or use transport udp-multicast (a virtual bus) or sim");
    }
    fail("cannot create a CAN socket (socket(AF_CAN): " + errno_text(e) + ")");
  }
  if (name.empty() || name.size() >= IFNAMSIZ) {
    fail("'" + name + "' is not an interface name (1 to " + std::to_string(IFNAMSIZ - 1) + " characters)");
  }
  const unsigned index = ::if_nametoindex(name.c_str());
  if (index == 0) {
    fail("no CAN interface '" + name + "' (if_nametoindex: " + errno_text(errno) + "); create it with '" + bring_up +
         "', or for a virtual bus 'ip link add dev " + name + " type vcan && ip link set " + name + " up'");
  }

  const auto filters = build_can_filters(options_.filters);
  if (!filters.empty()) {
    if (::setsockopt(fd.get(), SOL_CAN_RAW, CAN_RAW_FILTER, filters.data(),
                     static_cast<socklen_t>(filters.size() * sizeof(can_filter))) != 0) {
      fail("cannot set " + std::to_string(filters.size()) + " receive filters (CAN_RAW_FILTER: " + errno_text(errno) + ")");
    }
  }
  // Every error class: the controller state comes from these (and nothing else tells us).
  set_option(fd.get(), SOL_CAN_RAW, CAN_RAW_ERR_FILTER, can_err_mask_t{CAN_ERR_MASK}, "CAN_RAW_ERR_FILTER");
  // Our frames are neither echoed to other sockets on this host nor to us.
  set_option(fd.get(), SOL_CAN_RAW, CAN_RAW_LOOPBACK, int{0}, "CAN_RAW_LOOPBACK");
  set_option(fd.get(), SOL_CAN_RAW, CAN_RAW_RECV_OWN_MSGS, int{0}, "CAN_RAW_RECV_OWN_MSGS");
  // Kernel reception stamps are better than the time receive() runs; without them, `now`.
  const int on = 1;
  kernel_stamps_ = ::setsockopt(fd.get(), SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on) == 0;

  sockaddr_can address{};
  address.can_family = AF_CAN;
  address.can_ifindex = static_cast<int>(index);
  if (::bind(fd.get(), reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
    const int e = errno;
    if (e == ENODEV) fail("'" + name + "' is not a CAN interface (bind: " + errno_text(e) + ")");
    fail("cannot bind to '" + name + "' (bind: " + errno_text(e) + ")");
  }
  ifreq request{};
  std::memcpy(request.ifr_name, name.c_str(), name.size() + 1);
  if (::ioctl(fd.get(), SIOCGIFFLAGS, &request) == 0 && (request.ifr_flags & IFF_UP) == 0) {
    fail("CAN interface '" + name + "' is down; bring it up with '" + bring_up + "'");
  }

  controller_.reset();
  fd_ = fd.release();
}

void SocketCanTransport::close() noexcept {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

std::size_t SocketCanTransport::receive(std::span<CanFrame> out, core::TimePoint now) noexcept {
  if (fd_ < 0) return 0;
  std::size_t n = 0;
  bool have_realtime = false;
  timespec realtime{};
  while (n < out.size()) {
    // No more messages than frames still fit in `out`: every one of them may be a frame.
    const std::size_t want = std::min(out.size() - n, kCanBatch);
    for (std::size_t i = 0; i < want; ++i) {
      rx_msgs_[i].msg_hdr.msg_control = rx_control_[i].bytes.data();
      rx_msgs_[i].msg_hdr.msg_controllen = kernel_stamps_ ? rx_control_[i].bytes.size() : 0;
    }
    const int got = ::recvmmsg(fd_, rx_msgs_.data(), static_cast<unsigned>(want), MSG_DONTWAIT, nullptr);
    if (got < 0) {
      if (errno == EINTR) continue;
      break;  // EAGAIN: nothing more; ENETDOWN and the like show as error frames or on send()
    }
    const auto count = static_cast<std::size_t>(got);
    for (std::size_t i = 0; i < count; ++i) {
      const can_frame& k = rx_frames_[i];
      msghdr& msg = rx_msgs_[i].msg_hdr;
      if (rx_msgs_[i].msg_len != sizeof k) {  // CAN FD frames are not enabled on this socket
        counters_.rx_malformed.add();
        continue;
      }
      if ((k.can_id & CAN_ERR_FLAG) != 0) {
        controller_.report(decode_error_frame(k.can_id & CAN_ERR_MASK, {k.data, sizeof k.data}), counters_);
        continue;
      }
      CanFrame& f = out[n];
      if (!from_linux_frame(k, f)) {
        counters_.rx_malformed.add();
        continue;
      }
      f.timestamp = now;
      for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c != nullptr; c = CMSG_NXTHDR(&msg, c)) {
        if (c->cmsg_level != SOL_SOCKET || c->cmsg_type != SCM_TIMESTAMPNS) continue;
        timespec stamp{};
        std::memcpy(&stamp, CMSG_DATA(c), sizeof stamp);
        if (!have_realtime) {  // one clock read per call, and only when a stamp needs it
          ::clock_gettime(CLOCK_REALTIME, &realtime);
          have_realtime = true;
        }
        f.timestamp = reception_time(now, realtime, stamp);
      }
      ++n;
      counters_.rx_frames.add();
    }
    if (count < want) break;  // nothing more pending
  }
  return n;
}

SendResult SocketCanTransport::send(const CanFrame& frame, core::TimePoint now) noexcept {
  if (fd_ < 0 || controller_.state() == ControllerState::BusOff) return SendResult::Down;
  if (!frame.valid()) return SendResult::Invalid;
  const auto r = send_batch({&frame, 1}, now);
  return r.busy ? SendResult::Busy : r.sent == 1 ? SendResult::Sent : SendResult::Down;
}

SendBatchResult SocketCanTransport::send_batch(std::span<const CanFrame> frames, core::TimePoint /*now*/) noexcept {
  SendBatchResult r;
  // Down for every frame while bus-off: the kernel would refuse or queue them anyway.
  if (fd_ < 0 || controller_.state() == ControllerState::BusOff) {
    r.taken = frames.size();
    return r;
  }
  return send_in_batches(fd_, frames, tx_msgs_, tx_frame_of_, counters_,
                         [this](std::size_t slot, const CanFrame& f) { tx_frames_[slot] = to_linux_frame(f); });
}

std::string SocketCanTransport::describe() const {
  return "socketcan " + options_.interface + " @ " + std::to_string(options_.bitrate / 1000) + " kbit/s";
}

}  // namespace drivegate::canopen
