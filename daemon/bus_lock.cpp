#include "daemon/bus_lock.hpp"

#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

#include "config/bus_types.hpp"
#include "core/bus.hpp"

namespace drivegate::daemon {

namespace {

sockaddr_un address_of(const std::string& resource, socklen_t& len) {
  sockaddr_un a{};
  a.sun_family = AF_UNIX;
  // Abstract namespace: a leading NUL, no file, gone with the process.
  const std::string name = "drivegate-bus " + resource;
  const std::size_t n = std::min(name.size(), sizeof a.sun_path - 1);
  std::memcpy(a.sun_path + 1, name.data(), n);
  len = static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + 1 + n);
  return a;
}

// "pid 1234 (drivegated --config /etc/drivegate/cell.yaml)" for the process holding `a`.
std::string holder(const sockaddr_un& a, socklen_t len) {
  // Non-blocking: the holder never accepts, so a full backlog must not make this wait.
  const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  if (fd < 0) return "another process";
  std::string who = "another process";
  if (::connect(fd, reinterpret_cast<const sockaddr*>(&a), len) == 0) {
    ucred cred{};
    socklen_t size = sizeof cred;
    if (::getsockopt(fd, SOL_SOCKET, SO_PEERCRED, &cred, &size) == 0 && cred.pid > 0) {
      std::ifstream in("/proc/" + std::to_string(cred.pid) + "/cmdline", std::ios::binary);
      std::string cmd((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      for (char& c : cmd)
        if (c == '\0') c = ' ';
      while (!cmd.empty() && cmd.back() == ' ') cmd.pop_back();
      who = "process " + std::to_string(cred.pid) + (cmd.empty() ? std::string{} : " (" + cmd + ")");
    }
  }
  ::close(fd);
  return who;
}

}  // namespace

std::string bus_resource(const config::BusPlan& bus) {
  return bus.type_info && bus.type_info->resource ? bus.type_info->resource(bus) : std::string{};
}

BusLock::BusLock(const std::string& resource) {
  socklen_t len = 0;
  const sockaddr_un a = address_of(resource, len);
  fd_ = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd_ < 0) throw core::BusError("cannot lock " + resource + ": " + std::strerror(errno));
  if (::bind(fd_, reinterpret_cast<const sockaddr*>(&a), len) != 0) {
    const int err = errno;
    ::close(fd_);
    fd_ = -1;
    if (err == EADDRINUSE)
      throw core::BusError(resource + " is already driven by " + holder(a, len) +
                           " on this machine: two masters on one bus fight over the drives; stop that one first");
    throw core::BusError("cannot lock " + resource + ": " + std::strerror(err));
  }
  // Listening lets a refused process ask who holds it (SO_PEERCRED); nobody is ever accepted.
  ::listen(fd_, 1);
}

BusLock::~BusLock() {
  if (fd_ >= 0) ::close(fd_);
}

}  // namespace drivegate::daemon
