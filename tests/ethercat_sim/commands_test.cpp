// Read-write and read-multiple-write commands, FMMU overlap and SM access rules of EscSlave
// [ETG.1000.4 §5.4 per-command working counter; Table 56 FMMU; Table 59 SyncManager].
#include <gtest/gtest.h>

#include "tests/ethercat_sim/harness.hpp"

namespace drivegate::ethercat::sim {
namespace {

using test::Bus;
using test::Reply;

struct Line3 {
  Line3() {
    for (std::size_t k = 0; k < 3; ++k) {
      apps.push_back(std::make_unique<GenericIoSlave>(2, 2, SiiIdentity{1, 2, 3, 4}));
      escs.push_back(std::make_unique<EscSlave>(EscConfig{}, apps.back()->sii(), apps.back().get()));
      bus.line().add(*escs.back());
    }
    bus.assign_addresses(3);
  }
  Bus bus;
  std::vector<std::unique_ptr<GenericIoSlave>> apps;
  std::vector<std::unique_ptr<EscSlave>> escs;
};

TEST(EthercatSimCommands, ReadWriteCommandsCountThree) {
  Line3 l;
  // Process RAM 1800h, free of SMs.
  const std::array<std::uint8_t, 2> a{0x11, 0x22};
  EXPECT_EQ(l.bus.fpwr(Bus::station(1), 0x1800, a).wkc, 1);
  // FPRW: old content comes back, new is stored; WKC 3 (+1 read, +2 write).
  const std::array<std::uint8_t, 2> b{0x33, 0x44};
  Reply r = l.bus.send(Command::FPRW, physical_address(Bus::station(1), 0x1800), 2, b);
  EXPECT_EQ(r.wkc, 3);
  EXPECT_EQ(r.u16(), 0x2211);
  EXPECT_EQ(l.bus.fprd(Bus::station(1), 0x1800, 2).u16(), 0x4433);
  // APRW to position 2.
  r = l.bus.send(Command::APRW, physical_address(auto_increment_adp(2), 0x1800), 2, a);
  EXPECT_EQ(r.wkc, 3);
  // BWR to all, then BRW: each slave ORs its memory in and stores the frame's data; WKC 3 × 3.
  EXPECT_EQ(l.bus.send(Command::BWR, physical_address(0, 0x1800), 2, a).wkc, 3);
  const std::array<std::uint8_t, 2> c{0x00, 0x80};
  r = l.bus.send(Command::BRW, physical_address(0, 0x1800), 2, c);
  EXPECT_EQ(r.wkc, 9);
  EXPECT_EQ(r.u16(), 0xA211);
  // FRMW: the addressed slave (station 1002h) reads, the others write; each counts once.
  const std::array<std::uint8_t, 2> d{0x55, 0x66};
  EXPECT_EQ(l.bus.fpwr(Bus::station(1), 0x1800, d).wkc, 1);
  r = l.bus.send(Command::FRMW, physical_address(Bus::station(1), 0x1800), 2);
  EXPECT_EQ(r.wkc, 3);
  EXPECT_EQ(r.u16(), 0x6655);
  // Slave 0 wrote what the frame carried before slave 1 read: zeros; slave 2 got slave 1's value.
  EXPECT_EQ(l.bus.fprd(Bus::station(0), 0x1800, 2).u16(), 0x0000);
  EXPECT_EQ(l.bus.fprd(Bus::station(2), 0x1800, 2).u16(), 0x6655);
}

TEST(EthercatSimCommands, SmAccessRulesAndBitGranularFmmuIgnored) {
  Line3 l;
  const std::uint16_t st = Bus::station(0);
  // SM3 (inputs, ECAT reads) enabled but still deactivated by the PDI in INIT: no access.
  l.bus.write_sm(st, 3, SmEntry{kGenericInputsAddress, 2, sm_control::kInputs, 0, 1, 0});
  EXPECT_EQ(l.bus.fprd(st, kGenericInputsAddress, 2).wkc, 0);
  // The PDI-control byte and the SM status byte are read-only for the master.
  const std::array<std::uint8_t, 2> junk{0xFF, 0x00};
  EXPECT_EQ(l.bus.fpwr(st, reg::sm_status(3), junk).wkc, 1);
  const Reply s = l.bus.fprd(st, reg::sm_status(3), 3);
  EXPECT_EQ(s.data[0], 0x00);
  EXPECT_EQ(s.data[1], 0x00);       // activate byte written 0: SM3 disabled
  EXPECT_EQ(s.data[2], 0x01);       // still deactivated by the PDI
  // Disabled SM: plain memory again.
  EXPECT_EQ(l.bus.fprd(st, kGenericInputsAddress, 2).wkc, 1);
  // An FMMU with a bit-granular mapping is not modelled: it maps nothing (WKC 0).
  l.bus.write_fmmu(st, 2, FmmuEntry{0x20000, 1, 2, 5, 0x1800, 0, fmmu_type::kRead, true});
  EXPECT_EQ(l.bus.send(Command::LRD, 0x20000, 1).wkc, 0);
  l.bus.write_fmmu(st, 2, FmmuEntry{0x20000, 1, 0, 7, 0x1800, 0, fmmu_type::kRead, true});
  EXPECT_EQ(l.bus.send(Command::LRD, 0x20000, 1).wkc, 1);
}

TEST(EthercatSimCommands, AliasAddressingNeedsDlControlBit) {
  // Alias 0042h in SII word 4, loaded into 0012h at power-on [ETG.1000.6 §5.4]; a slave with no
  // application (registers only).
  SiiProfile p;
  p.header.station_alias = 0x0042;
  p.name = "bare";
  std::vector<std::uint8_t> image(2048);
  ASSERT_TRUE(build_sii(p, image).ok());
  EscSlave esc(EscConfig{}, image, nullptr);
  Bus bus;
  bus.line().add(esc);
  bus.assign_addresses(1);
  EXPECT_EQ(bus.fprd(Bus::station(0), reg::kStationAlias, 2).u16(), 0x0042);
  // Read-only for ECAT.
  EXPECT_EQ(bus.fpwr16(Bus::station(0), reg::kStationAlias, 0x0043).wkc, 1);
  EXPECT_EQ(bus.fprd(Bus::station(0), reg::kStationAlias, 2).u16(), 0x0042);
  // FPRD by alias only with DL control bit 24 set [ETG.1000.4 Table 31, 0100h].
  EXPECT_EQ(bus.fprd(0x0042, reg::kType, 1).wkc, 0);
  EXPECT_EQ(bus.fpwr32(Bus::station(0), reg::kDlControl, 0x01000001).wkc, 1);
  EXPECT_EQ(bus.fprd(0x0042, reg::kType, 1).wkc, 1);
  // Without an application: INIT -> PRE-OP -> SAFE-OP -> OP need no SMs.
  EXPECT_EQ(bus.request(0x0042, AlState::PreOp), 0x0002);
  EXPECT_EQ(bus.request(0x0042, AlState::SafeOp), 0x0004);
  EXPECT_EQ(bus.request(0x0042, AlState::Op), 0x0008);
}

}  // namespace
}  // namespace drivegate::ethercat::sim
