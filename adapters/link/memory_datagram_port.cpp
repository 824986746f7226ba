#include "adapters/link/memory_datagram_port.hpp"

#include <algorithm>
#include <cstring>

namespace drivegate::link {

MemoryDatagramPort::MemoryDatagramPort(const Ipv4Endpoint& local, std::size_t capacity)
    : local_(local), slots_(std::max<std::size_t>(capacity, 1)) {}

MemoryDatagramPort::~MemoryDatagramPort() { detach(); }

void MemoryDatagramPort::detach() noexcept {
  if (peer_ != nullptr && peer_->peer_ == this) peer_->peer_ = nullptr;
  peer_ = nullptr;
}

void MemoryDatagramPort::connect(MemoryDatagramPort& a, MemoryDatagramPort& b) noexcept {
  a.detach();
  b.detach();
  a.peer_ = &b;
  b.peer_ = &a;
}

void MemoryDatagramPort::close() noexcept {
  open_ = false;
  head_ = 0;
  count_ = 0;
}

bool MemoryDatagramPort::deliver(const Ipv4Endpoint& from, std::span<const std::uint8_t> payload) noexcept {
  if (!open_) return false;
  if (payload.size() > kMaxDatagramBytes) {
    counters_.rx_too_long.add();
    return false;
  }
  if (count_ == slots_.size()) {
    counters_.rx_overflow.add();
    return false;
  }
  Datagram& slot = slots_[(head_ + count_) % slots_.size()];
  std::memcpy(slot.bytes.data(), payload.data(), payload.size());
  slot.size = payload.size();
  slot.from = from;
  ++count_;
  return true;
}

DatagramStatus MemoryDatagramPort::send_to(const Ipv4Endpoint& to, std::span<const std::uint8_t> payload) noexcept {
  if (!sendable_datagram(payload)) {
    counters_.tx_invalid.add();
    return DatagramStatus::Invalid;
  }
  if (!open_) {
    counters_.tx_down.add();
    return DatagramStatus::Down;
  }
  counters_.tx_datagrams.add();
  if (peer_ != nullptr && peer_->is_open() && to == peer_->local_) peer_->deliver(local_, payload);
  return DatagramStatus::Sent;
}

bool MemoryDatagramPort::receive_from(Datagram& out) noexcept {
  if (count_ == 0) return false;
  const Datagram& slot = slots_[head_];
  std::memcpy(out.bytes.data(), slot.bytes.data(), slot.size);
  out.size = slot.size;
  out.from = slot.from;
  head_ = (head_ + 1) % slots_.size();
  --count_;
  counters_.rx_datagrams.add();
  return true;
}

std::string MemoryDatagramPort::describe() const { return "memory udp " + to_string(local_); }

}  // namespace drivegate::link
