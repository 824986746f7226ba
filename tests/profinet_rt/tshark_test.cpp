// The provider's output frames (RUN, then STOP) and a device's input frame dissect cleanly in
// tshark (tests/support/pcap.hpp): PROFINET cyclic RTC1 with the FrameID, the cycle counter and
// the DataStatus, no "Malformed", no expert warning or error. Skipped when tshark is missing.
#include <gtest/gtest.h>

#include <string>

#include "tests/profinet_rt/rt_fixture.hpp"
#include "tests/support/pcap.hpp"

namespace drivegate::profinet::test {
namespace {

TEST(PnRtTshark, ProviderFramesDissectCleanly) {
  RtProvider p(iocr(kOutputFrameId));
  const std::array<std::uint8_t, 4> stw{0x04, 0x7F, 0x40, 0x00};
  std::copy(stw.begin(), stw.end(), p.data(kDrive).begin());
  (void)p.set_iops(kDrive, iox_status::kGood);
  const core::TimePoint start{std::chrono::seconds(2)};  // 64000 units: the counter starts at 64000 + 32
  p.start(start);
  std::vector<Bytes> frames;
  std::array<std::uint8_t, kMaxFrameSize> out{};
  for (int n = 0; n < 3; ++n) {
    if (n == 2) p.set_provider_run(false);
    const std::size_t len = p.poll(p.next_deadline(), out);
    ASSERT_GT(len, 0U);
    frames.emplace_back(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(len));
  }
  frames.push_back(input_frame({.cycle = 0x1234}));
  const std::optional<std::string> text = drivegate::test::tshark_dissect(frames);
  if (!text) GTEST_SKIP() << "tshark is not installed";
  EXPECT_EQ(text->find("Malformed"), std::string::npos) << *text;
  EXPECT_EQ(text->find("Expert Info (Error"), std::string::npos) << *text;
  EXPECT_EQ(text->find("Expert Info (Warning"), std::string::npos) << *text;
  for (const char* field : {"ID:0x8001, Len:  40, Cycle:64032 (Valid,Primary,Ok,Run)",
                            "ID:0x8001, Len:  40, Cycle:64096 (Valid,Primary,Ok,Run)",
                            "ID:0x8001, Len:  40, Cycle:64160 (Valid,Primary,Ok,Stop)",
                            "ID:0x8002, Len:  40, Cycle: 4660 (Valid,Primary,Ok,Run)", "Priority: Internetwork Control (6)"}) {
    EXPECT_NE(text->find(field), std::string::npos) << "missing: " << field << "\n" << *text;
  }
}

}  // namespace
}  // namespace drivegate::profinet::test
