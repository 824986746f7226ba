// Record access through the parameter path (ParamRequest::record): I&M0 of an AKD's DAP read as a
// record and compared with what the simulated device holds, I&M1 written and read back, the
// device's refusals in words (unknown slot, a read-only record, a wrong length), the PROFIdrive
// parameter channel kept for the master, a device out of data exchange, and no allocation while
// records travel.
#include <gtest/gtest.h>

#include <array>
#include <vector>

#include "core/record_address.hpp"
#include "tests/profinet_bus/bus_harness.hpp"
#include "tests/support/alloc_counter.hpp"

namespace drivegate::profinet::test {
namespace {

core::ParamRequest record_request(PnHarness& h, const std::string& axis, std::string_view address) {
  const core::ParsedRecordAddress parsed = core::parse_record_address(address);
  if (!parsed.address) throw std::invalid_argument(parsed.error);
  core::ParamRequest r;
  r.id = h.next_id++;
  r.axis = h.axis(axis);
  r.record = *parsed.address;
  r.type = core::ParamType::OctetString;  // as the daemon sends a record without --type
  return r;
}

core::ParamRequest record_write(PnHarness& h, const std::string& axis, std::string_view address,
                                std::span<const std::uint8_t> bytes) {
  core::ParamRequest r = record_request(h, axis, address);
  r.write = true;
  r.size = static_cast<std::uint16_t>(bytes.size());
  std::copy(bytes.begin(), bytes.end(), r.data.begin());
  return r;
}

core::ParamReply exchange(PnHarness& h, const core::ParamRequest& r) {
  EXPECT_TRUE(h.runner->push_parameter(r));
  core::ParamReply reply;
  EXPECT_TRUE(h.run_until([&] { return h.runner->pop_parameter_reply(reply); }, 3s)) << "no reply";
  EXPECT_EQ(reply.id, r.id);
  return reply;
}

std::vector<std::uint8_t> bytes_of(const core::ParamReply& r) { return {r.bytes().begin(), r.bytes().end()}; }

// What the simulated device answers itself for a read of the record.
std::vector<std::uint8_t> held(PnPersona& p, std::uint16_t slot, std::uint16_t subslot, std::uint16_t index) {
  RecordReqHeader q;
  q.type = block_type::kReadReqHeader;
  q.slot = slot;
  q.subslot = subslot;
  q.index = index;
  std::array<std::uint8_t, 256> buf{};
  std::size_t n = 0;
  EXPECT_TRUE(p.read_record(q, buf, n).ok());
  return {buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n)};
}

TEST(ProfinetBusRecords, ReadsIm0OfTheDapAsTheDeviceHoldsIt) {
  PnHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details();
  const core::ParamReply r = exchange(h, record_request(h, "x", "rec:0:1:0xAFF0"));
  ASSERT_TRUE(r.ok) << r.error.view();
  EXPECT_EQ(r.type, core::ParamType::OctetString);
  EXPECT_EQ(r.axis, h.axis("x"));
  EXPECT_EQ(bytes_of(r), held(*h.sim->akd_x, 0, 1, record_index::kIm0));
  const Im0View v = decode_im0(r.bytes());
  ASSERT_EQ(v.error, WireError::None);
  EXPECT_EQ(v.im0.order_id, "AKD-P00306-NBPN-0000");
  EXPECT_EQ(v.im0.serial_number, "SIM0000001");
  // The telegram submodule's I&M0 in API 3A00h: the API the configuration gives slot 1 by default.
  const core::ParamReply t = exchange(h, record_request(h, "y", "rec:1:1:0xAFF0"));
  ASSERT_TRUE(t.ok) << t.error.view();
  EXPECT_EQ(decode_im0(t.bytes()).im0.profile_id, 0x3A00);
}

TEST(ProfinetBusRecords, WritesI_M1AndReadsItBack) {
  PnHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details();
  std::array<std::uint8_t, kIm1Size> tags{};
  ASSERT_EQ(encode_im1({"conveyor 3 drive", "hall B"}, tags), kIm1Size);
  const core::ParamReply w = exchange(h, record_write(h, "y", "rec:0:1:0xAFF1@0", tags));
  ASSERT_TRUE(w.ok) << w.error.view();
  EXPECT_EQ(bytes_of(w), std::vector<std::uint8_t>(tags.begin(), tags.end()));  // what was written
  EXPECT_EQ(held(*h.sim->akd_y, 0, 1, record_index::kIm1), std::vector<std::uint8_t>(tags.begin(), tags.end()));
  const core::ParamReply r = exchange(h, record_request(h, "y", "rec:0:1:0xAFF1"));
  ASSERT_TRUE(r.ok) << r.error.view();
  EXPECT_EQ(bytes_of(r), std::vector<std::uint8_t>(tags.begin(), tags.end()));
  EXPECT_EQ(decode_im1(r.bytes()).im1.tag_location, "hall B");
  // The other drive's tags were not touched.
  EXPECT_NE(held(*h.sim->akd_x, 0, 1, record_index::kIm1), std::vector<std::uint8_t>(tags.begin(), tags.end()));
  // The drive keeps running its PNU exchanges next to it: its axis stays up.
  EXPECT_TRUE(h.all_up()) << h.details();
}

TEST(ProfinetBusRecords, RefusalsComeBackInWords) {
  PnHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details();
  // No slot 5: the device's PNIORW error, decoded, with its PNIOStatus as the code.
  core::ParamReply r = exchange(h, record_request(h, "x", "rec:5:1:0xAFF0"));
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.error.view().find("station \"akd-x\""), std::string_view::npos) << r.error.view();
  EXPECT_NE(r.error.view().find("invalid slot"), std::string_view::npos) << r.error.view();
  EXPECT_EQ(r.error_code, 0xDE80B200U);
  // I&M0 is read-only.
  std::array<std::uint8_t, kIm0Size> im0{};
  r = exchange(h, record_write(h, "x", "rec:0:1:0xAFF0", im0));
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.error.view().find("access denied"), std::string_view::npos) << r.error.view();
  EXPECT_EQ(r.error_code, 0xDF80B600U);
  // I&M1 of the wrong length.
  const std::array<std::uint8_t, 3> short_tags{1, 2, 3};
  r = exchange(h, record_write(h, "x", "rec:0:1:0xAFF1", short_tags));
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.error.view().find("write length error"), std::string_view::npos) << r.error.view();
  // Record 47 of the telegram is the master's parameter channel: refused before it goes out.
  const std::array<std::uint8_t, 4> request{1, 1, 1, 0};
  r = exchange(h, record_write(h, "y", "rec:1:1:47", request));
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.error.view().find("PROFIdrive parameter channel"), std::string_view::npos) << r.error.view();
  EXPECT_TRUE(h.all_up()) << h.details();
}

