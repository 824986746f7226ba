// The PROFINET fault console (PnConsole) on the network of a config, against the controller's
// engines in memory on virtual time (tests/profinet_sim/sim_bench.hpp): alarms reaching the
// controller's AlarmChannel with their text, power loss and return, reboot, AR abort, frame loss,
// a drive fault, a generic device's IO bytes (`io`), `status`, and every refusal with its answer.
#include <gtest/gtest.h>

#include "adapters/profinet/sim/pn_console.hpp"
#include "tests/profinet_sim/sim_bench.hpp"
#include "tests/profinet_simtool/support.hpp"

namespace drivegate::profinet::test {
namespace {

class Alarms final : public AlarmListener {
 public:
  void on_alarm(const AlarmEvent& e) noexcept override { texts.emplace_back(e.text); }
  std::vector<std::string> texts;
};

constexpr MacAddress kAkdY{0x02, 0x50, 0x4E, 0x00, 0x00, 0x02};
constexpr std::uint32_t kAkdYIp = 0xC0A8000B;  // 192.168.0.11

// The network of pn_config() in memory, with its console, the controller's DCP client and an AR
// plan for akd-y (telegram 1) whose alarm CR the controller's AlarmChannel serves.
class PnConsoleTest : public ::testing::Test {
 protected:
  PnConsoleTest()
      : plan_(plan_of(pn_config("eth1"))), net_(build_pn_network(plan_.buses.at(0), 0)), bench_(net_->network()),
        ar_plan_(akd_plan(1, 4, 4), kAkdYIp, kAkdY, 0) {
    console_.add(*net_);
  }

  std::string cmd(const std::string& line) { return console_.command(line, bench_.now); }
  PnDevice& akd_y() { return *net_->station(1).device; }

  // The station finder gives every station its configured address.
  void assign_addresses() {
    bench_.finder = std::make_unique<StationFinder>(bench_.dcp, stations_of(plan_.buses[0].section<config::ProfinetBusOptions>()));
    ASSERT_TRUE(bench_.run_until([&] { return bench_.finder->done(); }, 30s));
    ASSERT_TRUE(bench_.finder->all_ok());
    bench_.finder.reset();
  }
  // The AR to akd-y, in data exchange with its alarm CR open on both sides.
  SimBench::Ar& connect() {
    SimBench::Ar& ar = bench_.add_ar(ar_plan_);
    ar.alarms = std::make_unique<AlarmChannel>(
        AlarmChannelConfig{kControllerMac, kAkdY, ar_plan_.connect.alarm, kDeviceAlarmReference}, &alarms_);
    bench_.start(ar);
    EXPECT_TRUE(bench_.run_until([&] { return ar.cm->state() == CmClientState::DataExchange; }, 5s)) << ar.cm->reason();
    return ar;
  }
  // The part of a status answer about `station`, up to its `;`.
  std::string item(const std::string& station) {
    const std::string status = cmd("status");
    const auto at = status.find(" pn0:" + station + " ");
    if (at == std::string::npos) return {};
    return status.substr(at + 1, status.find(';', at) - at - 1);
  }

