// Frames no well-behaved master sends: each is counted where it lands and dropped, and the node
// goes on answering as before.
#include <gtest/gtest.h>

#include "tests/canopen_sim/sim_test_support.hpp"

namespace drivegate::canopen::sim::test {
namespace {

CanFrame with_dlc(std::uint32_t id, std::uint8_t dlc) {
  CanFrame f;
  f.id = id;
  f.dlc = dlc;
  return f;
}

TEST(BadInput, IsCountedAndDropped) {
  for (auto config : {akd(1), nord(1), sd6(1), generic(1)}) {
    Drive d(std::move(config));
    d.boot();
    const std::string name(d.node.persona().name);
    d.send(nmt(NmtCommand::Start, 1));
    std::vector<CanFrame> replies;
    const auto feed = [&](const CanFrame& f) {
      const auto got = d.send(f);
      replies.insert(replies.end(), got.begin(), got.end());
    };
    feed(with_dlc(cob::kNmt, 1));             // NMT without a node byte
    feed(make_frame(cob::kNmt, {0x42, 1}));   // unknown NMT command
    feed(with_dlc(0x601, 7));                 // SDO of the wrong length
    feed(with_dlc(0x601, 9));                 // a DLC no frame has
    feed(with_dlc(0x900, 1));                 // an id beyond 11 bits
    feed(with_dlc(cob::kSync, 2));            // SYNC with more than a counter
    feed(make_frame(0x701, {0x05}));          // data on its own error-control id
    CanFrame rtr_pdo = rtr(0x201);            // RTR on an RPDO
    feed(rtr_pdo);
    CanFrame ext = make_frame(0x601, sdo_upload_request({0x1000, 0}));
    ext.extended = true;                      // 29-bit frame with an SDO id
    feed(ext);
    feed(make_frame(0x601, SdoBytes{0xC0, 0x00, 0x10, 0x00, 0, 0, 0, 0}));  // block upload: aborted
    // Only the block request is answered, with an abort (05040001h).
    const auto sdo = on_id(replies, 0x581);
    ASSERT_EQ(sdo.size(), 1U) << name;
    EXPECT_TRUE(is_frame(sdo[0], 0x581, {0x80, 0x00, 0x10, 0x00, 0x01, 0x00, 0x04, 0x05})) << name;
    EXPECT_EQ(d.node.nmt().counters().malformed, 2U) << name;
    EXPECT_EQ(d.node.nmt().counters().unexpected, 1U) << name;
    EXPECT_EQ(d.node.sdo(1)->counters().malformed, 1U) << name;
    EXPECT_EQ(d.node.counters().malformed, 3U) << name;
    EXPECT_EQ(d.node.pdos().counters().ignored, 1U) << name;
    EXPECT_EQ(d.node.nmt_state(), NmtState::Operational) << name;
    EXPECT_EQ(d.read({0x1000, 0}).abort, 0U) << name;
  }
}

TEST(BadInput, OddSdoWritesAreRefusedWithTheRightAbort) {
  Drive d(generic(1));
  d.boot();
  EXPECT_EQ(d.write({0x1017, 0}, 10, 4), 0x06070010U);  // U16 written with four bytes
  EXPECT_EQ(d.write({0x1017, 1}, 10, 2), 0x06090011U);
  EXPECT_EQ(d.write({0x1000, 0}, 1, 4), 0x06010002U);
  EXPECT_EQ(d.write({0x1016, 1}, 0x01000000U, 4), 0x06090030U);  // reserved bits
  EXPECT_EQ(d.write({0x1005, 0}, 0, 4), 0x06090030U);
  EXPECT_EQ(d.write({0x6041, 0}, 0, 2), 0x06010002U);
  EXPECT_EQ(d.write({0x6060, 0}, 5, 1), 0x06090030U);  // a mode the drive lacks
  EXPECT_EQ(d.write({0x6060, 0}, 1, 2), 0x06070010U);
  EXPECT_EQ(d.write({0x1600, 1}, 0x12340008U, 4), 0x08000022U);  // mapping of a valid PDO
  // A segmented download to an object of four bytes or less does not fit it.
  EXPECT_EQ(d.sdo(sdo_download_initiate({0x6081, 0}, 6)).abort, 0U);
  const std::array<std::uint8_t, 6> six{1, 2, 3, 4, 5, 6};
  EXPECT_EQ(d.sdo(sdo_download_segment(false, six, true)).abort, 0x06070010U);
  EXPECT_EQ(d.value({0x1017, 0}), 0U);
}

}  // namespace
}  // namespace drivegate::canopen::sim::test
