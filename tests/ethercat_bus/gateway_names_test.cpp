// A client's parameter name on an EtherCAT axis without an ESI, as the DDS bridge resolves it:
// daemon::Gateway::lookup_parameter asks the bus for the drive's own dictionary (read over SDO
// Information once the drive is in OP) when the configuration does not know the name.
#include <gtest/gtest.h>

#include <thread>

#include "daemon/gateway.hpp"
#include "tests/ethercat_bus/bus_harness.hpp"

namespace drivegate::ethercat::test {
namespace {

TEST(EthercatGatewayNames, NameWithoutEsiResolvesFromTheDrivesDictionary) {
  const config::Plan plan = config::load_plan_from_string(kLine, "ecat-test.yaml", load_options());
  daemon::Gateway gw(plan);
  const std::size_t gen = 1;  // the plan's second axis
  ASSERT_EQ(gw.axes()[gen].name, "gen");

  // Not started: the drive has not been in OP.
  daemon::ParameterLookup p = gw.lookup_parameter(gen, "position_actual_value", 0, 0);
  EXPECT_FALSE(p.ok);
  EXPECT_EQ(p.error.rfind("axis 'gen': the dictionary of slave 3 is read over SDO Information once it is in OP", 0), 0U)
      << p.error;
  // By index the configuration answers as before.
  p = gw.lookup_parameter(gen, "", 0x6064, 0);
  ASSERT_TRUE(p.ok) << p.error;

  gw.start();
  // The simulated line runs in real time: the whole dictionary is read within seconds.
  const auto until = std::chrono::steady_clock::now() + 60s;
  do {
    p = gw.lookup_parameter(gen, "position_actual_value", 0, 0);
    if (p.ok) break;
    std::this_thread::sleep_for(20ms);
  } while (std::chrono::steady_clock::now() < until);
  ASSERT_TRUE(p.ok) << p.error;
  EXPECT_EQ(p.index, 0x6064);
  EXPECT_EQ(p.sub, 0);
  EXPECT_EQ(p.type, core::ParamType::I32);
  EXPECT_NE(p.type_source.find("SDO Information"), std::string::npos) << p.type_source;
  p = gw.lookup_parameter(gen, "Flux capacitor", 0, 0);
  EXPECT_FALSE(p.ok);
  EXPECT_EQ(p.error.rfind("axis 'gen': no object named 'Flux capacitor' in the dictionary of slave 3", 0), 0U) << p.error;
  gw.shutdown(1s);
}

}  // namespace
}  // namespace drivegate::ethercat::test
