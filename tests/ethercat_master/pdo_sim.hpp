#pragma once
// A simulated line for the process data tests: CoE slaves whose object dictionary has the PDO
// assignment (1C12h/1C13h) and mapping objects (1600h/1601h, 1A00h, a fixed 1A01h) and whose
// process data sizes follow what is assigned there [ETG.1000.6: SM2/SM3 lengths are checked
// against the assignment at PRE-OP -> SAFE-OP], plus generic I/O slaves. Writes to chosen objects
// are accepted and ignored, as the ESR drive does (dunker-ethercat-coe.md quirk 8).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <memory>
#include <vector>

#include "adapters/ethercat/link/ethercat_link.hpp"
#include "adapters/ethercat/master/coe_sdo_client.hpp"
#include "adapters/ethercat/master/line_boot.hpp"
#include "adapters/ethercat/master/transactions.hpp"
#include "adapters/ethercat/sim/esc_slave.hpp"
#include "adapters/ethercat/sim/generic_io.hpp"
#include "adapters/ethercat/sim/object_dictionary.hpp"
#include "adapters/ethercat/sim/sim_line.hpp"
#include "core/bytes.hpp"
#include "core/clock.hpp"
#include "tests/ethercat_sim/line_exchange.hpp"

namespace drivegate::ethercat::pdo_test {

using namespace std::chrono_literals;

inline constexpr std::uint16_t kMbxOut = 0x1000;
inline constexpr std::uint16_t kMbxIn = 0x1080;
inline constexpr std::uint16_t kMbxSize = 128;
inline constexpr std::uint16_t kSm2 = 0x1100;
inline constexpr std::uint16_t kSm3 = 0x1180;
inline constexpr SiiIdentity kDriveId{0x0000066F, 0x2345, 1, 1};
inline constexpr SiiIdentity kIoId{0x00000099, 0x1000, 1, 2};

struct WriteLog {
  std::uint16_t index = 0;
  std::uint8_t subindex = 0;
  std::uint32_t value = 0;
  bool operator==(const WriteLog&) const = default;
};

// The drive's dictionary in front of a SimpleObjectDictionary: logs every write that reached it,
// and takes writes to `ignored` objects without storing them.
class QuirkyOd final : public sim::ObjectDictionary {
 public:
  explicit QuirkyOd(sim::SimpleObjectDictionary& od) : od_(od) { log.reserve(512); }
  sim::OdReadResult read(std::uint16_t index, std::uint8_t subindex, std::span<std::uint8_t> out,
                         AlState state) noexcept override {
    return od_.read(index, subindex, out, state);
  }
  std::uint32_t write(std::uint16_t index, std::uint8_t subindex, std::span<const std::uint8_t> data,
                      AlState state) noexcept override {
    std::uint32_t v = 0;
    for (std::size_t i = 0; i < std::min<std::size_t>(data.size(), 4); ++i) v |= std::uint32_t{data[i]} << (8 * i);
    if (log.size() < log.capacity()) log.push_back(WriteLog{index, subindex, v});
    if (std::find(ignored.begin(), ignored.end(), WriteLog{index, subindex, 0}) != ignored.end()) return 0;
    return od_.write(index, subindex, data, state);
  }
  std::size_t list(OdListType type, std::span<std::uint16_t> out) const noexcept override { return od_.list(type, out); }
  bool describe_object(std::uint16_t index, SdoInfoObjectDescription& out) const noexcept override {
    return od_.describe_object(index, out);
  }
  bool describe_entry(std::uint16_t index, std::uint8_t subindex, SdoInfoEntryDescription& out) const noexcept override {
    return od_.describe_entry(index, subindex, out);
  }

  std::vector<WriteLog> log;
  std::vector<WriteLog> ignored;  // value unused

