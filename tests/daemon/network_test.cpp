// The daemon on the network the user chooses: `gateway.dds.interfaces: [lo]` makes it announce
// loopback locators only, and a client restricted to loopback works with it.
#include <gtest/gtest.h>
#include <signal.h>

#include <atomic>
#include <mutex>
#include <string>
#include <vector>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>

#include "client/client.hpp"
#include "tests/daemon/daemon_process.hpp"

using namespace drivegate;
using namespace std::chrono_literals;
namespace fdds = eprosima::fastdds::dds;
namespace rtps = eprosima::fastrtps::rtps;

namespace {

// Records the locators every discovered participant announces.
class Announcements final : public fdds::DomainParticipantListener {
 public:
  void on_participant_discovery(fdds::DomainParticipant*, rtps::ParticipantDiscoveryInfo&& info) override {
    if (info.status != rtps::ParticipantDiscoveryInfo::DISCOVERED_PARTICIPANT) return;
    std::lock_guard lock(mutex_);
    Seen s;
    s.name = info.info.m_participantName.to_string();
    for (const auto* list : {&info.info.metatraffic_locators.unicast, &info.info.default_locators.unicast})
      for (const auto& l : *list) s.locators.push_back(l);
    seen_.push_back(std::move(s));
  }
  struct Seen {
    std::string name;
    std::vector<rtps::Locator_t> locators;
  };
  std::vector<Seen> seen() {
    std::lock_guard lock(mutex_);
    return seen_;
  }

 private:
  std::mutex mutex_;
  std::vector<Seen> seen_;
};

TEST(DdsNetwork, ADaemonOnLoopbackAnnouncesLoopbackOnlyAndALoopbackClientWorks) {
  const auto dds = test::unique_dds("lo");
  const auto config = test::write_demo_config("loop", dds, [](YAML::Node& root) {
    root["gateway"]["dds"]["interfaces"].push_back("lo");
  });
  // An observer on loopback alone, listening to participant announcements.
  Announcements listener;
  auto* factory = fdds::DomainParticipantFactory::get_instance();
  fdds::DomainParticipantQos q;
  factory->get_default_participant_qos(q);
  auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
  udp->interfaceWhiteList.push_back("127.0.0.1");
  q.transport().use_builtin_transports = false;
  q.transport().user_transports.push_back(udp);
  auto* observer = factory->create_participant(dds.domain, q, &listener);
  ASSERT_NE(observer, nullptr);

  test::NotifySocket notify;
  test::DaemonProcess daemon(config, notify.path());
  ASSERT_TRUE(notify.wait_for("READY=1", 15s)) << daemon.log();

  auto opts = client::options_for(dds.domain, dds.ns, "loop-client");
  opts.interfaces = {"lo"};
  client::Client c(opts);
  client::CommandRequest en;
  en.axis = "x";
  en.kind = "enable";
  const auto r = c.send(en, true, 15s);
  EXPECT_EQ(r.outcome, client::Outcome::Completed) << r.reason << daemon.log();
  client::CommandRequest mv;
  mv.axis = "x";
  mv.kind = "move";
  mv.position = 3;
  EXPECT_EQ(c.send(mv, true, 20s).outcome, client::Outcome::Completed);

  bool found = false;
  for (const auto& s : listener.seen()) {
    if (s.name != "drivegated/loop") continue;
    found = true;
    ASSERT_FALSE(s.locators.empty());
    for (const auto& l : s.locators) {
      EXPECT_EQ(l.kind, LOCATOR_KIND_UDPv4) << l;  // no shared memory, no other transport
      EXPECT_TRUE(rtps::IPLocator::isLocal(l)) << "the daemon announced " << l;
    }
  }
  EXPECT_TRUE(found) << "the loopback observer never discovered the daemon";
  factory->delete_participant(observer);
  EXPECT_EQ(daemon.terminate(SIGTERM, 20s), 0);
}

// An interface that does not exist is a clear start-up error, not a participant on every network.
TEST(DdsNetwork, AnUnknownInterfaceStopsTheStartWithItsName) {
  const auto dds = test::unique_dds("noif");
  const auto config = test::write_demo_config("noif", dds, [](YAML::Node& root) {
    root["gateway"]["dds"]["interfaces"].push_back("nosuch0");
  });
  test::NotifySocket notify;
  test::DaemonProcess daemon(config, notify.path());
  const auto rc = daemon.wait_exit(15s);
  ASSERT_TRUE(rc.has_value()) << daemon.log();
  EXPECT_EQ(*rc, 1);
  EXPECT_NE(daemon.log().find("DDS interface nosuch0 does not exist on this machine"), std::string::npos)
      << daemon.log();
}

}  // namespace
