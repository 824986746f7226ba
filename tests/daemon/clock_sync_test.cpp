// The real drivegated with the demo's EtherCAT line plus a second generic CiA 402 drive: both
// drives run on distributed clocks, so bus_status of ec0 carries the system time difference
// (092Ch) and the master's offset to the reference clock; the sim and CANopen buses report none.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <optional>
#include <string>

#include "client/client.hpp"
#include "tests/daemon/daemon_process.hpp"

namespace drivegate {
namespace {

using namespace std::chrono_literals;

TEST(DaemonClockSync, EthercatBusStatusCarriesTheSystemTimeDifference) {
  const auto dds = test::unique_dds("clk");
  const std::string config = test::write_demo_config("clktest", dds, [](YAML::Node& root) {
    // A second DC drive behind the demo's servo (position 3): a 092Ch to read besides the
    // reference clock's.
    YAML::Node axis;
    for (const auto& a : root["axes"])
      if (a["name"].as<std::string>() == "servo") axis = YAML::Clone(a);
    ASSERT_TRUE(axis.IsMap());
    axis["name"] = "servo2";
    axis["address"] = 4;
    root["axes"].push_back(axis);
  });
  test::NotifySocket notify;
  test::DaemonProcess process(config, notify.path());
  ASSERT_TRUE(notify.wait_for("READY=1", 20s)) << process.log();

  client::Client c(client::options_for(dds.domain, dds.ns, "clock-client"));
  auto find = [&](const std::string& bus) -> std::optional<client::BusStatus> {
    for (const auto& b : c.buses()) {
      if (b.bus == bus) return b;
    }
    return std::nullopt;
  };
  // bus_status goes out once a second; the first 092Ch round completes about a second after the
  // line reached OP.
  ASSERT_TRUE(c.wait_until([&] { const auto b = find("ec0"); return b && b->clock_sync; }, 30s)) << process.log();
  const auto ec = *find("ec0");
  EXPECT_EQ(ec.type, "ethercat");
  EXPECT_GE(ec.clock_difference_ns, 0);
  // The simulated clocks are held within a microsecond (tests/ethercat_bus/dc_bus_test.cpp); the
  // bound here leaves room for a loaded machine's cycle jitter.
  EXPECT_LT(ec.clock_difference_ns, 100'000) << ec.clock_difference_ns;
  EXPECT_LT(std::llabs(ec.clock_master_offset_ns), 50'000'000) << ec.clock_master_offset_ns;
  for (const char* name : {"sim0", "can0"}) {
    const auto b = find(name);
    ASSERT_TRUE(b.has_value()) << name;
    EXPECT_FALSE(b->clock_sync) << name;
    EXPECT_EQ(b->clock_difference_ns, 0) << name;
  }
}

}  // namespace
}  // namespace drivegate
