// The DCP engines allocate nothing once built (DESIGN.md §3): Identify all with several devices,
// Identify by name, Set name / IP and Signal between a DcpClient and DcpResponders, frames passed
// as bytes through the hub, with the allocation counter armed (tests/support/alloc_counter.hpp).
#include <gtest/gtest.h>

#include <memory>

#include "tests/profinet_dcp/hub.hpp"
#include "tests/support/alloc_counter.hpp"

namespace drivegate::profinet::test {
namespace {

TEST(PnDcpNoAlloc, ClientAndRespondersExchange) {
  Hub hub;
  hub.keep_log = false;
  DcpClient client(kControllerMac);
  std::vector<std::unique_ptr<DcpResponder>> devices;
  for (std::uint16_t i = 0; i < 4; ++i) {
    devices.push_back(std::make_unique<DcpResponder>(device(static_cast<std::uint16_t>(0x200 + i), "n" + std::to_string(i), suite(static_cast<std::uint8_t>(10 + i)))));
  }
  hub.add(client);
  for (auto& d : devices) hub.add(*d);
  std::array<DcpStation, 8> found{};
  int flashes = 0;
  devices[1]->on_signal([&] { ++flashes; });
  // The predicate is made before the scope: std::function of a lambda may allocate.
  const std::function<bool()> ended = [&] { return client.idle(); };
  std::size_t identified = 0;

  const drivegate::test::AllocationScope scope;
  for (int round = 0; round < 3; ++round) {
    const std::array<DcpRequestId, 5> ids{
        client.identify_all(found, 0x20),
        client.identify_name("n2", std::span(found).subspan(4, 2)),
        client.set_name(devices[1]->mac(), "renamed", DcpQualifier::Temporary),
        client.set_ip(devices[3]->mac(), suite(static_cast<std::uint8_t>(40 + round)), DcpQualifier::Permanent),
        client.signal(devices[1]->mac()),
    };
    hub.run_until(ended);
    identified += client.result(ids[0]).stations;
    for (const DcpRequestId id : ids) EXPECT_EQ(client.take(id).status, DcpRequestStatus::Done);
  }
  EXPECT_EQ(scope.count(), 0U);
  EXPECT_EQ(identified, 12U);
  EXPECT_EQ(flashes, 3);
  EXPECT_EQ(devices[1]->name_of_station(), "renamed");
  EXPECT_EQ(devices[3]->ip(), suite(42));
  EXPECT_EQ(client.counters().failed, 0U);
}

}  // namespace
}  // namespace drivegate::profinet::test
