// SimLine + EscSlave basics: addressing, WKC, identity, SII, AL state machine, process data,
// watchdog, faults. Vectors are derived from ETG.1000.4 §5.4 (commands and working counter) and
// §6 (registers), ETG.1000.6 §5.3 (AL) as cited at each test.
#include <gtest/gtest.h>

#include "tests/ethercat_sim/harness.hpp"
#include "tests/support/alloc_counter.hpp"

namespace drivegate::ethercat::sim {
namespace {

using test::Bus;
using test::Reply;

struct IoLine {
  explicit IoLine(std::size_t n, EscConfig cfg = {}) {
    for (std::size_t k = 0; k < n; ++k) {
      apps.push_back(std::make_unique<GenericIoSlave>(2, 1 + k, SiiIdentity{0x00000099, 0x1000 + static_cast<std::uint32_t>(k), 1, 0}));
      cfg.clock_offset_ns = static_cast<std::int64_t>(k) * 1'000'000;
      escs.push_back(std::make_unique<EscSlave>(cfg, apps.back()->sii(), apps.back().get()));
      bus.line().add(*escs.back());
    }
  }
  Bus bus;
  std::vector<std::unique_ptr<GenericIoSlave>> apps;
  std::vector<std::unique_ptr<EscSlave>> escs;
};

TEST(EthercatSimLine, BrdCountsEverySlaveAndApIncrementsAdp) {
  IoLine l(3);
  // BRD: every slave reads, WKC = number of slaves [ETG.1000.4 §5.4 BRD]; ESC type 11h ORed in.
  const Reply r = l.bus.brd(reg::kType, 1);
  ASSERT_TRUE(r.returned);
  EXPECT_EQ(r.wkc, 3);
  EXPECT_EQ(r.data[0], 0x11);
  EXPECT_EQ(r.adp, 3);  // each slave incremented ADP
  // APRD to position 1 (ADP = -1 = FFFFh): only that slave answers.
  const Reply a = l.bus.send(Command::APRD, physical_address(auto_increment_adp(1), reg::kType), 1);
  EXPECT_EQ(a.wkc, 1);
  EXPECT_EQ(a.adp, 2);  // FFFFh + 3
  // Beyond the line: nobody.
  EXPECT_EQ(l.bus.send(Command::APRD, physical_address(auto_increment_adp(3), reg::kType), 1).wkc, 0);
}

TEST(EthercatSimLine, StationAddressesAndIdentity) {
  IoLine l(3);
  l.bus.assign_addresses(3);
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(l.escs[k]->station_address(), Bus::station(k));
    // Identity registers 0000h-0009h [ETG.1000.4 Table 31]: type 11h, rev 0, build 0002h,
    // 3 FMMUs, 4 SMs, 8 KiB, ports 0F, features 01C0h (01CCh with the DC bits 2 and 3 cleared: no DC).
    const Reply r = l.bus.fprd(Bus::station(k), 0x0000, 10);
    ASSERT_EQ(r.wkc, 1);
    const std::array<std::uint8_t, 10> expect{0x11, 0x00, 0x02, 0x00, 0x03, 0x04, 0x08, 0x0F, 0xC0, 0x01};
    EXPECT_TRUE(std::equal(expect.begin(), expect.end(), r.data.begin()));
  }
  // Read-only registers stay: a write to the type register counts but changes nothing.
  const std::array<std::uint8_t, 1> junk{0x55};
  EXPECT_EQ(l.bus.fpwr(Bus::station(0), reg::kType, junk).wkc, 1);
  EXPECT_EQ(l.bus.fprd(Bus::station(0), reg::kType, 1).data[0], 0x11);
  // An unknown station address: WKC 0.
  EXPECT_EQ(l.bus.fprd(0x7777, reg::kType, 1).wkc, 0);
}

TEST(EthercatSimLine, SiiReadThroughEepromInterface) {
  IoLine l(1);
  l.bus.assign_addresses(1);
  const std::uint16_t st = Bus::station(0);
  const auto image = l.apps[0]->sii();
  std::vector<std::uint8_t> got;
  for (std::uint32_t word = 0; word < 64; word += 4) {  // 8 bytes per read (0502h bit 6)
    EXPECT_EQ(l.bus.fpwr32(st, reg::kSiiAddress, word).wkc, 1);
    EXPECT_EQ(l.bus.fpwr16(st, reg::kSiiControl, sii_control::kCommandRead).wkc, 1);
    // Busy for one frame after the command [ETG.1000.4 Table 48 bit 15].
    Reply s = l.bus.fprd(st, reg::kSiiControl, 2);
    EXPECT_NE(s.u16() & sii_control::kBusy, 0);
    int polls = 0;
    while ((s.u16() & sii_control::kBusy) != 0 && polls++ < 5) s = l.bus.fprd(st, reg::kSiiControl, 2);
    EXPECT_EQ(s.u16() & (sii_control::kBusy | sii_control::kCommandError), 0);
    EXPECT_NE(s.u16() & sii_control::kRead8Bytes, 0);
    const Reply d = l.bus.fprd(st, reg::kSiiData, 8);
    got.insert(got.end(), d.data.begin(), d.data.begin() + 8);
  }
  ASSERT_GE(image.size(), got.size());
  EXPECT_TRUE(std::equal(got.begin(), got.end(), image.begin()));
  // Vendor ID at word 8 [ETG.1000.6 §5.4].
  EXPECT_EQ(get_u32(got, 16), 0x00000099U);
}

TEST(EthercatSimLine, SiiFourByteReadsAndWriteCommandRefused) {
  EscConfig cfg;
  cfg.sii_read_8_bytes = false;
  cfg.sii_busy_frames = 0;  // done by the next frame
  IoLine l(1, cfg);
  l.bus.assign_addresses(1);
  const std::uint16_t st = Bus::station(0);
  EXPECT_EQ(l.bus.fprd(st, reg::kSiiControl, 2).u16() & sii_control::kRead8Bytes, 0);
  l.bus.fpwr32(st, reg::kSiiAddress, 0x0008);  // vendor ID, word 8 [ETG.1000.6 §5.4]
  l.bus.fpwr16(st, reg::kSiiControl, sii_control::kCommandRead);
  const Reply s = l.bus.fprd(st, reg::kSiiControl, 2);
  EXPECT_EQ(s.u16() & sii_control::kBusy, 0);
  const Reply d = l.bus.fprd(st, reg::kSiiData, 8);
  EXPECT_EQ(d.u32(0), 0x00000099U);
  EXPECT_EQ(d.u32(4), 0U);  // only 4 bytes read
  // A write command is not offered: command error bit 13 [ETG.1000.4 Table 48].
  l.bus.fpwr16(st, reg::kSiiControl, sii_control::kCommandWrite | sii_control::kWriteEnable);
  EXPECT_NE(l.bus.fprd(st, reg::kSiiControl, 2).u16() & sii_control::kCommandError, 0);
}

// Configures generic slave k for process data: SM2/SM3 and FMMU0 outputs, FMMU1 inputs at
// logical addresses out_log / in_log.
void configure_pd(Bus& bus, std::uint16_t st, std::size_t outputs, std::size_t inputs, std::uint32_t out_log,
                  std::uint32_t in_log) {
  bus.write_sm(st, 2, SmEntry{kGenericOutputsAddress, static_cast<std::uint16_t>(outputs), sm_control::kOutputs, 0, 1, 0});
  bus.write_sm(st, 3, SmEntry{kGenericInputsAddress, static_cast<std::uint16_t>(inputs), sm_control::kInputs, 0, 1, 0});
  bus.write_fmmu(st, 0, FmmuEntry{out_log, static_cast<std::uint16_t>(outputs), 0, 7, kGenericOutputsAddress, 0,
                                  fmmu_type::kWrite, true});
  bus.write_fmmu(st, 1, FmmuEntry{in_log, static_cast<std::uint16_t>(inputs), 0, 7, kGenericInputsAddress, 0,
                                  fmmu_type::kRead, true});
}

TEST(EthercatSimLine, AlTransitionsAndRefusals) {
  IoLine l(1);
  l.bus.assign_addresses(1);
  const std::uint16_t st = Bus::station(0);
  EXPECT_EQ(l.bus.fprd(st, reg::kAlStatus, 2).u16(), 0x0001);
  // INIT -> SAFE-OP skips PRE-OP: refused with 0011h, error bit set [ETG.1000.6 §5.3.2].
  EXPECT_EQ(l.bus.request(st, AlState::SafeOp), 0x0011);
  EXPECT_EQ(l.bus.fprd(st, reg::kAlStatusCode, 2).u16(), 0x0011);
  // While the error is set a higher state without acknowledge is ignored.
  EXPECT_EQ(l.bus.request(st, AlState::PreOp), 0x0011);
  // Acknowledge clears it and performs the request (no mailbox: no SM0/SM1 check).
  EXPECT_EQ(l.bus.request(st, AlState::PreOp, true), 0x0002);
  EXPECT_EQ(l.bus.fprd(st, reg::kAlStatusCode, 2).u16(), 0x0000);
  // PRE-OP -> SAFE-OP without SM2/SM3: invalid output configuration 001Dh.
  EXPECT_EQ(l.bus.request(st, AlState::SafeOp), 0x0012);
  EXPECT_EQ(l.bus.fprd(st, reg::kAlStatusCode, 2).u16(), 0x001D);
  // Outputs right, inputs wrong length: 001Eh.
  l.bus.write_sm(st, 2, SmEntry{kGenericOutputsAddress, 1, sm_control::kOutputs, 0, 1, 0});
  l.bus.write_sm(st, 3, SmEntry{kGenericInputsAddress, 3, sm_control::kInputs, 0, 1, 0});
  EXPECT_EQ(l.bus.request(st, AlState::SafeOp, true), 0x0012);
  EXPECT_EQ(l.bus.fprd(st, reg::kAlStatusCode, 2).u16(), 0x001E);
  configure_pd(l.bus, st, 1, 2, 0x10000, 0x10100);
  EXPECT_EQ(l.bus.request(st, AlState::SafeOp, true), 0x0004);
  EXPECT_EQ(l.bus.request(st, AlState::Op), 0x0008);
  // Unknown state 5: 0012h; bootstrap: 0013h.
  EXPECT_EQ(l.bus.request(st, static_cast<AlState>(5)), 0x0018);
  EXPECT_EQ(l.bus.fprd(st, reg::kAlStatusCode, 2).u16(), 0x0012);
  EXPECT_EQ(l.bus.request(st, AlState::Boot, true), 0x0018);
  EXPECT_EQ(l.bus.fprd(st, reg::kAlStatusCode, 2).u16(), 0x0013);
  // Down to INIT directly (allowed even with the error set); the SMs are deactivated by the PDI.
  EXPECT_EQ(l.bus.request(st, AlState::Init, true), 0x0001);
  EXPECT_EQ(l.bus.fprd(st, reg::sm_pdi_control(2), 1).data[0] & sm_pdi_control::kDeactivate, sm_pdi_control::kDeactivate);
}

TEST(EthercatSimLine, LrwProcessDataThreeSlaves) {
  IoLine l(3);
  l.bus.assign_addresses(3);
  // Image: outputs of slave k at 0x10000 + 8k (k+1 bytes), inputs at 0x10000 + 8k + 4 (2 bytes).
  for (std::size_t k = 0; k < 3; ++k) {
    const std::uint16_t st = Bus::station(k);
    configure_pd(l.bus, st, k + 1, 2, 0x10000 + 8U * static_cast<std::uint32_t>(k), 0x10000 + 8U * static_cast<std::uint32_t>(k) + 4U);
    EXPECT_EQ(l.bus.request(st, AlState::PreOp), 0x0002);
    EXPECT_EQ(l.bus.request(st, AlState::SafeOp), 0x0004);
    l.apps[k]->inputs()[0] = static_cast<std::uint8_t>(0xA0 + k);
    l.apps[k]->inputs()[1] = static_cast<std::uint8_t>(0xB0 + k);
  }
  std::array<std::uint8_t, 24> image{};
  for (std::size_t k = 0; k < 3; ++k) {
    for (std::size_t i = 0; i <= k; ++i) image[8 * k + i] = static_cast<std::uint8_t>(0x10 * (k + 1) + i);
  }
  // SAFE-OP: an LRW counts 3 per slave (input read +1, output write +2) [ETG.1000.4 §5.4 LRW];
  // the outputs are not applied yet.
  l.bus.send(Command::LRW, 0x10000, 24, image);  // inputs are copied in by the PDI after this frame
  Reply r = l.bus.send(Command::LRW, 0x10000, 24, image);
  EXPECT_EQ(r.wkc, 9);
  EXPECT_EQ(r.data[4], 0xA0);
  EXPECT_EQ(r.data[13], 0xB1);
  EXPECT_EQ(r.data[20], 0xA2);
  EXPECT_EQ(r.data[0], 0x10);  // output bytes come back as sent
  EXPECT_EQ(l.apps[2]->outputs()[0], 0x00);
  for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ(l.bus.request(Bus::station(k), AlState::Op), 0x0008);
  r = l.bus.send(Command::LRW, 0x10000, 24, image);
  EXPECT_EQ(r.wkc, 9);
  EXPECT_EQ(l.apps[0]->outputs()[0], 0x10);
  EXPECT_EQ(l.apps[2]->outputs()[2], 0x32);
  // LRD counts reads only, LWR writes only.
  EXPECT_EQ(l.bus.send(Command::LRD, 0x10000, 24).wkc, 3);
  EXPECT_EQ(l.bus.send(Command::LWR, 0x10000, 24, image).wkc, 3);
  // A window that covers only slave 1's inputs: WKC 1.
  EXPECT_EQ(l.bus.send(Command::LRD, 0x1000C, 2).wkc, 1);
}

TEST(EthercatSimLine, SmWatchdogDropsToSafeOp) {
  IoLine l(1);
  l.bus.assign_addresses(1);
  const std::uint16_t st = Bus::station(0);
  configure_pd(l.bus, st, 1, 2, 0x10000, 0x10004);
  l.bus.request(st, AlState::PreOp);
  l.bus.request(st, AlState::SafeOp);
  // Watchdog: divider 2498 -> 100 µs ticks, 100 ticks = 10 ms [digest §8.2].
  l.bus.fpwr16(st, reg::kWatchdogTimeProcessData, 100);
  l.bus.line().set_time(1'000'000);
  EXPECT_EQ(l.bus.request(st, AlState::Op), 0x0008);
  std::array<std::uint8_t, 8> image{0x5A};
  for (std::uint64_t t = 2'000'000; t < 30'000'000; t += 1'000'000) {
    l.bus.line().set_time(t);
    EXPECT_EQ(l.bus.send(Command::LRW, 0x10000, 8, image).wkc, 3);
  }
  EXPECT_EQ(l.apps[0]->outputs()[0], 0x5A);
  EXPECT_EQ(l.escs[0]->state(), AlState::Op);
  // No more outputs: after 10 ms the slave falls back to SAFE-OP with 001Bh.
  l.bus.line().advance(39'000'000);
  EXPECT_EQ(l.escs[0]->state(), AlState::Op);
  l.bus.line().advance(40'000'001);
  EXPECT_EQ(l.bus.fprd(st, reg::kAlStatus, 2).u16(), 0x0014);
  EXPECT_EQ(l.bus.fprd(st, reg::kAlStatusCode, 2).u16(), 0x001B);
  EXPECT_EQ(l.bus.fprd(st, reg::kWatchdogStatusProcessData, 2).u16() & 1, 0);
  EXPECT_EQ(l.apps[0]->outputs()[0], 0x00);  // outputs treated as zero
}

TEST(EthercatSimLine, SlaveStuckInSafeOp) {
  IoLine l(1);
  l.bus.assign_addresses(1);
  const std::uint16_t st = Bus::station(0);
  configure_pd(l.bus, st, 1, 2, 0x10000, 0x10004);
  l.bus.request(st, AlState::PreOp);
  l.bus.request(st, AlState::SafeOp);
  EXPECT_EQ(l.bus.request(st, AlState::Op), 0x0008);
  // Stuck at SAFE-OP with 001Ah (synchronization error): drops from OP on its own...
  l.bus.line().stick(0, AlState::SafeOp, 0x001A);
  EXPECT_EQ(l.bus.fprd(st, reg::kAlStatus, 2).u16(), 0x0014);
  EXPECT_EQ(l.bus.fprd(st, reg::kAlStatusCode, 2).u16(), 0x001A);
  // ...and refuses OP again after the acknowledge.
  EXPECT_EQ(l.bus.request(st, AlState::Op, true), 0x0014);
  EXPECT_EQ(l.bus.fprd(st, reg::kAlStatusCode, 2).u16(), 0x001A);
  l.bus.line().stick(0, AlState::Op, 0);
  EXPECT_EQ(l.bus.request(st, AlState::Op, true), 0x0008);
}

TEST(EthercatSimLine, PowerLossAndCableBreak) {
  IoLine l(3);
  l.bus.assign_addresses(3);
  EXPECT_EQ(l.bus.brd(reg::kType, 1).wkc, 3);
  // Slave 1 powered off: slaves 1 and 2 unreachable; slave 0 closes port 1; the frame returns.
  l.bus.line().power_off(1);
  Reply r = l.bus.brd(reg::kType, 1);
  EXPECT_TRUE(r.returned);
  EXPECT_EQ(r.wkc, 1);
  EXPECT_NE(l.bus.fprd(Bus::station(0), reg::kDlStatus, 2).u16() & dl_status::loop_closed_port(1), 0);
  EXPECT_EQ(l.bus.fprd(Bus::station(2), reg::kType, 1).wkc, 0);
  // Power back: slave 1 restarts in INIT with station address 0; slave 2 kept its address.
  l.bus.line().power_on(1);
  EXPECT_EQ(l.bus.brd(reg::kType, 1).wkc, 3);
  EXPECT_EQ(l.bus.fprd(Bus::station(1), reg::kType, 1).wkc, 0);
  EXPECT_EQ(l.bus.fprd(0, reg::kAlStatus, 2).u16(), 0x0001);
  EXPECT_EQ(l.bus.fprd(Bus::station(2), reg::kType, 1).wkc, 1);
  // Cable break after slave 0.
  l.bus.line().break_after(0);
  r = l.bus.brd(reg::kType, 1);
  EXPECT_TRUE(r.returned);
  EXPECT_EQ(r.wkc, 1);
  l.bus.line().repair_cable();
  EXPECT_EQ(l.bus.brd(reg::kType, 1).wkc, 3);
  // Dropped and corrupted frames do not come back; slave 0 counts the CRC error (0300h).
  l.bus.line().drop_next(2);
  EXPECT_FALSE(l.bus.brd(reg::kType, 1).returned);
  EXPECT_FALSE(l.bus.brd(reg::kType, 1).returned);
  EXPECT_TRUE(l.bus.brd(reg::kType, 1).returned);
  l.bus.line().corrupt_next();
  EXPECT_FALSE(l.bus.brd(reg::kType, 1).returned);
  EXPECT_EQ(l.bus.fprd(Bus::station(0), reg::kRxErrorCounter, 1).data[0], 1);
  // Slave 0 off: nothing returns.
  l.bus.line().power_off(0);
  EXPECT_FALSE(l.bus.brd(reg::kType, 1).returned);
}

TEST(EthercatSimLine, NoAllocationWhileFramesPass) {
  IoLine l(3);
  l.bus.assign_addresses(3);
  for (std::size_t k = 0; k < 3; ++k) {
    configure_pd(l.bus, Bus::station(k), k + 1, 2, 0x10000 + 8U * static_cast<std::uint32_t>(k), 0x10004 + 8U * static_cast<std::uint32_t>(k));
    l.bus.request(Bus::station(k), AlState::PreOp);
    l.bus.request(Bus::station(k), AlState::SafeOp);
    l.bus.request(Bus::station(k), AlState::Op);
  }
  std::array<std::uint8_t, kMaxFrameSize> tx{};
  FrameBuilder b(tx, test::kMasterMac, test::kMasterMac);
  b.add(Command::LRW, 0, 0x10000, 24);
  b.add(Command::BRD, 1, physical_address(0, reg::kAlStatus), 2);
  b.add(Command::FPRD, 2, physical_address(Bus::station(1), reg::kDlStatus), 2);
  const auto frame = b.finish();
  std::array<FrameBuffer, 1> rx;
  const drivegate::test::AllocationScope scope;
  for (int i = 0; i < 100; ++i) {
    l.bus.line().set_time(static_cast<std::uint64_t>(i) * 1'000'000);
    l.bus.link().send(FrameView(frame.data(), frame.size()));
    ASSERT_EQ(l.bus.link().receive(rx), 1U);
  }
  EXPECT_EQ(scope.count(), 0U);
}

}  // namespace
}  // namespace drivegate::ethercat::sim