TEST(ProfinetBusRecords, ReadsARecordOfAnIoDevice) {
  PnHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details();
  core::ParamRequest q = record_request(h, "x", "rec:1:1:0xAFF0");
  q.axis = core::kNoAxis;
  q.record.io = 0;  // "panel"
  const core::ParamReply r = exchange(h, q);
  ASSERT_TRUE(r.ok) << r.error.view();
  EXPECT_EQ(r.axis, core::kNoAxis);
  EXPECT_EQ(bytes_of(r), held(*h.sim->io, 1, 1, record_index::kIm0));
  EXPECT_EQ(decode_im0(r.bytes()).im0.order_id, "IO-1");
  // The generic device has no record 0x1234: its refusal in words.
  q.id = h.next_id++;
  q.record.index = 0x1234;
  const core::ParamReply no = exchange(h, q);
  EXPECT_FALSE(no.ok);
  EXPECT_NE(no.error.view().find("station \"io-block\": IODReadRes PNIORW"), std::string_view::npos) << no.error.view();
  EXPECT_NE(no.error.view().find("invalid index"), std::string_view::npos) << no.error.view();
  // An IO device the bus does not have.
  q.id = h.next_id++;
  q.record.io = 1;
  const core::ParamReply unknown = exchange(h, q);
  EXPECT_FALSE(unknown.ok);
  EXPECT_EQ(unknown.error.view(), "no such axis or IO device on this bus");
}

TEST(ProfinetBusRecords, DeviceOutOfDataExchangeIsNamed) {
  PnHarness h;
  // Before the device is found: refused at once, with where the station stands.
  const core::ParamReply r = exchange(h, record_request(h, "x", "rec:0:1:0xAFF0"));
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.error.view().find("station \"akd-x\" is not in data exchange"), std::string_view::npos) << r.error.view();
}

TEST(ProfinetBusRecords, NoAllocationWhileRecordsTravel) {
  PnHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details();
  h.run_for(100ms);  // the I&M0 read of the connect is done
  const core::ParamRequest reads[] = {record_request(h, "x", "rec:0:1:0xAFF0"), record_request(h, "y", "rec:0:1:0xAFF0"),
                                      record_request(h, "x", "rec:9:1:0xAFF0")};
  std::size_t replies = 0, ok = 0;
  core::ParamReply reply;
  {
    const drivegate::test::AllocationScope scope;
    for (const auto& q : reads) ASSERT_TRUE(h.runner->push_parameter(q));
    for (int i = 0; i < 500 && replies < 3; ++i) {
      h.now += 1ms;
      h.runner->cycle(h.now);
      while (h.runner->pop_parameter_reply(reply)) {
        ++replies;
        ok += reply.ok ? 1 : 0;
      }
    }
    EXPECT_EQ(scope.count(), 0U);
  }
  EXPECT_EQ(replies, 3U);
  EXPECT_EQ(ok, 2U);
}

}  // namespace
}  // namespace drivegate::profinet::test
