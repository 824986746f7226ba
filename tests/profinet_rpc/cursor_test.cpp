// The cursor every PNIO codec reads and writes with (adapters/profinet/wire/rpc_cursor.hpp): byte
// order per message, the first error sticks and stops the cursor.
#include <gtest/gtest.h>

#include <array>

#include "adapters/profinet/wire/rpc_cursor.hpp"
#include "tests/profinet_rpc/hex.hpp"

namespace drivegate::profinet {
namespace {

using test::hex;

TEST(PnCursor, ReadsInEitherOrder) {
  const auto b = hex("01 02 03 04 05 06 07 08 09 0A 0B 0C 0D 0E 0F 10");
  Reader le(b, ByteOrder::Little);
  EXPECT_EQ(le.u16(), 0x0201);
  EXPECT_EQ(le.u32(), 0x06050403U);
  Reader be(b, ByteOrder::Big);
  EXPECT_EQ(be.u16(), 0x0102);
  EXPECT_EQ(be.u32(), 0x03040506U);
  // A UUID: the first three fields by the order, the last eight octets as they are.
  Reader u(b, ByteOrder::Little);
  const Uuid id = u.uuid();
  EXPECT_EQ(id.time_low, 0x04030201U);
  EXPECT_EQ(id.time_mid, 0x0605);
  EXPECT_EQ(id.time_hi_and_version, 0x0807);
  EXPECT_EQ(id.clock_seq_node[0], 0x09);
  EXPECT_EQ(u.remaining(), 0U);
}

TEST(PnCursor, FirstErrorSticks) {
  const auto b = hex("01 02 03");
  Reader r(b, ByteOrder::Big);
  EXPECT_EQ(r.u16(), 0x0102);
  EXPECT_EQ(r.u16(), 0);  // one byte left: truncated
  EXPECT_EQ(r.error(), WireError::Truncated);
  EXPECT_EQ(r.position(), 2U);
  EXPECT_EQ(r.u8(), 0);  // the byte is there, but the cursor stopped
  EXPECT_TRUE(r.bytes(1).empty());
  r.fail(WireError::CountBeyondData);
  EXPECT_EQ(r.error(), WireError::Truncated);  // the first error wins
}

TEST(PnCursor, WriterStopsAtTheEnd) {
  std::array<std::uint8_t, 5> out{};
  Writer w(out, ByteOrder::Little);
  w.u32(0x11223344);
  EXPECT_EQ(w.size_or_zero(), 4U);
  w.u16(0xAABB);  // does not fit
  EXPECT_EQ(w.error(), WireError::BufferTooSmall);
  EXPECT_EQ(w.size_or_zero(), 0U);
  w.u8(0xCC);  // stopped: nothing more written
  EXPECT_EQ(out, (std::array<std::uint8_t, 5>{0x44, 0x33, 0x22, 0x11, 0x00}));
  Writer p(out, ByteOrder::Big);
  p.u16(0);
  p.patch_u16(0, 0x0102);
  p.patch_u32(1, 0xA0B0C0D0);
  EXPECT_EQ(out, (std::array<std::uint8_t, 5>{0x01, 0xA0, 0xB0, 0xC0, 0xD0}));
}

TEST(PnCursor, ErrorTexts) {
  for (int e = 0; e <= static_cast<int>(WireError::MissingBlock); ++e) {
    const std::string_view t = to_string(static_cast<WireError>(e));
    EXPECT_FALSE(t.empty());
    EXPECT_NE(t, "?");
  }
}

}  // namespace
}  // namespace drivegate::profinet
