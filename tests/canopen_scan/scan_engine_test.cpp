// The CANopen scan engine on the in-process wire with simulated drives, in virtual time: what it
// finds at which node-IDs, what it reads, the profiles it matches, the time it takes, and that bad
// input (malformed frames, aborts, a server answering garbage) is counted or noted, never fatal.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "adapters/canopen/scan.hpp"
#include "adapters/canopen/sim/sim_network.hpp"
#include "adapters/canopen/transport/inproc_bus.hpp"
#include "adapters/canopen/wire/sdo_codec.hpp"
#include "config/canopen/plan.hpp"
#include "config/device_profile.hpp"
#include "tests/canopen_sim/sim_test_support.hpp"

namespace drivegate::canopen::test {
namespace {

using namespace std::chrono_literals;
using sim::test::kT0;

bool has_note(const std::vector<std::string>& notes, const std::string& what) {
  return std::any_of(notes.begin(), notes.end(), [&](const std::string& n) { return n.find(what) != std::string::npos; });
}

// A scan on a 500 kbit/s wire: the scanner on one endpoint, the simulated drives on another, and a
// third for frames a test makes by hand. Steps of 100 us.
class ScanOnWire : public ::testing::Test {
 protected:
  ScanOnWire()
      : scanner_(wire_.connect()),
        drives_(wire_.connect()),
        other_(wire_.connect()),
        more_drives_(wire_.connect()),
        network_(*drives_),
        more_network_(*more_drives_) {
    scanner_->open();
    drives_->open();
    other_->open();
    more_drives_->open();
  }

  // Runs the scan to its end (or `limit`); returns the time it took.
  core::Duration run(CanopenScanSettings settings = {}, core::Duration limit = 5s) {
    scan_ = std::make_unique<CanopenScan>(settings, kT0);
    TxQueue tx;
    std::array<CanFrame, 64> rx{};
    for (now_ = kT0; !scan_->done() && now_ < kT0 + limit; now_ += 100us) {
      network_.step(now_);
      more_network_.step(now_);
      if (responder_) responder_(now_);
      wire_.advance(now_);
      for (std::size_t got; (got = scanner_->receive(rx, now_)) > 0;)
        for (std::size_t i = 0; i < got; ++i) scan_->on_frame(rx[i], now_);
      scan_->poll(now_, tx);
      while (!tx.empty() && scanner_->send(tx.front(), now_) != SendResult::Busy) {
        sent_.push_back(tx.front());
        tx.pop();
      }
    }
    return now_ - kT0;
  }

  // The drive's SDO servers exist once it has booted (its first step).
  void inject_after_boot(sim::SlaveNode& drive, ObjectId object, std::uint32_t code) {
    responder_ = [&drive, object, code, done = false](core::TimePoint t) mutable {
      if (done || t < kT0 + 1ms) return;
      drive.inject_sdo_abort(object, code);
      done = true;
    };
  }

  [[nodiscard]] const ScannedNode* node(NodeId id) {
    nodes_ = scan_->nodes();
    for (const auto& n : nodes_)
      if (n.node == id) return &n;
    return nullptr;
  }

  static std::vector<config::DeviceProfile> profiles() {
    std::vector<std::string> notes;
    auto p = scan_profiles(config::default_device_dirs(), config::BusTypeRegistry::builtin(), notes);
    EXPECT_TRUE(notes.empty());
    return p;
  }

  static config::BusPlan udp_plan() {
    core::ScanRequest r;
    r.bus_type = "canopen";
    r.where = "udp-multicast?group=239.1.2.3&port=17555&interface=127.0.0.1";
    r.device_dirs = config::default_device_dirs();
    return scan_bus_plan(r, config::BusTypeRegistry::builtin());
  }

