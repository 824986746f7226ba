#include "adapters/profinet/sim/pn_sim_network.hpp"

#include <algorithm>
#include <stdexcept>

namespace drivegate::profinet {

PnDevice& PnSimNetwork::add(const PnDeviceConfig& config, PnPersona& persona) {
  if (std::any_of(devices_.begin(), devices_.end(), [&config](const auto& d) { return d->mac() == config.dcp.mac; })) {
    throw std::invalid_argument("simulated PROFINET network: two devices with one MAC address");
  }
  devices_.push_back(std::make_unique<PnDevice>(config, persona));
  return *devices_.back();
}

void PnSimNetwork::on_frame(std::span<const std::uint8_t> frame, core::TimePoint now) noexcept {
  ++counters_.frames_in;
  if (frame.size() < 6) {
    ++counters_.frames_unrouted;
    return;
  }
  const bool multicast = (frame[0] & 1U) != 0;
  bool routed = false;
  for (const auto& d : devices_) {
    if (multicast || std::equal(d->mac().begin(), d->mac().end(), frame.begin())) {
      routed = true;
      (void)d->on_frame(frame, now);
    }
  }
  if (!routed) ++counters_.frames_unrouted;
}

bool PnSimNetwork::on_datagram(std::span<const std::uint8_t> datagram, const UdpEndpoint& from, const UdpEndpoint& to,
                               core::TimePoint now, PnSimWire& wire) noexcept {
  ++counters_.datagrams_in;
  const bool server = to.port == kRpcUdpPort;
  if (to.ip != 0 && (server || to.port == kSimDeviceClientPort)) {
    for (const auto& d : devices_) {
      if (d->ip() != to.ip) continue;
      d->on_datagram(datagram, from, server ? CmSocket::Server : CmSocket::Client, now, out_);
      flush(*d, wire);
      return true;
    }
  }
  ++counters_.datagrams_unrouted;
  return false;
}

void PnSimNetwork::flush(PnDevice& d, PnSimWire& wire) noexcept {
  while (!out_.empty()) {
    const CmDatagram& g = out_.front();
    const UdpEndpoint from{d.ip(), g.from == CmSocket::Server ? kRpcUdpPort : kSimDeviceClientPort};
    wire.send_datagram(from, g.to, g.view());
    out_.pop();
  }
}

void PnSimNetwork::poll(core::TimePoint now, PnSimWire& wire) noexcept {
  for (const auto& d : devices_) {
    while (const std::size_t n = d->poll(now, frame_, out_)) wire.send_frame(std::span<const std::uint8_t>(frame_).first(n));
    flush(*d, wire);
  }
  counters_.outbox_overflows = out_.overflows();
}

core::TimePoint PnSimNetwork::next_deadline() const noexcept {
  core::TimePoint t = core::TimePoint::max();
  for (const auto& d : devices_) t = std::min(t, d->next_deadline());
  return t;
}

}  // namespace drivegate::profinet
