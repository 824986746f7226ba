#include "adapters/link/datagram.hpp"

namespace drivegate::link {

std::string ipv4_text(const std::array<std::uint8_t, 4>& address) {
  return std::to_string(address[0]) + "." + std::to_string(address[1]) + "." + std::to_string(address[2]) + "." +
         std::to_string(address[3]);
}

std::string to_string(const Ipv4Endpoint& e) { return ipv4_text(e.address) + ":" + std::to_string(e.port); }

const char* to_string(DatagramStatus s) noexcept {
  switch (s) {
    case DatagramStatus::Sent: return "sent";
    case DatagramStatus::Invalid: return "invalid (empty or too long)";
    case DatagramStatus::Busy: return "send buffer full";
    case DatagramStatus::Down: return "down or unreachable";
  }
  return "?";
}

DatagramCounters DatagramCounterCells::snapshot() const noexcept {
  DatagramCounters c;
  c.tx_datagrams = tx_datagrams.get();
  c.tx_invalid = tx_invalid.get();
  c.tx_busy = tx_busy.get();
  c.tx_down = tx_down.get();
  c.rx_datagrams = rx_datagrams.get();
  c.rx_too_long = rx_too_long.get();
  c.rx_overflow = rx_overflow.get();
  return c;
}

}  // namespace drivegate::link