 private:
  sim::SimpleObjectDictionary& od_;
};

// A CoE drive: 1C12h -> 1600h/1601h, 1C13h -> 1A00h, fixed 1A01h (read-only, 6041h:00/16); the
// default assignment is 1600h (6040h:00/16) and 1A00h (6041h:00/16), 2 bytes each way
// (digest §7.1). Outputs and inputs are kept as they pass.
class PdoDrive final : public sim::SlaveApplication {
 public:
  PdoDrive() : quirky(od) {
    constexpr std::uint16_t rw = object_access::kReadPreOp | object_access::kReadSafeOp | object_access::kReadOp |
                                 object_access::kWritePreOp;
    constexpr std::uint16_t ro = object_access::kReadPreOp | object_access::kReadSafeOp | object_access::kReadOp;
    auto u8 = [&](std::uint16_t i, std::uint8_t s, std::uint16_t access, std::uint8_t v) {
      const std::array<std::uint8_t, 1> b{v};
      od.add_entry(sim::OdEntrySpec{i, s, sim::data_type::kUnsigned8, access, "u8", b});
    };
    auto u16 = [&](std::uint16_t i, std::uint8_t s, std::uint16_t access, std::uint16_t v) {
      const std::array<std::uint8_t, 2> b{static_cast<std::uint8_t>(v), static_cast<std::uint8_t>(v >> 8)};
      od.add_entry(sim::OdEntrySpec{i, s, sim::data_type::kUnsigned16, access, "u16", b});
    };
    auto u32 = [&](std::uint16_t i, std::uint8_t s, std::uint16_t access, std::uint32_t v) {
      std::array<std::uint8_t, 4> b{};
      core::put_u32(b, 0, v);
      od.add_entry(sim::OdEntrySpec{i, s, sim::data_type::kUnsigned32, access, "u32", b});
    };
    for (std::uint16_t assign : {std::uint16_t{0x1C12}, std::uint16_t{0x1C13}}) {
      od.add_object(assign, object_code::kArray, "PDO assign");
      u8(assign, 0, rw, 1);
      for (std::uint8_t s = 1; s <= 4; ++s) {
        const auto base = static_cast<std::uint16_t>(assign == 0x1C12 ? 0x1600 : 0x1A00);
        u16(assign, s, rw, static_cast<std::uint16_t>(base + s - 1));
      }
    }
    for (std::uint16_t pdo : {std::uint16_t{0x1600}, std::uint16_t{0x1601}, std::uint16_t{0x1A00}}) {
      od.add_object(pdo, object_code::kRecord, "PDO mapping");
      u8(pdo, 0, rw, pdo == 0x1601 ? 0 : 1);
      for (std::uint8_t s = 1; s <= 8; ++s) u32(pdo, s, rw, 0);
    }
    core::put_u32(od.value(0x1600, 1), 0, 0x60400010);
    core::put_u32(od.value(0x1600, 3), 0, 0x60710010);  // left from an earlier mapping
    core::put_u32(od.value(0x1A00, 1), 0, 0x60410010);
    od.add_object(0x1A01, object_code::kRecord, "Fixed TxPDO");
    u8(0x1A01, 0, ro, 1);
    u32(0x1A01, 1, ro, 0x60410010);
    od.add_object(0x6007, object_code::kVariable, "Abort connection option code");
    u16(0x6007, 0, rw | object_access::kWriteSafeOp | object_access::kWriteOp, 0);
    od.add_object(0x60C2, object_code::kRecord, "Interpolation time period");
    u8(0x60C2, 0, ro, 2);
    u8(0x60C2, 1, rw, 4);
    u8(0x60C2, 2, rw, 0xFD);  // -3: milliseconds (digest TV-3); writes are ignored
    quirky.ignored.push_back(WriteLog{0x60C2, 2, 0});
  }

  // Bytes of the PDOs assigned in `assign` (entry bits summed, rounded up).
  std::size_t assigned_bytes(std::uint16_t assign) const noexcept {
    const auto n = od.value(assign, 0);
    if (n.empty()) return 0;
    std::uint32_t bits = 0;
    for (std::uint8_t i = 1; i <= n[0]; ++i) {
      const auto p = od.value(assign, i);
      if (p.size() < 2) return 0;
      const std::uint16_t pdo = core::get_u16(p, 0);
      const auto m = od.value(pdo, 0);
      if (m.empty()) return 0;
      for (std::uint8_t j = 1; j <= m[0]; ++j) {
        const auto e = od.value(pdo, j);
        if (e.size() == 4) bits += e[0];
      }
    }
    return (bits + 7) / 8;
  }
  std::size_t output_size() const noexcept override { return assigned_bytes(0x1C12); }
  std::size_t input_size() const noexcept override { return assigned_bytes(0x1C13); }
  void exchange(std::span<const std::uint8_t> out, std::span<std::uint8_t> in, AlState state,
                std::uint64_t /*now_ns*/) noexcept override {
    std::fill(outputs.begin(), outputs.end(), 0);
    std::copy_n(out.begin(), std::min(out.size(), outputs.size()), outputs.begin());
    std::copy_n(inputs.begin(), std::min(in.size(), inputs.size()), in.begin());
    last_state = state;
  }
  sim::ObjectDictionary* object_dictionary() noexcept override { return &quirky; }

