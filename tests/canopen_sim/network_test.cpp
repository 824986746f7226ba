// Simulated drives on a shared wire: two nodes on one in-process bus endpoint, and every persona
// brought up by the real CanopenBus through SimPeer (`transport: sim`).
#include <gtest/gtest.h>

#include <string>

#include "adapters/canopen/canopen_bus.hpp"
#include "adapters/canopen/sim/sim_network.hpp"
#include "adapters/canopen/transport/inproc_bus.hpp"
#include "config/loader.hpp"
#include "tests/canopen_sim/sim_test_support.hpp"

namespace drivegate::canopen::sim::test {
namespace {

class TwoNodes : public ::testing::Test {
 protected:
  TwoNodes() : master_(wire_.connect()), drives_(wire_.connect()), network_(*drives_) {
    master_->open();
    drives_->open();
    network_.add(akd(1));
    network_.add(sd6(2));
  }

  // Master frames in, one network step, the drives' frames out (the instant bus delivers them
  // within the step).
  std::vector<CanFrame> exchange(std::initializer_list<CanFrame> to_drives = {}) {
    for (const auto& f : to_drives) EXPECT_EQ(master_->send(f, now_), SendResult::Sent);
    network_.step(now_);
    std::vector<CanFrame> got(64);
    got.resize(master_->receive(got, now_));
    return got;
  }
  std::vector<CanFrame> run(core::Duration d) {
    std::vector<CanFrame> out;
    for (const auto end = now_ + d; now_ < end;) {
      now_ += 1ms;
      const auto got = exchange();
      out.insert(out.end(), got.begin(), got.end());
    }
    return out;
  }

  InprocBus wire_{0};
  std::unique_ptr<InprocEndpoint> master_;
  std::unique_ptr<InprocEndpoint> drives_;
  SimNetwork network_;
  core::TimePoint now_ = kT0;
};

TEST_F(TwoNodes, BootAndAnswerSdoOnTheirOwnCobIds) {
  const auto boot = exchange();
  ASSERT_EQ(boot.size(), 2U);
  EXPECT_TRUE(is_frame(boot[0], 0x701, {0x00}));
  EXPECT_TRUE(is_frame(boot[1], 0x702, {0x00}));
  const auto replies = exchange({make_frame(0x601, sdo_upload_request({0x1018, 1})),
                                 make_frame(0x602, sdo_upload_request({0x1018, 1}))});
  ASSERT_EQ(replies.size(), 2U);
  EXPECT_TRUE(is_frame(replies[0], 0x581, {0x43, 0x18, 0x10, 0x01, 0x6A, 0x00, 0x00, 0x00}));
  EXPECT_TRUE(is_frame(replies[1], 0x582, {0x42, 0x18, 0x10, 0x01, 0xB9, 0x00, 0x00, 0x00}));
  EXPECT_EQ(network_.counters().received, 2U);

  exchange({make_frame(cob::kNmt, {0x01, 0x00})});  // start all (TV-3)
  EXPECT_EQ(network_.node(0).nmt_state(), NmtState::Operational);
  EXPECT_EQ(network_.node(1).nmt_state(), NmtState::Operational);
  EXPECT_EQ(network_.find(2), &network_.node(1));
  EXPECT_EQ(network_.find(3), nullptr);
  EXPECT_THROW(network_.add(generic(2)), std::invalid_argument);
}

TEST_F(TwoNodes, NodesHearEachOther) {
  exchange();
  // Node 1 watches node 2's heartbeat, which reaches it on the wire they share, not through the
  // transport (a sender does not receive its own frames back).
  ASSERT_TRUE(on_id(exchange({make_frame(0x602, sdo_download_expedited({0x1017, 0}, 10, 2))}), 0x582).size() == 1);
  ASSERT_TRUE(on_id(exchange({make_frame(0x601, sdo_download_expedited({0x1016, 1}, (2U << 16) | 50U, 4))}), 0x581).size() == 1);
  EXPECT_EQ(on_id(run(200ms), 0x702).size(), 20U);
  EXPECT_EQ(network_.node(0).drive().state(), core::AxisState::SwitchOnDisabled);
  network_.node(1).power_off();
  const auto emcy = on_id(run(100ms), 0x81);
  ASSERT_FALSE(emcy.empty());
  EXPECT_EQ(emcy[0].data[0], 0x30);  // 8130h: heartbeat lost (AKD F129)
  EXPECT_EQ(emcy[0].data[1], 0x81);
}

// A `transport: sim` bus with one axis per persona.
config::BusPlan sim_bus_plan() {
  const std::string yaml = R"(
gateway: { name: sim-test }
buses:
  - name: can0
    type: canopen
    cycle_time: 4ms
    options: { transport: sim, bitrate: 1000000 }
axes:
  - { name: akd, bus: can0, address: 1, device: kollmorgen-akd, mechanics: { encoder_counts_per_rev: 1048576 } }
  - { name: nord, bus: can0, address: 2, device: nord-sk500p }
  - { name: sd6, bus: can0, address: 3, device: stoeber-sd6, mechanics: { encoder_counts_per_rev: 10000 } }
  - { name: generic, bus: can0, address: 4, device: generic-cia402, mechanics: { encoder_counts_per_rev: 10000 } }
)";
  return config::load_plan_from_string(yaml, "network_test.yaml").buses.at(0);
}

TEST(SimPeerWiring, GatewayEndOutlivesThePeer) {
  // CanopenBus destroys its peer before its transport: the wire must stay.
  auto wiring = SimPeer::wire(sim_bus_plan());
  wiring.gateway->open();
  wiring.peer->step(kT0);
  wiring.peer->bus().advance(kT0 + 1ms);  // four frames take 0.2 ms at 1 Mbit/s
  std::array<CanFrame, 8> rx{};
  EXPECT_EQ(wiring.gateway->receive(rx, kT0 + 1ms), 4U);  // the boot-ups
  wiring.peer.reset();
  EXPECT_EQ(wiring.gateway->send(make_frame(0x601, sdo_upload_request({0x1000, 0})), kT0 + 1ms), SendResult::Sent);
  EXPECT_NE(wiring.gateway->describe().find("simulated drives"), std::string::npos);
}

// Every persona behind the real master: identity checks, start-up writes, PDO mapping written or
// verified, heartbeat or guarding, NMT start.
class SimulatedBus : public ::testing::Test {
 protected:
  SimulatedBus() : plan_(sim_bus_plan()) {
    auto wiring = SimPeer::wire(plan_);
    peer_ = wiring.peer.get();
    bus_ = std::make_unique<CanopenBus>(plan_, std::move(wiring.gateway), std::move(wiring.peer));
  }

