// The cyclic path of the simulated drives allocates nothing once they are built: SlaveNode's
// on_frame()/step() through every service and fault injection, SimNetwork::step() and SimPeer.
#include <gtest/gtest.h>

#include <vector>

#include "adapters/canopen/sim/sim_network.hpp"
#include "adapters/canopen/transport/inproc_bus.hpp"
#include "tests/canopen_sim/sim_test_support.hpp"
#include "tests/support/alloc_counter.hpp"

namespace drivegate::canopen::sim::test {
namespace {

// A session touching every service: SDO reads and writes (communication, PDO, vendor, model and
// absent objects), NMT commands and resets, guarding, heartbeat, SYNC and RPDOs.
std::vector<CanFrame> session(NodeId n) {
  const auto sdo = [n](const SdoBytes& b) { return make_frame(cob::sdo_rx(n), b); };
  return {
      sdo(sdo_upload_request({0x1000, 0})),
      sdo(sdo_upload_request({0x1018, 1})),
      sdo(sdo_upload_request({0x1002, 0})),
      sdo(sdo_upload_request({0x2852, 0})),
      sdo(sdo_upload_request({0x36E9, 0})),
      sdo(sdo_upload_request({0x603F, 0})),
      sdo(sdo_upload_request({0x1016, 1})),
      sdo(sdo_upload_request({0x1201, 1})),
      sdo(sdo_upload_request({0x7777, 0})),
      sdo(sdo_download_expedited({0x1017, 0}, 5, 2)),
      sdo(sdo_download_expedited({0x1016, 1}, (127U << 16) | 40U, 4)),
      sdo(sdo_download_expedited({0x1014, 0}, 0x80U + n, 4)),
      sdo(sdo_download_expedited({0x1005, 0}, 0x80, 4)),
      sdo(sdo_download_expedited({0x1801, 1}, 0x80000000U | (0x280U + n), 4)),
      sdo(sdo_download_expedited({0x1A01, 0}, 0, 1)),
      sdo(sdo_download_expedited({0x1A01, 1}, 0x60640020U, 4)),
      sdo(sdo_download_expedited({0x1A01, 0}, 1, 1)),
      sdo(sdo_download_expedited({0x1801, 1}, 0x280U + n, 4)),
      sdo(sdo_download_expedited({0x1202, 1}, 0x80000000U | (0x640U + n), 4)),
      sdo(sdo_download_expedited({0x6060, 0}, 1, 1)),
      sdo(sdo_download_expedited({0x6040, 0}, 6, 2)),
      sdo(SdoBytes{0xE0, 0, 0, 0, 0, 0, 0, 0}),  // unknown specifier
      make_frame(0x77F, {0x05}),
      make_frame(cob::kNmt, {0x01, n}),
      sync_frame(),
      make_frame(cob::rpdo(0, n), {0x07, 0x00, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00}),
      make_frame(cob::rpdo(0, n), {0x07}),  // short: EMCY 8210h
      sync_frame(),
      rtr(cob::error_control(n)),
      make_frame(0x123, {0x01}),
      make_frame(cob::kNmt, {0x82, n}),
      make_frame(cob::kNmt, {0x01, n}),
      make_frame(cob::kNmt, {0x81, 0}),
  };
}

TEST(NoAllocation, SlaveNodeAfterConstruction) {
  for (auto config : {akd(1), nord(2), sd6(3), generic(4)}) {
    const NodeId n = config.node;
    SlaveNode node(std::move(config));
    const auto frames = session(n);
    auto tx = std::make_unique<TxQueue>();
    core::TimePoint t = kT0;
    std::size_t sent = 0;
    const auto step = [&](core::Duration d) {
      t += d;
      node.step(t, *tx);
      sent += tx->size();
      tx->clear();
    };
    drivegate::test::AllocationScope scope;
    step(1ms);
    for (const auto& f : frames) {
      node.on_frame(f, t);
      step(1ms);
    }
    node.inject_fault(0x2310, 1);
    step(10ms);
    node.clear_fault_cause();
    node.damage_next(2, FrameDamage::Garbage);
    node.on_frame(make_frame(cob::sdo_rx(n), sdo_download_expedited({0x6040, 0}, 0x80, 2)), t);
    step(10ms);
    node.set_silent(true);
    step(200ms);  // heartbeat consumer times out: a comm-loss fault
    node.set_silent(false);
    node.power_off();
    step(10ms);
    node.power_on();
    for (int i = 0; i < 100; ++i) step(1ms);
    EXPECT_EQ(scope.count(), 0U) << node.persona().name;
    EXPECT_GT(sent, 20U) << node.persona().name;
  }
}

TEST(NoAllocation, NetworkStep) {
  InprocBus wire(500000);
  auto master = wire.connect();
  auto drives = wire.connect();
  master->open();
  drives->open();
  SimNetwork network(*drives);
  network.add(akd(1));
  network.add(sd6(2));
  std::array<CanFrame, 64> rx{};
  const auto frames = session(1);
  core::TimePoint t = kT0;
  drivegate::test::AllocationScope scope;
  for (int i = 0; i < 200; ++i) {
    t += 1ms;
    wire.advance(t);
    network.step(t);
    wire.advance(t);
    (void)master->receive(rx, t);
    master->send(frames[static_cast<std::size_t>(i) % frames.size()], t);
  }
  EXPECT_EQ(scope.count(), 0U);
  EXPECT_GT(network.counters().sent, 10U);
}

}  // namespace
}  // namespace drivegate::canopen::sim::test
