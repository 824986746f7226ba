// SDO client against the simulated SDO server, frames looped back through TxQueues in virtual
// time: every payload size both ways, the 42h persona, several channels, injected faults.
#include <gtest/gtest.h>

#include <algorithm>
#include <utility>
#include <vector>

#include "adapters/canopen/master/sdo_client.hpp"
#include "adapters/canopen/sim/sdo_server.hpp"
#include "profiles/cia402/sdo_abort.hpp"
#include "sdo_test_support.hpp"
#include "tests/support/alloc_counter.hpp"

namespace drivegate::canopen {
namespace {

using namespace std::chrono_literals;
using namespace test_sdo;
using sim::SdoServer;
using sim::SdoServerConfig;

constexpr core::TimePoint kT0{std::chrono::seconds(10)};
const ObjectId kObject{0x2100, 0x01};

// A CAN bus between one client and its servers. Nothing here allocates, so whole transfers can
// run inside an AllocationScope.
class Loop {
 public:
  Loop(SdoClient& client, std::span<SdoServer* const> servers) : client_(client), servers_(servers) {}

  // Rounds of client poll -> servers -> client until no channel has work, or `limit` rounds.
  void run(core::TimePoint now, int limit = 100) noexcept {
    for (int i = 0; i < limit && busy(); ++i) round(now);
  }
  void round(core::TimePoint now) noexcept {
    client_.poll(now, tx_);
    for (; !tx_.empty(); tx_.pop()) {
      ++client_frames_;
      for (auto* s : servers_) s->on_frame(tx_.front(), now);
    }
    for (auto* s : servers_) s->poll(now, tx_);
    for (; !tx_.empty(); tx_.pop()) client_.on_frame(tx_.front(), now);
  }
  [[nodiscard]] bool busy() const noexcept {
    for (int ch = 0; ch < 8; ++ch) {
      if (client_.pending(ch) > 0) return true;
    }
    return false;
  }
  // Frames the client has sent, then reset.
  std::size_t take_client_frames() noexcept { return std::exchange(client_frames_, 0); }

