// A simulated PROFINET IO device (adapters/profinet/sim PnDevice, AKD persona, telegram 1) in data
// exchange with the controller engines of tests/profinet_sim, then on traffic and faults from
// outside, on virtual time.
//
// Input: records [kind u8] [time step in ms u8] [length u16 big-endian] [length octets], kind:
//   0  a frame to the device's port (DCP, RT cyclic, anything)
//   1  a datagram to its RPC server port 34964 from the controller's address
//   2  a datagram to its client port (as an answer to its ApplicationReady call)
//   3  a fault: the first octet picks power loss, power return, abort the AR, lose the next
//      received / sent cyclic frames, a drive fault (the second and third octets its number)
//   other: the controller's STW1 (the first two octets)
// Invariants: every frame the device gives is one Ethernet frame (60..1518 octets) from its MAC that
// decodes as DCP or RT cyclic; every datagram decodes as DCE/RPC from its address; a powered device
// has cyclic engines exactly while it has an AR; nothing it holds as a name breaks the NameOfStation rules.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "adapters/profinet/wire/byte_order.hpp"
#include "tests/profinet_sim/sim_bench.hpp"

namespace {

using namespace drivegate::profinet;
using namespace drivegate::profinet::test;

void check_frame(std::span<const std::uint8_t> frame) {
  if (frame.size() < kMinFrameSize || frame.size() > kMaxFrameSize) std::abort();
  const EthernetView e = decode_ethernet(frame);
  if (!e.ok() || e.header.src != device_mac(1)) std::abort();
  if (!is_dcp(e.frame_class) && e.frame_class != FrameClass::RtCyclic) std::abort();
}

void check_datagram(const UdpEndpoint& from, std::span<const std::uint8_t> bytes) {
  if (from.ip != ip_of(11) || decode_rpc(bytes).error != WireError::None) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 16384) return 0;
  AkdPersona akd{AkdPersonaConfig{}};
  SimBench bench;
  PnDevice& device = bench.net.add(device_config(1, "drive-a", suite(11)), akd);
  ArPlan plan(akd_plan(1, 4, 4), ip_of(11), device_mac(1), 0);
  SimBench::Ar& ar = bench.add_ar(plan);
  bench.watch_frames = check_frame;
  bench.watch_datagrams = check_datagram;
  bench.start(ar);
  (void)bench.run_until([&] { return ar.cm->state() == CmClientState::DataExchange; }, std::chrono::seconds(2));

  const std::span<const std::uint8_t> in(data, size);
  for (std::size_t at = 0; at + 4 <= in.size();) {
    const std::uint8_t kind = in[at];
    const std::uint8_t step = in[at + 1];
    const std::size_t length = std::min<std::size_t>(get_be16(in, at + 2), in.size() - at - 4);
    const std::span<const std::uint8_t> body = in.subspan(at + 4, length);
    at += 4 + length;
    bench.run_for(std::chrono::milliseconds(step));
    switch (kind) {
      case 0: bench.inject_frame(body); break;
      case 1: bench.inject_datagram(body, {kControllerIp, kControllerClientPort}, {ip_of(11), kRpcUdpPort}); break;
      case 2: bench.inject_datagram(body, {kControllerIp, kRpcUdpPort}, {ip_of(11), kSimDeviceClientPort}); break;
      case 3:
        if (body.empty()) break;
        switch (body[0] % 6) {
          case 0: device.power_loss(); break;
          case 1: device.power_return(bench.now); break;
          case 2: device.abort_ar("fuzz"); break;
          case 3: device.lose_rx_frames(body[0] / 6U); break;
          case 4: device.lose_tx_frames(body[0] / 6U); break;
          default: akd.inject_drive_fault(body.size() >= 3 ? get_be16(body, 1) : 702); break;
        }
        break;
      default:
        if (body.size() >= 2 && plan.provider->data(plan.index(1)).size() >= 2) {
          put_be16(plan.provider->data(plan.index(1)), 0, get_be16(body, 0));
        }
        break;
    }
    bench.pump();
    if (device.powered() && (device.ar_state() == CmServerState::NoAr) != (device.input_cr() == nullptr)) std::abort();
    const std::string_view name = device.dcp().name_of_station();
    if (!name.empty() && validate_name_of_station(name) != NameError::None) std::abort();
  }
  return 0;
}
