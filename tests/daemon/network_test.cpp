// The daemon on the network the user chooses: `gateway.dds.interfaces: [lo]` makes it announce
// loopback locators only, and a client restricted to loopback works with it.
#include <gtest/gtest.h>
#include <signal.h>

#include <atomic>
#include <cstdio>
#include <fstream>
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

// A participant on loopback alone that records what the others announce.
class LoopbackObserver {
 public:
  explicit LoopbackObserver(std::uint32_t domain) {
    auto* factory = fdds::DomainParticipantFactory::get_instance();
    fdds::DomainParticipantQos q;
    factory->get_default_participant_qos(q);
    auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
    udp->interfaceWhiteList.push_back("127.0.0.1");
    q.transport().use_builtin_transports = false;
    q.transport().user_transports.push_back(udp);
    participant_ = factory->create_participant(domain, q, &listener_);
  }
  ~LoopbackObserver() {
    if (participant_ != nullptr) fdds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
  }
  LoopbackObserver(const LoopbackObserver&) = delete;
  LoopbackObserver& operator=(const LoopbackObserver&) = delete;
  [[nodiscard]] bool ok() const { return participant_ != nullptr; }

  // The daemon `name` was seen and announced loopback UDPv4 locators only.
  void expect_loopback_only(const std::string& name) {
    bool found = false;
    for (const auto& s : listener_.seen()) {
      if (s.name != name) continue;
      found = true;
      ASSERT_FALSE(s.locators.empty());
      for (const auto& l : s.locators) {
        EXPECT_EQ(l.kind, LOCATOR_KIND_UDPv4) << l;  // no shared memory, no other transport
        EXPECT_TRUE(rtps::IPLocator::isLocal(l)) << name << " announced " << l;
      }
    }
    EXPECT_TRUE(found) << "the loopback observer never discovered " << name;
  }

 private:
  Announcements listener_;
  fdds::DomainParticipant* participant_ = nullptr;
};

// A client on loopback alone commands axis x.
void command_over_loopback(const test::DdsIsolation& dds, test::DaemonProcess& daemon) {
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
}

TEST(DdsNetwork, ADaemonOnLoopbackAnnouncesLoopbackOnlyAndALoopbackClientWorks) {
  const auto dds = test::unique_dds("lo");
  const auto config = test::write_demo_config("loop", dds, [](YAML::Node& root) {
    root["gateway"]["dds"]["interfaces"].push_back("lo");
  });
  LoopbackObserver observer(dds.domain);
  ASSERT_TRUE(observer.ok());
  test::NotifySocket notify;
  test::DaemonProcess daemon(config, notify.path());
  ASSERT_TRUE(notify.wait_for("READY=1", 15s)) << daemon.log();
  command_over_loopback(dds, daemon);
  observer.expect_loopback_only("drivegated/loop");
  EXPECT_EQ(daemon.terminate(SIGTERM, 20s), 0);
}

// A standard Fast DDS XML profile applies: as FASTRTPS_DEFAULT_PROFILES_FILE (the variable Fast DDS
// 2.9 reads; the daemon starts from the factory's default participant QoS, not from compiled-in
// defaults) and as the config's gateway.dds.profiles_file with its profile. Here the profile keeps
// the participant on loopback.
constexpr const char* kLoopbackProfile = R"(<?xml version="1.0" encoding="UTF-8" ?>
<profiles xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles">
  <transport_descriptors>
    <transport_descriptor>
      <transport_id>loopback_only</transport_id>
      <type>UDPv4</type>
      <interfaceWhiteList><address>127.0.0.1</address></interfaceWhiteList>
    </transport_descriptor>
  </transport_descriptors>
  <participant profile_name="loopback_participant" is_default_profile="true">
    <rtps>
      <userTransports><transport_id>loopback_only</transport_id></userTransports>
      <useBuiltinTransports>false</useBuiltinTransports>
    </rtps>
  </participant>
</profiles>
)";

class DdsProfiles : public ::testing::TestWithParam<bool> {};

TEST_P(DdsProfiles, AFastDdsXmlProfileApplies) {
  const bool from_environment = GetParam();
  const auto dds = test::unique_dds(from_environment ? "xmlenv" : "xmlcfg");
  const std::string xml = test::write_config_text("profile", "") + ".xml";
  {
    std::ofstream out(xml);
    out << kLoopbackProfile;
  }
  const std::string name = from_environment ? "xmlenv" : "xmlcfg";
  const auto config = test::write_demo_config(name, dds, [&](YAML::Node& root) {
    if (from_environment) return;
    root["gateway"]["dds"]["profiles_file"] = xml;
    root["gateway"]["dds"]["profile"] = "loopback_participant";
  });
  LoopbackObserver observer(dds.domain);
  ASSERT_TRUE(observer.ok());
  test::NotifySocket notify;
  std::vector<std::string> env;
  if (from_environment) env.push_back("FASTRTPS_DEFAULT_PROFILES_FILE=" + xml);
  test::DaemonProcess daemon(config, notify.path(), "debug", env);
  ASSERT_TRUE(notify.wait_for("READY=1", 15s)) << daemon.log();
  command_over_loopback(dds, daemon);
  observer.expect_loopback_only("drivegated/" + name);
  EXPECT_EQ(daemon.terminate(SIGTERM, 20s), 0);
  std::remove(xml.c_str());
}

INSTANTIATE_TEST_SUITE_P(Daemon, DdsProfiles, ::testing::Values(true, false),
                         [](const ::testing::TestParamInfo<bool>& p) {
                           return p.param ? std::string("Environment") : std::string("ConfigFile");
                         });

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
