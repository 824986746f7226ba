#include "config/canopen/bus_options.hpp"

#include <algorithm>
#include <array>

#include "config/scalars.hpp"
#include "config/text_util.hpp"

namespace drivegate::config {

namespace {

using namespace std::chrono_literals;

// Bit rates of the CiA 301 bit timing table (CiA 301 §7.2.1 / CiA 305).
constexpr std::array<std::int64_t, 8> kBitrates{10000, 20000, 50000, 125000, 250000, 500000, 800000, 1000000};

const std::vector<std::string>& transports() {
  static const std::vector<std::string> kTransports{"socketcan", "udp-multicast", "sim"};
  return kTransports;
}

template <typename T>
const T& option(const BusPlan& bus, const char* name) {
  return std::get<T>(bus.options.at(name));
}

int option_int(const BusPlan& bus, const char* name) { return static_cast<int>(option<std::int64_t>(bus, name)); }

// Objects 1017h, 1016h and 100Ch count whole milliseconds [CiA 301].
void check_whole_ms(const MapReader& m, const BusPlan& bus, const char* name, const char* object) {
  const core::Duration d = option<core::Duration>(bus, name);
  if (d % 1ms != 0ns)
    m.error(name, std::string{"must be whole milliseconds ("} + object + " counts ms), got " + format_duration(d));
}

}  // namespace

std::vector<OptionSpec> canopen_options() {
  const auto ms = [](double v) { return v / 1000.0; };
  return {
      {"transport", OptionKind::Choice, 0, 0, std::string{"socketcan"},
       "socketcan: a Linux CAN interface; udp-multicast: a virtual CAN bus shared over UDP (python-can "
       "udp_multicast); sim: in-process bus with simulated drives made from the axes' device profiles",
       transports()},
      {"interface", OptionKind::String, 0, 0, std::string{},
       "socketcan: the CAN interface (default can0); udp-multicast: the local IPv4 address to send from "
       "(default: any)", {}},
      {"bitrate", OptionKind::Integer, 10000, 1000000, std::int64_t{500000},
       "bit/s, one of the CiA 301 rates; the drives must be set to the same rate", {}},
      {"group", OptionKind::String, 0, 0, std::string{"239.74.163.2"},
       "udp-multicast: IPv4 multicast group (python-can's default)", {}},
      {"port", OptionKind::Integer, 1, 65535, std::int64_t{43113}, "udp-multicast: UDP port (python-can's default)", {}},
      {"gateway_node_id", OptionKind::Integer, 1, 127, std::int64_t{127},
       "the gateway's own node-ID: its heartbeat is 700h + this, drives watch it through 1016h", {}},
      {"heartbeat_period", OptionKind::Duration, ms(1), ms(65535), core::Duration{100ms},
       "how often the gateway sends its own heartbeat", {}},
      {"drive_heartbeat", OptionKind::Duration, ms(1), ms(65535), core::Duration{100ms},
       "heartbeat period written to each heartbeat drive (1017h)", {}},
      {"heartbeat_misses", OptionKind::Integer, 1, 255, std::int64_t{3},
       "periods of silence after which a drive (or, through 1016h, the gateway) counts as lost", {}},
      {"guard_time", OptionKind::Duration, ms(1), ms(65535), core::Duration{100ms},
       "node guarding period for guarding drives (100Ch)", {}},
      {"life_time_factor", OptionKind::Integer, 1, 255, std::int64_t{3},
       "guard requests a guarding drive may miss before it stops (100Dh)", {}},
      {"sdo_timeout", OptionKind::Duration, ms(1), 10, core::Duration{100ms}, "time a drive has to answer an SDO request", {}},
      {"sdo_retries", OptionKind::Integer, 0, 10, std::int64_t{2}, "repeats of a timed-out SDO request", {}},
      {"boot_retry", OptionKind::Duration, ms(10), 600, core::Duration{1s},
       "wait before the first retry of a failed drive boot; doubles on every failure", {}},
      {"boot_retry_max", OptionKind::Duration, ms(10), 3600, core::Duration{10s}, "longest wait between boot retries", {}},
      {"sync", OptionKind::Boolean, 0, 0, true, "produce SYNC every cycle_time (needed by synchronous PDOs)", {}},
      {"rpdo_refresh", OptionKind::Duration, -1, 10, core::Duration{100ms},
       "a synchronous RPDO goes after a SYNC when its data changed, and unchanged at least this often; "
       "0 sends every one after every SYNC", {}},
  };
}

const char* to_string(CanTransportKind kind) noexcept {
  switch (kind) {
    case CanTransportKind::SocketCan: return "socketcan";
    case CanTransportKind::UdpMulticast: return "udp-multicast";
    case CanTransportKind::Simulated: return "sim";
  }
  return "?";
}

void read_canopen_bus(const MapReader& b, const MapReader& m, BusPlan& bus) {
  auto& c = bus.sections.edit<CanopenBusOptions>();
  const std::string& transport = option<std::string>(bus, "transport");
  c.transport = transport == "udp-multicast" ? CanTransportKind::UdpMulticast
                : transport == "sim"         ? CanTransportKind::Simulated
                                             : CanTransportKind::SocketCan;

  const auto bitrate = option<std::int64_t>(bus, "bitrate");
  if (std::find(kBitrates.begin(), kBitrates.end(), bitrate) == kBitrates.end())
    m.error("bitrate", "must be a CiA 301 bit rate: 10000, 20000, 50000, 125000, 250000, 500000, 800000 or "
                       "1000000 (bit/s), got " + std::to_string(bitrate));
  c.bitrate = static_cast<std::uint32_t>(bitrate);

  std::string interface = option<std::string>(bus, "interface");
  c.group = option<std::string>(bus, "group");
  c.port = option_int(bus, "port");
  if (c.transport == CanTransportKind::SocketCan) {
    if (interface.empty()) interface = "can0";
    if (!is_interface_name(interface))
      m.error("interface", "must be a CAN network interface name of 1 to 15 characters such as can0, got \"" +
                               interface + "\"");
  } else if (c.transport == CanTransportKind::UdpMulticast) {
    if (interface.empty()) interface = "0.0.0.0";
    if (!parse_ipv4(interface))
      m.error("interface", "with transport udp-multicast, must be the local IPv4 address to send from (such as "
                           "192.168.1.10; left out: any), got \"" + interface + "\"");
    const auto group = parse_ipv4(c.group);
    if (!group || (*group)[0] < 224 || (*group)[0] > 239)
      m.error("group", "must be an IPv4 multicast group (224.0.0.0 to 239.255.255.255) such as 239.74.163.2, got \"" +
                           c.group + "\"");
  }
  if (c.transport != CanTransportKind::UdpMulticast)
    for (const char* key : {"group", "port"})
      if (m.has(key))
        m.source().warning(m.mark_of(key), m.field(key),
                           std::string{"is only used with transport udp-multicast; transport is "} + transport);
  c.interface = interface;
  bus.options["interface"] = interface;  // the resolved default, as --check-config shows it

  c.gateway_node_id = option_int(bus, "gateway_node_id");
  c.heartbeat_period = option<core::Duration>(bus, "heartbeat_period");
  c.drive_heartbeat = option<core::Duration>(bus, "drive_heartbeat");
  c.heartbeat_misses = option_int(bus, "heartbeat_misses");
  c.guard_time = option<core::Duration>(bus, "guard_time");
  c.life_time_factor = option_int(bus, "life_time_factor");
  c.sdo_timeout = option<core::Duration>(bus, "sdo_timeout");
  c.sdo_retries = option_int(bus, "sdo_retries");
  c.boot_retry = option<core::Duration>(bus, "boot_retry");
  c.boot_retry_max = option<core::Duration>(bus, "boot_retry_max");
  c.sync = option<bool>(bus, "sync");
  c.rpdo_refresh = option<core::Duration>(bus, "rpdo_refresh");

  check_whole_ms(m, bus, "heartbeat_period", "a heartbeat consumer (1016h)");
  check_whole_ms(m, bus, "drive_heartbeat", "1017h");
  check_whole_ms(m, bus, "guard_time", "100Ch");
  // A drive's consumer time 1016h is UNSIGNED16 ms [AKD part 1 §11.2]: it must cover the misses.
  const auto consumer = c.heartbeat_period * c.heartbeat_misses;
  if (consumer > 65535ms)
    m.error("heartbeat_misses", "heartbeat_period x heartbeat_misses = " + format_duration(consumer) +
                                    " must fit a drive's heartbeat consumer time (1016h: at most 65535ms)");
  if (c.boot_retry > c.boot_retry_max)
    m.error("boot_retry_max", "must not be shorter than boot_retry (" + format_duration(c.boot_retry) + "), got " +
                                  format_duration(c.boot_retry_max));
  // 1006h (communication cycle period) counts microseconds [CiA 301].
  if (bus.cycle_time % 1us != 0ns)
    b.error("cycle_time", "must be whole microseconds for a canopen bus (the SYNC period, 1006h counts us), got " +
                              format_duration(bus.cycle_time));
}

}  // namespace drivegate::config
