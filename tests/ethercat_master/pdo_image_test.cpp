// ProcessImage: byte-exact SM and FMMU entries, cyclic datagrams, working counters and frame
// sizes for a line of three slaves, and the layouts it refuses.
//
// The vectors are derived by hand from ETG.1000.4 Table 59 (SM entry: start u16, length u16,
// control, status, activate, PDI control) and Table 56 (FMMU entry: logical start u32, length u16,
// start bit, stop bit, physical start u16, physical start bit, type 1 read / 2 write, activate,
// 3 reserved), little-endian, with the image laid out per slave as outputs then inputs.
#include <gtest/gtest.h>

#include <array>
#include <memory>
#include <vector>

#include "adapters/ethercat/master/process_image.hpp"
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

TEST(ProcessImage, AnImageLargerThanOneFrameIsRefused) {
  std::array<ImageSlave, 2> s{};
  s[0] = ImageSlave{0x1001, 800, 0, ProcessSm{0x1000, 0x64, 0}, ProcessSm{0x2000, 0x20, 0}, 0, 1, false};
  s[1] = ImageSlave{0x1002, 0, 800, ProcessSm{0x1000, 0x64, 0}, ProcessSm{0x1000, 0x20, 0}, 0, 1, false};
  ProcessImage img;
  EXPECT_FALSE(img.build(s));
  EXPECT_EQ(img.error(), ImageError::FrameTooLarge);
  // 14 + 2 + 2 × 12 + 1600 + 2 = 1642 bytes.
  EXPECT_EQ(img.text(),
            "process image of 1600 bytes: the cyclic frame needs 1642 bytes in 2 datagrams (1 for the image), one "
            "Ethernet frame carries 1514 bytes and 32 datagrams");
  EXPECT_EQ(img.slave_count(), 0U);
  EXPECT_FALSE(img.fits(std::chrono::seconds(1)));
  // 1468 data bytes fit exactly: 16 + 12 + 1468 + 14 = 1510.
  s[1].input_bytes = 668;
  EXPECT_TRUE(img.build(s)) << img.text();
  EXPECT_EQ(img.frame_bytes(), 1510U);
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
