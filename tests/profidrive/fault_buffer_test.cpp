// Fault buffer reading plan against akd-profinet-profidrive.md §18.2 and §24 step 12.
#include "profiles/profidrive/fault_buffer.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <vector>

#include "tests/support/alloc_counter.hpp"

namespace drivegate::profidrive {
namespace {

using Words = std::vector<std::uint16_t>;

TEST(ProfidriveFaultBuffer, SnapshotGroupsSituations) {
  std::array<std::uint16_t, 64> buffer{};
  buffer[0] = 702;   // current situation: F702 fieldbus communication lost [§18.3]
  buffer[1] = 501;
  buffer[8] = 302;   // the previous (acknowledged) situation
  buffer[63] = 135;  // the oldest
  const FaultSnapshot s = fault_snapshot(5, buffer, 5);
  EXPECT_TRUE(s.consistent);
  EXPECT_EQ(s.counter, 5);
  EXPECT_EQ(Words(s.current().begin(), s.current().end()), (Words{702, 501}));
  EXPECT_EQ(Words(s.situations[1].numbers().begin(), s.situations[1].numbers().end()), Words{302});
  EXPECT_EQ(s.situations[2].count, 0);
  EXPECT_EQ(Words(s.situations[7].numbers().begin(), s.situations[7].numbers().end()), Words{135});
  EXPECT_FALSE(fault_snapshot(5, buffer, 6).consistent);
  // Fewer than 64 entries read (8: the current situation only); more than 64 are ignored.
  EXPECT_EQ(fault_snapshot(1, std::span(buffer).first(8), 1).current().size(), 2U);
  std::array<std::uint16_t, 70> longer{};
  longer[64] = 1;
  EXPECT_EQ(fault_snapshot(1, longer, 1).situations[7].count, 0);
}

TEST(ProfidriveFaultBuffer, ReaderReadsCounterBufferCounter) {
  FaultBufferReader r;
  ASSERT_EQ(r.next_read(), (ParamAddress{Attribute::Value, 1, 944, 0}));
  r.on_values(Words{3});
  ASSERT_EQ(r.next_read(), (ParamAddress{Attribute::Value, 64, 947, 0}));
  Words buffer(64, 0);
  buffer[0] = 702;
  r.on_values(buffer);
  ASSERT_EQ(r.next_read(), (ParamAddress{Attribute::Value, 1, 944, 0}));
  r.on_values(Words{3});
  EXPECT_EQ(r.status(), FaultBufferReader::Status::Consistent);
  EXPECT_FALSE(r.next_read().has_value());
  EXPECT_EQ(Words(r.snapshot().current().begin(), r.snapshot().current().end()), Words{702});
  EXPECT_EQ(r.attempts(), 1);

  // The requests the plan asks for are the digest's constructed vectors (§5.6) when reading 8.
  FaultBufferReader eight(8);
  std::array<std::uint8_t, 16> out{};
  const std::array<ParamAddress, 1> counter{*eight.next_read()};
  ASSERT_EQ(encode_read_request(out, 7, counter).size, 10U);
  EXPECT_EQ(out[6], 0x03);
  EXPECT_EQ(out[7], 0xB0);
  eight.on_values(Words{1});
  const std::array<ParamAddress, 1> faults{*eight.next_read()};
  ASSERT_EQ(encode_read_request(out, 8, faults).size, 10U);
  EXPECT_EQ((std::array<std::uint8_t, 10>{out[0], out[1], out[2], out[3], out[4], out[5], out[6], out[7], out[8], out[9]}),
            (std::array<std::uint8_t, 10>{0x08, 0x01, 0x00, 0x01, 0x10, 0x08, 0x03, 0xB3, 0x00, 0x00}));
}

TEST(ProfidriveFaultBuffer, NewFaultDuringTheReadRereadsTheBuffer) {
  FaultBufferReader r(8, 2);
  r.on_values(Words{3});
  r.on_values(Words{501, 0, 0, 0, 0, 0, 0, 0});
  r.on_values(Words{4});  // a new situation arrived: read the buffer again
  EXPECT_EQ(r.status(), FaultBufferReader::Status::Reading);
  ASSERT_EQ(r.next_read(), (ParamAddress{Attribute::Value, 8, 947, 0}));
  r.on_values(Words{702, 0, 0, 0, 0, 0, 0, 0});
  r.on_values(Words{4});
  EXPECT_EQ(r.status(), FaultBufferReader::Status::Consistent);
  EXPECT_EQ(r.attempts(), 2);
  EXPECT_EQ(r.snapshot().counter, 4);
  EXPECT_EQ(Words(r.snapshot().current().begin(), r.snapshot().current().end()), Words{702});

  // Faults keep arriving: give up after max_attempts with the last data, marked inconsistent.
  FaultBufferReader busy(8, 2);
  busy.on_values(Words{1});
  busy.on_values(Words(8, 0));
  busy.on_values(Words{2});
  busy.on_values(Words(8, 0));
  busy.on_values(Words{3});
  EXPECT_EQ(busy.status(), FaultBufferReader::Status::Inconsistent);
  EXPECT_FALSE(busy.snapshot().consistent);
  EXPECT_FALSE(busy.next_read().has_value());
}

TEST(ProfidriveFaultBuffer, FailuresAndWrongShapes) {
  FaultBufferReader failed;
  failed.on_failed();
  EXPECT_EQ(failed.status(), FaultBufferReader::Status::Failed);
  EXPECT_FALSE(failed.next_read().has_value());
  FaultBufferReader two_counters;
  two_counters.on_values(Words{1, 2});
  EXPECT_EQ(two_counters.status(), FaultBufferReader::Status::Failed);
  FaultBufferReader short_buffer(64);
  short_buffer.on_values(Words{1});
  short_buffer.on_values(Words(8, 0));
  EXPECT_EQ(short_buffer.status(), FaultBufferReader::Status::Failed);
}

TEST(ProfidriveFaultBuffer, ValuesFromAResponseBlock) {
  const std::array<std::uint8_t, 12> reply{0x08, 0x01, 0x00, 0x01, 0x42, 0x03, 0x02, 0xBE, 0x01, 0xF5, 0x00, 0x00};
  const ResponseResult r = decode_param_response(reply);
  ASSERT_EQ(r.error, ParamError::None);
  std::array<std::uint16_t, 8> words{};
  EXPECT_EQ(u16_values(r.response.values()[0], words), std::optional<std::size_t>(3));
  EXPECT_EQ(words[0], 702);
  EXPECT_EQ(words[1], 501);
  const std::array<std::uint8_t, 10> dword_full{0x08, 0x01, 0x00, 0x01, 0x43, 0x01, 0x00, 0x00, 0x02, 0xBE};
  const ResponseResult d = decode_param_response(dword_full);
  ASSERT_EQ(d.error, ParamError::None);
  EXPECT_FALSE(u16_values(d.response.values()[0], words).has_value());
}

TEST(ProfidriveFaultBuffer, NoAllocation) {
  const std::array<std::uint16_t, 64> buffer{702};
  test::AllocationScope scope;
  FaultBufferReader r;
  const std::array<std::uint16_t, 1> c{9};
  r.on_values(c);
  r.on_values(buffer);
  r.on_values(c);
  EXPECT_EQ(r.status(), FaultBufferReader::Status::Consistent);
  EXPECT_EQ(scope.count(), 0U);
}

}  // namespace
}  // namespace drivegate::profidrive
