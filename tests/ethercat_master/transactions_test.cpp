// Transactions: packing of queued datagrams into frames, matching returned frames by index,
// loss at the deadline, foreign indexes, malformed and mismatched frames. Byte vectors are derived
// from ETG.1000.4 §5.3 (EtherCAT header) and §5.4 (datagram header: cmd, idx, ADP/ADO, length with
// M bit 15, IRQ; data; WKC).
#include <gtest/gtest.h>

#include <array>
#include <vector>

#include "adapters/ethercat/master/transactions.hpp"
#include "core/bytes.hpp"
#include "tests/support/alloc_counter.hpp"

namespace drivegate::ethercat {

using core::put_u16;

namespace {

using namespace std::chrono_literals;

struct Recorder final : DatagramOwner {
  struct Got {
    std::uint32_t tag;
    DatagramOutcome outcome;
    Command command;
    std::vector<std::uint8_t> data;
    std::uint16_t wkc;
  };
  std::vector<Got> got;
  void on_result(std::uint32_t tag, const DatagramAnswer& a) noexcept override {
    got.push_back({tag, a.outcome, a.command, {a.data.begin(), a.data.end()}, a.wkc});
  }
};

core::TimePoint at(std::chrono::milliseconds ms) { return core::TimePoint{} + ms; }

std::vector<std::uint8_t> copy(std::span<const std::uint8_t> s) { return {s.begin(), s.end()}; }

// A frame's bytes held by value (a fixed array: GCC 12's -Wnull-dereference misreads vector copies).
struct FrameBytes {
  std::array<std::uint8_t, kMaxFrameSize> b{};
  std::size_t n = 0;
  explicit FrameBytes(std::span<const std::uint8_t> s) : n(s.size()) { std::copy(s.begin(), s.end(), b.begin()); }
  std::uint8_t& operator[](std::size_t i) { return b[i]; }
  operator std::span<const std::uint8_t>() const { return {b.data(), n}; }
  std::span<std::uint8_t> span() { return {b.data(), n}; }
};

TEST(EthercatTransactions, PacksDatagramsIntoOneFrameWithMoreBitsAndOneIndex) {
  Transactions tx(MacAddress{0x02, 0, 0, 0, 0, 0x01});
  Recorder r;
  ASSERT_TRUE(tx.queue(&r, 1, Command::BRD, physical_address(0, 0x0000), 2));
  const std::array<std::uint8_t, 2> station{0x01, 0x10};
  ASSERT_TRUE(tx.queue(&r, 2, Command::APWR, physical_address(auto_increment_adp(1), 0x0010), 2, station));
  ASSERT_TRUE(tx.queue(&r, 3, Command::FPRD, physical_address(0x1001, 0x0130), 2));
  const auto frames = tx.take_frames(at(1ms));
  ASSERT_EQ(frames.size(), 1U);
  const auto f = frames[0];
  ASSERT_EQ(f.size(), 60U);  // 14 + 2 + 3 × 14 = 58, padded to the 60-byte minimum
  // Ethernet: broadcast destination, our source, EtherType 88A4h big-endian.
  EXPECT_EQ(copy(f.first(14)), (std::vector<std::uint8_t>{0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0x02, 0, 0, 0, 0,
                                                            0x01, 0x88, 0xA4}));
  // EtherCAT header: length 42 = 3 × (10 + 2 + 2), type 1 in bits 12-15 -> 0x102A LE.
  EXPECT_EQ(f[14], 0x2A);
  EXPECT_EQ(f[15], 0x10);
  const std::uint8_t idx = f[17];
  // BRD: cmd 7, idx, ADP 0000 ADO 0000, length 2 | M (0x8002), IRQ 0, data 2, WKC 0.
  EXPECT_EQ(copy(f.subspan(16, 14)),
            (std::vector<std::uint8_t>{0x07, idx, 0, 0, 0, 0, 0x02, 0x80, 0, 0, 0, 0, 0, 0}));
  // APWR position 1: ADP FFFFh, ADO 0010h, M set, data 01 10.
  EXPECT_EQ(copy(f.subspan(30, 14)),
            (std::vector<std::uint8_t>{0x02, idx, 0xFF, 0xFF, 0x10, 0x00, 0x02, 0x80, 0, 0, 0x01, 0x10, 0, 0}));
  // FPRD 1001h:0130h, last datagram: M clear.
  EXPECT_EQ(copy(f.subspan(44, 14)),
            (std::vector<std::uint8_t>{0x04, idx, 0x01, 0x10, 0x30, 0x01, 0x02, 0x00, 0, 0, 0, 0, 0, 0}));
  EXPECT_EQ(tx.frames_in_flight(), 1U);
  EXPECT_EQ(tx.counters().frames_sent, 1U);
}

TEST(EthercatTransactions, StartsANewFrameWhenTheDatagramDoesNotFit) {
  Transactions tx;
  Recorder r;
  // 1486 bytes of data fill one untagged frame (1514 - 14 - 2 - 12).
  ASSERT_TRUE(tx.queue(&r, 1, Command::LRW, 0, 1000));
  ASSERT_TRUE(tx.queue(&r, 2, Command::LRW, 1000, 486));  // 1000 + 12 + 486 + 12 > 1498: new frame
  ASSERT_TRUE(tx.queue(&r, 3, Command::FPRD, physical_address(0x1001, 0x0130), 2));  // fits frame 2
  const auto frames = tx.take_frames(at(1ms));
  ASSERT_EQ(frames.size(), 2U);
  EXPECT_EQ(frames[0].size(), 14U + 2U + 1012U);
  EXPECT_EQ(frames[1].size(), 14U + 2U + 498U + 14U);
  EXPECT_NE(frames[0][17], frames[1][17]);  // each frame its own index
  EXPECT_FALSE(tx.queue(&r, 4, Command::LRW, 0, static_cast<std::uint16_t>(kMaxDatagramData + 1)));
  EXPECT_EQ(tx.counters().too_long, 1U);
}

TEST(EthercatTransactions, ReturnedFrameIsMatchedByIndexAndResultsHandedBackInPlace) {
  Transactions tx;
  Recorder r;
  ASSERT_TRUE(tx.queue(&r, 10, Command::BRD, physical_address(0, 0x0000), 2));
  ASSERT_TRUE(tx.queue(&r, 11, Command::FPRD, physical_address(0x1001, 0x0130), 2));
  auto f = copy(tx.take_frames(at(1ms))[0]);
  // Slaves: 3 answer the BRD (ADP incremented 3 times, data OR-ed), one the FPRD with AL status 2.
  put_u16(f, 18, 3);
  f[26] = 0x11;
  put_u16(f, 28, 3);
  f[40] = 0x02;
  put_u16(f, 42, 1);
  EXPECT_TRUE(tx.on_frame(f));
  ASSERT_EQ(r.got.size(), 2U);
  EXPECT_EQ(r.got[0].tag, 10U);
  EXPECT_EQ(r.got[0].outcome, DatagramOutcome::Answered);
  EXPECT_EQ(r.got[0].wkc, 3);
  EXPECT_EQ(r.got[0].data, (std::vector<std::uint8_t>{0x11, 0x00}));
  EXPECT_EQ(r.got[1].tag, 11U);
  EXPECT_EQ(r.got[1].data, (std::vector<std::uint8_t>{0x02, 0x00}));
  EXPECT_EQ(r.got[1].wkc, 1);
  EXPECT_EQ(tx.frames_in_flight(), 0U);
  // The same frame again: its index is no longer in flight.
  EXPECT_FALSE(tx.on_frame(f));
  EXPECT_EQ(tx.counters().foreign, 1U);
  EXPECT_EQ(r.got.size(), 2U);
}

TEST(EthercatTransactions, FrameNotBackByItsDeadlineIsLost) {
  Transactions tx;
  Recorder r;
  ASSERT_TRUE(tx.queue(&r, 1, Command::FPRD, physical_address(0x1001, 0x0130), 2));
  ASSERT_TRUE(tx.queue(&r, 2, Command::FPRD, physical_address(0x1002, 0x0130), 2));
  const auto f = copy(tx.take_frames(at(1ms))[0]);
  tx.expire(at(0ms) + 999us);
  EXPECT_TRUE(r.got.empty());
  tx.expire(at(1ms));
  ASSERT_EQ(r.got.size(), 2U);
  EXPECT_EQ(r.got[0].outcome, DatagramOutcome::Lost);
  EXPECT_EQ(r.got[1].outcome, DatagramOutcome::Lost);
  EXPECT_EQ(tx.counters().frames_lost, 1U);
  EXPECT_EQ(tx.counters().datagrams_lost, 2U);
  // Arriving late: foreign, nothing delivered twice.
  EXPECT_FALSE(tx.on_frame(f));
  EXPECT_EQ(tx.counters().foreign, 1U);
  EXPECT_EQ(r.got.size(), 2U);
}

TEST(EthercatTransactions, ForeignIndexMalformedAndMismatchedFramesAreCountedAndDropped) {
  Transactions tx;
  Recorder r;
  ASSERT_TRUE(tx.queue(&r, 1, Command::FPRD, physical_address(0x1001, 0x0130), 2));
  ASSERT_TRUE(tx.queue(&r, 2, Command::FPWR, physical_address(0x1001, 0x0120), 2));
  const FrameBytes sent(tx.take_frames(at(1ms))[0]);

  FrameBytes foreign = sent;
  foreign[17] = static_cast<std::uint8_t>(foreign[17] + 1);
  foreign[31] = foreign[17];
  EXPECT_FALSE(tx.on_frame(foreign));
  EXPECT_EQ(tx.counters().foreign, 1U);

  FrameBytes truncated(std::span<const std::uint8_t>(sent).first(20));
  EXPECT_FALSE(tx.on_frame(truncated));
  EXPECT_EQ(tx.counters().malformed, 1U);
  EXPECT_EQ(tx.frame_errors()[FrameError::EcatLengthBeyondFrame], 1U);

  FrameBytes wrong_type = sent;
  wrong_type[13] = 0x00;  // EtherType 8800h
  EXPECT_FALSE(tx.on_frame(wrong_type));
  EXPECT_EQ(tx.frame_errors()[FrameError::WrongEtherType], 1U);

  FrameBytes other_command = sent;
  other_command[30] = static_cast<std::uint8_t>(Command::FPRD);  // second datagram sent as FPWR
  EXPECT_FALSE(tx.on_frame(other_command));
  FrameBytes other_address = sent;
  other_address[18] = 0x02;  // station 1002h instead of 1001h
  EXPECT_FALSE(tx.on_frame(other_address));
  EXPECT_EQ(tx.counters().mismatched, 2U);
  EXPECT_TRUE(r.got.empty());
  EXPECT_EQ(tx.frames_in_flight(), 1U);

  // The genuine answer still matches afterwards.
  EXPECT_TRUE(tx.on_frame(sent));
  EXPECT_EQ(r.got.size(), 2U);
}

TEST(EthercatTransactions, AutoIncrementAddressMayComeBackIncremented) {
  Transactions tx;
  Recorder r;
  ASSERT_TRUE(tx.queue(&r, 1, Command::APRD, physical_address(auto_increment_adp(2), 0x0130), 2));
  auto f = copy(tx.take_frames(at(1ms))[0]);
  put_u16(f, 18, static_cast<std::uint16_t>(auto_increment_adp(2) + 3));  // three slaves passed
  put_u16(f, 28, 1);
  EXPECT_TRUE(tx.on_frame(f));
  ASSERT_EQ(r.got.size(), 1U);
  EXPECT_EQ(r.got[0].wkc, 1);
}

TEST(EthercatTransactions, FixedCapacityRefusesWhenAllFramesAreInFlight) {
  Transactions tx;
  Recorder r;
  for (std::size_t i = 0; i < Transactions::kMaxFrames; ++i) {
    ASSERT_TRUE(tx.queue(&r, 0, Command::LRW, 0, static_cast<std::uint16_t>(kMaxDatagramData)));
  }
  EXPECT_FALSE(tx.queue(&r, 0, Command::BRD, 0, 2));
  EXPECT_EQ(tx.counters().queue_full, 1U);
  EXPECT_EQ(tx.take_frames(at(1ms)).size(), Transactions::kMaxFrames);
  EXPECT_FALSE(tx.queue(&r, 0, Command::BRD, 0, 2));
  tx.expire(at(1ms));
  EXPECT_TRUE(tx.queue(&r, 0, Command::BRD, 0, 2));
  // A frame holds as many datagrams as fit: 124 without data (16 + 124 × 12 = 1504 bytes), the
  // 125th opens a second frame.
  static_assert(Transactions::kMaxDatagramsPerFrame == 124);
  Transactions small;
  for (std::size_t i = 0; i < Transactions::kMaxDatagramsPerFrame + 1; ++i) {
    ASSERT_TRUE(small.queue(&r, 0, Command::BRD, 0, 0));
  }
  const auto frames = small.take_frames(at(1ms));
  ASSERT_EQ(frames.size(), 2U);
  EXPECT_EQ(frames[0].size(), 1504U);
  EXPECT_EQ(frames[1].size(), 60U);  // one datagram, padded to the Ethernet minimum
}

TEST(EthercatTransactions, ForgottenOwnerIsNotCalled) {
  Transactions tx;
  Recorder r;
  ASSERT_TRUE(tx.queue(&r, 1, Command::BRD, 0, 2));
  (void)tx.take_frames(at(1ms));
  tx.forget(&r);
  tx.expire(at(2ms));
  EXPECT_TRUE(r.got.empty());
  EXPECT_EQ(tx.counters().datagrams_lost, 1U);
}

struct Counter final : DatagramOwner {
  std::size_t n = 0;
  std::uint16_t wkc_sum = 0;
  void on_result(std::uint32_t, const DatagramAnswer& a) noexcept override {
    ++n;
    wkc_sum = static_cast<std::uint16_t>(wkc_sum + a.wkc);
  }
};

TEST(EthercatTransactions, CyclicCallsDoNotAllocate) {
  Transactions tx;
  Counter c;
  std::array<std::uint8_t, kMaxFrameSize> echo{};
  test::AllocationScope scope;
  for (int cycle = 0; cycle < 100; ++cycle) {
    for (int i = 0; i < 5; ++i) (void)tx.queue(&c, 0, Command::FPRD, physical_address(0x1001, 0x0130), 2);
    (void)tx.queue(&c, 0, Command::LRW, 0, 64);
    const auto frames = tx.take_frames(at(std::chrono::milliseconds(cycle + 1)));
    for (const auto& f : frames) {
      std::copy(f.begin(), f.end(), echo.begin());
      if (cycle % 2 == 0) (void)tx.on_frame(std::span<const std::uint8_t>(echo.data(), f.size()));
    }
    tx.expire(at(std::chrono::milliseconds(cycle + 1)));
  }
  EXPECT_EQ(scope.count(), 0U);
  EXPECT_EQ(c.n, 600U);
}

}  // namespace
}  // namespace drivegate::ethercat
