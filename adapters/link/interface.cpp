#include "adapters/link/interface.hpp"

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

std::string own_binary() {
  std::array<char, 4096> path{};
  const ssize_t n = ::readlink("/proc/self/exe", path.data(), path.size() - 1);
  return n > 0 ? std::string(path.data(), static_cast<std::size_t>(n)) : std::string("/path/to/drivegated");
}

}  // namespace drivegate::link