  void cycle() {
    now_ += plan_.cycle_time;
    bus_->receive(now_);
    bus_->transmit(now_);
  }
  // Cycles until every axis is in `state` or `limit` passes; true when they all got there.
  bool run_until(core::LinkState state, core::Duration limit) {
    for (const auto end = now_ + limit; now_ < end;) {
      cycle();
      bool all = true;
      for (std::size_t i = 0; i < bus_->axis_count(); ++i) all = all && bus_->link_state(i) == state;
      if (all) return true;
    }
    return false;
  }
  std::string links() const {
    std::string s;
    for (std::size_t i = 0; i < bus_->axis_count(); ++i) {
      s += std::string(core::to_string(bus_->link_state(i))) + " (" + std::string(bus_->link_detail(i)) + "); ";
    }
    return s;
  }

  config::BusPlan plan_;
  SimPeer* peer_ = nullptr;
  std::unique_ptr<CanopenBus> bus_;
  core::TimePoint now_ = kT0;
};

TEST_F(SimulatedBus, EveryPersonaBecomesOperational) {
  ASSERT_EQ(peer_->network().size(), 4U);
  EXPECT_EQ(peer_->network().node(2).persona().name, "stoeber-sd6");
  bus_->open(now_);
  ASSERT_TRUE(run_until(core::LinkState::Operational, 10s)) << links();
  cycle();  // the drives take the NMT start the gateway sent last
  for (std::size_t i = 0; i < 4; ++i) EXPECT_EQ(peer_->network().node(i).nmt_state(), NmtState::Operational);
  // The SD6 is guarded (no 1016h), the others watch the gateway's heartbeat.
  EXPECT_EQ(peer_->network().node(2).nmt().guard_time(), 100U);
  EXPECT_EQ(peer_->network().node(0).nmt().heartbeat_consumer() >> 16, 127U);
  EXPECT_EQ(peer_->network().node(0).drive().dictionary().get({0x6040, 0}), 0);  // nothing enabled
  bus_->close();
}

TEST_F(SimulatedBus, ADriveThatLosesPowerIsBroughtBack) {
  bus_->open(now_);
  ASSERT_TRUE(run_until(core::LinkState::Operational, 10s)) << links();
  auto& sd6 = peer_->network().node(2);
  sd6.power_off();
  for (int i = 0; i < 500 && bus_->link_state(2) == core::LinkState::Operational; ++i) run_until(core::LinkState::Lost, 4ms);
  EXPECT_NE(bus_->link_state(2), core::LinkState::Operational) << links();
  sd6.power_on();
  ASSERT_TRUE(run_until(core::LinkState::Operational, 30s)) << links();
  EXPECT_GT(bus_->boots(2), 1U);
}

}  // namespace
}  // namespace drivegate::canopen::sim::test
