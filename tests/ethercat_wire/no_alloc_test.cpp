// The codecs the cycle calls allocate nothing (issue 9: "zero heap allocations per cycle"): one
// cyclic frame built, answered in place and parsed, a mailbox encoded and decoded, an SII image
// parsed, all with the allocation counter armed (tests/support/alloc_counter.hpp).
#include <gtest/gtest.h>

#include <array>
#include <memory>

#include "adapters/ethercat/wire/frame.hpp"
#include "adapters/ethercat/wire/mailbox.hpp"
#include "adapters/ethercat/wire/registers.hpp"
#include "adapters/ethercat/wire/sii.hpp"
#include "tests/support/alloc_counter.hpp"

namespace drivegate::ethercat {
namespace {

TEST(EcatNoAlloc, CyclicFrameAndMailbox) {
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  std::array<std::uint8_t, 128> mbx{};
  std::array<std::uint8_t, 64> image{};
  std::size_t datagrams = 0;
  std::uint16_t wkc = 0;
  SdoView sdo;
  const test::AllocationScope scope;
  for (int cycle = 0; cycle < 100; ++cycle) {
    FrameBuilder b(buf, kBroadcastMac, MacAddress{0x02, 0, 0, 0, 0, 1});
    const auto dc = b.add(Command::FRMW, 0, physical_address(0x1001, reg::kDcSystemTime), 8);
    const auto pd = b.add(Command::LRW, 1, 0x00010000, static_cast<std::uint16_t>(image.size()), image);
    const auto frame = b.finish();
    buf[pd.slot.wkc_offset] = 3;
    buf[dc.slot.wkc_offset] = 2;
    FrameParser p(frame);
    Datagram d;
    while (p.next(d)) {
      ++datagrams;
      wkc = static_cast<std::uint16_t>(wkc + d.wkc);
    }
    const std::size_t n = encode_sdo_download_value(mbx, next_mailbox_counter(static_cast<std::uint8_t>(cycle % 8)),
                                                    0x60C2, 1, 4, 1);
    sdo = decode_sdo_request(std::span<const std::uint8_t>(mbx).first(n));
  }
  EXPECT_EQ(scope.count(), 0U);
  EXPECT_EQ(datagrams, 200U);
  EXPECT_EQ(wkc, 500U);
  EXPECT_EQ(sdo.error, MailboxError::None);
}

TEST(EcatNoAlloc, SiiParse) {
  std::array<std::uint8_t, 1024> img{};
  SiiProfile p;
  p.eeprom_bytes = img.size();
  p.name = "drive";
  ASSERT_TRUE(build_sii(p, img).ok());
  auto info = std::make_unique<SiiInfo>();  // allocated before the scope: it is large
  const test::AllocationScope scope;
  parse_sii(img, *info);
  EXPECT_EQ(scope.count(), 0U);
  EXPECT_EQ(info->string(info->general.name_index), "drive");
}

}  // namespace
}  // namespace drivegate::ethercat
