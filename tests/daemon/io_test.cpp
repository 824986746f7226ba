// The real drivegated with the demo's EtherCAT bus (`transport: sim`: the line inside the gateway)
// and its `io:` panel: its bytes on io_state, a write through the client library reaches the bus
// and comes back as the outputs the gateway holds.
#include <gtest/gtest.h>

#include <chrono>
#include <vector>

#include "client/client.hpp"
#include "tests/daemon/daemon_process.hpp"

namespace drivegate {
namespace {

using namespace std::chrono_literals;

TEST(DaemonIo, EthercatIoSlaveIsReadAndWrittenOverDds) {
  const auto dds = test::unique_dds("io");
  // config/demo.yaml: bus ec0 (EtherCAT, transport sim) has `panel` at position 2, 2 bytes each way.
  const std::string config = test::write_demo_config("iotest", dds);
  test::NotifySocket notify;
  test::DaemonProcess process(config, notify.path());
  ASSERT_TRUE(notify.wait_for("READY=1", 20s)) << process.log();

  client::Client c(client::options_for(dds.domain, dds.ns, "io-client"));
  ASSERT_TRUE(c.wait_until([&] { const auto s = c.io_state("panel"); return s && s->valid; }, 20s)) << process.log();
  auto st = *c.io_state("panel");
  EXPECT_EQ(st.gateway, "iotest");
  EXPECT_EQ(st.bus, "ec0");
  EXPECT_EQ(st.address, 2U);
  EXPECT_EQ(st.inputs, (std::vector<std::uint8_t>{0x00, 0x00}));
  EXPECT_EQ(st.outputs, (std::vector<std::uint8_t>{0x00, 0x00}));

  client::IoWriteRequest w;
  w.slave = "panel";
  w.offset = 1;
  w.data = {0xC3};
  const auto r = c.io_write(w, 10s);
  ASSERT_TRUE(r.ok) << r.status << ": " << r.error << "\n" << process.log();
  EXPECT_TRUE(c.wait_until([&] { return c.io_state("panel")->outputs == std::vector<std::uint8_t>{0x00, 0xC3}; },
                           10s));
  w.data = {0x01, 0x02};
  const auto refused = c.io_write(w, 10s);
  EXPECT_FALSE(refused.ok);
  EXPECT_EQ(refused.status, "out_of_range") << refused.error;
}

}  // namespace
}  // namespace drivegate
