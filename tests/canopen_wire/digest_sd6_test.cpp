// STÖBER SD6 §11 (stoeber-sd6-canopen.md) vectors on the wire: the predefined connection set of
// node 5 (TV-8) and the derived SDO frames D-2, D-10 and D-12. TV-1..TV-5, D-1 and D-3..D-14 are
// tested with the engines that send and answer them (tests/canopen_sdo, canopen_nmt, canopen_sim),
// TV-6/TV-7 with the profile (tests/config).
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "adapters/canopen/wire/can_frame.hpp"
#include "adapters/canopen/wire/cob_id.hpp"
#include "adapters/canopen/wire/sdo_codec.hpp"

namespace drivegate::canopen {
namespace {

using Bytes = std::vector<std::uint8_t>;
Bytes bytes(const SdoBytes& b) { return {b.begin(), b.end()}; }

constexpr NodeId kNode = 5;

// TV-8 (§5.3): every COB-ID of node 5, and what the master's router makes of each.
TEST(Sd6Digest, Tv8PredefinedConnectionSet) {
  struct Entry {
    const char* name;
    std::uint32_t cob;
    std::uint32_t expected;
    Function function;
    int index;
  };
  const std::vector<Entry> set = {
      {"EMCY", cob::emcy(kNode), 0x085, Function::Emcy, 0},
      {"TxPDO1", cob::tpdo(0, kNode), 0x185, Function::Tpdo, 0},
      {"RxPDO1", cob::rpdo(0, kNode), 0x205, Function::Rpdo, 0},
      {"TxPDO2", cob::tpdo(1, kNode), 0x285, Function::Tpdo, 1},
      {"RxPDO2", cob::rpdo(1, kNode), 0x305, Function::Rpdo, 1},
      {"TxPDO3", cob::tpdo(2, kNode), 0x385, Function::Tpdo, 2},
      {"RxPDO3", cob::rpdo(2, kNode), 0x405, Function::Rpdo, 2},
      {"TxPDO4", cob::tpdo(3, kNode), 0x485, Function::Tpdo, 3},
      {"RxPDO4", cob::rpdo(3, kNode), 0x505, Function::Rpdo, 3},
      {"TxSDO1", cob::sdo_tx(kNode), 0x585, Function::SdoTx, 0},
      {"RxSDO1", cob::sdo_rx(kNode), 0x605, Function::SdoRx, 0},
      {"error control", cob::error_control(kNode), 0x705, Function::ErrorControl, 0},
  };
  for (const auto& e : set) {
    SCOPED_TRACE(e.name);
    EXPECT_EQ(e.cob, e.expected);
    const CobSplit route = split_cob_id(e.cob);
    EXPECT_EQ(route.function, e.function);
    EXPECT_EQ(route.node, kNode);
    EXPECT_EQ(route.index, e.index);
  }
  EXPECT_EQ(split_cob_id(cob::kSync).function, Function::Sync);
  EXPECT_EQ(cob::kSync, 0x080U);
  EXPECT_EQ(split_cob_id(cob::kNmt).function, Function::Nmt);
  EXPECT_EQ(cob::kNmt, 0x000U);

  // SDO channels 1..4: 580h/600h + 20h * (channel - 1) + node-ID.
  EXPECT_EQ(cob::sdo_tx(1, kNode), 0x585U);
  EXPECT_EQ(cob::sdo_rx(1, kNode), 0x605U);
  EXPECT_EQ(cob::sdo_tx(2, kNode), 0x5A5U);
  EXPECT_EQ(cob::sdo_rx(2, kNode), 0x625U);
  EXPECT_EQ(cob::sdo_tx(3, kNode), 0x5C5U);
  EXPECT_EQ(cob::sdo_rx(3, kNode), 0x645U);
  EXPECT_EQ(cob::sdo_tx(4, kNode), 0x5E5U);
  EXPECT_EQ(cob::sdo_rx(4, kNode), 0x665U);
  // Channel k of node 5 has the channel-1 COB-IDs of node 5 + 32 (k - 1): the reason node-IDs
  // stay <= 31 once channels 2..4 are on (§5.3, quirk 1). Routing by COB-ID alone cannot tell them
  // apart, so the SDO client matches channels by their configured COB-IDs.
  for (int channel = 2; channel <= 4; ++channel) {
    SCOPED_TRACE(channel);
    const auto other = static_cast<NodeId>(kNode + 32 * (channel - 1));
    EXPECT_EQ(cob::sdo_tx(channel, kNode), cob::sdo_tx(other));
    EXPECT_EQ(cob::sdo_rx(channel, kNode), cob::sdo_rx(other));
  }
}

// D-2: the vendor-ID read; the reply is 43h or, as the SD6 sends it, 42h (size not indicated).
TEST(Sd6Digest, D2VendorId) {
  EXPECT_EQ(bytes(sdo_upload_request({0x1018, 1})), (Bytes{0x40, 0x18, 0x10, 0x01, 0x00, 0x00, 0x00, 0x00}));
  for (const std::uint8_t cs : {std::uint8_t{0x43}, std::uint8_t{0x42}}) {
    SCOPED_TRACE(int{cs});
    const SdoDecoded d = decode_sdo_response(Bytes{cs, 0x18, 0x10, 0x01, 0xB9, 0x00, 0x00, 0x00});
    ASSERT_EQ(d.error, SdoDecodeError::None);
    EXPECT_EQ(d.message.command, SdoCommand::InitiateUploadResponse);
    EXPECT_EQ(d.message.object, (ObjectId{0x1018, 1}));
    EXPECT_TRUE(d.message.expedited);
    EXPECT_EQ(d.message.size_indicated, cs == 0x43);
    EXPECT_EQ(d.message.length, 4);
    EXPECT_EQ(get_le(d.message.data, 0, d.message.length), 0xB9U);
  }
}

// D-10 (A245, A246: CAN diagnosis) and D-12 (1600h:04, RxPDO1 mapping entry 4) read requests.
TEST(Sd6Digest, D10D12ReadRequests) {
  EXPECT_EQ(bytes(sdo_upload_request({0x20F5, 0})), (Bytes{0x40, 0xF5, 0x20, 0x00, 0x00, 0x00, 0x00, 0x00}));
  EXPECT_EQ(bytes(sdo_upload_request({0x20F6, 0})), (Bytes{0x40, 0xF6, 0x20, 0x00, 0x00, 0x00, 0x00, 0x00}));
  EXPECT_EQ(bytes(sdo_upload_request({0x1600, 4})), (Bytes{0x40, 0x00, 0x16, 0x04, 0x00, 0x00, 0x00, 0x00}));
}

}  // namespace
}  // namespace drivegate::canopen
