#pragma once
// Several simulated PROFINET IO devices (PnDevice) on one network segment, sans-I/O: the frames the
// controller side sends go to the device they are addressed to (a multicast to every device), the
// datagrams to the device whose IP address (its current one: DCP may change it) they name, at
// its RPC server port 34964 or its client port (the answers to its ApplicationReady calls); what
// the devices send goes to the caller's PnSimWire. A transport (in-memory links in tests, a raw
// socket and UDP endpoints on a veth end) sits on both sides.
//
// add() allocates (construction); on_frame(), on_datagram(), poll() do not.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "adapters/profinet/sim/pn_device.hpp"

namespace drivegate::profinet {

// [sim] The UDP port a simulated device calls the controller from (its ApplicationReady).
inline constexpr std::uint16_t kSimDeviceClientPort = 49152;

// Where the devices' traffic goes.
class PnSimWire {
 public:
  virtual void send_frame(std::span<const std::uint8_t> frame) noexcept = 0;
  virtual void send_datagram(const UdpEndpoint& from, const UdpEndpoint& to, std::span<const std::uint8_t> bytes) noexcept = 0;

 protected:
  PnSimWire() = default;
  PnSimWire(const PnSimWire&) = default;
  PnSimWire& operator=(const PnSimWire&) = default;
  ~PnSimWire() = default;
};

struct PnSimNetworkCounters {
  std::uint64_t frames_in = 0, frames_unrouted = 0;        // a unicast to no device's MAC
  std::uint64_t datagrams_in = 0, datagrams_unrouted = 0;  // to no device's IP or port
  std::uint64_t outbox_overflows = 0;
};

class PnSimNetwork {
 public:
  // A device with its persona (which must outlive the network). Throws as PnDevice does, and
  // std::invalid_argument for a MAC already on the network.
  PnDevice& add(const PnDeviceConfig& config, PnPersona& persona);
  [[nodiscard]] std::size_t size() const noexcept { return devices_.size(); }
  [[nodiscard]] PnDevice& device(std::size_t i) noexcept { return *devices_[i]; }

  void on_frame(std::span<const std::uint8_t> frame, core::TimePoint now) noexcept;
  // A datagram sent by `from` to `to`; the device's answers go to `wire` at once. False when no
  // device has `to`'s address and port.
  bool on_datagram(std::span<const std::uint8_t> datagram, const UdpEndpoint& from, const UdpEndpoint& to,
                   core::TimePoint now, PnSimWire& wire) noexcept;
  // Runs every device; what they send goes to `wire`.
  void poll(core::TimePoint now, PnSimWire& wire) noexcept;
  [[nodiscard]] core::TimePoint next_deadline() const noexcept;
  [[nodiscard]] const PnSimNetworkCounters& counters() const noexcept { return counters_; }

 private:
  void flush(PnDevice& d, PnSimWire& wire) noexcept;

  std::vector<std::unique_ptr<PnDevice>> devices_;
  CmOutbox out_;
  std::array<std::uint8_t, kMaxFrameSize> frame_{};
  PnSimNetworkCounters counters_{};
};

}  // namespace drivegate::profinet
