// ProfidriveMaster against the scripted drive: parameter access over record 47 (reads, writes,
// negative responses, refusals, timeouts, malformed and foreign responses), one reply per command
// in bursts, and no allocation in update().
#include <gtest/gtest.h>

#include <cstring>
#include <initializer_list>
#include <random>

#include "tests/profidrive/master_harness.hpp"
#include "tests/support/alloc_counter.hpp"

namespace drivegate::profidrive::test {
namespace {

core::ParamRequest read_req(core::CommandId id, std::uint16_t pnu, core::ParamType type = core::ParamType::Unknown) {
  core::ParamRequest r;
  r.id = id;
  r.index = pnu;
  r.type = type;
  return r;
}
core::ParamRequest write_req(core::CommandId id, std::uint16_t pnu, std::uint32_t value, std::uint16_t size) {
  core::ParamRequest r;
  r.id = id;
  r.index = pnu;
  r.write = true;
  r.size = size;
  for (std::uint16_t i = 0; i < size; ++i) r.data[i] = static_cast<std::uint8_t>(value >> (8U * i));
  return r;
}
bool replied(const Harness& h, core::CommandId id) {
  for (const auto& r : h.sink.params) {
    if (r.id == id) return true;
  }
  return false;
}
const core::ParamReply& reply_for(const Harness& h, core::CommandId id) {
  static const core::ParamReply kNone{};
  for (const auto& r : h.sink.params) {
    if (r.id == id) return r;
  }
  ADD_FAILURE() << "no parameter reply for " << id;
  return kNone;
}

TEST(ProfidriveMasterParams, ReadsAndWritesByPnuLittleEndian) {
  Harness h(9);
  h.enable();
  ASSERT_TRUE(h.param(read_req(10, 1002, core::ParamType::U16)).accepted);
  ASSERT_TRUE(h.param(write_req(11, 1004, 0x1234, 2)).accepted);
  ASSERT_TRUE(h.param(read_req(12, 2157)).accepted);  // a DWord
  ASSERT_TRUE(h.run_until([&] { return h.sink.params.size() == 3; }));
  const core::ParamReply* r = &reply_for(h, 10);
  ASSERT_TRUE(r->ok) << r->error.view();
  EXPECT_EQ(r->size, 2);
  EXPECT_EQ(r->data[0], 16);
  EXPECT_EQ(r->data[1], 0);
  r = &reply_for(h, 11);
  ASSERT_TRUE(r->ok) << r->error.view();  // the AKD's 6-byte change reply [§5.3]
  EXPECT_EQ(h.drive.find(1004)->value, 0x1234U);
  r = &reply_for(h, 12);
  ASSERT_TRUE(r->ok);
  EXPECT_EQ(r->size, 4);
  EXPECT_EQ(r->data[0], 9);
  EXPECT_EQ(h.drive.requests, 3);
}

TEST(ProfidriveMasterParams, ChangeRequestBytesAreTheProfileLayout) {
  Harness h(9);
  h.enable();
  ASSERT_TRUE(h.param(write_req(11, 1004, 0x1234, 2)).accepted);
  ASSERT_TRUE(h.run_until([&] { return h.drive.requests == 1; }, 10));
  // ref 02 00 01 | 10 01 03EC 0000 | 42 01 1234 [§5.2, §5.5]
  const std::uint8_t expected[] = {0x02, 0x00, 0x01, 0x10, 0x01, 0x03, 0xEC, 0x00, 0x00, 0x42, 0x01, 0x12, 0x34};
  ASSERT_EQ(h.drive.last_request_size, sizeof expected + 1);
  EXPECT_EQ(std::memcmp(h.drive.last_request.data() + 1, expected, sizeof expected), 0);
}

TEST(ProfidriveMasterParams, NegativeResponsesAndTypeMismatchesAreErrorsInWords) {
  Harness h(9);
  h.enable();
  ASSERT_TRUE(h.param(read_req(10, 4711)).accepted);
  ASSERT_TRUE(h.param(write_req(11, 3022, 5, 4)).accepted);
  ASSERT_TRUE(h.param(read_req(12, 2157, core::ParamType::U16)).accepted);
  ASSERT_TRUE(h.run_until([&] { return h.sink.params.size() == 3; }));
  const core::ParamReply* r = &reply_for(h, 10);
  EXPECT_FALSE(r->ok);
  EXPECT_EQ(r->error_code, 0U);
  EXPECT_NE(r->error.view().find("PNU 4711:0"), std::string_view::npos) << r->error.view();
  r = &reply_for(h, 11);
  EXPECT_FALSE(r->ok);
  EXPECT_EQ(r->error_code, 1U);
  r = &reply_for(h, 12);
  EXPECT_FALSE(r->ok);
  EXPECT_NE(r->error.view().find("the drive sent 4 bytes"), std::string_view::npos) << r->error.view();
}

TEST(ProfidriveMasterParams, RefusesWritesToWhatTheGatewayDrives) {
  Harness h(9);
  h.enable();
  for (const std::uint16_t pnu : std::initializer_list<std::uint16_t>{1, 32, 34, 915, 916, 922, 930}) {
    const core::Admission a = h.param(write_req(20, pnu, 1, 2));
    EXPECT_FALSE(a.accepted) << pnu;
    EXPECT_NE(a.reason.view().find("driven by the gateway"), std::string_view::npos) << a.reason.view();
  }
  EXPECT_TRUE(h.param(read_req(21, 1)).accepted);  // reading STW1 is harmless
  EXPECT_FALSE(h.param(write_req(22, 1004, 1, 3)).accepted);
  EXPECT_FALSE(h.param(read_req(23, 0)).accepted);
  EXPECT_FALSE(h.param(read_req(24, 1002, core::ParamType::VisibleString)).accepted);
}

TEST(ProfidriveMasterParams, BusyWhenFullAndOneReplyEach) {
  Harness h(9);
  h.enable();
  for (core::CommandId id = 30; id < 30 + ProfidriveMaster::kMaxParameterRequests; ++id)
    ASSERT_TRUE(h.param(read_req(id, 1002)).accepted);
  const core::Admission busy = h.param(read_req(99, 1002));
  EXPECT_FALSE(busy.accepted);
  EXPECT_TRUE(busy.busy);
  ASSERT_TRUE(h.run_until([&] { return h.sink.params.size() == ProfidriveMaster::kMaxParameterRequests; }));
  h.run(20);
  EXPECT_EQ(h.sink.params.size(), ProfidriveMaster::kMaxParameterRequests);
  for (const auto& r : h.sink.params) EXPECT_TRUE(r.ok);
}

TEST(ProfidriveMasterParams, ChannelFailuresEndTheRequest) {
  MasterSettings s;
  s.param_timeout = 30ms;
  Harness h(9, s);
  h.enable();
  h.drive.param_hang = true;
  ASSERT_TRUE(h.param(read_req(40, 1002)).accepted);
  ASSERT_TRUE(h.run_until([&] { return replied(h, 40); }, 100));
  EXPECT_NE(reply_for(h, 40).error.view().find("no answer on record 47 within 30 ms"), std::string_view::npos);
  EXPECT_EQ(h.drive.cancels, 1);
  h.drive.param_hang = false;

  h.drive.param_garbage = true;
  ASSERT_TRUE(h.param(read_req(41, 1002)).accepted);
  ASSERT_TRUE(h.run_until([&] { return replied(h, 41); }, 100));
  EXPECT_NE(reply_for(h, 41).error.view().find("malformed parameter response"), std::string_view::npos)
      << reply_for(h, 41).error.view();
  h.drive.param_garbage = false;

  h.drive.param_wrong_reference = true;
  ASSERT_TRUE(h.param(read_req(42, 1002)).accepted);
  ASSERT_TRUE(h.run_until([&] { return replied(h, 42); }, 100));
  EXPECT_NE(reply_for(h, 42).error.view().find("does not answer the request"), std::string_view::npos)
      << reply_for(h, 42).error.view();
  h.drive.param_wrong_reference = false;

  h.drive.param_rpc_fails = true;
  ASSERT_TRUE(h.param(read_req(43, 1002)).accepted);
  ASSERT_TRUE(h.run_until([&] { return replied(h, 43); }, 100));
  EXPECT_NE(reply_for(h, 43).error.view().find("IODReadReq timed out"), std::string_view::npos);
  h.drive.param_rpc_fails = false;

  ASSERT_TRUE(h.param(read_req(44, 1002)).accepted);
  ASSERT_TRUE(h.run_until([&] { return replied(h, 44); }, 100));
  EXPECT_TRUE(reply_for(h, 44).ok);
}

TEST(ProfidriveMasterParams, FaultBufferGoesBeforeClientRequests) {
  Harness h(9);
  h.enable();
  h.drive.raise_fault({702});
  h.cycle();
  ASSERT_TRUE(h.param(read_req(50, 1002)).accepted);
  ASSERT_TRUE(h.run_until([&] { return replied(h, 50); }));
  EXPECT_EQ(h.sink.count(core::EventKind::Fault), 1U);
  EXPECT_EQ(h.drive.requests, 4);  // 944, 947, 944, then the client's
}

// Commands in bursts, against every state the axis goes through: each accepted one gets exactly
// one final reply, a refused one none.
TEST(ProfidriveMaster, EveryAcceptedCommandGetsExactlyOneReply) {
  Harness h(9);
  std::mt19937 rng(7);
  std::vector<core::CommandId> accepted;
  core::CommandId next = 100;
  const auto some_command = [&](core::CommandId id) {
    switch (rng() % 10) {
      case 0: return command(id, CommandKind::Enable);
      case 1: return command(id, CommandKind::Disable);
      case 2: return command(id, CommandKind::QuickStop);
      case 3: return command(id, CommandKind::FaultReset);
      case 4: return home(id);
      case 5: return move(id, static_cast<std::int32_t>(rng() % 20000));
      case 6: return velocity(id, rng() % 2 == 0 ? kOneRps : -kOneRps);
      case 7: return command(id, CommandKind::Halt);
      case 8: return command(id, CommandKind::Resume);
      default: return command(id, CommandKind::Stop);
    }
  };
  h.cycle();
  for (int round = 0; round < 400; ++round) {
    const int burst = static_cast<int>(rng() % 4);
    for (int i = 0; i < burst; ++i) {
      const core::CommandId id = next++;
      const core::Admission a = h.submit(some_command(id));
      if (a.accepted) accepted.push_back(id);
      else EXPECT_EQ(h.sink.replies(id), 0U);
    }
    if (rng() % 50 == 0) h.drive.raise_fault({702});
    if (rng() % 80 == 0) h.master.link_lost(h.now, h.sink);
    h.run(static_cast<int>(rng() % 30));
  }
  ASSERT_TRUE(h.submit(command(next, CommandKind::Disable)).accepted);
  accepted.push_back(next);
  h.run(3000);
  ASSERT_GT(accepted.size(), 100U);
  for (const core::CommandId id : accepted) EXPECT_EQ(h.sink.replies(id), 1U) << "command " << id;
}

// A sink that only counts: the recording one allocates.
struct CountingSink final : core::ControllerSink {
  std::size_t replies = 0;
  std::size_t events = 0;
  std::size_t params = 0;
  void completed(core::CommandId) noexcept override { ++replies; }
  void failed(core::CommandId, std::string_view) noexcept override { ++replies; }
  void event(core::EventKind, std::uint32_t, std::string_view) noexcept override { ++events; }
  void parameter_done(const core::ParamReply&) noexcept override { ++params; }
};

TEST(ProfidriveMaster, UpdateAllocatesNothing) {
  for (const std::uint16_t telegram : std::initializer_list<std::uint16_t>{1, 7, 9, 353}) {
    ScriptedDrive drive(telegram);
    ProfidriveMaster master(drive, drive, drive.layout, MasterSettings{});
    CountingSink sink;
    core::TimePoint now{};
    const auto cycles = [&](int n) {
      for (int i = 0; i < n; ++i) {
        drive.step();
        master.update(now, sink);
        now += std::chrono::milliseconds(1);
      }
    };
    const drivegate::test::AllocationScope scope;
    cycles(2);
    (void)master.submit(command(1, CommandKind::Enable), now, sink);
    cycles(20);
    if (telegram == 1) {
      (void)master.submit(velocity(2, kOneRps), now, sink);
    } else {
      (void)master.submit(home(2), now, sink);
      cycles(50);
      (void)master.submit(telegram == 7 ? run_block(3, 1) : move(3, 700), now, sink);
    }
    core::ParamRequest r;
    r.id = 9;
    r.index = 1002;
    (void)master.parameter(r, now);
    cycles(300);
    drive.raise_fault({702, 501});
    cycles(50);
    (void)master.submit(command(4, CommandKind::FaultReset), now, sink);
    cycles(50);
    master.link_lost(now, sink);
    cycles(500);
    EXPECT_EQ(scope.count(), 0U) << "telegram " << telegram;
    EXPECT_GE(sink.replies, telegram == 1 ? 3U : 4U) << "telegram " << telegram;
    EXPECT_EQ(sink.params, 1U);
  }
}

}  // namespace
}  // namespace drivegate::profidrive::test