 private:
  SdoClient& client_;
  std::span<SdoServer* const> servers_;
  TxQueue tx_;
  std::size_t client_frames_ = 0;
};

// Request frames a transfer of n bytes takes: the initiate, plus one per 7-byte segment.
std::size_t frames_for(std::size_t n) { return n <= 4 ? 1 : 1 + (n + 6) / 7; }

TEST(SdoLoopback, EveryPayloadSizeBothDirectionsWithoutAllocation) {
  TestBackend od;
  od.add(kObject, {});
  SdoServer server({0x605, 0x585, 1000ms, false}, od);
  SdoServer* servers[] = {&server};
  const SdoChannelConfig cfg{5, 1, 0, 0};
  SdoClient client(std::span<const SdoChannelConfig>(&cfg, 1), SdoTiming{});
  Loop bus(client, servers);

  // Outcomes are recorded in fixed arrays and checked after the scope, so that the checks do not
  // count as allocations of the code under test.
  constexpr std::size_t kMax = SdoClient::kMaxData;
  std::array<bool, kMax + 1> written{};
  std::array<bool, kMax + 1> read_back{};
  std::array<std::size_t, kMax + 1> write_frames{};
  std::array<std::size_t, kMax + 1> read_frames{};
  std::array<std::uint32_t, kMax + 1> values{};
  std::size_t allocations = 0;
  {
    const drivegate::test::AllocationScope scope;
    std::array<std::uint8_t, kMax> payload{};
    for (std::size_t n = 1; n <= kMax; ++n) {
      for (std::size_t i = 0; i < n; ++i) payload[i] = static_cast<std::uint8_t>(n * 7 + i);
      const auto w = client.write_from(0, kObject, {payload.data(), n});
      bus.run(kT0);
      write_frames[n] = bus.take_client_frames();
      written[n] = client.take(w).status == SdoStatus::Done;

      const auto r = client.read(0, kObject);
      bus.run(kT0);
      read_frames[n] = bus.take_client_frames();
      const auto data = client.data(r);
      read_back[n] = client.result(r).size == n && std::equal(data.begin(), data.end(), payload.begin(), payload.begin() + n);
      values[n] = client.take(r).value;
    }
    allocations = scope.count();
  }
  EXPECT_EQ(allocations, 0U);
  for (std::size_t n = 1; n <= kMax; ++n) {
    SCOPED_TRACE(testing::Message() << n << " bytes");
    EXPECT_TRUE(written[n]);
    EXPECT_TRUE(read_back[n]);
    EXPECT_EQ(write_frames[n], frames_for(n));
    EXPECT_EQ(read_frames[n], frames_for(n));
    if (n <= 4) {
      std::uint32_t expect = 0;
      for (std::size_t i = 0; i < n; ++i) expect |= std::uint32_t{static_cast<std::uint8_t>(n * 7 + i)} << (8 * i);
      EXPECT_EQ(values[n], expect);
    }
  }
  EXPECT_EQ(client.counters().completed, 2 * kMax);
  EXPECT_EQ(client.counters().failed + client.counters().unexpected + client.counters().malformed, 0U);
  EXPECT_EQ(server.counters().completed, 2 * kMax);
  EXPECT_EQ(server.counters().aborts_sent, 0U);
}

// The SD6 persona answers with 42h; the client trims to the size the caller expects
// (stoeber-sd6-canopen.md §6.4).
TEST(SdoLoopback, Sd6PersonaWithExpectedSizes) {
  TestBackend od;
  od.add({0x6041, 0}, {0x37, 0x02});
  od.add({0x6061, 0}, {0xFD});
  od.add({0x6064, 0}, {0x78, 0x56, 0x34, 0x12});
  SdoServer server({0x605, 0x585, 1000ms, true}, od);
  SdoServer* servers[] = {&server};
  const SdoChannelConfig cfg{5, 1, 0, 0};
  SdoClient client(std::span<const SdoChannelConfig>(&cfg, 1), SdoTiming{});
  Loop bus(client, servers);
  const auto sw = client.read(0, {0x6041, 0}, 2);
  const auto mode = client.read(0, {0x6061, 0}, 1);
  const auto pos = client.read(0, {0x6064, 0}, 4);
  const auto unsized = client.read(0, {0x6061, 0});
  bus.run(kT0);
  EXPECT_EQ(client.result(sw).value, 0x0237U);
  EXPECT_EQ(client.result(sw).size, 2);
  EXPECT_EQ(client.result(mode).value, 0xFDU);
  EXPECT_EQ(client.result(mode).size, 1);
  EXPECT_EQ(client.result(pos).value, 0x12345678U);
  EXPECT_EQ(client.result(unsized).size, 4);  // 42h: the bytes after the value are padding (0)
  EXPECT_EQ(client.result(unsized).value, 0xFDU);
}

// SD6 with two SDO channels (node 5: 605h/585h and 625h/5A5h, one axis each: stoeber-sd6-canopen.md
// §6.3, §11.2 D-14) and a second drive on node 7, all busy at once.
TEST(SdoLoopback, SeveralChannelsInterleaved) {
  TestBackend axis1;
  TestBackend axis2;
  TestBackend node7;
  for (auto* od : {&axis1, &axis2, &node7}) od->add(kObject, {});
  SdoServer s1({0x605, 0x585, 1000ms, false}, axis1);
  SdoServer s2({0x625, 0x5A5, 1000ms, false}, axis2);
  SdoServer s7({0x607, 0x587, 1000ms, false}, node7);
  SdoServer* servers[] = {&s1, &s2, &s7};
  const std::vector<SdoChannelConfig> cfg = {{5, 1, 0, 0}, {5, 2, 0, 0}, {7, 1, 0, 0}};
  SdoClient client(cfg, SdoTiming{});
  Loop bus(client, servers);

  const Bytes a = counting(20);
  const Bytes b(33, 0x5A);
  const Bytes c = {0xC0, 0xFF, 0xEE};
  const auto wa = client.write_from(0, kObject, a);
  const auto wb = client.write_from(1, kObject, b);
  const auto wc = client.write_from(2, kObject, c);
  const auto ra = client.read(0, kObject);
  const auto rb = client.read(1, kObject);
  const auto rc = client.read(2, kObject);
  // Every round moves one frame per channel: the three transfers advance side by side.
  bus.round(kT0);
  EXPECT_EQ(bus.take_client_frames(), 3U);
  bus.run(kT0);

  for (auto id : {wa, wb, wc}) EXPECT_EQ(client.result(id).status, SdoStatus::Done);
  EXPECT_EQ(axis1.value(kObject), a);
  EXPECT_EQ(axis2.value(kObject), b);
  EXPECT_EQ(node7.value(kObject), c);
  const auto bytes = [&](SdoRequestId id) {
    const auto d = client.data(id);
    return Bytes(d.begin(), d.end());
  };
  EXPECT_EQ(bytes(ra), a);
  EXPECT_EQ(bytes(rb), b);
  EXPECT_EQ(bytes(rc), c);
  for (auto* s : servers) EXPECT_EQ(s->counters().completed, 2U);
  EXPECT_EQ(client.counters().unexpected, 0U);
}

TEST(SdoLoopback, InjectedAbortReachesTheCallerWithItsText) {
  TestBackend od;
  od.add({0x6060, 0}, {0});
  SdoServer server({0x605, 0x585, 1000ms, false}, od);
  SdoServer* servers[] = {&server};
  const SdoChannelConfig cfg{5, 1, 0, 0};
  SdoClient client(std::span<const SdoChannelConfig>(&cfg, 1), SdoTiming{});
  Loop bus(client, servers);
  server.inject_abort({0x6060, 0}, 0x06090030);
  const auto refused = client.write(0, {0x6060, 0}, 9, 1);
  const auto accepted = client.write(0, {0x6060, 0}, 3, 1);
  const auto missing = client.read(0, {0x6061, 0});
  bus.run(kT0);
  EXPECT_EQ(client.result(refused).status, SdoStatus::Failed);
  EXPECT_EQ(cia402::sdo_abort_text(client.result(refused).abort_code), "invalid value for parameter (download only)");
  EXPECT_EQ(client.result(accepted).status, SdoStatus::Done);
  EXPECT_EQ(od.value({0x6060, 0}), Bytes{3});
  EXPECT_EQ(client.result(missing).abort_code, cia402::sdo_abort_code::kNoObject);
  EXPECT_EQ(cia402::sdo_abort_text(client.result(missing).abort_code), "object does not exist in the object dictionary");
}

// A silent server: the client sends the initiate 1 + retries times, then its abort.
TEST(SdoLoopback, SilentServerMakesTheClientRetryAndGiveUp) {
  TestBackend od;
  od.add({0x1000, 0}, {0x92, 0x01, 0x02, 0x00});
  SdoServer server({0x605, 0x585, 1000ms, false}, od);
  SdoServer* servers[] = {&server};
  const SdoChannelConfig cfg{5, 1, 0, 0};
  SdoClient client(std::span<const SdoChannelConfig>(&cfg, 1), SdoTiming{50ms, 3});
  Loop bus(client, servers);
  server.set_silent(true);
  const auto id = client.read(0, {0x1000, 0});
  for (core::TimePoint now = kT0; bus.busy(); now += 10ms) bus.round(now);
  EXPECT_EQ(bus.take_client_frames(), 5U);
  EXPECT_EQ(server.counters().ignored_silent, 5U);
  EXPECT_EQ(client.result(id).abort_code, cia402::sdo_abort_code::kTimeout);
  EXPECT_EQ(client.counters().retries, 3U);

  server.set_silent(false);
  const auto again = client.read(0, {0x1000, 0});
  bus.run(kT0 + 1s);
  EXPECT_EQ(client.result(again).value, 0x00020192U);
}

// Objects beyond the client's own slots travel through the caller's buffer: a 4 KiB upload and
// download whole, an object longer than the buffer aborted with 05040005h, and a cancel in the
// middle of a transfer aborts it on the bus at once so the buffer is free.
TEST(SdoLoopback, CallerBuffersCarryFourKilobytes) {
  TestBackend od;
  Bytes blob(4096);
  for (std::size_t i = 0; i < blob.size(); ++i) blob[i] = static_cast<std::uint8_t>(i * 7 + 1);
  od.add(kObject, blob);
  od.add({0x2101, 0}, {});
  od.add({0x2102, 0}, {1, 2});
  SdoServer server({0x605, 0x585, 1000ms, false}, od);
  SdoServer* servers[] = {&server};
  const SdoChannelConfig cfg{5, 1, 0, 0};
  SdoClient client(std::span<const SdoChannelConfig>(&cfg, 1), SdoTiming{});
  Loop bus(client, servers);

  std::vector<std::uint8_t> into(4096);
  auto id = client.read_into(0, kObject, into);
  ASSERT_NE(id, kNoSdoRequest);
  bus.run(kT0, 2000);
  SdoResult r = client.take(id);
  ASSERT_EQ(r.status, SdoStatus::Done) << std::hex << r.abort_code;
  EXPECT_EQ(r.size, 4096);
  EXPECT_EQ(into, blob);
  EXPECT_EQ(bus.take_client_frames(), frames_for(4096));

  id = client.write_from(0, {0x2101, 0}, blob);
  bus.run(kT0, 2000);
  EXPECT_EQ(client.take(id).status, SdoStatus::Done);
  EXPECT_EQ(od.value({0x2101, 0}), blob);

  std::vector<std::uint8_t> small(100);
  id = client.read_into(0, kObject, small);
  bus.run(kT0, 2000);
  r = client.take(id);
  EXPECT_EQ(r.status, SdoStatus::Failed);
  EXPECT_EQ(r.abort_code, 0x05040005U);
  bus.round(kT0);  // the abort goes out
  EXPECT_FALSE(server.transfer_open());
  EXPECT_EQ(server.counters().aborts_received, 1U);

  // Cancelled after the first segment: the client aborts (08000000h), writes nothing more into
  // the buffer, and the channel is free for the next request.
  std::fill(into.begin(), into.end(), 0);
  id = client.read_into(0, kObject, into);
  bus.round(kT0);
  bus.round(kT0);
  ASSERT_EQ(client.result(id).status, SdoStatus::InFlight);
  client.cancel(id);
  EXPECT_EQ(client.pending(0), 0U);
  const auto before = into;
  bus.round(kT0);  // the abort goes out
  EXPECT_FALSE(server.transfer_open());
  EXPECT_EQ(server.counters().aborts_received, 2U);
  EXPECT_EQ(into, before);
  EXPECT_EQ(client.result(id).status, SdoStatus::Unknown);
  id = client.read(0, {0x2102, 0});
  bus.run(kT0, 2000);
  EXPECT_EQ(client.take(id).status, SdoStatus::Done);
}

}  // namespace
}  // namespace drivegate::canopen
