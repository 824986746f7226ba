// AKD part 1 §14 (akd-canopen-part1-communication.md) vectors the other tests do not hold byte-exact:
// the §5.3 number encodings (vectors 1, 2) and node guarding on node 1 (vectors 25, 26). The other
// vectors are in the SDO, NMT, PDO and EMCY engine tests, which cite them by number.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>

#include "adapters/canopen/wire/can_frame.hpp"
#include "adapters/canopen/wire/cob_id.hpp"
#include "adapters/canopen/wire/nmt_codec.hpp"

namespace drivegate::canopen {
namespace {

// Vectors 1 and 2 (§5.3): little-endian, INTEGER16 in two's complement (the source's range text
// is garbled, §15 item 2; the wire bytes are not).
TEST(AkdPart1Digest, NumberEncodings) {
  std::array<std::uint8_t, 2> b{};
  put_le(b, 0, 2, 266);
  EXPECT_EQ(b, (std::array<std::uint8_t, 2>{0x0A, 0x01}));
  EXPECT_EQ(get_le(b, 0, 2), 0x010AU);

  put_le(b, 0, 2, static_cast<std::uint32_t>(std::int32_t{-266}));
  EXPECT_EQ(b, (std::array<std::uint8_t, 2>{0xF6, 0xFE}));
  EXPECT_EQ(static_cast<std::int16_t>(get_le(b, 0, 2)), -266);
}

// Vectors 25 and 26 (§11.1): the guard request is an RTR on 701h, DLC 1 per CiA 301; the replies
// carry the state in bits 6..0 and a toggle in bit 7 that alternates from 0.
TEST(AkdPart1Digest, NodeGuardingOnNode1) {
  CanFrame request;
  request.id = cob::error_control(1);
  request.remote = true;
  request.dlc = 1;
  EXPECT_EQ(request.id, 0x701U);
  EXPECT_TRUE(request.valid());
  EXPECT_TRUE(request.payload().empty());  // an RTR carries no data, whatever its DLC
  const CobSplit route = split_cob_id(request.id);
  EXPECT_EQ(route.function, Function::ErrorControl);
  EXPECT_EQ(route.node, 1);

  const std::array<std::uint8_t, 3> replies{0x05, 0x85, 0x05};
  for (std::size_t k = 0; k < replies.size(); ++k) {
    SCOPED_TRACE(k);
    const auto reply = make_frame(0x701, {replies[k]});
    const auto d = decode_error_control(reply.payload());
    ASSERT_TRUE(d.has_value());
    EXPECT_EQ(d->state, NmtState::Operational);
    EXPECT_EQ(d->toggle, k % 2 == 1);
    EXPECT_EQ(encode_error_control(NmtState::Operational, k % 2 == 1), replies[k]);
  }
}

}  // namespace
}  // namespace drivegate::canopen
