#pragma once
// A ProfinetBus transport onto simulated devices in the same process (a PnSimNetwork, sim/): what
// the bus sends goes into the network at once; what the devices send waits in fixed queues
// (link::MemoryLink, link::MemoryDatagramPort) until the bus reads it; the transport's peer runs
// the devices every cycle, at the start of the bus' receive(). The unit tests of the bus use it,
// and `transport: sim` (the simulated devices of a plan inside drivegated).
#include <cstdint>
#include <memory>

#include "adapters/profinet/profinet_bus.hpp"
#include "adapters/profinet/sim/pn_sim_network.hpp"

namespace drivegate::profinet {

// The controller's addresses on the simulated network.
struct SimControllerAddress {
  MacAddress mac{0x02, 0x00, 0x00, 0x00, 0x00, 0x01};
  std::uint32_t ip = 0;          // host order; the devices' subnet
  std::uint16_t client_port = 0xC001;
};

// A transport onto `network`. `keep` holds whatever the network needs alive (itself, its personas)
// for as long as the transport's parts live.
ProfinetTransport sim_transport(PnSimNetwork& network, std::shared_ptr<void> keep, const SimControllerAddress& address);

// The bus of a `transport: sim` plan with its simulated devices. Throws core::BusError naming the
// station when a device cannot be made.
std::unique_ptr<ProfinetBus> make_simulated_profinet_bus(const config::BusPlan& plan);

}  // namespace drivegate::profinet
