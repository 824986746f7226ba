// SocketCAN: what can be tested without CAN in the kernel (the build machines have none): the
// open() message, and the pure pieces (filters, frame mapping, error frames, time stamps).
#include <gtest/gtest.h>

#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <string>

#include "adapters/canopen/transport/socketcan_transport.hpp"
#include "tests/support/alloc_counter.hpp"

namespace drivegate::canopen {
namespace {

using namespace std::chrono_literals;

bool kernel_has_can() {
  const int fd = ::socket(PF_CAN, SOCK_RAW, CAN_RAW);
  if (fd < 0) return false;
  ::close(fd);
  return true;
}

std::string open_error(SocketCanTransport& t) {
  try {
    t.open();
  } catch (const TransportError& e) {
    return e.what();
  }
  return "";
}

TEST(SocketCan, OpenSaysWhatIsMissingInOneLine) {
  if (!kernel_has_can()) {
    SocketCanTransport t(SocketCanOptions{.interface = "can0", .bitrate = 500000, .filters = {}});
    EXPECT_EQ(open_error(t),
              "socketcan: this kernel has no CAN support (socket(AF_CAN): Address family not supported by protocol); "
              "load the can and can_raw modules, or use transport udp-multicast (a virtual bus) or sim");
    EXPECT_FALSE(t.is_open());
    EXPECT_EQ(t.wait_fd(), -1);
  } else {  // a machine with CAN: the interface is what is missing
    SocketCanTransport t(SocketCanOptions{.interface = "dgnocan9", .bitrate = 250000, .filters = {}});
    const auto e = open_error(t);
    EXPECT_EQ(e.rfind("socketcan: no CAN interface 'dgnocan9' (", 0), 0U) << e;
    EXPECT_NE(e.find("ip link set dgnocan9 up type can bitrate 250000"), std::string::npos) << e;
    EXPECT_EQ(e.find('\n'), std::string::npos);
  }
}

TEST(SocketCan, ClosedTransportRefusesQuietlyWithoutAllocating) {
  SocketCanTransport t(SocketCanOptions{});
  std::array<CanFrame, 4> buf{};
  const auto f = make_frame(0x181, {1, 2});
  test::AllocationScope scope;
  const auto sent = t.send(f, core::TimePoint{});
  const auto got = t.receive(buf, core::TimePoint{});
  EXPECT_EQ(scope.count(), 0U);
  EXPECT_EQ(sent, SendResult::Down);
  EXPECT_EQ(got, 0U);
  EXPECT_EQ(t.controller_state(), ControllerState::Active);
  EXPECT_EQ(t.describe(), "socketcan can0 @ 500 kbit/s");
}

TEST(SocketCan, FiltersMatchIdAndFormatButNotRtr) {
  const CanIdFilter in[] = {
      {.id = 0x181, .mask = 0x7FF, .extended = false},      // one TPDO1
      {.id = 0x580, .mask = 0x780, .extended = false},      // every SDO response
      {.id = 0x18FF0000, .mask = 0x1FFF0000, .extended = true},
  };
  const auto k = build_can_filters(in);
  ASSERT_EQ(k.size(), 3U);
  EXPECT_EQ(k[0].can_id, 0x181U);
  EXPECT_EQ(k[0].can_mask, 0x7FFU | CAN_EFF_FLAG);  // a base-format filter refuses extended frames
  EXPECT_EQ(k[1].can_id, 0x580U);
  EXPECT_EQ(k[1].can_mask, 0x780U | CAN_EFF_FLAG);
  EXPECT_EQ(k[2].can_id, 0x18FF0000U | CAN_EFF_FLAG);
  EXPECT_EQ(k[2].can_mask, 0x1FFF0000U | CAN_EFF_FLAG);
  for (const auto& f : k) EXPECT_EQ(f.can_mask & CAN_RTR_FLAG, 0U);  // remote frames pass too
  // The kernel's rule: (received_id & mask) == (can_id & mask).
  const auto passes = [](const can_filter& f, canid_t id) { return (id & f.can_mask) == (f.can_id & f.can_mask); };
  EXPECT_TRUE(passes(k[1], 0x5FF));
  EXPECT_TRUE(passes(k[1], 0x581 | CAN_RTR_FLAG));
  EXPECT_FALSE(passes(k[1], 0x601));
  EXPECT_FALSE(passes(k[1], 0x581 | CAN_EFF_FLAG));
  EXPECT_TRUE(passes(k[2], 0x18FF1234 | CAN_EFF_FLAG));
  EXPECT_FALSE(passes(k[2], 0x18FE1234 | CAN_EFF_FLAG));

  EXPECT_TRUE(build_can_filters({}).empty());
  const CanIdFilter too_big[] = {{.id = 0x800, .mask = 0x7FF, .extended = false}};
  try {
    build_can_filters(too_big);
    FAIL() << "no error";
  } catch (const TransportError& e) {
    EXPECT_STREQ(e.what(), "socketcan: receive filter 800h/7FFh is outside the 11-bit identifier range");
  }
  const CanIdFilter bad_mask[] = {{.id = 0x1, .mask = 0x3FFFFFFF, .extended = true}};
  EXPECT_THROW(build_can_filters(bad_mask), TransportError);
}

TEST(SocketCan, FramesMapBothWaysWithExtendedAndRtr) {
  CanFrame f = make_frame(0x1ABCDE0, {1, 2, 3});
  f.extended = true;
  can_frame k = to_linux_frame(f);
  EXPECT_EQ(k.can_id, 0x1ABCDE0U | CAN_EFF_FLAG);
  EXPECT_EQ(k.len, 3);
  EXPECT_EQ(k.data[2], 3);
  CanFrame back;
  ASSERT_TRUE(from_linux_frame(k, back));
  EXPECT_EQ(back.id, 0x1ABCDE0U);
  EXPECT_TRUE(back.extended);
  EXPECT_FALSE(back.remote);
  EXPECT_EQ(back.dlc, 3);
  EXPECT_EQ(back.data[0], 1);

  CanFrame r;
  r.id = 0x705;
  r.remote = true;
  r.dlc = 1;
  k = to_linux_frame(r);
  EXPECT_EQ(k.can_id, 0x705U | CAN_RTR_FLAG);
  EXPECT_EQ(k.len, 1);
  ASSERT_TRUE(from_linux_frame(k, back));
  EXPECT_TRUE(back.remote);
  EXPECT_FALSE(back.extended);
  EXPECT_EQ(back.id, 0x705U);
  EXPECT_EQ(back.dlc, 1);

  can_frame bad{};
  bad.can_id = 0x181;
  bad.len = 9;
  EXPECT_FALSE(from_linux_frame(bad, back));
  bad.len = 2;
  bad.can_id = CAN_ERR_FLAG | CAN_ERR_BUSOFF;
  EXPECT_FALSE(from_linux_frame(bad, back));
  // A base-format id keeps only its 11 bits even if the kernel left others set.
  bad.can_id = 0xFFFF;
  ASSERT_TRUE(from_linux_frame(bad, back));
  EXPECT_EQ(back.id, 0x7FFU);
}

TEST(SocketCan, ErrorFramesTellTheControllerState) {
  std::array<std::uint8_t, 8> data{};
  auto decode = [&](std::uint32_t id, std::uint8_t crtl) {
    data[1] = crtl;
    return decode_error_frame(id, data);
  };
  auto e = decode(CAN_ERR_BUSOFF, 0);
  EXPECT_EQ(e.state, ControllerState::BusOff);
  EXPECT_FALSE(e.restarted);
  e = decode(CAN_ERR_CRTL, CAN_ERR_CRTL_TX_PASSIVE);
  EXPECT_EQ(e.state, ControllerState::Passive);
  e = decode(CAN_ERR_CRTL, CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_RX_WARNING);
  EXPECT_EQ(e.state, ControllerState::Passive);  // the worse of the two
  e = decode(CAN_ERR_CRTL, CAN_ERR_CRTL_TX_WARNING);
  EXPECT_EQ(e.state, ControllerState::Warning);
  e = decode(CAN_ERR_CRTL, CAN_ERR_CRTL_RX_WARNING);
  EXPECT_EQ(e.state, ControllerState::Warning);
  e = decode(CAN_ERR_CRTL, CAN_ERR_CRTL_ACTIVE);
  EXPECT_EQ(e.state, ControllerState::Active);
  EXPECT_FALSE(e.restarted);
  e = decode(CAN_ERR_RESTARTED, 0);
  EXPECT_EQ(e.state, ControllerState::Active);
  EXPECT_TRUE(e.restarted);
  // Reports that say nothing about the state: overflow, protocol violation, no ACK.
  EXPECT_FALSE(decode(CAN_ERR_CRTL, CAN_ERR_CRTL_RX_OVERFLOW).state.has_value());
  EXPECT_FALSE(decode(CAN_ERR_PROT | CAN_ERR_ACK, 0).state.has_value());
  // Bus-off outranks whatever else the same frame reports.
  EXPECT_EQ(decode(CAN_ERR_BUSOFF | CAN_ERR_CRTL, CAN_ERR_CRTL_TX_PASSIVE).state, ControllerState::BusOff);
  // Controller bits without their data byte are ignored, not read past the end.
  EXPECT_FALSE(decode_error_frame(CAN_ERR_CRTL, std::span<const std::uint8_t>(data.data(), 1)).state.has_value());
}

TEST(SocketCan, TrackerCountsBusOffAndRestarts) {
  CounterCells cells;
  ControllerTracker t;
  t.report({ControllerState::Warning, false}, cells);
  t.report({ControllerState::Passive, false}, cells);
  t.report({ControllerState::BusOff, false}, cells);
  t.report({ControllerState::BusOff, false}, cells);  // still bus-off: not a second transition
  EXPECT_EQ(t.state(), ControllerState::BusOff);
  t.report({std::nullopt, false}, cells);  // e.g. a protocol error: state unchanged
  EXPECT_EQ(t.state(), ControllerState::BusOff);
  t.report({ControllerState::Active, true}, cells);
  EXPECT_EQ(t.state(), ControllerState::Active);
  // Recovery seen only as a state (CRTL_ACTIVE, no RESTARTED frame) is a restart too.
  t.report({ControllerState::BusOff, false}, cells);
  t.report({ControllerState::Active, false}, cells);
  const auto c = cells.snapshot();
  EXPECT_EQ(c.error_frames, 8U);
  EXPECT_EQ(c.bus_off, 2U);
  EXPECT_EQ(c.restarts, 2U);
}

TEST(SocketCan, KernelStampsBecomeAgesOnTheCallersTimeLine) {
  const core::TimePoint now = core::TimePoint{} + 100s;
  const timespec realtime{1'700'000'000, 500'000'000};
  EXPECT_EQ(reception_time(now, realtime, timespec{1'700'000'000, 499'750'000}), now - 250us);
  EXPECT_EQ(reception_time(now, realtime, timespec{1'699'999'999, 900'000'000}), now - 600ms);
  EXPECT_EQ(reception_time(now, realtime, realtime), now);
  // A stamp ahead of the clock (it was stepped back): no negative age.
  EXPECT_EQ(reception_time(now, realtime, timespec{1'700'000'001, 0}), now);
}

TEST(SocketCan, PurePiecesAllocateNothing) {
  std::array<std::uint8_t, 8> data{0, CAN_ERR_CRTL_TX_PASSIVE};
  CanFrame f = make_frame(0x181, {1, 2, 3});
  CanFrame back;
  int passive = 0;
  test::AllocationScope scope;
  for (int i = 0; i < 100; ++i) {
    const auto k = to_linux_frame(f);
    passive += from_linux_frame(k, back) ? 0 : 1;
    passive += decode_error_frame(CAN_ERR_CRTL, data).state == ControllerState::Passive ? 1 : 0;
  }
  EXPECT_EQ(scope.count(), 0U);
  EXPECT_EQ(passive, 100);
}

}  // namespace
}  // namespace drivegate::canopen
