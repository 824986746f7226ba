// The boot steps compiled from the device profiles, as the SDO frames they become, against the
// digests' vectors.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "adapters/canopen/boot_plan.hpp"
#include "adapters/canopen/wire/sdo_codec.hpp"
#include "config/loader.hpp"

namespace drivegate::canopen::test {
namespace {

const char* kPlan = R"(gateway: { name: boot-test }
buses:
  - { name: can0, type: canopen, cycle_time: 4ms, options: { transport: sim, bitrate: 1000000 } }
axes:
  - { name: akd, bus: can0, address: 1, device: kollmorgen-akd, unit: mm, mechanics: { feed: 5 } }
  - { name: nord, bus: can0, address: 32, device: nord-sk500p }
  - { name: sd6, bus: can0, address: 5, device: stoeber-sd6, mechanics: { encoder_counts_per_rev: 10000 } }
)";

using Bytes = std::vector<std::uint8_t>;

// Every Write step as the expedited download frame the SDO client sends for it.
std::vector<Bytes> write_frames(const std::vector<BootStep>& steps) {
  std::vector<Bytes> out;
  for (const auto& s : steps) {
    if (s.kind != BootStep::Kind::Write) continue;
    const auto b = sdo_download_expedited(s.def.id, static_cast<std::uint32_t>(s.value), cia402::size_of(s.def.type));
    out.emplace_back(b.begin(), b.end());
  }
  return out;
}

// True when `needle` occurs in `hay` as a contiguous run.
bool contains_run(const std::vector<Bytes>& hay, const std::vector<Bytes>& needle) {
  for (std::size_t i = 0; i + needle.size() <= hay.size(); ++i) {
    bool all = true;
    for (std::size_t k = 0; k < needle.size() && all; ++k) all = hay[i + k] == needle[k];
    if (all) return true;
  }
  return false;
}

struct BootPlanTest : ::testing::Test {
  config::Plan plan = config::load_plan_from_string(kPlan, "boot-test.yaml");
  const config::BusPlan& bus = plan.buses.at(0);
};

// NORD TV-D: RPDO4 (60FFh + 6071h) mapped with invalidate, count 0, entries, count, validate; node
// 0x20. The transmission type is written while the PDO is invalid, before it is validated.
TEST_F(BootPlanTest, NordRpdo4FollowsTvD) {
  const auto frames = write_frames(build_boot_steps(bus.axes[1], bus));
  EXPECT_TRUE(contains_run(frames, {{0x23, 0x03, 0x14, 0x01, 0x20, 0x05, 0x00, 0x80},
                                    {0x2F, 0x03, 0x16, 0x00, 0x00, 0x00, 0x00, 0x00},
                                    {0x23, 0x03, 0x16, 0x01, 0x20, 0x00, 0xFF, 0x60},
                                    {0x23, 0x03, 0x16, 0x02, 0x10, 0x00, 0x71, 0x60},
                                    {0x2F, 0x03, 0x16, 0x00, 0x02, 0x00, 0x00, 0x00},
                                    {0x2F, 0x03, 0x14, 0x02, 0xFF, 0x00, 0x00, 0x00},
                                    {0x23, 0x03, 0x14, 0x01, 0x20, 0x05, 0x00, 0x00}}));
}

// AKD part 1 §14 vectors 3, 4, 7, 8 (TPDO1 off, count 0, count n, on again with bit 30) and the
// heartbeat producer (vector 21) and consumer (vector 22 form: node 127, gateway period x misses).
TEST_F(BootPlanTest, AkdTpdo1AndHeartbeat) {
  const auto frames = write_frames(build_boot_steps(bus.axes[0], bus));
  EXPECT_TRUE(contains_run(frames, {{0x23, 0x00, 0x18, 0x01, 0x81, 0x01, 0x00, 0xC0},
                                    {0x2F, 0x00, 0x1A, 0x00, 0x00, 0x00, 0x00, 0x00}}));
  EXPECT_TRUE(contains_run(frames, {{0x2F, 0x00, 0x18, 0x02, 0x01, 0x00, 0x00, 0x00},
                                    {0x23, 0x00, 0x18, 0x01, 0x81, 0x01, 0x00, 0x40}}));
  EXPECT_TRUE(contains_run(frames, {{0x2B, 0x17, 0x10, 0x00, 0x64, 0x00, 0x00, 0x00},
                                    {0x23, 0x16, 0x10, 0x01, 0x2C, 0x01, 0x7F, 0x00}}));
  // The unused RPDO4 and TPDO4 are switched off.
  EXPECT_TRUE(contains_run(frames, {{0x23, 0x03, 0x14, 0x01, 0x01, 0x05, 0x00, 0x80}}));
  EXPECT_TRUE(contains_run(frames, {{0x23, 0x03, 0x18, 0x01, 0x81, 0x04, 0x00, 0xC0}}));
  // FBUS.PARAM05 policy first of the start-up writes, with its reason for a failure message.
  const auto steps = build_boot_steps(bus.axes[0], bus);
  bool param05 = false;
  for (const auto& s : steps)
    if (s.def.id == cia402::ObjectId{0x36E9, 0} && s.kind == BootStep::Kind::Write)
      param05 = s.why.find("FBUS.PARAM05") != std::string::npos;
  EXPECT_TRUE(param05);
}

// SD6: the mapping is only verified (no write to 1600h../1A00h.. or their counts), guarding is set
// up with heartbeat off first (SD6 D-5), and identity is the STÖBER vendor-ID.
TEST_F(BootPlanTest, Sd6VerifiesMappingAndUsesGuarding) {
  const auto steps = build_boot_steps(bus.axes[2], bus);
  for (const auto& s : steps) {
    const auto index = s.def.id.index;
    if ((index >= 0x1600 && index <= 0x1603) || (index >= 0x1A00 && index <= 0x1A03)) {
      EXPECT_EQ(s.kind, BootStep::Kind::Expect) << std::hex << index;
    }
  }
  EXPECT_TRUE(contains_run(write_frames(steps), {{0x2B, 0x17, 0x10, 0x00, 0x00, 0x00, 0x00, 0x00},
                                                 {0x2B, 0x0C, 0x10, 0x00, 0x64, 0x00, 0x00, 0x00},
                                                 {0x2F, 0x0D, 0x10, 0x00, 0x03, 0x00, 0x00, 0x00}}));
  bool vendor = false;
  for (const auto& s : steps)
    vendor = vendor || (s.kind == BootStep::Kind::Expect && s.def.id == cia402::ObjectId{0x1018, 1} && s.value == 0xB9);
  EXPECT_TRUE(vendor);
}

}  // namespace
}  // namespace drivegate::canopen::test