  InprocBus wire_{500000};
  std::unique_ptr<InprocEndpoint> scanner_;
  std::unique_ptr<InprocEndpoint> drives_;
  std::unique_ptr<InprocEndpoint> other_;
  std::unique_ptr<InprocEndpoint> more_drives_;
  sim::SimNetwork network_;
  sim::SimNetwork more_network_;  // a second cable segment: drives on node-IDs network_ has too
  std::function<void(core::TimePoint)> responder_;  // a hand-made node on `other_`
  std::unique_ptr<CanopenScan> scan_;
  std::vector<ScannedNode> nodes_;
  std::vector<CanFrame> sent_;
  core::TimePoint now_ = kT0;
};

TEST_F(ScanOnWire, NobodyThereEndsWithinASecondAndFindsNothing) {
  const auto took = run();
  ASSERT_TRUE(scan_->done());
  EXPECT_TRUE(scan_->nodes().empty());
  // listen 200 ms + one answer time (100 ms + the probe's frames on the wire) + the aborts.
  EXPECT_LT(took, 500ms);
  EXPECT_GT(took, 300ms);
  const auto r = scan_result(*scan_, udp_plan(), profiles(), true);
  EXPECT_TRUE(r.devices.empty());
  EXPECT_TRUE(r.notes.empty());
}

TEST_F(ScanOnWire, FindsPersonasAtTheirNodeIdsAndReadsTheirIdentity) {
  network_.add(sim::test::akd(1));
  network_.add(sim::test::sd6(5));
  network_.add(sim::test::nord(0x20));
  network_.add(sim::test::generic(127));
  const auto took = run();
  ASSERT_TRUE(scan_->done());
  EXPECT_LT(took, 1s);

  const auto* akd = node(1);
  ASSERT_NE(akd, nullptr);
  EXPECT_TRUE(akd->boot_up);  // the simulated drives boot at their first step, inside the listen window
  EXPECT_EQ(akd->device_type, 0x00020192U);
  EXPECT_EQ(akd->identity.vendor_id, 0x6AU);
  EXPECT_EQ(akd->identity.product_code, 0x3630304DU);  // "M006" (AKD part 1 quirk 12)
  EXPECT_EQ(akd->identity.revision, 0x00140000U);
  EXPECT_EQ(akd->name, "M006");
  EXPECT_EQ(akd->hardware_version, std::nullopt);  // the AKD has no 1009h
  EXPECT_TRUE(has_note(akd->notes, "1009h not present"));
  EXPECT_EQ(akd->software_version, "0.20");

  const auto* sd6 = node(5);
  ASSERT_NE(sd6, nullptr);
  EXPECT_EQ(sd6->identity.vendor_id, 0xB9U);  // answered 42h, size not indicated (SD6 §6.4)
  EXPECT_EQ(sd6->identity.product_code, 40U);
  const auto* nord = node(0x20);
  ASSERT_NE(nord, nullptr);
  EXPECT_EQ(nord->device_type, 0x00010192U);
  EXPECT_EQ(nord->name, "NORD SK 500P");  // segmented upload into the caller's buffer
  ASSERT_NE(node(127), nullptr);
  EXPECT_EQ(node(127)->name, "drivegate simulated CiA 402 drive");

  // The SD6's channels 2..4 answer on the default channels of 37, 69, 101 (SD6 §5.3): the table
  // folds them into node 5.
  EXPECT_NE(node(37), nullptr);
  const auto r = scan_result(*scan_, udp_plan(), profiles(), true);
  std::vector<int> ids;
  for (const auto& d : r.devices) ids.push_back(d.address.number);
  EXPECT_EQ(ids, (std::vector<int>{1, 5, 0x20, 127}));
  EXPECT_EQ(r.devices[0].profile, "kollmorgen-akd");
  EXPECT_EQ(r.devices[0].address.text, "1 (01h)");
  EXPECT_EQ(r.devices[0].device_type_text, "CiA 402 drive: servo drive");
  EXPECT_EQ(r.devices[1].profile, "stoeber-sd6");
  EXPECT_TRUE(has_note(r.devices[1].notes, "its SDO channel 2"));
  EXPECT_TRUE(has_note(r.devices[1].notes, "its SDO channel 4"));
  // NORD has no vendor-ID in its digest: matched through 1000h only, where generic-cia402 asks as
  // little and comes first by name; the reason says why and names the other.
  EXPECT_EQ(r.devices[2].profile, "generic-cia402");
  EXPECT_NE(r.devices[2].profile_reason.find("matches no profile; generic-cia402 fits: 1000h = 0x00010192"),
            std::string::npos)
      << r.devices[2].profile_reason;
  EXPECT_NE(r.devices[2].profile_reason.find("nord-sk500p"), std::string::npos);
  EXPECT_EQ(r.devices[3].profile, "generic-cia402");
  EXPECT_TRUE(std::all_of(r.devices.begin(), r.devices.end(), [](const auto& d) { return d.drive; }));
  // Node 127 is taken: the skeleton's gateway gets the highest free node-ID.
  EXPECT_NE(std::find(r.bus_options.begin(), r.bus_options.end(), std::pair<std::string, std::string>{
                          "gateway_node_id", "126"}),
            r.bus_options.end());
}

TEST_F(ScanOnWire, OnlyReadsNeverWrites) {
  network_.add(sim::test::akd(3));
  network_.add(sim::test::sd6(9));
  run();
  ASSERT_TRUE(scan_->done());
  ASSERT_FALSE(sent_.empty());
  for (const auto& f : sent_) {
    // Upload requests (40h, 60h/70h segments) and aborts (80h) on 600h + N; no NMT, no download.
    const auto s = split_cob_id(f.id);
    ASSERT_EQ(s.function, Function::SdoRx) << std::hex << f.id;
    const auto cs = f.data[0] & 0xE0;
    EXPECT_TRUE(cs == 0x40 || cs == 0x60 || cs == 0x80) << std::hex << f.id << " " << int{f.data[0]};
  }
  for (std::size_t i = 0; i < network_.size(); ++i) EXPECT_EQ(network_.node(i).nmt_state(), NmtState::PreOperational);
}

TEST_F(ScanOnWire, AnAbortOnOneObjectLeavesTheOthers) {
  auto& drive = network_.add(sim::test::generic(12));
  inject_after_boot(drive, {0x1018, 2}, 0x08000000);
  run();
  const auto* n = node(12);
  ASSERT_NE(n, nullptr);
  EXPECT_EQ(n->identity.product_code, std::nullopt);
  EXPECT_TRUE(has_note(n->notes, "1018h:02: abort 0x08000000")) << n->notes.size();
  EXPECT_TRUE(n->identity.vendor_id && n->identity.revision && n->identity.serial);
  EXPECT_EQ(n->name, "drivegate simulated CiA 402 drive");
}

TEST_F(ScanOnWire, AnAbortOnTheProbeStillShowsTheNode) {
  auto& drive = network_.add(sim::test::generic(40));
  inject_after_boot(drive, {0x1000, 0}, 0x06010000);
  run();
  const auto* n = node(40);
  ASSERT_NE(n, nullptr);
  EXPECT_TRUE(n->answered);
  EXPECT_EQ(n->device_type, std::nullopt);
  EXPECT_TRUE(has_note(n->notes, "1000h: abort 0x06010000"));
  EXPECT_TRUE(n->identity.vendor_id.has_value());
  const auto r = scan_result(*scan_, udp_plan(), profiles(), true);
  ASSERT_EQ(r.devices.size(), 1U);
  EXPECT_FALSE(r.devices[0].drive);  // no device type: no profile can be chosen
  EXPECT_NE(r.devices[0].profile_reason.find("1000h not read"), std::string::npos) << r.devices[0].profile_reason;
}

TEST_F(ScanOnWire, AStringLongerThanTheLimitIsNotedNotTruncatedSilently) {
  network_.add(sim::test::nord(7));
  CanopenScanSettings s;
  s.string_limit = 8;
  run(s);
  const auto* n = node(7);
  ASSERT_NE(n, nullptr);
  EXPECT_EQ(n->name, std::nullopt);  // "NORD SK 500P" is 12 bytes
  // The scanner's own limit, not the device's fault.
  EXPECT_TRUE(has_note(n->notes, "1008h: longer than 8 bytes, not read"));
  EXPECT_FALSE(has_note(n->notes, "out of memory"));
  EXPECT_EQ(n->software_version, "V1.2 R0");
}

TEST_F(ScanOnWire, MalformedFramesAreCountedAndNoted) {
  network_.add(sim::test::generic(2));
  bool sent = false;
  responder_ = [&](core::TimePoint t) {
    if (sent || t < kT0 + 50ms) return;
    sent = true;
    EXPECT_EQ(other_->send(make_frame(0x709, {0x05, 0x00, 0x00}), t), SendResult::Sent);  // heartbeat, 3 bytes
    EXPECT_EQ(other_->send(make_frame(0x70A, {0x33}), t), SendResult::Sent);              // no NMT state
    CanFrame ext = make_frame(0x12345, {1, 2});
    ext.extended = true;
    EXPECT_EQ(other_->send(ext, t), SendResult::Sent);
    EXPECT_EQ(other_->send(make_frame(0x5FF, {0xE0, 1, 2, 3, 4, 5, 6, 7}), t), SendResult::Sent);  // SDO answer, nobody asked
  };
  run();
  ASSERT_TRUE(scan_->done());
  const auto c = scan_->counters();
  EXPECT_EQ(c.malformed, 2U);
  EXPECT_EQ(c.foreign_master, 0U);
  EXPECT_GE(c.sdo_unexpected + c.sdo_malformed, 1U);
  EXPECT_EQ(node(9), nullptr);
  EXPECT_EQ(node(10), nullptr);
  ASSERT_NE(node(2), nullptr);
  EXPECT_EQ(node(2)->name, "drivegate simulated CiA 402 drive");
  const auto r = scan_result(*scan_, udp_plan(), profiles(), true);
  EXPECT_TRUE(has_note(r.notes, "2 malformed frames dropped"));
}

TEST_F(ScanOnWire, AnotherMasterOnTheBusStopsTheScanBeforeAnyRequest) {
  // Another master runs the bus: SYNC every 10 ms and an SDO transfer with node 5.
  network_.add(sim::test::generic(5));
  core::TimePoint next = kT0;
  bool asked = false;
  responder_ = [&](core::TimePoint t) {
    if (t >= next) {
      EXPECT_EQ(other_->send(make_frame(0x080, std::initializer_list<std::uint8_t>{}), t), SendResult::Sent);
      next = t + 10ms;
    }
    if (!asked && t >= kT0 + 50ms) {
      asked = true;
      EXPECT_EQ(other_->send(make_frame(cob::sdo_rx(5), {0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0}), t), SendResult::Sent);
    }
  };
  const auto took = run();
  ASSERT_TRUE(scan_->done());
  EXPECT_LT(took, 250ms);  // right after listening
  EXPECT_TRUE(sent_.empty()) << sent_.size() << " frames sent";
  EXPECT_EQ(scan_->refusal(),
            "another CANopen master is active on this bus (SYNC 080h seen 20 times, SDO requests on 605h seen 1 time): stop "
            "it, or scan while it is off; the scan sent nothing, its SDO requests would break that master's transfers");
  try {
    (void)scan_result(*scan_, udp_plan(), profiles(), true);
    FAIL() << "a result while another master runs the bus";
  } catch (const core::ScanError& e) {
    EXPECT_EQ(std::string(e.what()), scan_->refusal());
  }
}

TEST_F(ScanOnWire, AServerAnsweringWithTogglingGarbageEndsCleanly) {
  // Node 50 announces a segmented upload of every object and then answers each segment request
  // with the wrong toggle bit and garbage.
  constexpr NodeId kNode = 50;
  network_.add(sim::test::generic(3));
  std::array<CanFrame, 16> rx{};
  responder_ = [&](core::TimePoint t) {
    for (std::size_t got = other_->receive(rx, t), i = 0; i < got; ++i) {
      const CanFrame& f = rx[i];
      if (f.id != cob::sdo_rx(kNode) || f.dlc != 8) continue;
      if (f.data[0] == 0x40)
        (void)other_->send(make_frame(cob::sdo_tx(kNode), {0x41, f.data[1], f.data[2], f.data[3], 200, 0, 0, 0}), t);
      else if ((f.data[0] & 0xE0) == 0x60)  // segment request: answer with the other toggle
        (void)other_->send(make_frame(cob::sdo_tx(kNode), {static_cast<std::uint8_t>((f.data[0] & 0x10) ^ 0x10),
                                                           0xDE, 0xAD, 0xBE, 0xEF, 0x55, 0xAA, 0x00}),
                           t);
    }
  };
  const auto took = run();
  ASSERT_TRUE(scan_->done());
  EXPECT_LT(scan_->hard_deadline() - kT0, 2s);
  EXPECT_LT(took, scan_->hard_deadline() - kT0);
  const auto* n = node(kNode);
  ASSERT_NE(n, nullptr);
  EXPECT_EQ(n->device_type, std::nullopt);
  // 1000h and 1018h go into the client's 64-byte slots: 200 bytes do not fit; the strings go into
  // buffers of 256 bytes, where the toggle error shows.
  EXPECT_TRUE(has_note(n->notes, "1000h: abort 0x05040005"));
  EXPECT_TRUE(has_note(n->notes, "100Ah: abort 0x05030000 (toggle bit not alternated)"));
  ASSERT_NE(node(3), nullptr);
  EXPECT_EQ(node(3)->name, "drivegate simulated CiA 402 drive");
}

TEST_F(ScanOnWire, AServerThatStopsAnsweringAfterTheProbeTimesOutPerObject) {
  auto& drive = network_.add(sim::test::generic(20));
  responder_ = [&](core::TimePoint) {
    // Once the probe is answered, the cable is cut.
    if (drive.sdo(1) != nullptr && drive.sdo(1)->counters().completed == 1) drive.set_silent(true);
  };
  run();
  ASSERT_TRUE(scan_->done());
  const auto* n = node(20);
  ASSERT_NE(n, nullptr);
  EXPECT_EQ(n->device_type, 0x00020192U);
  EXPECT_TRUE(has_note(n->notes, "1018h:01: no answer in time"));
  EXPECT_TRUE(has_note(n->notes, "100Ah: no answer in time"));
}

TEST_F(ScanOnWire, ANodeHeardButWithoutSdoAnswerIsListedWithoutAProfile) {
  // Node 33 sends a pre-operational heartbeat every 100 ms and never answers an SDO request.
  core::TimePoint next = kT0;
  responder_ = [&](core::TimePoint t) {
    if (t < next) return;
    EXPECT_EQ(other_->send(make_frame(cob::error_control(33), {0x7F}), t), SendResult::Sent);
    next = t + 100ms;
  };
  run();
  ASSERT_TRUE(scan_->done());
  const auto* n = node(33);
  ASSERT_NE(n, nullptr);
  EXPECT_TRUE(n->heard);
  EXPECT_FALSE(n->answered);
  EXPECT_FALSE(n->boot_up);
  EXPECT_EQ(n->state, NmtState::PreOperational);
  EXPECT_TRUE(has_note(n->notes, "heard on the bus (pre-operational) but its SDO server did not answer 1000h"));
  const auto r = scan_result(*scan_, udp_plan(), profiles(), true);
  ASSERT_EQ(r.devices.size(), 1U);
  EXPECT_FALSE(r.devices[0].drive);
  EXPECT_EQ(r.devices[0].profile, "");
  EXPECT_EQ(r.devices[0].profile_reason, "heard (heartbeat, boot-up, EMCY or PDO) but its SDO server did not answer");
  EXPECT_NE(r.devices[0].next_step.find("its SDO server did not answer"), std::string::npos);
}

TEST_F(ScanOnWire, ANodeHeardWhoseProbeRunsPastTheDeadlineIsNotAnswered) {
  // The engine is polled only at its hard deadline: the probe of node 33, heard, is still running.
  CanopenScan scan({}, kT0);
  scan.on_frame(make_frame(cob::error_control(33), {0x05}), kT0 + 10ms);
  TxQueue tx;
  scan.poll(scan.hard_deadline(), tx);
  ASSERT_TRUE(scan.done());
  const auto nodes = scan.nodes();
  ASSERT_EQ(nodes.size(), 1U);
  EXPECT_TRUE(nodes[0].heard);
  EXPECT_FALSE(nodes[0].answered);
  EXPECT_TRUE(has_note(nodes[0].notes, "1000h: no answer before the scan's deadline"));
  const auto r = scan_result(scan, udp_plan(), profiles(), true);
  ASSERT_EQ(r.devices.size(), 1U);
  EXPECT_EQ(r.devices[0].profile_reason, "heard (heartbeat, boot-up, EMCY or PDO) but its SDO server did not answer");
}

TEST_F(ScanOnWire, WhatToDoAboutADeviceWithoutProfileFollowsWhy) {
  sim::Persona akd_identity_io_type = sim::persona_for("akd");
  akd_identity_io_type.device_type = 0x000F0191;  // the AKD's identity, an I/O module's 1000h
  sim::Persona io_module = sim::persona_for("generic");
  io_module.device_type = 0x00000195;
  network_.add(sim::make_slave_config(14, akd_identity_io_type, sim::test::drive_with_modes({1, 3})));
  network_.add(sim::make_slave_config(15, io_module, sim::test::drive_with_modes({1, 3})));
  auto& unread = network_.add(sim::test::generic(16));
  inject_after_boot(unread, {0x1000, 0}, 0x06010000);
  run();
  ASSERT_TRUE(scan_->done());
  const auto r = scan_result(*scan_, udp_plan(), profiles(), true);
  ASSERT_EQ(r.devices.size(), 3U);
  EXPECT_FALSE(r.devices[0].drive);
  EXPECT_NE(r.devices[0].profile_reason.find("is kollmorgen-akd's, but its 1000h = 0x000F0191"), std::string::npos)
      << r.devices[0].profile_reason;
  EXPECT_NE(r.devices[0].next_step.find("its identity is kollmorgen-akd's but its device type (1000h) is not"),
            std::string::npos)
      << r.devices[0].next_step;
  EXPECT_EQ(r.devices[1].next_step, "add a device profile for it (profiles/devices/README.md) and scan again");
  EXPECT_NE(r.devices[2].next_step.find("its device type (1000h) could not be read"), std::string::npos)
      << r.devices[2].next_step;
}

TEST(ScanResultBitRate, NotGivenIsMarkedForCheckingAndSaidToBeAssumed) {
  core::ScanRequest req;
  req.bus_type = "canopen";
  req.device_dirs = config::default_device_dirs();
  req.where = "can0";
  EXPECT_FALSE(scan_option_given(req, "bitrate"));
  const CanopenScan scan({}, kT0);
  auto r = scan_result(scan, scan_bus_plan(req, config::BusTypeRegistry::builtin()), {}, false);
  EXPECT_EQ(r.bus_option_checks, (std::vector<std::pair<std::string, std::string>>{
                                     {"bitrate", "the bus' bit rate (not read from the interface; set it to the "
                                                 "interface's)"}}));
  EXPECT_NE(r.assumed.find("bit rate not given (500 kbit/s assumed"), std::string::npos) << r.assumed;
  req.where = "can0?bitrate=250000";
  EXPECT_TRUE(scan_option_given(req, "bitrate"));
  r = scan_result(scan, scan_bus_plan(req, config::BusTypeRegistry::builtin()), {}, true);
  EXPECT_TRUE(r.bus_option_checks.empty());
  EXPECT_TRUE(r.assumed.empty());
}

TEST_F(ScanOnWire, TwoDevicesOnOneNodeIdAreAConflictWithoutProfile) {
  network_.add(sim::test::akd(12));
  more_network_.add(sim::test::nord(12));
  network_.add(sim::test::generic(13));
  run();
  ASSERT_TRUE(scan_->done());
  const auto* n = node(12);
  ASSERT_NE(n, nullptr);
  // The first answer is kept, the second noted: the AKD servo drive against the NORD frequency
  // converter.
  EXPECT_TRUE(has_note(n->second_answers, "1000h: answered twice, differently: 0x00020192 and 0x00010192"))
      << (n->second_answers.empty() ? "" : n->second_answers[0]);
  EXPECT_TRUE(has_note(n->second_answers, "1018h:01: answered twice, differently"));
  ASSERT_NE(node(13), nullptr);
  EXPECT_TRUE(node(13)->second_answers.empty());
  // The second answers went nowhere else: the node next door reads cleanly.
  EXPECT_EQ(node(13)->name, "drivegate simulated CiA 402 drive");

  const auto r = scan_result(*scan_, udp_plan(), profiles(), true);
  ASSERT_EQ(r.devices.size(), 2U);
  const auto& d = r.devices[0];
  EXPECT_EQ(d.conflict,
            "node-ID 12: more than one device answers on 60Ch/58Ch (a node-ID conflict); its identity cannot be "
            "trusted");
  EXPECT_FALSE(d.drive);
  EXPECT_EQ(d.profile, "");
  EXPECT_TRUE(has_note(d.notes, "1000h: answered twice"));
  EXPECT_EQ(r.warnings, std::vector<std::string>{d.conflict});
  EXPECT_TRUE(r.devices[1].drive);
  EXPECT_TRUE(r.devices[1].conflict.empty());
}

TEST_F(ScanOnWire, TwoIdenticalDrivesOnOneNodeIdAreStillAConflict) {
  network_.add(sim::test::generic(40));
  more_network_.add(sim::test::generic(40));
  run();
  ASSERT_TRUE(scan_->done());
  const auto* n = node(40);
  ASSERT_NE(n, nullptr);
  // Both answer the same; every object comes twice.
  EXPECT_TRUE(has_note(n->second_answers, "1000h: answered twice, the same (0x00020192)"))
      << (n->second_answers.empty() ? "" : n->second_answers[0]);
  EXPECT_TRUE(has_note(n->second_answers, "1008h: answered twice, the same (a segmented upload of 33 bytes)"));
  const auto r = scan_result(*scan_, udp_plan(), profiles(), true);
  ASSERT_EQ(r.devices.size(), 1U);
  EXPECT_FALSE(r.devices[0].drive);
  EXPECT_NE(r.devices[0].conflict.find("node-ID 40: more than one device answers on 628h/5A8h"), std::string::npos);
  EXPECT_EQ(r.warnings.size(), 1U);
}

TEST_F(ScanOnWire, ADriveOnAnSd6ExtraChannelIsAConflictThatNamesTheSd6) {
  // The SD6 at 3 answers on the default channels of 35, 67, 99 too (SD6 §5.3); a drive at 35.
  network_.add(sim::test::sd6(3));
  network_.add(sim::test::generic(35));
  run();
  ASSERT_TRUE(scan_->done());
  const auto r = scan_result(*scan_, udp_plan(), profiles(), true);
  std::vector<int> ids;
  for (const auto& d : r.devices) ids.push_back(d.address.number);
  EXPECT_EQ(ids, (std::vector<int>{3, 35}));  // 67 and 99 folded into the SD6, 35 not
  ASSERT_EQ(r.devices.size(), 2U);
  EXPECT_EQ(r.devices[0].profile, "stoeber-sd6");
  EXPECT_TRUE(r.devices[0].drive);
  EXPECT_TRUE(has_note(r.devices[0].notes, "its SDO channel 3"));
  EXPECT_FALSE(has_note(r.devices[0].notes, "its SDO channel 2"));
  const auto& d = r.devices[1];
  EXPECT_EQ(d.conflict,
            "node-ID 35: more than one device answers on 623h/5A3h (a node-ID conflict, or another drive's extra SDO "
            "channel: node 3 is a stoeber-sd6 whose SDO channel 2 is node-ID 35); its identity cannot be trusted");
  EXPECT_FALSE(d.drive);
  EXPECT_TRUE(has_note(d.notes, "1000h: answered twice"));
  // The SD6 answers 42h (size not indicated, SD6 §6.4), the other drive 43h: the same value.
  EXPECT_TRUE(has_note(d.notes, "1018h:03: answered twice, the same (0x00000000)"));
  EXPECT_EQ(r.warnings, std::vector<std::string>{d.conflict});
}

TEST(ScanBusPlan, TakesAnInterfaceOrUdpMulticastWithOptions) {
  core::ScanRequest r;
  r.bus_type = "canopen";
  r.device_dirs = config::default_device_dirs();
  r.where = "can1";
  auto p = scan_bus_plan(r, config::BusTypeRegistry::builtin());
  EXPECT_EQ(p.section<config::CanopenBusOptions>().transport, config::CanTransportKind::SocketCan);
  EXPECT_EQ(p.section<config::CanopenBusOptions>().interface, "can1");
  r.where = "socketcan?interface=vcan0&bitrate=250000";
  p = scan_bus_plan(r, config::BusTypeRegistry::builtin());
  EXPECT_EQ(p.section<config::CanopenBusOptions>().interface, "vcan0");
  EXPECT_EQ(p.section<config::CanopenBusOptions>().bitrate, 250000U);
  r.where = "udp-multicast?group=239.1.2.3&port=17000&interface=127.0.0.1";
  p = scan_bus_plan(r, config::BusTypeRegistry::builtin());
  EXPECT_EQ(p.section<config::CanopenBusOptions>().transport, config::CanTransportKind::UdpMulticast);
  EXPECT_EQ(p.section<config::CanopenBusOptions>().group, "239.1.2.3");
  EXPECT_EQ(p.section<config::CanopenBusOptions>().port, 17000);
}

TEST(ScanBusPlan, RefusesWhatTheConfigurationWouldRefuse) {
  const auto error = [](const std::string& where) {
    core::ScanRequest r;
    r.bus_type = "canopen";
    r.where = where;
    r.device_dirs = config::default_device_dirs();
    try {
      (void)scan_bus_plan(r, config::BusTypeRegistry::builtin());
    } catch (const core::ScanError& e) {
      return std::string(e.what());
    }
    return std::string("(accepted)");
  };
  EXPECT_NE(error("udp-multicast?port=0").find("port must be"), std::string::npos) << error("udp-multicast?port=0");
  EXPECT_NE(error("udp-multicast?group=10.0.0.1").find("group must be an IPv4 multicast group"), std::string::npos);
  EXPECT_NE(error("can0?bitrate=125001").find("bitrate must be a CiA 301 bit rate"), std::string::npos);
  EXPECT_NE(error("can0?group=239.1.1.1").find("\"group\" is not a scan option of socketcan"), std::string::npos);
  EXPECT_NE(error("udp-multicast?sdo_timeout=1s").find("is not a scan option"), std::string::npos);
  EXPECT_NE(error("udp-multicast?port=1%0a").find("a value is letters, digits"), std::string::npos);
  EXPECT_NE(error("udp-multicast?port").find("is not KEY=VALUE"), std::string::npos);
  EXPECT_NE(error("sim").find("only inside a gateway"), std::string::npos);
  EXPECT_NE(error("").find("name the bus"), std::string::npos);
}

TEST(DeviceTypeText, NamesTheProfileAndTheDriveType) {
  EXPECT_EQ(device_type_text(0x00020192), "CiA 402 drive: servo drive");
  EXPECT_EQ(device_type_text(0x00010192), "CiA 402 drive: frequency converter");
  EXPECT_EQ(device_type_text(0x00000192), "CiA 402 drive");
  EXPECT_EQ(device_type_text(0x000F0191), "CiA 401 I/O module");
  EXPECT_EQ(device_type_text(0x00000000), "no standard device profile");
  EXPECT_EQ(device_type_text(0x00000195), "device profile 405");
}

}  // namespace
}  // namespace drivegate::canopen::test
