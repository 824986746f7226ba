// The DCP decoders (adapters/profinet/wire/dcp.hpp) on whatever arrives with EtherType 8892h:
// decode_ethernet, decode_dcp, the block reader, decode_identify_request, decode_device_info,
// decode_set_response, decode_get_request, read_set_block/read_ip_suite and the NameOfStation
// check. Invariants: every view lies inside the input; a decoded device info re-encodes into an
// Identify response that decodes to the same fields; decoded Set results and Get options
// re-encode into PDUs that decode to the same lists; a name validate_name_of_station accepts has
// only the characters and lengths the rules allow.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <string_view>

#include "adapters/profinet/wire/dcp.hpp"
#include "adapters/profinet/wire/ethernet.hpp"
#include "adapters/profinet/wire/station_name.hpp"

namespace {

using namespace drivegate::profinet;

std::span<const std::uint8_t> input;

void inside(std::span<const std::uint8_t> s) {
  if (s.empty()) return;
  if (s.data() < input.data() || s.data() + s.size() > input.data() + input.size()) std::abort();
}
void inside(std::string_view s) {
  inside(std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(s.data()), s.size()));
}

void check_name(std::string_view name) {
  if (validate_name_of_station(name) != NameError::None) return;
  if (name.empty() || name.size() > kMaxNameOfStationLength) std::abort();
  for (const char c : name) {
    if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-' || c == '.')) std::abort();
  }
}

bool same(const DcpDeviceInfo& a, const DcpDeviceInfo& b) {
  const auto eq = [](std::span<const std::uint8_t> x, std::span<const std::uint8_t> y) {
    return std::equal(x.begin(), x.end(), y.begin(), y.end());
  };
  return a.has_type_of_station == b.has_type_of_station && a.type_of_station == b.type_of_station &&
         a.has_name_of_station == b.has_name_of_station && a.name_of_station == b.name_of_station &&
         a.has_device_id == b.has_device_id && a.vendor_id == b.vendor_id && a.device_id == b.device_id &&
         a.has_device_role == b.has_device_role && a.device_role == b.device_role &&
         a.has_device_options == b.has_device_options && eq(a.device_options, b.device_options) &&
         a.has_device_instance == b.has_device_instance && a.instance_high == b.instance_high &&
         a.instance_low == b.instance_low && a.has_oem_device_id == b.has_oem_device_id &&
         a.oem_vendor_id == b.oem_vendor_id && a.oem_device_id == b.oem_device_id && a.has_ip == b.has_ip &&
         a.ip_block_info == b.ip_block_info && a.ip == b.ip && a.has_mac == b.has_mac && a.mac == b.mac &&
         a.has_dhcp == b.has_dhcp && a.dhcp_suboption == b.dhcp_suboption && eq(a.dhcp, b.dhcp) &&
         a.has_device_initiative == b.has_device_initiative && a.device_initiative == b.device_initiative;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 4096) return 0;
  input = std::span<const std::uint8_t>(data, size);
  const EthernetView e = decode_ethernet(input);
  if (!e.ok()) return 0;
  inside(e.pdu);
  const DcpPdu pdu = decode_dcp(e.pdu);
  if (!pdu.ok()) return 0;
  inside(pdu.blocks);

  DcpBlockReader r(pdu.blocks);
  DcpBlock b;
  while (r.next(b)) {
    inside(b.value);
    DcpSetBlock s;
    if (read_set_block(b, s) == DcpError::None) {
      inside(s.data);
      IpSuite ip;
      (void)read_ip_suite(s.data, ip);
    }
  }

  const DcpIdentifyFilter f = decode_identify_request(pdu);
  if (f.error == DcpError::None) {
    inside(f.name_of_station);
    check_name(f.name_of_station);
  }

  static std::array<std::uint8_t, 1600> out{};
  const DcpDeviceInfoView v = decode_device_info(pdu);
  if (v.error == DcpError::None) {
    inside(v.info.type_of_station);
    inside(v.info.name_of_station);
    inside(v.info.device_options);
    inside(v.info.dhcp);
    check_name(v.info.name_of_station);
    // Every field this struct holds comes back from an Identify response written from it (the
    // blocks it has no field for are not written). The views are copied first: `out` is reused.
    const std::size_t n = encode_identify_response(out, pdu.header.xid, v.info);
    if (n == 0) {
      // Only a response too large for one frame may fail. Rewriting adds at most a pad octet per
      // 4-octet block, so what came in under 1000 octets always fits (1250 < 1488).
      if (pdu.blocks.size() < 1000) std::abort();
    } else {
      const DcpDeviceInfoView again = decode_device_info(decode_dcp(std::span<const std::uint8_t>(out).first(n)));
      if (again.error != DcpError::None || !same(again.info, v.info)) std::abort();
    }
  }

  std::array<DcpSetResult, 32> results{};
  const DcpSetResponse s = decode_set_response(pdu, results);
  if (s.error == DcpError::None) {
    const std::size_t n = encode_set_response(out, pdu.header.xid, std::span(results).first(s.count));
    std::array<DcpSetResult, 32> again{};
    const DcpSetResponse s2 = decode_set_response(decode_dcp(std::span<const std::uint8_t>(out).first(n)), again);
    if (n == 0 || s2.error != DcpError::None || s2.count != s.count || s2.any_failed != s.any_failed) std::abort();
    for (std::size_t i = 0; i < s.count; ++i) {
      if (again[i].id != results[i].id || again[i].error != results[i].error) std::abort();
    }
  }

  const DcpGetRequest g = decode_get_request(pdu);
  if (g.error == DcpError::None) {
    inside(g.options);
    std::array<std::uint16_t, 800> ids{};
    for (std::size_t i = 0; i < g.count(); ++i) ids[i] = g.option(i);
    const std::size_t n = encode_get_request(out, pdu.header.xid, std::span(ids).first(g.count()));
    const DcpGetRequest g2 = decode_get_request(decode_dcp(std::span<const std::uint8_t>(out).first(n)));
    if (n == 0 || g2.error != DcpError::None || g2.count() != g.count()) std::abort();
    if (!std::equal(g.options.begin(), g.options.end(), g2.options.begin())) std::abort();
  }
  return 0;
}
