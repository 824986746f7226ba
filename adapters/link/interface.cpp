#include "adapters/link/interface.hpp"

#include <arpa/inet.h>
#include <ifaddrs.h>
#include <linux/if_packet.h>
#include <netinet/in.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>

namespace drivegate::link {

std::string interface_name_problem(const std::string& name) {
  if (!name.empty() && name.size() < IFNAMSIZ && name.find('/') == std::string::npos) return "";
  return "'" + name + "' is not a network interface name (1 to " + std::to_string(IFNAMSIZ - 1) + " characters)";
}

InterfaceName interface_name(const std::string& name) noexcept {
  InterfaceName n{};
  std::memcpy(n.data(), name.data(), std::min(name.size(), n.size() - 1));
  return n;
}

ifreq request_for(const InterfaceName& name) noexcept {
  ifreq r{};
  std::memcpy(r.ifr_name, name.data(), name.size());
  return r;
}

std::string no_interface_text(const std::string& name, const char* peers) {
  return "no network interface '" + name + "'; give the name of the Ethernet port the " + peers + " are on";
}

std::string interface_down_text(const std::string& name) {
  return "interface '" + name + "' is down; bring it up with 'ip link set " + name + " up'";
}

InterfaceAddresses interface_addresses(const std::string& name) {
  InterfaceAddresses out;
  ifaddrs* list = nullptr;
  if (::getifaddrs(&list) != 0) return out;
  for (const ifaddrs* a = list; a != nullptr; a = a->ifa_next) {
    if (a->ifa_name == nullptr || name != a->ifa_name) continue;
    out.found = true;
    if (a->ifa_addr == nullptr) continue;
    if (a->ifa_addr->sa_family == AF_PACKET) {
      sockaddr_ll ll{};
      std::memcpy(&ll, a->ifa_addr, sizeof ll);
      if (ll.sll_halen == out.mac.size()) {
        std::memcpy(out.mac.data(), ll.sll_addr, out.mac.size());
        out.has_mac = true;
      }
    } else if (a->ifa_addr->sa_family == AF_INET) {
      sockaddr_in in{};
      std::memcpy(&in, a->ifa_addr, sizeof in);
      InterfaceAddresses::Ipv4 v;
      v.address = ntohl(in.sin_addr.s_addr);
      if (a->ifa_netmask != nullptr) {
        std::memcpy(&in, a->ifa_netmask, sizeof in);
        v.netmask = ntohl(in.sin_addr.s_addr);
      }
      out.ipv4.push_back(v);
    }
  }
  ::freeifaddrs(list);
  return out;
}

std::string own_binary() {
  std::array<char, 4096> path{};
  const ssize_t n = ::readlink("/proc/self/exe", path.data(), path.size() - 1);
  return n > 0 ? std::string(path.data(), static_cast<std::size_t>(n)) : std::string("/path/to/drivegated");
}

}  // namespace drivegate::link
