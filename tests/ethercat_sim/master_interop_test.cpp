// The master engines on main (adapters/ethercat/master: Transactions, LineBoot, CoeSdoClient)
// against the simulator instead of their scripted fake line: a check that both sides read
// ETG.1000.4/.6 the same way. Two CoE slaves and a generic I/O slave (no mailbox).
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "adapters/ethercat/master/coe_sdo_client.hpp"
#include "adapters/ethercat/master/line_boot.hpp"
#include "core/clock.hpp"
#include "tests/ethercat_sim/coe_line.hpp"
#include "tests/ethercat_sim/line_exchange.hpp"

namespace drivegate::ethercat::sim {
namespace {

using namespace std::chrono_literals;

struct Interop {
  Interop() : sii(test::coe_sii()), io(2, 2, SiiIdentity{0x99, 0x1000, 1, 0}) {
    link.open();
    for (int k = 0; k < 2; ++k) {
      apps.push_back(std::make_unique<test::CoeApp>());
      escs.push_back(std::make_unique<EscSlave>(EscConfig{}, sii, apps.back().get()));
      line.add(*escs.back());
    }
    io_esc = std::make_unique<EscSlave>(EscConfig{}, io.sii(), &io);
    line.add(*io_esc);
  }
  // One master cycle: engines queue, frames go through the line, answers come back.
  void cycle() {
    if (boot) boot->poll(now, tx);
    for (auto& c : clients) c->poll(now, tx);
    drivegate::ethercat::test::exchange_over_line(tx, link, line, now);
  }

  MemoryLink link{16};
  SimLine line{link};
  std::vector<std::uint8_t> sii;
  std::vector<std::unique_ptr<test::CoeApp>> apps;
  std::vector<std::unique_ptr<EscSlave>> escs;
  GenericIoSlave io;
  std::unique_ptr<EscSlave> io_esc;
  Transactions tx;
  std::unique_ptr<LineBoot> boot;
  std::vector<std::unique_ptr<CoeSdoClient>> clients;
  core::TimePoint now{};
};

const std::vector<ExpectedSlave> kExpected{
    {0x0000066F, 0x1234, 1, "CoE test slave"},
    {0x0000066F, 0x1234, 1, "CoE test slave"},
    {0x00000099, 0x1000, 1, "Generic I/O"},
};

TEST(EthercatSimInterop, LineBootReachesPreOpAndSdoClientTalksToTheServer) {
  Interop t;
  t.boot = std::make_unique<LineBoot>(kExpected, LineBootConfig{});
  t.boot->start(t.now);
  for (int i = 0; i < 20000 && t.boot->status() == LineStatus::Running; ++i) t.cycle();
  ASSERT_EQ(t.boot->status(), LineStatus::Done) << t.boot->line_text();
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(t.boot->slave(k).status, SlaveStatus::Ready) << k << ": " << t.boot->slave(k).text.view();
  }
  EXPECT_TRUE(t.boot->ok());
  EXPECT_EQ(t.escs[0]->state(), AlState::PreOp);
  EXPECT_EQ(t.escs[1]->station_address(), 0x1002);
  EXPECT_EQ(t.io_esc->state(), AlState::PreOp);

  // SDO client of slave 1: expedited upload, segmented upload, download, abort.
  t.clients.push_back(std::make_unique<CoeSdoClient>(0x1002, SiiMailbox{0x1000, 128, 0x1080, 128}));
  CoeSdoClient& c = *t.clients.back();
  ASSERT_TRUE(c.valid());
  std::array<std::uint8_t, 512> big{};
  const CoeSdoId a = c.upload_value(0x1000, 0);
  const CoeSdoId b = c.upload(0x2001, 0, big);
  const CoeSdoId d = c.download_value(0x2000, 0, 0xBEEF, 2);
  const CoeSdoId e = c.upload_value(0x3000, 0);
  for (int i = 0; i < 2000 && !(c.idle() && c.result(e).status >= CoeSdoStatus::Done); ++i) t.cycle();
  EXPECT_EQ(c.result(a).status, CoeSdoStatus::Done);
  EXPECT_EQ(c.result(a).value, 0x00020192U);
  EXPECT_EQ(c.result(b).status, CoeSdoStatus::Done);
  ASSERT_EQ(c.result(b).size, 300U);
  EXPECT_TRUE(std::equal(t.apps[1]->long_value.begin(), t.apps[1]->long_value.end(), big.begin()));
  EXPECT_EQ(c.result(d).status, CoeSdoStatus::Done);
  EXPECT_EQ(get_u16(t.apps[1]->od.value(0x2000, 0), 0), 0xBEEF);
  EXPECT_EQ(c.result(e).status, CoeSdoStatus::Failed);
  EXPECT_EQ(c.result(e).abort_code, 0x06020000U);

