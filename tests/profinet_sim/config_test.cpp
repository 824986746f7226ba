// What the simulator refuses to build, with its message, and what the network cannot route.
#include <gtest/gtest.h>

#include <stdexcept>

#include "tests/profinet_sim/sim_bench.hpp"

namespace drivegate::profinet::test {
namespace {

std::string what_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(PnSimConfig, BadPersonasAndDuplicateMacsAreRefusedWithAMessage) {
  EXPECT_EQ(what_of([] {
              AkdPersonaConfig c;
              c.drive.telegram = 0;
              AkdPersona p(c);
            }),
            "AKD persona: no telegram module for telegram 0");
  EXPECT_EQ(what_of([] { GenericIoPersona p({{{0, 1, 0x20, {{1, 0x21, 2, 0}, {1, 0x22, 2, 0}}}}}); }),
            "generic IO persona: slot 1 subslot 1 given twice");
  EXPECT_EQ(what_of([] { GenericIoPersona p({{{0, 1, 0x20, {{1, 0x21, 2, 0}}}, {0, 1, 0x30, {{2, 0x31, 2, 0}}}}}); }),
            "generic IO persona: slot 1 given twice");
  EXPECT_EQ(what_of([] { GenericIoPersona p({{{0, 1, 0x20, {{1, 0x21, 1441, 0}}}}}); }),
            "generic IO persona: slot 1 subslot 1 has more than 1440 octets of data");
  AkdPersona a{AkdPersonaConfig{}};
  PnSimNetwork net;
  net.add(device_config(1, "drive-a", suite(11)), a);
  EXPECT_EQ(what_of([&] { net.add(device_config(1, "drive-b", suite(12)), a); }),
            "simulated PROFINET network: two devices with one MAC address");
  EXPECT_THROW(net.add(device_config(2, "Drive-B", suite(12)), a), std::invalid_argument);  // upper case name
}

TEST(PnSimConfig, TrafficForNoDeviceIsCounted) {
  SimBench bench;
  AkdPersona a{AkdPersonaConfig{}};
  bench.net.add(device_config(1, "drive-a", suite(11)), a);
  Bytes frame(60, 0);
  frame[5] = 0x99;  // unicast to a MAC nobody has
  bench.inject_frame(frame);
  bench.inject_frame(std::span<const std::uint8_t>(frame).first(3));
  const Bytes datagram(80, 0);
  bench.inject_datagram(datagram, {kControllerIp, kControllerClientPort}, {ip_of(99), kRpcUdpPort});
  bench.inject_datagram(datagram, {kControllerIp, kControllerClientPort}, {ip_of(11), 4242});
  EXPECT_EQ(bench.net.counters().frames_unrouted, 2U);
  EXPECT_EQ(bench.net.counters().datagrams_unrouted, 2U);
  // A datagram that is no RPC reaches the device and is counted there.
  bench.inject_datagram(datagram, {kControllerIp, kControllerClientPort}, {ip_of(11), kRpcUdpPort});
  EXPECT_EQ(bench.net.device(0).cm().counters().rpc.malformed, 1U);
}

}  // namespace
}  // namespace drivegate::profinet::test
