// NORD SK 500P TV-A (nord-sk500p-ds402.md §10) on the wire: the node-0x20 COB-IDs (§8.2), the
// NMT frames around the remap, the mapping entries, and the drive's side of the SDO frames, whose
// "xx" bytes (don't care) must not change what a frame means. The client's request bytes are
// tested in tests/canopen_sdo (SdoClientVectors.NordTvARemapTxPdo3), the PDO layouts of TV-B..TV-D
// in tests/canopen_pdo.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <vector>

#include "adapters/canopen/wire/can_frame.hpp"
#include "adapters/canopen/wire/cob_id.hpp"
#include "adapters/canopen/wire/nmt_codec.hpp"
#include "adapters/canopen/wire/pdo_mapping.hpp"
#include "adapters/canopen/wire/sdo_codec.hpp"

namespace drivegate::canopen {
namespace {

using Bytes = std::vector<std::uint8_t>;
constexpr NodeId kNode = 0x20;

// §8.2: the predefined connection set of node 20h.
TEST(NordDigest, CobIdsOfNode20h) {
  EXPECT_EQ(cob::rpdo(0, kNode), 0x220U);
  EXPECT_EQ(cob::rpdo(1, kNode), 0x320U);
  EXPECT_EQ(cob::rpdo(2, kNode), 0x420U);
  EXPECT_EQ(cob::rpdo(3, kNode), 0x520U);
  EXPECT_EQ(cob::tpdo(0, kNode), 0x1A0U);
  EXPECT_EQ(cob::tpdo(1, kNode), 0x2A0U);
  EXPECT_EQ(cob::tpdo(2, kNode), 0x3A0U);
  EXPECT_EQ(cob::tpdo(3, kNode), 0x4A0U);
  EXPECT_EQ(cob::sdo_rx(kNode), 0x620U);
  EXPECT_EQ(cob::sdo_tx(kNode), 0x5A0U);
  const CobSplit tx3 = split_cob_id(0x3A0);
  EXPECT_EQ(tx3.function, Function::Tpdo);
  EXPECT_EQ(tx3.index, 2);
  EXPECT_EQ(tx3.node, kNode);
}

// TV-A: NMT pre-operational before A1 and operational after A6 (prose in the source, standard
// CiA 301 frames per the digest).
TEST(NordDigest, TvaNmtFrames) {
  EXPECT_EQ(encode_nmt(NmtCommand::EnterPreOperational, kNode), (std::array<std::uint8_t, 2>{0x80, 0x20}));
  EXPECT_EQ(encode_nmt(NmtCommand::Start, kNode), (std::array<std::uint8_t, 2>{0x01, 0x20}));
  const std::array<std::uint8_t, 2> pre_op{0x80, 0x20};
  const auto d = decode_nmt(pre_op);
  ASSERT_TRUE(d.has_value());
  EXPECT_EQ(d->command, NmtCommand::EnterPreOperational);
  EXPECT_EQ(d->node, kNode);
}

// TV-A A3/A4: the mapping entries of TxPDO3, statusword 16 bit and mode display 8 bit.
TEST(NordDigest, TvaMappingEntries) {
  EXPECT_EQ(decode_mapping(0x60410010), (MappingEntry{{0x6041, 0}, 16}));
  EXPECT_EQ(decode_mapping(0x60610008), (MappingEntry{{0x6061, 0}, 8}));
  EXPECT_EQ(encode_mapping({{0x6061, 0}, 8}), 0x60610008U);
}

// TV-A as the drive reads the requests and the master the replies. The "xx" bytes are filled
// with two different patterns: the decoded meaning must be the same for both.
TEST(NordDigest, TvaDontCareBytesDoNotMatter) {
  struct Step {
    const char* name;
    std::array<int, 8> request;  // -1: xx
    ObjectId object;
    std::uint32_t value;
    std::uint8_t size;
  };
  const std::vector<Step> steps = {
      {"A1", {0x23, 0x02, 0x18, 0x01, 0xA0, 0x03, 0x00, 0xC0}, {0x1802, 1}, 0xC00003A0, 4},
      {"A2", {0x2F, 0x02, 0x1A, 0x00, 0x00, -1, -1, -1}, {0x1A02, 0}, 0, 1},
      {"A3", {0x23, 0x02, 0x1A, 0x01, 0x10, 0x00, 0x41, 0x60}, {0x1A02, 1}, 0x60410010, 4},
      {"A4", {0x23, 0x02, 0x1A, 0x02, 0x08, 0x00, 0x61, 0x60}, {0x1A02, 2}, 0x60610008, 4},
      {"A5", {0x2F, 0x02, 0x1A, 0x00, 0x02, -1, -1, -1}, {0x1A02, 0}, 2, 1},
      {"A6", {0x23, 0x02, 0x18, 0x01, 0xA0, 0x03, 0x00, 0x40}, {0x1802, 1}, 0x400003A0, 4},
  };
  for (const auto& s : steps) {
    for (const std::uint8_t fill : {std::uint8_t{0x00}, std::uint8_t{0xA5}}) {
      SCOPED_TRACE(testing::Message() << s.name << " xx = " << int{fill});
      Bytes request(8);
      for (std::size_t i = 0; i < 8; ++i) request[i] = s.request[i] < 0 ? fill : static_cast<std::uint8_t>(s.request[i]);
      const SdoDecoded req = decode_sdo_request(request);
      ASSERT_EQ(req.error, SdoDecodeError::None);
      EXPECT_EQ(req.message.command, SdoCommand::InitiateDownloadRequest);
      EXPECT_EQ(req.message.object, s.object);
      EXPECT_EQ(req.message.length, s.size);
      EXPECT_EQ(get_le(req.message.data, 0, req.message.length), s.value);

      // The reply "60 <index> <sub> xx xx xx xx".
      Bytes reply{0x60, request[1], request[2], request[3], fill, fill, fill, fill};
      const SdoDecoded rep = decode_sdo_response(reply);
      ASSERT_EQ(rep.error, SdoDecodeError::None);
      EXPECT_EQ(rep.message.command, SdoCommand::InitiateDownloadResponse);
      EXPECT_EQ(rep.message.object, s.object);
    }
  }
  // After A6, TxPDO3 on 3A0h is valid with "no RTR" (bit 30) still set.
  const auto cob_word = get_le(std::array<std::uint8_t, 4>{0xA0, 0x03, 0x00, 0x40}, 0, 4);
  EXPECT_EQ(cob_word & cob::kInvalid, 0U);
  EXPECT_EQ(cob_word & cob::kNoRtr, cob::kNoRtr);
  EXPECT_EQ(cob_word & cob::kIdMask, cob::tpdo(2, kNode));
}

}  // namespace
}  // namespace drivegate::canopen
