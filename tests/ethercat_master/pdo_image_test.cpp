// ProcessImage: byte-exact SM and FMMU entries, cyclic datagrams, working counters and frame
// sizes for a line of three slaves, the frames of a line of 64 (several per cycle, as
// Transactions sends them), and the layouts it refuses.
//
// The vectors are derived by hand from ETG.1000.4 Table 59 (SM entry: start u16, length u16,
// control, status, activate, PDI control) and Table 56 (FMMU entry: logical start u32, length u16,
// start bit, stop bit, physical start u16, physical start bit, type 1 read / 2 write, activate,
// 3 reserved), little-endian, with the image laid out per slave as outputs then inputs.
#include <gtest/gtest.h>

#include <array>
#include <memory>
#include <vector>

#include "adapters/ethercat/master/cyclic_exchange.hpp"
#include "adapters/ethercat/master/process_image.hpp"
#include "adapters/ethercat/master/transactions.hpp"
#include "adapters/ethercat/sim/generic_io.hpp"
#include "tests/ethercat_master/pdo_sim.hpp"

namespace drivegate::ethercat {
namespace {

using Bytes8 = std::array<std::uint8_t, 8>;
using Bytes16 = std::array<std::uint8_t, 16>;

struct ThreeSlaves {
  ThreeSlaves() : drive(pdo_test::drive_sii()), io(1, 2, pdo_test::kIoId), in_only(4, 0, pdo_test::kIoId) {
    parse_sii(drive, *drive_info);
    parse_sii(io.sii(), *io_info);
    parse_sii(in_only.sii(), *in_info);
    // A drive with the IP-mode image of TV-6/TV-7 (6 bytes each way: controlword + 60C1h:01,
    // statusword + 6063h), a generic I/O slave without mailbox (2 outputs, 1 input) and an input-only
    // I/O slave (4 inputs).
    slaves = {image_slave_from_sii(*drive_info, 0x1001, 48, 48), image_slave_from_sii(*io_info, 0x1002, 16, 8),
              image_slave_from_sii(*in_info, 0x1003, 0, 32)};
  }
  std::vector<std::uint8_t> drive;
  sim::GenericIoSlave io;
  sim::GenericIoSlave in_only;
  std::unique_ptr<SiiInfo> drive_info = std::make_unique<SiiInfo>();
  std::unique_ptr<SiiInfo> io_info = std::make_unique<SiiInfo>();
  std::unique_ptr<SiiInfo> in_info = std::make_unique<SiiInfo>();
  std::array<ImageSlave, 3> slaves{};
};

TEST(ProcessImage, SmAndFmmuFromTheSii) {
  ThreeSlaves t;
  // Drive: SM2 1100h/64h, room (1180h - 1100h) / 3 = 42 bytes; SM3 1180h/20h, nothing above it.
  EXPECT_EQ(t.slaves[0].sm2.start, 0x1100);
  EXPECT_EQ(t.slaves[0].sm2.control, 0x64);
  EXPECT_EQ(t.slaves[0].sm2.capacity, 42);
  EXPECT_EQ(t.slaves[0].sm3.start, 0x1180);
  EXPECT_EQ(t.slaves[0].sm3.control, 0x20);
  EXPECT_EQ(t.slaves[0].sm3.capacity, 0);
  EXPECT_EQ(t.slaves[0].fmmu_outputs, 0);  // no FMMU category: FMMU0/FMMU1
  EXPECT_EQ(t.slaves[0].fmmu_inputs, 1);
  EXPECT_FALSE(t.slaves[0].lrd_lwr);
  // Generic I/O: SM2 1000h, SM3 1100h, FMMU category "outputs, inputs, unused".
  EXPECT_EQ(t.slaves[1].sm2.start, 0x1000);
  EXPECT_EQ(t.slaves[1].sm2.capacity, 85);
  EXPECT_EQ(t.slaves[1].sm3.start, 0x1100);
  EXPECT_EQ(t.slaves[1].output_bytes, 2);
  EXPECT_EQ(t.slaves[1].input_bytes, 1);
  // Bits round up to bytes per SM.
  EXPECT_EQ(image_slave_from_sii(*t.drive_info, 0x1001, 17, 1).output_bytes, 3);
  EXPECT_EQ(image_slave_from_sii(*t.drive_info, 0x1001, 17, 1).input_bytes, 1);
}

TEST(ProcessImage, ThreeSlavesByteExact) {
  ThreeSlaves t;
  ProcessImage img;
  ASSERT_TRUE(img.build(t.slaves)) << img.text();
  ASSERT_EQ(img.slave_count(), 3U);
  EXPECT_EQ(img.size(), 19U);  // 6 + 6 | 2 + 1 | 4

  const SlaveImage& d = img.slave(0);
  EXPECT_EQ(d.output_offset, 0U);
  EXPECT_EQ(d.input_offset, 6U);
  EXPECT_EQ(encode_sm(d.sm2), (Bytes8{0x00, 0x11, 0x06, 0x00, 0x64, 0x00, 0x01, 0x00}));
  EXPECT_EQ(encode_sm(d.sm3), (Bytes8{0x80, 0x11, 0x06, 0x00, 0x20, 0x00, 0x01, 0x00}));
  EXPECT_EQ(d.fmmu_outputs_index, 0);
  EXPECT_EQ(encode_fmmu(d.fmmu_outputs),
            (Bytes16{0x00, 0x00, 0x00, 0x00, 0x06, 0x00, 0x00, 0x07, 0x00, 0x11, 0x00, 0x02, 0x01, 0x00, 0x00, 0x00}));
  EXPECT_EQ(d.fmmu_inputs_index, 1);
  EXPECT_EQ(encode_fmmu(d.fmmu_inputs),
            (Bytes16{0x06, 0x00, 0x00, 0x00, 0x06, 0x00, 0x00, 0x07, 0x80, 0x11, 0x00, 0x01, 0x01, 0x00, 0x00, 0x00}));
  EXPECT_EQ(d.expected_wkc, 3);

  const SlaveImage& io = img.slave(1);
  EXPECT_EQ(io.output_offset, 12U);
  EXPECT_EQ(io.input_offset, 14U);
  EXPECT_EQ(encode_sm(io.sm2), (Bytes8{0x00, 0x10, 0x02, 0x00, 0x64, 0x00, 0x01, 0x00}));
  EXPECT_EQ(encode_sm(io.sm3), (Bytes8{0x00, 0x11, 0x01, 0x00, 0x20, 0x00, 0x01, 0x00}));
  EXPECT_EQ(encode_fmmu(io.fmmu_outputs),
            (Bytes16{0x0C, 0x00, 0x00, 0x00, 0x02, 0x00, 0x00, 0x07, 0x00, 0x10, 0x00, 0x02, 0x01, 0x00, 0x00, 0x00}));
  EXPECT_EQ(encode_fmmu(io.fmmu_inputs),
            (Bytes16{0x0E, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x07, 0x00, 0x11, 0x00, 0x01, 0x01, 0x00, 0x00, 0x00}));

  // Input only: SM2 written disabled with length 0, its FMMU inactive (all zero).
  const SlaveImage& in = img.slave(2);
  EXPECT_EQ(in.input_offset, 15U);
  EXPECT_EQ(encode_sm(in.sm2), (Bytes8{0x00, 0x10, 0x00, 0x00, 0x64, 0x00, 0x00, 0x00}));
  EXPECT_EQ(encode_sm(in.sm3), (Bytes8{0x00, 0x11, 0x04, 0x00, 0x20, 0x00, 0x01, 0x00}));
  EXPECT_EQ(encode_fmmu(in.fmmu_outputs), Bytes16{});
  EXPECT_EQ(encode_fmmu(in.fmmu_inputs),
            (Bytes16{0x0F, 0x00, 0x00, 0x00, 0x04, 0x00, 0x00, 0x07, 0x00, 0x11, 0x00, 0x01, 0x01, 0x00, 0x00, 0x00}));
  EXPECT_EQ(in.expected_wkc, 1);

  // One LRW over the image: WKC 3 + 3 + 1 [ETG.1000.4 §5.4].
  ASSERT_EQ(img.datagrams().size(), 1U);
  EXPECT_EQ(img.datagrams()[0].command, Command::LRW);
  EXPECT_EQ(img.datagrams()[0].logical_address, 0U);
  EXPECT_EQ(img.datagrams()[0].length, 19);
  EXPECT_EQ(img.expected_wkc(), 7);
  // Frame: 14 + 2 + (12 + 19) + the AL status check (12 + 2) = 61 bytes; on the wire + 24 = 85
  // bytes = 6.8 µs at 100 Mbit/s.
  EXPECT_EQ(img.frame_bytes(), 61U);
  EXPECT_EQ(img.wire_bytes(), 85U);
  EXPECT_EQ(img.wire_time(), std::chrono::nanoseconds(6800));
  EXPECT_EQ(img.round_trip(), std::chrono::nanoseconds(9800));  // + 3 slaves × 1 µs
  EXPECT_TRUE(img.fits(std::chrono::microseconds(250)));
  EXPECT_FALSE(img.fits(std::chrono::microseconds(16)));  // half of 16 µs < 9.8 µs
}

TEST(ProcessImage, LogicalBaseAndLrdLwr) {
  ThreeSlaves t;
  t.slaves[1].lrd_lwr = true;  // SII general flag "enable not LRW"
  ProcessImage img;
  ASSERT_TRUE(img.build(t.slaves, ImageOptions{0x00010000, CyclicDatagrams::WholeImage, 0, 0})) << img.text();
  EXPECT_EQ(img.slave(1).fmmu_outputs.logical_start, 0x0001000CU);
  EXPECT_EQ(img.slave(1).expected_wkc, 2);  // LWR 1 + LRD 1
  ASSERT_EQ(img.datagrams().size(), 2U);
  EXPECT_EQ(img.datagrams()[0].command, Command::LWR);
  EXPECT_EQ(img.datagrams()[0].logical_address, 0x00010000U);
  EXPECT_EQ(img.datagrams()[0].length, 19);
  EXPECT_EQ(img.datagrams()[0].expected_wkc, 2);  // writers: drive, I/O
  EXPECT_EQ(img.datagrams()[1].command, Command::LRD);
  EXPECT_EQ(img.datagrams()[1].expected_wkc, 3);  // readers: all three
  EXPECT_EQ(img.expected_wkc(), 5);
  EXPECT_EQ(img.frame_bytes(), 16U + 2 * (12 + 19));

  // Per slave: LRW for the drive (0..11, WKC 3), LWR + LRD for the I/O slave, LRW for the input one.
  ASSERT_TRUE(img.build(t.slaves, ImageOptions{0, CyclicDatagrams::PerSlave, 0, 0})) << img.text();
  const auto dg = img.datagrams();
  ASSERT_EQ(dg.size(), 4U);
  EXPECT_EQ(dg[0].command, Command::LRW);
  EXPECT_EQ(dg[0].length, 12);
  EXPECT_EQ(dg[0].expected_wkc, 3);
  EXPECT_EQ(dg[1].command, Command::LWR);
  EXPECT_EQ(dg[1].image_offset, 12U);
  EXPECT_EQ(dg[1].length, 2);
  EXPECT_EQ(dg[2].command, Command::LRD);
  EXPECT_EQ(dg[2].image_offset, 14U);
  EXPECT_EQ(dg[2].length, 1);
  EXPECT_EQ(dg[3].command, Command::LRW);
  EXPECT_EQ(dg[3].slave, 2);
  EXPECT_EQ(dg[3].expected_wkc, 1);
  EXPECT_EQ(img.expected_wkc(), 6);
}

// Two slaves of 800 bytes: the whole-image LRW does not fit one frame, so it is cut at the slave
// boundary into two LRWs, one per frame, each with its slaves' working counter.
TEST(ProcessImage, AnImageLargerThanOneFrameIsCutAtASlaveBoundary) {
  std::array<ImageSlave, 2> s{};
  s[0] = ImageSlave{0x1001, 800, 0, ProcessSm{0x1000, 0x64, 0}, ProcessSm{0x2000, 0x20, 0}, 0, 1, false};
  s[1] = ImageSlave{0x1002, 0, 800, ProcessSm{0x1000, 0x64, 0}, ProcessSm{0x1000, 0x20, 0}, 0, 1, false};
  ProcessImage img;
  ASSERT_TRUE(img.build(s)) << img.text();
  ASSERT_EQ(img.datagrams().size(), 2U);
  EXPECT_EQ(img.datagrams()[0].command, Command::LRW);
  EXPECT_EQ(img.datagrams()[0].logical_address, 0U);
  EXPECT_EQ(img.datagrams()[0].length, 800);
  EXPECT_EQ(img.datagrams()[0].expected_wkc, 2);  // slave 1 writes
  EXPECT_EQ(img.datagrams()[0].frame, 0);
  EXPECT_EQ(img.datagrams()[1].logical_address, 800U);
  EXPECT_EQ(img.datagrams()[1].length, 800);
  EXPECT_EQ(img.datagrams()[1].expected_wkc, 1);  // slave 2 reads
  EXPECT_EQ(img.datagrams()[1].frame, 1);
  EXPECT_EQ(img.expected_wkc(), 3);
  // Frame 1: 16 + the AL status check (12 + 2) + 12 + 800 = 842; frame 2: 16 + 12 + 800 = 828.
  ASSERT_EQ(img.frame_count(), 2U);
  EXPECT_EQ(img.frames()[0].bytes, 842U);
  EXPECT_EQ(img.frames()[0].datagrams, 2U);
  EXPECT_EQ(img.frames()[1].bytes, 828U);
  EXPECT_EQ(img.frames()[1].datagrams, 1U);
  EXPECT_EQ(img.frame_bytes(), 1670U);
  EXPECT_EQ(img.wire_bytes(), 1670U + 2 * 24);
  EXPECT_EQ(img.wire_time(), std::chrono::nanoseconds(80 * 1718));
  // 1468 data bytes fit one frame exactly: 16 + 12 + 1468 + 14 = 1510.
  s[1].input_bytes = 668;
  ASSERT_TRUE(img.build(s)) << img.text();
  EXPECT_EQ(img.frame_count(), 1U);
  EXPECT_EQ(img.datagrams().size(), 1U);
  EXPECT_EQ(img.frame_bytes(), 1510U);
  // One slave with more than one datagram carries.
  s[0].output_bytes = 1500;
  EXPECT_FALSE(img.build(s));
  EXPECT_EQ(img.error(), ImageError::FrameTooLarge);
  EXPECT_EQ(img.text(), "slave 1 (0x1001): 1500 bytes of process data, one Ethernet frame carries 1486");
  EXPECT_EQ(img.frame_count(), 0U);
  EXPECT_FALSE(img.fits(std::chrono::seconds(1)));
}

// `n` generic CiA 402 drives as the bus plans them without an SII (17 bytes out, 15 in; SM2 at
// 1000h, SM3 after its three buffers).
std::vector<ImageSlave> generic_drives(std::size_t n) {
  std::vector<ImageSlave> v(n);
  for (std::size_t k = 0; k < n; ++k) {
    v[k] = ImageSlave{static_cast<std::uint16_t>(0x1001 + k), 17, 15, ProcessSm{0x1000, 0x64, 0},
                      ProcessSm{0x1033, 0x20, 0}, 0, 1, false};
  }
  return v;
}

// The bus' options: one LRW per slave, DC's FRMW (8 bytes) and the AL status check (2) first.
constexpr ImageOptions kBusOptions{0, CyclicDatagrams::PerSlave, 2, 10};

// 64 drives, one LRW of 32 bytes each: 66 datagrams in two frames of at most 1514 bytes, packed in
// queue order as Transactions does.
TEST(ProcessImage, SixtyFourSlavesTakeTwoFrames) {
  const auto drives = generic_drives(64);
  ProcessImage img;
  ASSERT_TRUE(img.build(drives, kBusOptions)) << img.text();
  EXPECT_EQ(img.size(), 64U * 32U);
  const auto dg = img.datagrams();
  ASSERT_EQ(dg.size(), 64U);
  for (std::size_t k = 0; k < 64; ++k) {
    EXPECT_EQ(dg[k].command, Command::LRW) << k;
    EXPECT_EQ(dg[k].logical_address, 32U * k) << k;
    EXPECT_EQ(dg[k].length, 32) << k;
    EXPECT_EQ(dg[k].expected_wkc, 3) << k;
    EXPECT_EQ(dg[k].slave, k) << k;
    // FRMW, AL check and slaves 1-33 | slaves 34-64.
    EXPECT_EQ(dg[k].frame, k < 33 ? 0 : 1) << k;
  }
  EXPECT_EQ(img.expected_wkc(), 192);
  ASSERT_EQ(img.frame_count(), 2U);
  // 16 + (12 + 8) + (12 + 2) + 33 × (12 + 32) = 1502 (a 34th slave would make 1546 > 1514);
  // 16 + 31 × 44 = 1380.
  EXPECT_EQ(img.frames()[0].bytes, 1502U);
  EXPECT_EQ(img.frames()[0].datagrams, 35U);
  EXPECT_EQ(img.frames()[1].bytes, 1380U);
  EXPECT_EQ(img.frames()[1].datagrams, 31U);
  EXPECT_EQ(img.frame_bytes(), 2882U);
  // On the wire 2882 + 2 × 24 = 2930 bytes = 234.4 µs; + 64 slaves × 1 µs = 298.4 µs.
  EXPECT_EQ(img.wire_time(), std::chrono::nanoseconds(234'400));
  EXPECT_EQ(img.round_trip(), std::chrono::nanoseconds(298'400));
  EXPECT_TRUE(img.fits(std::chrono::milliseconds(1)));
  EXPECT_FALSE(img.fits(std::chrono::microseconds(500)));  // half: 250 µs

  // The same line in whole-image mode: LRWs cut at slave boundaries. The first frame has room for
  // 1514 - 16 - 34 - 12 = 1452 bytes: 45 slaves (1440); the other 19 (608 bytes) go in the second.
  ProcessImage whole;
  ASSERT_TRUE(whole.build(drives, ImageOptions{0x10000, CyclicDatagrams::WholeImage, 2, 10})) << whole.text();
  ASSERT_EQ(whole.datagrams().size(), 2U);
  EXPECT_EQ(whole.datagrams()[0].logical_address, 0x10000U);
  EXPECT_EQ(whole.datagrams()[0].length, 1440);
  EXPECT_EQ(whole.datagrams()[0].expected_wkc, 135);
  EXPECT_EQ(whole.datagrams()[1].logical_address, 0x10000U + 1440U);
  EXPECT_EQ(whole.datagrams()[1].image_offset, 1440U);
  EXPECT_EQ(whole.datagrams()[1].length, 608);
  EXPECT_EQ(whole.datagrams()[1].expected_wkc, 57);
  EXPECT_EQ(whole.datagrams()[1].frame, 1);
  ASSERT_EQ(whole.frame_count(), 2U);
  EXPECT_EQ(whole.frames()[0].bytes, 16U + 34U + 12U + 1440U);
  EXPECT_EQ(whole.frames()[1].bytes, 16U + 12U + 608U);
}

// Slaves with 40 output and 40 input bytes that need an LWR and an LRD each (52 bytes a datagram).
std::vector<ImageSlave> lrd_lwr_slaves(std::size_t n) {
  std::vector<ImageSlave> v(n);
  for (std::size_t k = 0; k < n; ++k) {
    v[k] = ImageSlave{static_cast<std::uint16_t>(0x1001 + k), 40, 40, ProcessSm{0x1000, 0x64, 0},
                      ProcessSm{0x1078, 0x20, 0}, 0, 1, true};
  }
  return v;
}

// Beyond ProcessImage::kMaxFrames frames the line is refused in one sentence: 64 slaves that each
// need an LWR and an LRD of 40 bytes are 128 datagrams of 52 bytes + 2, five frames (28 a frame).
TEST(ProcessImage, MoreFramesThanACycleSendsAreRefused) {
  ProcessImage img;
  EXPECT_FALSE(img.build(lrd_lwr_slaves(64), kBusOptions));
  EXPECT_EQ(img.error(), ImageError::FrameTooLarge);
  EXPECT_EQ(img.text(),
            "process image of 5120 bytes: its 128 cyclic datagrams (and 2 more) need 5 Ethernet frames, a cycle sends at "
            "most 4 (of 1514 bytes each)");
  EXPECT_EQ(img.slave_count(), 0U);
  EXPECT_EQ(img.frame_count(), 0U);
  EXPECT_TRUE(img.datagrams().empty());
  // 56 such slaves: 112 + 2 datagrams, exactly four full frames (the first with the 2 extra ones:
  // 16 + 34 + 28 × 52 = 1506; a 29th would make 1558 > 1514).
  ASSERT_TRUE(img.build(lrd_lwr_slaves(56), kBusOptions)) << img.text();
  ASSERT_EQ(img.frame_count(), 4U);
  EXPECT_EQ(img.frames()[0].datagrams, 30U);
  for (std::size_t f = 1; f < 4; ++f) EXPECT_EQ(img.frames()[f].datagrams, 28U) << f;
  EXPECT_EQ(img.datagrams()[111].frame, 3);
}

// What goes on the wire is what was planned: DC's FRMW, then CyclicExchange's datagrams through
// Transactions give two frames of the planned sizes; the end of the last one byte by byte.
TEST(ProcessImage, TransactionsSendThePlannedFrames) {
  const auto drives = generic_drives(64);
  ProcessImage img;
  ASSERT_TRUE(img.build(drives, kBusOptions)) << img.text();
  CyclicExchange cx(img);
  for (std::size_t k = 62; k < 64; ++k) {
    const auto out = cx.outputs(k);
    ASSERT_EQ(out.size(), 17U);
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = static_cast<std::uint8_t>(0x10 * (k - 61) + i);
  }
  Transactions tx;
  ASSERT_TRUE(tx.queue(nullptr, 0, Command::FRMW, physical_address(0x1001, 0x0910), 8));
  ASSERT_TRUE(cx.queue(tx));
  const auto frames = tx.take_frames(core::TimePoint{} + std::chrono::milliseconds(1));
  ASSERT_EQ(frames.size(), img.frame_count());
  for (std::size_t f = 0; f < frames.size(); ++f) EXPECT_EQ(frames[f].size(), img.frames()[f].bytes) << f;
  // Frame 1 starts with the FRMW, then the AL status check of slave 1, then slave 1's LRW.
  {
    FrameParser p(frames[0]);
    Datagram d;
    ASSERT_TRUE(p.next(d));
    EXPECT_EQ(d.header.command, Command::FRMW);
    ASSERT_TRUE(p.next(d));
    EXPECT_EQ(d.header.command, Command::FPRD);
    EXPECT_EQ(d.header.address, physical_address(0x1001, 0x0130));
    ASSERT_TRUE(p.next(d));
    EXPECT_EQ(d.header.command, Command::LRW);
    EXPECT_EQ(d.header.address, 0U);
  }
  {
    FrameParser p(frames[1]);
    Datagram d;
    ASSERT_TRUE(p.next(d));
    EXPECT_EQ(d.header.command, Command::LRW);
    EXPECT_EQ(d.header.address, 1056U);  // slave 34
  }
  // Frame 2 [ETG.1000.4 §5.3-§5.4]: broadcast destination, source 02:00:00:00:00:01, EtherType
  // 88A4h; EtherCAT header: length 31 × 44 = 1364 (554h), type 1 (1554h).
  const std::vector<std::uint8_t> header = {0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0x02, 0x00,
                                            0x00, 0x00, 0x00, 0x01, 0x88, 0xA4, 0x54, 0x15};
  ASSERT_EQ(frames[1].size(), 1380U);
  EXPECT_EQ(std::vector<std::uint8_t>(frames[1].begin(), frames[1].begin() + 16), header);
  // It ends with slaves 63 and 64: LRW (0Ch), index 1 (the second frame of Transactions), logical
  // address 7C0h (1984), length 32 with the M bit (8020h), IRQ 0, the 17 output bytes and 15
  // input bytes (zero), WKC 0; then the same at 7E0h without the M bit (the last datagram).
  std::vector<std::uint8_t> want;
  for (const std::uint8_t k : {std::uint8_t{1}, std::uint8_t{2}}) {
    const std::uint8_t lo = k == 1 ? 0xC0 : 0xE0;
    const std::uint8_t more = k == 1 ? 0x80 : 0x00;
    for (const std::uint8_t b : {std::uint8_t{0x0C}, std::uint8_t{0x01}, lo, std::uint8_t{0x07}, std::uint8_t{0x00},
                                 std::uint8_t{0x00}, std::uint8_t{0x20}, more, std::uint8_t{0x00}, std::uint8_t{0x00}})
      want.push_back(b);
    for (std::uint8_t i = 0; i < 17; ++i) want.push_back(static_cast<std::uint8_t>(0x10 * k + i));
    want.insert(want.end(), 15 + 2, 0x00);
  }
  ASSERT_EQ(want.size(), 88U);
  EXPECT_EQ(std::vector<std::uint8_t>(frames[1].end() - 88, frames[1].end()), want);
}

TEST(ProcessImage, PdosLargerThanTheirSmAreRefused) {
  ThreeSlaves t;
  t.slaves[0].output_bytes = 50;  // room for 42
  ProcessImage img;
  EXPECT_FALSE(img.build(t.slaves));
  EXPECT_EQ(img.error(), ImageError::OutputsBeyondSm);
  EXPECT_EQ(img.text(), "slave 1 (0x1001): 50 output bytes do not fit SM2 at 1100h (room for 42 bytes, 3 buffers, before the next SM)");

  ThreeSlaves u;
  u.slaves[1].sm3.start = 0x1002;  // inside SM2's three buffers (1000h-1005h)
  u.slaves[1].sm3.capacity = 0;
  EXPECT_FALSE(img.build(u.slaves));
  EXPECT_EQ(img.error(), ImageError::SmOverlap);
  EXPECT_EQ(img.text(), "slave 2 (0x1002): SM2 1000h-1005h and SM3 1002h-1004h overlap (3 buffers each)");

  ThreeSlaves v;
  v.slaves[2].sm3.start = 0x0F00;
  EXPECT_FALSE(img.build(v.slaves));
  EXPECT_EQ(img.error(), ImageError::BadSmAddress);
  EXPECT_EQ(img.text(),
            "slave 3 (0x1003): SM3 at 0F00h with 4 input bytes (3 buffers) is outside the process RAM 1000h-FFFFh");

  std::array<ImageSlave, ProcessImage::kMaxSlaves + 1> many{};
  EXPECT_FALSE(img.build(many));
  EXPECT_EQ(img.error(), ImageError::TooManySlaves);
}

}  // namespace
}  // namespace drivegate::ethercat
