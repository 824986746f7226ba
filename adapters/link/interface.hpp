#pragma once
// What the raw Ethernet link and the UDP endpoint both need of a named network interface: the name
// check, ifreq requests for the ioctls, and the texts of the errors they share (one line each, what
// is wrong and what to do), so that both say the same thing the same way. open() paths only.
#include <net/if.h>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace drivegate::link {

using InterfaceName = std::array<char, IFNAMSIZ>;

// "" when `name` can be an interface name (1 to IFNAMSIZ-1 characters, no '/'), else the problem:
// "'NAME' is not a network interface name (1 to 15 characters)".
std::string interface_name_problem(const std::string& name);
// `name` (checked by interface_name_problem) as the kernel takes it, zero-padded.
InterfaceName interface_name(const std::string& name) noexcept;
// An ifreq for `name`.
ifreq request_for(const InterfaceName& name) noexcept;

// "no network interface 'NAME'; give the name of the Ethernet port the PEERS are on"
std::string no_interface_text(const std::string& name, const char* peers);
// "interface 'NAME' is down; bring it up with 'ip link set NAME up'"
std::string interface_down_text(const std::string& name);
// What the kernel says of an interface (in the caller's network namespace): its hardware address
// and its IPv4 addresses with their netmasks, a.b.c.d as a << 24 | ... (getifaddrs).
struct InterfaceAddresses {
  bool found = false;  // an interface of that name exists
  bool has_mac = false;
  std::array<std::uint8_t, 6> mac{};
  struct Ipv4 {
    std::uint32_t address = 0;
    std::uint32_t netmask = 0;
  };
  std::vector<Ipv4> ipv4;
};
InterfaceAddresses interface_addresses(const std::string& name);

// The running binary's path for setcap hints (/proc/self/exe), or a placeholder.
std::string own_binary();

}  // namespace drivegate::link