  config::Plan plan_;
  std::unique_ptr<BuiltPnNetwork> net_;
  SimBench bench_;
  ArPlan ar_plan_;
  PnConsole console_;
  Alarms alarms_;
};

constexpr std::string_view kTelegramPlace =
    "API 0x00003A00 slot 1 subslot 0x0001, module 0x00000101 submodule 0x00000001";

TEST_F(PnConsoleTest, AlarmsFromTheConsoleReachTheControllersAlarmChannelWithTheirText) {
  EXPECT_EQ(cmd("alarm akd-y process"), "error: pn0:akd-y has no AR (an alarm needs the AR's alarm CR)");
  assign_addresses();
  SimBench::Ar& ar = connect();
  ASSERT_EQ(ar.alarms->state(), AlarmChannelState::Open);

  EXPECT_EQ(cmd("alarm akd-y process"), "ok alarm pn0:akd-y process slot 1 subslot 0x0001");
  EXPECT_EQ(cmd("alarm akd-y diagnosis"), "ok alarm pn0:akd-y diagnosis slot 1 subslot 0x0001");
  EXPECT_EQ(cmd("alarm akd-y diagnosis-gone 1:1 0x0005"), "ok alarm pn0:akd-y diagnosis-gone slot 1 subslot 0x0001");
  EXPECT_EQ(cmd("alarm pn0:akd-y pull 1"), "ok alarm pn0:akd-y pull slot 1 subslot 0x0001");
  // Four low priority alarms wait for their AlarmAck at most: the next after these are taken.
  ASSERT_TRUE(bench_.run_until([&] { return alarms_.texts.size() == 4; }, 5s)) << alarms_.texts.size();
  EXPECT_EQ(cmd("alarm akd-y plug 1"), "ok alarm pn0:akd-y plug slot 1 subslot 0x0001");
  EXPECT_EQ(cmd("alarm akd-y return 1"), "ok alarm pn0:akd-y return slot 1 subslot 0x0001");
  ASSERT_TRUE(bench_.run_until([&] { return alarms_.texts.size() == 6; }, 5s)) << alarms_.texts.size();
  const std::string place(kTelegramPlace);
  EXPECT_EQ(alarms_.texts[0], "alarm high: Process (0x0002), " + place + ", sequence 0");
  EXPECT_EQ(alarms_.texts[1], "alarm low: Diagnosis (0x0001), " + place +
                                  ", sequence 0, channel diagnosis, submodule has diagnosis, AR has diagnosis; "
                                  "submodule (manufacturer specific) error (0x0009), appears, fault");
  EXPECT_EQ(alarms_.texts[2], "alarm low: Diagnosis disappears (0x000C), " + place +
                                  ", sequence 1, channel diagnosis; submodule (manufacturer specific) overtemperature (0x0005), "
                                  "disappears, fault");
  EXPECT_EQ(alarms_.texts[3], "alarm low: Pull (0x0003), " + place + ", sequence 2");
  EXPECT_EQ(alarms_.texts[4], "alarm low: Plug (0x0004), " + place + ", sequence 3");
  EXPECT_EQ(alarms_.texts[5], "alarm low: Return of submodule (0x000B), " + place + ", sequence 4");
  EXPECT_EQ(ar.alarms->counters().acks_confirmed, 6U);
  EXPECT_EQ(akd_y().alarm_cr()->counters().acknowledged, 6U);
  EXPECT_NE(item("akd-y").find(" alarms=6/6"), std::string::npos) << item("akd-y");
  EXPECT_EQ(ar.cm->state(), CmClientState::DataExchange);

  // Refusals.
  const std::string usage = "error: alarm takes STATION process|diagnosis|diagnosis-gone|pull|plug|return [SLOT[:SUBSLOT]] [ERROR]";
  EXPECT_EQ(cmd("alarm akd-y"), usage);
  EXPECT_EQ(cmd("alarm akd-y overheat"), usage);
  EXPECT_EQ(cmd("alarm akd-y pull 7"), "error: pn0:akd-y has no submodule 7");
  EXPECT_EQ(cmd("alarm akd-y pull 1:x"), "error: alarm: \"1:x\" is not SLOT or SLOT:SUBSLOT");
  EXPECT_EQ(cmd("alarm akd-y pull 1 5"),
            "error: alarm: ERROR (a ChannelErrorType 1..0xFFFF) goes with diagnosis and diagnosis-gone");
  EXPECT_EQ(cmd("alarm akd-x process"), "error: pn0:akd-x has no AR (an alarm needs the AR's alarm CR)");
  // Four of one priority wait for their AlarmAck at most.
  for (int i = 0; i < 4; ++i) EXPECT_EQ(cmd("alarm akd-y process").rfind("ok alarm", 0), 0U);
  EXPECT_EQ(cmd("alarm akd-y process"), "error: pn0:akd-y: 4 high priority alarms wait for their AlarmAck already");
}

TEST_F(PnConsoleTest, AnAlarmNeverAcknowledgedAbortsTheAr) {
  assign_addresses();
  SimBench::Ar& ar = connect();
  // The controller's alarm CR goes deaf: the device sends its alarm 1 + 3 times, then an ERR, and
  // ends the AR.
  ar.alarms->close();
  EXPECT_EQ(cmd("alarm akd-y process"), "ok alarm pn0:akd-y process slot 1 subslot 0x0001");
  ASSERT_TRUE(bench_.run_until([&] { return akd_y().ar_state() == CmServerState::NoAr; }, 2s));
  EXPECT_EQ(akd_y().counters().alarm_cr_aborts, 1U);
  EXPECT_EQ(akd_y().abort_reason(),
            "alarm CR: alarm high: no ACK from the controller after 4 frames; ERR sent (CF 81 FD 08)");
  EXPECT_EQ(akd_y().alarm_cr(), nullptr);
  EXPECT_NE(item("akd-y").find(" ar=NoAr "), std::string::npos) << item("akd-y");
  EXPECT_NE(item("akd-y").find(" alarm-cr=1 "), std::string::npos) << item("akd-y");
}

TEST_F(PnConsoleTest, PowerLossSilencesTheDeviceAndPowerReturnBringsItBackWithoutAnAddress) {
  assign_addresses();
  SimBench::Ar& ar = connect();
  EXPECT_EQ(cmd("power-off akd-y"), "ok power-off pn0:akd-y");
  EXPECT_EQ(item("akd-y"), "pn0:akd-y kollmorgen-akd-profinet off");
  ASSERT_TRUE(bench_.run_until([&] { return ar_plan_.consumer->state() == RtConsumerState::Timeout; }, 1s));
  // Silent: Identify all finds the other two.
  std::array<DcpStation, 8> found{};
  DcpRequestId id = bench_.dcp.identify_all(found, 1);
  ASSERT_TRUE(bench_.run_until([&] { return bench_.dcp.result(id).status == DcpRequestStatus::Done; }, 5s));
  EXPECT_EQ(bench_.dcp.stations(id).size(), 2U);
  EXPECT_GT(akd_y().counters().rx_powered_off, 0U);  // the identify request and output frames
  EXPECT_EQ(cmd("alarm akd-y process"), "error: pn0:akd-y is off");

  // Back: its stored name, no address (it was temporary), no AR; the finder assigns it again.
  EXPECT_EQ(cmd("power-on akd-y"), "ok power-on pn0:akd-y");
  const std::string back = item("akd-y");
  EXPECT_EQ(back.rfind("pn0:akd-y kollmorgen-akd-profinet name=akd-y mac=02:50:4e:00:00:02 ip=0.0.0.0 ar=NoAr ", 0), 0U)
      << back;
  EXPECT_TRUE(back.ends_with(" alarms=-")) << back;
  id = bench_.dcp.identify_all(found, 1);
  ASSERT_TRUE(bench_.run_until([&] { return bench_.dcp.result(id).status == DcpRequestStatus::Done; }, 5s));
  EXPECT_EQ(bench_.dcp.stations(id).size(), 3U);
  bench_.finder = std::make_unique<StationFinder>(
      bench_.dcp, std::vector<StationConfig>{stations_of(plan_.buses[0].section<config::ProfinetBusOptions>())[1]});
  ASSERT_TRUE(bench_.run_until([&] { return bench_.finder->done(); }, 30s));
  EXPECT_EQ(bench_.finder->reports()[0].outcome, StationOutcome::IpAssigned) << bench_.finder->reports()[0].text;
  EXPECT_EQ(akd_y().ip(), kAkdYIp);
  (void)ar;
}

TEST_F(PnConsoleTest, RebootAbortLossAndDriveFault) {
  assign_addresses();
  SimBench::Ar& ar = connect();
  // One lost frame each way is bridged by the data hold time (3 x 16 ms).
  EXPECT_EQ(cmd("lose akd-y rx 1"), "ok lose pn0:akd-y rx 1");
  EXPECT_EQ(cmd("lose akd-y tx 0x1"), "ok lose pn0:akd-y tx 1");
  bench_.run_for(200ms);
  EXPECT_EQ(akd_y().counters().rx_lost, 1U);
  EXPECT_EQ(akd_y().counters().tx_lost, 1U);
  EXPECT_EQ(akd_y().ar_state(), CmServerState::DataExchange);
  // A drive fault shows in ZSW1 bit 3.
  EXPECT_EQ(cmd("drive-fault akd-y 501"), "ok drive-fault pn0:akd-y 501");
  bench_.run_for(100ms);
  const auto zsw1 = ar_plan_.consumer->data(ar_plan_.index(1));
  EXPECT_EQ(zsw1[1] & 0x08, 0x08);
  // The device ends the AR.
  EXPECT_EQ(cmd("abort-ar akd-y"), "ok abort-ar pn0:akd-y");
  EXPECT_EQ(akd_y().ar_state(), CmServerState::NoAr);
  EXPECT_EQ(akd_y().abort_reason(), "aborted from the simulator's console");
  EXPECT_EQ(cmd("abort-ar akd-y"), "error: pn0:akd-y has no AR");
  ASSERT_TRUE(bench_.run_until([&] { return ar_plan_.consumer->state() == RtConsumerState::Timeout; }, 1s));
  // A reboot: the address is gone at once, the name stays.
  EXPECT_EQ(cmd("reboot akd-x"), "ok reboot pn0:akd-x");
  EXPECT_EQ(net_->station(0).device->ip(), 0U);
  EXPECT_EQ(net_->station(0).device->name_of_station(), "akd-x");
  (void)ar;

  // Refusals.
  EXPECT_EQ(cmd("drive-fault io-block 501"), "error: pn0:io-block (generic-io) is not a drive");
  EXPECT_EQ(cmd("drive-fault akd-y 0"), "error: drive-fault takes STATION NUMBER (an AKD fault number 1..65535)");
  EXPECT_EQ(cmd("lose akd-y sideways 1"), "error: lose takes STATION rx|tx N (N frames, 1..1000000)");
  EXPECT_EQ(cmd("lose akd-y rx 0"), "error: lose takes STATION rx|tx N (N frames, 1..1000000)");
  EXPECT_EQ(cmd("lose akd-y rx"), "error: lose takes STATION rx|tx N (N frames, 1..1000000)");
  EXPECT_EQ(cmd("reboot"), "error: reboot takes a STATION (" + std::string(PnConsole::kCommands) + ")");
  EXPECT_EQ(cmd("reboot akd-y now"), "error: reboot takes STATION");
  EXPECT_EQ(cmd("power-off nosuch"), "error: no simulated PROFINET station nosuch");
  EXPECT_EQ(cmd("power-off pn9:akd-x"), "error: no simulated PROFINET network pn9");
  EXPECT_EQ(cmd("status now"), "error: status takes no arguments");
  EXPECT_EQ(cmd("jump akd-x"), "error: unknown command \"jump\" (" + std::string(PnConsole::kCommands) + ")");
  EXPECT_EQ(console_.matches("akd-x"), 1U);
  EXPECT_EQ(console_.matches("pn0:akd-x"), 1U);
  EXPECT_EQ(console_.matches("pn1:akd-x"), 0U);
  EXPECT_EQ(console_.matches("3"), 0U);
}

// `io`: the IO device's submodules as the controller's AR exchanges them, outputs seen and inputs
// set from the console (never looped back), and every refusal.
TEST_F(PnConsoleTest, IoShowsTheOutputsAndSetsTheInputsOfAGenericDevice) {
  assign_addresses();
  // Without an AR: nothing received yet, the inputs as at power-on.
  EXPECT_EQ(cmd("io io-block 1"), "io pn0:io-block 1:1 out=- out-state=lost in=0000");
  EXPECT_EQ(cmd("io pn0:io-block 2:1"), "io pn0:io-block 2:1 out=00 out-state=lost in=-");
  EXPECT_EQ(cmd("io io-block 1:1 0x12 52"), "ok io pn0:io-block 1:1 out=- out-state=lost in=1234");

  // The panel of pn_config(): the DAP, 2 input octets in slot 1, 1 output octet in slot 2.
  constexpr MacAddress kIoBlock{0x02, 0x50, 0x4E, 0x00, 0x00, 0x03};
  ArPlan plan({{0, 0, 0x100, 1, 1, IoKind::NoIo, 0, 0},
               {0, 1, 0x210, 1, 0x11, IoKind::Input, 2, 0},
               {0, 2, 0x220, 1, 0x12, IoKind::Output, 0, 1}},
              0xC0A80014, kIoBlock, 1);
  SimBench::Ar& ar = bench_.add_ar(plan);
  bench_.start(ar);
  ASSERT_TRUE(bench_.run_until([&] { return ar.cm->state() == CmClientState::DataExchange; }, 5s)) << ar.cm->reason();
  plan.provider->data(plan.index(2))[0] = 0xC3;
  bench_.run_for(100ms);
  EXPECT_EQ(cmd("io io-block 2"), "io pn0:io-block 2:1 out=C3 out-state=valid in=-");
  const auto in = plan.consumer->data(plan.index(1));
  EXPECT_EQ(Bytes(in.begin(), in.end()), (Bytes{0x12, 0x34}));
  EXPECT_EQ(cmd("io io-block 1 0xA5 0x5A"), "ok io pn0:io-block 1:1 out=- out-state=valid in=A55A");
  bench_.run_for(100ms);
  const auto in2 = plan.consumer->data(plan.index(1));
  EXPECT_EQ(Bytes(in2.begin(), in2.end()), (Bytes{0xA5, 0x5A}));
  EXPECT_EQ(cmd("io io-block 0"), "io pn0:io-block 0:1 out=- out-state=valid in=-");  // the DAP

  // Refusals, the device's data unchanged.
  EXPECT_EQ(cmd("io"), "error: io takes a STATION (" + std::string(PnConsole::kCommands) + ")");
  EXPECT_EQ(cmd("io nosuch 1"), "error: no simulated PROFINET station nosuch");
  EXPECT_EQ(cmd("io akd-x 1"), "error: pn0:akd-x (kollmorgen-akd-profinet) is not a generic IO device");
  EXPECT_EQ(cmd("io io-block"), "error: io takes STATION SLOT[:SUBSLOT] [BYTE...]");
  EXPECT_EQ(cmd("io io-block one"), "error: io: \"one\" is not SLOT or SLOT:SUBSLOT");
  EXPECT_EQ(cmd("io io-block 1:"), "error: io: \"1:\" is not SLOT or SLOT:SUBSLOT");
  EXPECT_EQ(cmd("io io-block 3"), "error: pn0:io-block has no submodule 3");
  EXPECT_EQ(cmd("io io-block 1:2"), "error: pn0:io-block has no submodule 1:2");
  EXPECT_EQ(cmd("io io-block 1 1"), "error: io: pn0:io-block 1:1 takes 2 input bytes, not 1");
  EXPECT_EQ(cmd("io io-block 1 1 2 3"), "error: io: pn0:io-block 1:1 takes 2 input bytes, not 3");
  EXPECT_EQ(cmd("io io-block 2 1"), "error: io: pn0:io-block 2:1 has no inputs to set");
  EXPECT_EQ(cmd("io io-block 1 1 0x100"), "error: io: \"0x100\" is not a byte (0..255 or 0x00..0xFF)");
  EXPECT_EQ(cmd("io io-block 1 1 -1"), "error: io: \"-1\" is not a byte (0..255 or 0x00..0xFF)");
  EXPECT_EQ(cmd("io io-block 1 zz 1"), "error: io: \"zz\" is not a byte (0..255 or 0x00..0xFF)");
  EXPECT_EQ(cmd("io io-block 1"), "io pn0:io-block 1:1 out=- out-state=valid in=A55A");
  EXPECT_EQ(cmd("power-off io-block"), "ok power-off pn0:io-block");
  EXPECT_EQ(cmd("io io-block 1"), "error: pn0:io-block is off (power-on io-block)");
}

}  // namespace
}  // namespace drivegate::profinet::test
