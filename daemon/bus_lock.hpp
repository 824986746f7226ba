#pragma once
// One process per bus interface on this machine: a gateway holds an abstract UNIX socket named
// after each bus' resource (the CAN interface, the UDP multicast group, later the Ethernet port)
// for as long as it runs, so a second gateway on the same interface refuses to start and says who
// has it. The kernel releases the name when the holder dies, however it dies.
#include <memory>
#include <string>

#include "config/plan.hpp"

namespace drivegate::daemon {

// What a bus drives that no second master may drive at the same time, e.g. "canopen socketcan
// can0"; empty for buses that own nothing outside the process (sim).
std::string bus_resource(const config::BusPlan& bus);

class BusLock {
 public:
  // Takes the lock for `resource`; throws core::BusError naming the process that holds it.
  explicit BusLock(const std::string& resource);
  ~BusLock();
  BusLock(const BusLock&) = delete;
  BusLock& operator=(const BusLock&) = delete;

 private:
  int fd_ = -1;
};

}  // namespace drivegate::daemon