  mutable sim::SimpleObjectDictionary od;
  QuirkyOd quirky;
  std::array<std::uint8_t, 64> outputs{};
  std::array<std::uint8_t, 64> inputs{};
  AlState last_state = AlState::Init;
};

// The drive's EEPROM: standard mailbox, SM2 at 1100h (64h), SM3 at 1180h (20h) with the default
// 2-byte lengths, CoE with PDO assignment and configuration.
inline std::vector<std::uint8_t> drive_sii() {
  const std::array<SiiSyncManager, 4> sms{
      SiiSyncManager{kMbxOut, kMbxSize, sm_control::kMailboxOut, 0, 1, sii_sm_type::kMailboxOut},
      SiiSyncManager{kMbxIn, kMbxSize, sm_control::kMailboxIn, 0, 1, sii_sm_type::kMailboxIn},
      SiiSyncManager{kSm2, 2, sm_control::kOutputs, 0, 1, sii_sm_type::kOutputs},
      SiiSyncManager{kSm3, 2, sm_control::kInputs, 0, 1, sii_sm_type::kInputs},
  };
  SiiProfile p;
  p.header.identity = kDriveId;
  p.header.standard_mailbox = SiiMailbox{kMbxOut, kMbxSize, kMbxIn, kMbxSize};
  p.header.mailbox_protocols = mailbox_protocol::kCoE;
  p.name = "PDO test drive";
  p.general.coe_details = coe_details::kSdo | coe_details::kPdoAssign | coe_details::kPdoConfig;
  p.sync_managers = sms;
  std::vector<std::uint8_t> image(2048, 0);
  const auto r = build_sii(p, image);
  EXPECT_TRUE(r.ok());
  image.resize(r.ok() ? r.size : 0);
  return image;
}

// `drives` PDO drives, then `ios` generic I/O slaves (2 inputs, 2 outputs), behind a MemoryLink;
// the master's Transactions, LineBoot and one CoeSdoClient per drive (made after the boot).
struct PdoLine {
  PdoLine(std::size_t drives, std::size_t ios) : sii(drive_sii()) {
    link.open();
    for (std::size_t k = 0; k < drives; ++k) {
      apps.push_back(std::make_unique<PdoDrive>());
      escs.push_back(std::make_unique<sim::EscSlave>(sim::EscConfig{}, sii, apps.back().get()));
      line.add(*escs.back());
      expected.push_back(ExpectedSlave{kDriveId.vendor_id, kDriveId.product_code, 0, "PDO test drive"});
    }
    for (std::size_t k = 0; k < ios; ++k) {
      ios_.push_back(std::make_unique<sim::GenericIoSlave>(2, 2, kIoId));
      escs.push_back(std::make_unique<sim::EscSlave>(sim::EscConfig{}, ios_.back()->sii(), ios_.back().get()));
      line.add(*escs.back());
      expected.push_back(ExpectedSlave{kIoId.vendor_id, kIoId.product_code, 0, "Generic I/O"});
    }
    boot = std::make_unique<LineBoot>(expected, LineBootConfig{});
  }

  // The engines queue, the frames pass the line and come back, time moves 1 ms.
  template <class Poll>
  void cycle(Poll&& poll) {
    poll(now);
    if (boot) boot->poll(now, tx);
    for (auto& c : clients) c->poll(now, tx);
    drivegate::ethercat::test::exchange_over_line(tx, link, line, now);
  }
  void cycle() {
    cycle([](core::TimePoint) {});
  }

  // Boots to PRE-OP and makes the drives' SDO clients.
  void preop() {
    boot->start(now);
    for (int i = 0; i < 20000 && boot->status() == LineStatus::Running; ++i) cycle();
    ASSERT_EQ(boot->status(), LineStatus::Done) << boot->line_text();
    ASSERT_TRUE(boot->ok()) << boot->slave(0).text.view();
    for (std::size_t k = 0; k < apps.size(); ++k) {
      clients.push_back(std::make_unique<CoeSdoClient>(static_cast<std::uint16_t>(0x1001 + k),
                                                       boot->sii(k).header.standard_mailbox));
      ASSERT_TRUE(clients.back()->valid());
    }
  }

  MemoryLink link{16};
  sim::SimLine line{link};
  std::vector<std::uint8_t> sii;
  std::vector<std::unique_ptr<PdoDrive>> apps;
  std::vector<std::unique_ptr<sim::GenericIoSlave>> ios_;
  std::vector<std::unique_ptr<sim::EscSlave>> escs;
  std::vector<ExpectedSlave> expected;
  Transactions tx;
  std::unique_ptr<LineBoot> boot;
  std::vector<std::unique_ptr<CoeSdoClient>> clients;
  core::TimePoint now{};
};

}  // namespace drivegate::ethercat::pdo_test
