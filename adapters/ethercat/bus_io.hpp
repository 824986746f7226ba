#pragma once
// The `io:` slaves of an EtherCAT bus as core::Bus I/O slaves (core/io.hpp, issue 9 "generic-io
// slaves whose input and output bytes are exposed"). Their bytes are the slave's own datagram in
// the process image (CyclicExchange inputs(k)/outputs(k)): the inputs are the last ones that came
// back with the expected working counter, the outputs what the gateway sends. EthercatBus keeps a
// BusIo and its io_*() overrides (defined in bus_io.cpp) call it with the slave's state.
//
// Rules: the outputs are zero until a client writes them (and again after the slave was lost and
// reconfigured: ethercat_bus.cpp zeroes a slave's outputs before SAFE-OP); a write is refused with
// SlaveLost unless the slave is in OP (outputs are applied in OP only, ETG.1000.6 §6.4.1 AL state
// table); the inputs are valid only when they came back in the latest completed cycle of a slave in
// OP, else the snapshot still holds the last good ones, marked stale.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "core/io.hpp"

namespace drivegate::ethercat {

struct PlannedSlave;
class CyclicExchange;

class BusIo {
 public:
  // The bus' slave `slave` is I/O slave count() from now on (`p` must outlive this).
  void add(std::size_t slave, const PlannedSlave& p) { slaves_.push_back(Entry{slave, &p}); }

  [[nodiscard]] std::size_t count() const noexcept { return slaves_.size(); }
  // The bus' slave index of I/O slave k.
  [[nodiscard]] std::size_t slave(std::size_t k) const noexcept { return slaves_[k].slave; }
  [[nodiscard]] core::IoInfo info(std::size_t k) const noexcept;

  // Cyclic path. `cx` null: no process image yet (the line has not booted).
  static void read(CyclicExchange* cx, std::size_t slave, bool fresh, core::IoSnapshot& out) noexcept;
  static core::IoWriteStatus write(CyclicExchange* cx, std::size_t slave, bool operational, std::size_t offset,
                                   std::span<const std::uint8_t> bytes) noexcept;

 private:
  struct Entry {
    std::size_t slave = 0;
    const PlannedSlave* plan = nullptr;  // in the bus' Slave, stable for the bus' life
  };
  std::vector<Entry> slaves_;
};

}  // namespace drivegate::ethercat
