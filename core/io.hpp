#pragma once
// Generic I/O slaves of a bus (issue 9): process-data bytes that belong to no axis, e.g. an
// EtherCAT terminal listed in a bus' `io:` section. The control plane reads them through a
// snapshot the bus runner takes every cycle (a seqlock, DESIGN.md §3) and writes output bytes
// through a bounded lock-free queue the cycle thread drains; every write gets one reply.
// Everything here is fixed size and trivially copyable: it crosses the cycle thread's boundary.
#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

namespace drivegate::core {

// Bytes per direction an I/O slave may expose (larger images are cut at this size: io_info()
// reports the true size, the snapshot holds the first kMaxIoBytes).
inline constexpr std::size_t kMaxIoBytes = 256;

struct IoInfo {
  std::string_view name;        // as configured (unique on its bus)
  std::uint32_t address = 0;    // on its bus (EtherCAT: the 1-based position)
  std::size_t input_size = 0;   // bytes; 0 with `sized` false: taken from the device at boot
  std::size_t output_size = 0;
  bool sized = false;           // the sizes are configured (else they are known once the bus booted)
};

enum class IoWriteStatus : std::uint8_t {
  Ok,
  UnknownSlave,  // no I/O slave of that index/name
  OutOfRange,    // offset + size past the slave's outputs (or nothing to write)
  SlaveLost,     // the slave is not exchanging process data (booting, lost, recovering)
  Busy,          // the gateway's queue stayed full
};
inline constexpr std::string_view to_string(IoWriteStatus s) noexcept {
  switch (s) {
    case IoWriteStatus::Ok: return "ok";
    case IoWriteStatus::UnknownSlave: return "unknown_slave";
    case IoWriteStatus::OutOfRange: return "out_of_range";
    case IoWriteStatus::SlaveLost: return "slave_lost";
    case IoWriteStatus::Busy: return "busy";
  }
  return "unknown";
}

// A write of `size` bytes at `offset` into slave `slave`'s outputs (indices as Bus::io_info()).
struct IoWrite {
  std::uint64_t id = 0;
  std::uint16_t slave = 0;
  std::uint16_t offset = 0;
  std::uint16_t size = 0;
  std::array<std::uint8_t, kMaxIoBytes> data{};
};

struct IoWriteReply {
  std::uint64_t id = 0;
  std::uint16_t slave = 0;
  IoWriteStatus status = IoWriteStatus::Ok;
};

// One I/O slave's bytes as the cycle left them: its last good inputs and the outputs the gateway
// holds for it (what goes out in the next frames).
struct IoSnapshot {
  bool valid = false;  // the inputs are this cycle's (false: stale, the slave is not exchanging)
  std::uint16_t input_size = 0;   // bytes used in `inputs` (at most kMaxIoBytes)
  std::uint16_t output_size = 0;
  std::int64_t stamp_ns = 0;      // the cycle's time
  std::uint64_t cycle = 0;        // the runner's cycle count when taken
  std::array<std::uint8_t, kMaxIoBytes> inputs{};
  std::array<std::uint8_t, kMaxIoBytes> outputs{};
};

}  // namespace drivegate::core
