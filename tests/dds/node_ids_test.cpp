// CANopen node-IDs in drivegatectl's words: decimal and hex.
#include "client/node_ids.hpp"

#include <gtest/gtest.h>

namespace drivegate::client {
namespace {

TEST(NodeIds, AddressOfACanopenAxisInDecimalAndHex) {
  EXPECT_EQ(format_address("canopen", 35), "35 (0x23)");
  EXPECT_EQ(format_address("canopen", 127), "127 (0x7F)");
  EXPECT_EQ(format_address("canopen", 5), "5 (0x05)");
  EXPECT_EQ(format_address("sim", 3), "3");
  EXPECT_EQ(format_address("", 3), "");
}

TEST(NodeIds, TextsNameNodesInDecimalAndHex) {
  EXPECT_EQ(annotate_node_ids("node 35 configured"), "node 35 (0x23) configured");
  EXPECT_EQ(annotate_node_ids("link lost -> booting: node 5: asking it again"),
            "link lost -> booting: node 5 (0x05): asking it again");
  EXPECT_EQ(annotate_node_ids("waiting for node 127's boot-up"), "waiting for node 127 (0x7F)'s boot-up");
  EXPECT_EQ(annotate_node_ids("node 3 and node 4"), "node 3 (0x03) and node 4 (0x04)");
  EXPECT_EQ(annotate_node_ids("node 35"), "node 35 (0x23)");
}

TEST(NodeIds, OtherNumbersStayAsTheyAre) {
  EXPECT_EQ(annotate_node_ids("node 35 (0x23) configured"), "node 35 (0x23) configured");
  EXPECT_EQ(annotate_node_ids("node 128 is no node-ID"), "node 128 is no node-ID");
  EXPECT_EQ(annotate_node_ids("node 1234"), "node 1234");
  EXPECT_EQ(annotate_node_ids("node guarding (100Ch/100Dh)"), "node guarding (100Ch/100Dh)");
  EXPECT_EQ(annotate_node_ids("anode 3"), "anode 3");
  EXPECT_EQ(annotate_node_ids(""), "");
  EXPECT_EQ(annotate_node_ids("node "), "node ");
}

}  // namespace
}  // namespace drivegate::client
