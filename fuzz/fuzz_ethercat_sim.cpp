// The EtherCAT slave simulator (adapters/ethercat/sim) under arbitrary datagram sequences: a line
// of the CoE test slave (adapters/ethercat/sim/coe_test_slave.hpp: mailbox at 1000h/1080h, SDO
// server over a small dictionary) and a generic I/O slave. The input is a script of operations:
//   F0h-FFh         advance the time by (b & 0Fh) ms (PDI cycles, watchdogs)
//   E0h-EFh         fault (b % 6): power slave 1 off / on, cable break after 0 / repair, drop one
//                   frame, corrupt one frame
//   otherwise       one datagram: command b % 15, address u32 LE, length u8, that many data bytes
// Invariants: nothing crashes; a returned frame has the length it was sent with and every WKC is
// at most 3 per slave.
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <vector>

#include "adapters/ethercat/link/ethercat_link.hpp"
#include "adapters/ethercat/sim/coe_test_slave.hpp"
#include "adapters/ethercat/sim/esc_slave.hpp"
#include "adapters/ethercat/sim/generic_io.hpp"
#include "adapters/ethercat/sim/sim_line.hpp"
#include "adapters/ethercat/wire/frame.hpp"

namespace {

using namespace drivegate::ethercat;
using namespace drivegate::ethercat::sim;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 8192) return 0;
  static const std::vector<std::uint8_t> sii = coe_test::coe_sii();
  coe_test::CoeApp app;
  GenericIoSlave io(2, 2, SiiIdentity{1, 2, 3, 4});
  EscConfig dc;
  dc.dc_supported = true;
  EscSlave s0(EscConfig{}, sii, &app);
  EscSlave s1(dc, io.sii(), &io);
  MemoryLink link(4);
  link.open();
  SimLine line(link);
  line.add(s0);
  line.add(s1);
  std::uint64_t now = 0;
  std::array<std::uint8_t, kMaxFrameSize> tx{};
  std::array<FrameBuffer, 4> rx;
  std::size_t at = 0;
  auto byte = [&]() -> std::uint8_t { return at < size ? data[at++] : 0; };
  while (at < size) {
    const std::uint8_t op = byte();
    if (op >= 0xF0) {
      now += static_cast<std::uint64_t>(op & 0x0F) * 1'000'000;
      line.advance(now);
      continue;
    }
    if (op >= 0xE0) {
      switch (op % 6) {
        case 0: line.power_off(1); break;
        case 1: line.power_on(1); break;
        case 2: line.break_after(0); break;
        case 3: line.repair_cable(); break;
        case 4: line.drop_next(1); break;
        default: line.corrupt_next(); break;
      }
      continue;
    }
    const auto cmd = static_cast<Command>(op % kCommandCount);
    std::uint32_t address = 0;
    for (int i = 0; i < 4; ++i) address |= static_cast<std::uint32_t>(byte()) << (8 * i);
    const std::uint16_t length = byte();
    std::array<std::uint8_t, 256> payload{};
    for (std::uint16_t i = 0; i < length; ++i) payload[i] = byte();
    FrameBuilder b(tx, kBroadcastMac, kBroadcastMac);
    const AddResult r = b.add(cmd, 0, address, length, std::span<const std::uint8_t>(payload.data(), length));
    if (!r.ok()) std::abort();
    const auto frame = b.finish();
    line.set_time(now);
    link.send(FrameView(frame.data(), frame.size()));
    const std::size_t n = link.receive(rx);
    if (n > 1) std::abort();
    if (n == 1) {
      if (rx[0].size != frame.size()) std::abort();
      const std::uint16_t wkc = static_cast<std::uint16_t>(rx[0].bytes[r.slot.wkc_offset] | (rx[0].bytes[r.slot.wkc_offset + 1] << 8));
      if (wkc > 6) std::abort();
    }
    now += 100'000;
  }
  return 0;
}
