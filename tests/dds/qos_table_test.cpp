// The README's DDS table states exactly the QoS the code uses (msg::qos_table()): a third-party
// reader that follows the README must match what the gateway publishes.
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "idl/dds_node.hpp"

namespace drivegate::dds_test {
namespace {

std::string trim(const std::string& s) {
  const auto a = s.find_first_not_of(' ');
  if (a == std::string::npos) return {};
  return s.substr(a, s.find_last_not_of(' ') - a + 1);
}

// The rows of the README's QoS table, by topic: the cells after the topic.
std::map<std::string, std::vector<std::string>> readme_rows() {
  std::ifstream in(DRIVEGATE_README);
  std::string line;
  bool inside = false;
  std::map<std::string, std::vector<std::string>> rows;
  while (std::getline(in, line)) {
    if (line == "<!-- qos-table -->") inside = true;
    if (line == "<!-- /qos-table -->") break;
    if (!inside || line.rfind("| `", 0) != 0) continue;
    std::vector<std::string> cells;
    std::stringstream ss(line.substr(1));
    std::string cell;
    while (std::getline(ss, cell, '|')) cells.push_back(trim(cell));
    const std::string topic = cells.at(0).substr(1, cells.at(0).size() - 2);  // without the backticks
    cells.erase(cells.begin());
    rows[topic] = cells;
  }
  return rows;
}

TEST(QosTable, TheReadmeSaysExactlyWhatTheCodeUses) {
  const auto rows = readme_rows();
  ASSERT_EQ(rows.size(), msg::kTopicCount) << "README.md: the table between the qos-table markers";
  for (const auto& q : msg::qos_table()) {
    const std::string topic(msg::topic_suffix(q.topic));
    const auto it = rows.find(topic);
    ASSERT_NE(it, rows.end()) << topic << " is missing from the README's table";
    const auto& c = it->second;  // direction, reliability, durability, history, key, content
    ASSERT_GE(c.size(), 6u) << topic;
    EXPECT_EQ(c[1], msg::reliability_text(q)) << topic;
    EXPECT_EQ(c[2], msg::durability_text(q)) << topic;
    EXPECT_EQ(c[3], msg::history_text(q)) << topic;
    EXPECT_EQ(c[4], std::string(q.key)) << topic;
  }
}

// The key columns are the IDL's @key fields (a keyed keep-last topic keeps its depth per instance).
TEST(QosTable, KeysMatchTheIdl) {
  std::ifstream in(DRIVEGATE_IDL);
  std::stringstream all;
  all << in.rdbuf();
  const std::string idl = all.str();
  const std::map<std::string, std::string> type_of{
      {"axis_state", "AxisState"},       {"axis_command", "AxisCommand"}, {"command_reply", "CommandReply"},
      {"setpoint", "Setpoint"},          {"axis_event", "AxisEvent"},     {"bus_status", "BusStatus"},
      {"param_request", "ParameterRequest"},  {"param_reply", "ParameterReply"},   {"gateway_info", "GatewayInfo"},
      {"axis_link", "AxisLink"}, {"io_state", "IoState"}, {"io_write", "IoWrite"},
      {"io_write_reply", "IoWriteReply"}};
  for (const auto& q : msg::qos_table()) {
    const std::string type = type_of.at(std::string(msg::topic_suffix(q.topic)));
    const auto at = idl.find("struct " + type + " {");
    ASSERT_NE(at, std::string::npos) << type;
    const std::string body = idl.substr(at, idl.find("};", at) - at);
    std::string keys;
    for (auto k = body.find("@key string "); k != std::string::npos; k = body.find("@key string ", k + 1)) {
      const auto name_at = k + 12;
      if (!keys.empty()) keys += ", ";
      keys += body.substr(name_at, body.find(';', name_at) - name_at);
    }
    EXPECT_EQ(keys, std::string(q.key)) << type;
  }
}

}  // namespace
}  // namespace drivegate::dds_test