  // SAFE-OP for the I/O slave before anyone configured SM2/SM3: refused with 001Dh, and LineBoot
  // reports the code [ETG.1000.6 §5.3.2].
  ASSERT_TRUE(t.boot->request_state(2, AlState::SafeOp, t.now));
  for (int i = 0; i < 2000 && t.boot->slave(2).status == SlaveStatus::Busy; ++i) t.cycle();
  EXPECT_EQ(t.boot->slave(2).status, SlaveStatus::Failed);
  EXPECT_EQ(t.boot->slave(2).al_code, 0x001D);
  EXPECT_EQ(t.io_esc->state(), AlState::PreOp);
}

// SDO Information from the simulator's CoE server: an OD list in fragments (104 indexes, a
// 128-byte mailbox carries 57 in the first fragment), object and entry descriptions with their
// names, and its errors [ETG.1000.6 §5.6.3].
TEST(EthercatSimInterop, SdoInformationListsAndDescribesTheDictionary) {
  Interop t;
  const std::array<std::uint8_t, 1> v{0};
  for (std::uint16_t i = 0; i < 100; ++i) {
    t.apps[0]->od.add_variable(static_cast<std::uint16_t>(0x3000 + i), data_type::kUnsigned8, object_access::kReadPreOp,
                               "Extra", v);
  }
  t.boot = std::make_unique<LineBoot>(kExpected, LineBootConfig{});
  t.boot->start(t.now);
  for (int i = 0; i < 20000 && t.boot->status() == LineStatus::Running; ++i) t.cycle();
  ASSERT_TRUE(t.boot->ok()) << t.boot->line_text();
  t.clients.push_back(std::make_unique<CoeSdoClient>(0x1001, SiiMailbox{0x1000, 128, 0x1080, 128}));
  CoeSdoClient& c = *t.clients.back();
  auto run = [&](CoeSdoId id) {
    for (int i = 0; i < 5000 && c.result(id).status < CoeSdoStatus::Done; ++i) t.cycle();
    return c.take(id);
  };
  std::array<std::uint16_t, 256> list{};
  CoeSdoResult r = run(c.od_list(OdListType::All, list));
  ASSERT_EQ(r.status, CoeSdoStatus::Done) << std::hex << r.abort_code;
  ASSERT_EQ(r.size, 104U);
  // The dictionary's own list, in its order (by index), across both fragments.
  std::array<std::uint16_t, 256> truth{};
  ASSERT_EQ(t.apps[0]->od.list(OdListType::All, truth), 104U);
  for (std::size_t i = 0; i < 104; ++i) EXPECT_EQ(list[i], truth[i]) << i;
  EXPECT_EQ(list[0], 0x1000);
  EXPECT_EQ(list[3], 0x3000);
  EXPECT_EQ(list[103], 0x6040);

  std::array<char, 64> name{};
  r = run(c.object_description(0x6040, name));
  ASSERT_EQ(r.status, CoeSdoStatus::Done) << std::hex << r.abort_code;
  EXPECT_EQ(std::string_view(name.data(), r.size), "Record");
  EXPECT_EQ(r.info.object_code, object_code::kRecord);
  r = run(c.entry_description(0x1000, 0, name));
  ASSERT_EQ(r.status, CoeSdoStatus::Done) << std::hex << r.abort_code;
  EXPECT_EQ(std::string_view(name.data(), r.size), "Device type");
  EXPECT_EQ(r.info.data_type, data_type::kUnsigned32);
  EXPECT_EQ(r.info.bit_length, 32);
  EXPECT_NE(r.info.object_access & object_access::kReadPreOp, 0);

  r = run(c.object_description(0x5555, name));
  EXPECT_EQ(r.status, CoeSdoStatus::Failed);
  EXPECT_EQ(r.abort_code, 0x06020000U);
  r = run(c.entry_description(0x6040, 9, name));
  EXPECT_EQ(r.status, CoeSdoStatus::Failed);
  EXPECT_EQ(r.abort_code, 0x06090011U);
  // SDO transfers go on as before on the same mailbox.
  r = run(c.upload_value(0x1000, 0));
  EXPECT_EQ(r.status, CoeSdoStatus::Done);
  EXPECT_EQ(r.value, 0x00020192U);
  EXPECT_EQ(c.counters().timeouts, 0U);
  EXPECT_EQ(c.counters().malformed, 0U);
}

TEST(EthercatSimInterop, RebootedLineAndResetClientKeepTalking) {
  // The boot run again (every slave through INIT: the mailboxes are set up afresh), the client
  // reset() as LineBoot users do after a re-init: requests work as before.
  Interop t;
  t.boot = std::make_unique<LineBoot>(kExpected, LineBootConfig{});
  t.clients.push_back(std::make_unique<CoeSdoClient>(0x1001, SiiMailbox{0x1000, 128, 0x1080, 128}));
  CoeSdoClient& c = *t.clients.back();
  for (int run = 0; run < 2; ++run) {
    t.boot->start(t.now);
    c.reset();
    for (int i = 0; i < 20000 && t.boot->status() == LineStatus::Running; ++i) t.cycle();
    ASSERT_TRUE(t.boot->ok()) << run << ": " << t.boot->line_text() << t.boot->slave(0).text.view();
    for (int k = 0; k < 3; ++k) {
      const CoeSdoId id = c.upload_value(0x1000, 0);
      for (int i = 0; i < 2000 && c.result(id).status < CoeSdoStatus::Done; ++i) t.cycle();
      const CoeSdoResult r = c.take(id);
      EXPECT_EQ(r.status, CoeSdoStatus::Done) << run << "/" << k << std::hex << " abort " << r.abort_code;
      EXPECT_EQ(r.value, 0x00020192U);
    }
  }
  EXPECT_EQ(c.counters().timeouts, 0U);
}

TEST(EthercatSimInterop, SlaveDroppedWithAnErrorIsTakenDownAndUpAgain) {
  // A slave in PRE-OP drops to INIT on its own with the error indication set (a local error,
  // ETG.1000.6 §5.3.2). Asking it for PRE-OP again acknowledges the error first; the same slave
  // stuck below PRE-OP is refused, acknowledged, and can be asked again once the fault is gone.
  Interop t;
  t.boot = std::make_unique<LineBoot>(kExpected, LineBootConfig{});
  t.boot->start(t.now);
  for (int i = 0; i < 20000 && t.boot->status() == LineStatus::Running; ++i) t.cycle();
  ASSERT_TRUE(t.boot->ok()) << t.boot->line_text();
  const auto settle = [&] {
    for (int i = 0; i < 2000 && t.boot->slave(0).status == SlaveStatus::Busy; ++i) t.cycle();
  };
  t.line.stick(0, AlState::Init, 0x0011);  // drops to INIT + error, refuses PRE-OP
  ASSERT_TRUE(t.boot->request_state(0, AlState::PreOp, t.now));
  settle();
  EXPECT_EQ(t.boot->slave(0).status, SlaveStatus::Failed);
  EXPECT_EQ(t.boot->slave(0).al_code, 0x0011);
  EXPECT_EQ(t.escs[0]->state(), AlState::Init);
  t.line.stick(0, AlState::Op, 0);  // the fault is gone
  ASSERT_TRUE(t.boot->request_state(0, AlState::PreOp, t.now));
  settle();
  EXPECT_EQ(t.boot->slave(0).status, SlaveStatus::Ready) << t.boot->slave(0).text.view();
  EXPECT_EQ(t.escs[0]->state(), AlState::PreOp);
}

}  // namespace
}  // namespace drivegate::ethercat::sim
