// The DCP engines on frames from outside: a DcpClient (controller 02:00:00:00:00:01) that always
// has an Identify all or a Set in flight, and a DcpResponder (device 00:1b:1b:12:34:56, the seeds'
// MACs) see every input frame; the frames each gives out go to the other, on virtual time.
//
// Input: records [time step in 10 ms units u8] [length u16 big-endian] [length octets of frame].
// Invariants: every frame an engine gives is one Ethernet frame (60..1518 octets) from its own MAC
// that decodes as DCP; the client never lists more stations than its array holds; the device's
// name is empty or a valid NameOfStation and its IP suite passes ip_suite_problem().
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "adapters/profinet/controller/dcp_client.hpp"
#include "adapters/profinet/sim/dcp_responder.hpp"

namespace {

using namespace drivegate::profinet;
using drivegate::core::TimePoint;

constexpr MacAddress kController{0x02, 0, 0, 0, 0, 1};
constexpr MacAddress kDevice{0x00, 0x1B, 0x1B, 0x12, 0x34, 0x56};

void check_out(std::span<const std::uint8_t> frame, const MacAddress& from) {
  if (frame.size() < kMinFrameSize || frame.size() > kMaxFrameSize) std::abort();
  const EthernetView e = decode_ethernet(frame);
  if (!e.ok() || !is_dcp(e.frame_class) || e.header.src != from || !decode_dcp(e.pdu).ok()) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 16384) return 0;
  DcpClient client(kController);
  DcpResponderConfig config;
  config.mac = kDevice;
  config.type_of_station = "AKD";
  config.name_of_station = "akd-1";
  DcpResponder device(config);
  std::array<DcpStation, 3> found{};
  DcpRequestId request = kNoDcpRequest;
  IpSuite ip;
  ip.address = {192, 168, 0, 10};
  ip.netmask = {255, 255, 255, 0};

  TimePoint now{};
  std::array<std::uint8_t, kMaxFrameSize> out{};
  const auto exchange = [&] {
    for (int round = 0; round < 8; ++round) {
      bool any = false;
      while (const std::size_t n = client.poll(now, out)) {
        check_out(std::span(out).first(n), kController);
        device.on_frame(std::span(out).first(n), now);
        any = true;
      }
      while (const std::size_t n = device.poll(now, out)) {
        check_out(std::span(out).first(n), kDevice);
        client.on_frame(std::span(out).first(n), now);
        any = true;
      }
      if (!any) break;
    }
  };

  std::size_t pos = 0;
  unsigned turn = 0;
  while (pos + 3 <= size) {
    if (client.idle()) {
      (void)client.take(request);
      request = (turn++ % 2 == 0) ? client.identify_all(found, 4) : client.set_ip(kDevice, ip, DcpQualifier::Temporary);
    }
    now += std::chrono::milliseconds(10 * data[pos]);
    const std::size_t length = std::min<std::size_t>((std::size_t{data[pos + 1]} << 8) | data[pos + 2], size - pos - 3);
    const std::span<const std::uint8_t> frame(data + pos + 3, length);
    pos += 3 + length;
    client.on_frame(frame, now);
    device.on_frame(frame, now);
    exchange();
    if (client.stations(request).size() > found.size()) std::abort();
    const std::string_view name = device.name_of_station();
    if (!name.empty() && validate_name_of_station(name) != NameError::None) std::abort();
    if (!ip_suite_problem(device.ip()).empty()) std::abort();
  }
  return 0;
}
