#pragma once
// Tiny helpers for driving a SimLine with frames built by FrameBuilder: one datagram per frame,
// the answer read back from the MemoryLink's receive queue. Not a master.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "adapters/ethercat/link/ethercat_link.hpp"
#include "adapters/ethercat/sim/esc_slave.hpp"
#include "adapters/ethercat/sim/generic_io.hpp"
#include "adapters/ethercat/sim/sim_line.hpp"
#include "adapters/ethercat/wire/frame.hpp"
#include "core/bytes.hpp"

namespace drivegate::ethercat {
using core::get_u16;
using core::get_u32;
using core::get_u64;
using core::put_u16;
using core::put_u32;
using core::put_u64;
}  // namespace drivegate::ethercat

namespace drivegate::ethercat::sim::test {

inline constexpr MacAddress kMasterMac{0x02, 0, 0, 0, 0, 0x01};

struct Reply {
  bool returned = false;
  std::uint16_t wkc = 0;
  std::uint16_t adp = 0;  // ADP as it came back
  std::array<std::uint8_t, kMaxDatagramData> data{};
  std::size_t size = 0;
  std::span<const std::uint8_t> bytes() const { return {data.data(), size}; }
  std::uint16_t u16(std::size_t at = 0) const { return get_u16(bytes(), at); }
  std::uint32_t u32(std::size_t at = 0) const { return get_u32(bytes(), at); }
  std::uint64_t u64(std::size_t at = 0) const { return get_u64(bytes(), at); }
};

class Bus {
 public:
  Bus() : link_(16), line_(link_) { link_.open(); }

  MemoryLink& link() { return link_; }
  SimLine& line() { return line_; }

  // One datagram in one frame; the answer (or returned = false when nothing came back).
  Reply send(Command c, std::uint32_t address, std::uint16_t length, std::span<const std::uint8_t> data = {}) {
    FrameBuilder b(tx_, kMasterMac, kMasterMac);
    const AddResult r = b.add(c, 0x42, address, length, data);
    EXPECT_TRUE(r.ok());
    const auto frame = b.finish();
    if (capture != nullptr) capture->emplace_back(frame.begin(), frame.end());
    link_.send(FrameView(frame.data(), frame.size()));
    Reply reply;
    std::array<FrameBuffer, 1> rx;
    if (link_.receive(rx) != 1) return reply;
    if (capture != nullptr) capture->emplace_back(rx[0].view().begin(), rx[0].view().end());
    FrameParser p(rx[0].view());
    Datagram d;
    if (!p.next(d)) return reply;
    reply.returned = true;
    reply.wkc = d.wkc;
    reply.adp = d.header.adp();
    reply.size = d.data.size();
    std::copy(d.data.begin(), d.data.end(), reply.data.begin());
    return reply;
  }

  Reply fprd(std::uint16_t station, std::uint16_t ado, std::uint16_t len) {
    return send(Command::FPRD, physical_address(station, ado), len);
  }
  Reply fpwr(std::uint16_t station, std::uint16_t ado, std::span<const std::uint8_t> data) {
    return send(Command::FPWR, physical_address(station, ado), static_cast<std::uint16_t>(data.size()), data);
  }
  Reply fpwr16(std::uint16_t station, std::uint16_t ado, std::uint16_t v) {
    std::array<std::uint8_t, 2> b{};
    put_u16(b, 0, v);
    return fpwr(station, ado, b);
  }
  Reply fpwr32(std::uint16_t station, std::uint16_t ado, std::uint32_t v) {
    std::array<std::uint8_t, 4> b{};
    put_u32(b, 0, v);
    return fpwr(station, ado, b);
  }
  Reply brd(std::uint16_t ado, std::uint16_t len) { return send(Command::BRD, physical_address(0, ado), len); }

  // APWR station addresses 1001h, 1002h, ... to every slave.
  void assign_addresses(std::size_t n) {
    for (std::size_t k = 0; k < n; ++k) {
      std::array<std::uint8_t, 2> b{};
      put_u16(b, 0, station(k));
      const Reply r = send(Command::APWR, physical_address(auto_increment_adp(static_cast<std::uint16_t>(k)), reg::kStationAddress), 2, b);
      EXPECT_EQ(r.wkc, 1);
    }
  }
  // When set, every frame sent and received is appended (for a capture file).
  std::vector<std::vector<std::uint8_t>>* capture = nullptr;

  static std::uint16_t station(std::size_t k) { return static_cast<std::uint16_t>(0x1001 + k); }

  // Writes an SM entry.
  Reply write_sm(std::uint16_t station, unsigned n, const SmEntry& e) {
    const auto b = encode_sm(e);
    return fpwr(station, reg::sm(n), b);
  }
  Reply write_fmmu(std::uint16_t station, unsigned n, const FmmuEntry& f) {
    const auto b = encode_fmmu(f);
    return fpwr(station, reg::fmmu(n), b);
  }
  // Requests a state and returns AL status.
  std::uint16_t request(std::uint16_t station, AlState s, bool ack = false) {
    fpwr16(station, reg::kAlControl, al_control(s, ack));
    return fprd(station, reg::kAlStatus, 2).u16();
  }

 private:
  MemoryLink link_;
  SimLine line_;
  std::array<std::uint8_t, kMaxFrameSize> tx_{};
};

}  // namespace drivegate::ethercat::sim::test
