#include "adapters/ethercat/bus_io.hpp"

#include <algorithm>

#include "adapters/ethercat/ethercat_bus.hpp"

namespace drivegate::ethercat {

core::IoInfo BusIo::info(std::size_t k) const noexcept {
  core::IoInfo out;
  if (k >= slaves_.size()) return out;
  const PlannedSlave& p = *slaves_[k].plan;
  out.name = p.name;
  out.address = static_cast<std::uint32_t>(p.position) + 1U;
  out.sized = p.io->input_bytes.has_value() && p.io->output_bytes.has_value();
  out.input_size = static_cast<std::size_t>(p.io->input_bytes.value_or(0));
  out.output_size = static_cast<std::size_t>(p.io->output_bytes.value_or(0));
  return out;
}

void BusIo::read(CyclicExchange* cx, std::size_t slave, bool fresh, core::IoSnapshot& out) noexcept {
  out.valid = false;
  out.input_size = 0;
  out.output_size = 0;
  if (cx == nullptr) return;
  const auto in = cx->inputs(slave);
  const auto ou = cx->outputs(slave);  // read only here
  const std::size_t ni = std::min(in.size(), core::kMaxIoBytes);
  const std::size_t no = std::min(ou.size(), core::kMaxIoBytes);
  std::copy_n(in.begin(), ni, out.inputs.begin());
  std::copy_n(ou.begin(), no, out.outputs.begin());
  out.input_size = static_cast<std::uint16_t>(ni);
  out.output_size = static_cast<std::uint16_t>(no);
  out.valid = fresh;
}

core::IoWriteStatus BusIo::write(CyclicExchange* cx, std::size_t slave, bool operational, std::size_t offset,
                                 std::span<const std::uint8_t> bytes) noexcept {
  if (cx == nullptr || !operational) return core::IoWriteStatus::SlaveLost;
  const auto ou = cx->outputs(slave);
  if (bytes.empty() || offset > ou.size() || bytes.size() > ou.size() - offset) return core::IoWriteStatus::OutOfRange;
  std::copy(bytes.begin(), bytes.end(), ou.begin() + static_cast<std::ptrdiff_t>(offset));
  return core::IoWriteStatus::Ok;
}

// --- EthercatBus' I/O overrides (kept here, apart from the bus' own engines) ---------------------

core::IoInfo EthercatBus::io_info(std::size_t k) const noexcept { return io_.info(k); }

void EthercatBus::io_read(std::size_t k, core::IoSnapshot& out) noexcept {
  const std::size_t s = io_.slave(k);
  CyclicExchange* cx = cx_ && image_.ok() ? &*cx_ : nullptr;
  const std::uint64_t done = cx != nullptr ? cx->last_completed_cycle() : 0;
  const bool fresh = open_ && cx != nullptr && slaves_[s]->phase == Phase::Op && done != 0 && cx->inputs_cycle(s) == done;
  BusIo::read(cx, s, fresh, out);
}

core::IoWriteStatus EthercatBus::io_write(std::size_t k, std::size_t offset, std::span<const std::uint8_t> bytes) noexcept {
  if (k >= io_.count()) return core::IoWriteStatus::UnknownSlave;
  const std::size_t s = io_.slave(k);
  CyclicExchange* cx = cx_ && image_.ok() ? &*cx_ : nullptr;
  return BusIo::write(cx, s, open_ && slaves_[s]->phase == Phase::Op, offset, bytes);
}

}  // namespace drivegate::ethercat
