// Faults, state-change events and the drive changing state on its own.
#include <gtest/gtest.h>

#include <array>

#include "tests/cia402/master_harness.hpp"

namespace drivegate::cia402::test {
namespace {

using core::CommandKind;
using core::EventKind;

// The first event of `kind` (an Info event with code 0xFFFFFFFF when there is none).
RecordingSink::Ev find_event(const RecordingSink& s, EventKind kind) {
  for (const auto& e : s.events) {
    if (e.kind == kind) return e;
  }
  return {EventKind::Info, 0xFFFFFFFFU, {}};
}

TEST(Faults, MappedErrorCodeIsReportedWithItsText) {
  Harness h;
  h.enable();
  auto c = command(7, CommandKind::Move);
  ASSERT_TRUE(h.submit(c).accepted);
  h.cycle(kSwEnabled);
  h.io.set(obj::kErrorCode.id, 0x8611);
  h.cycle(kSwFault);
  EXPECT_EQ(h.sink.failure(7), "drive fault 0x8611: following error");
  const auto ev = find_event(h.sink, EventKind::Fault);
  EXPECT_EQ(ev.code, 0x8611U);
  EXPECT_EQ(ev.text, "following error");
  EXPECT_EQ(h.master.feedback().fault_code, 0x8611U);
  EXPECT_EQ(h.master.feedback().fault_text.view(), "following error");
  EXPECT_EQ(h.cw(), 0x0000);  // never re-enables by itself after a reset
}

TEST(Faults, UnmappedErrorCodeIsReadOnceAcyclically) {
  Harness h;
  h.io.unmap(obj::kErrorCode.id);
  h.io.set(obj::kErrorCode.id, 0x3210);
  h.io.set_latency(2);
  h.cycle(kSwSwitchOnDisabled);
  h.cycle(kSwFault);
  EXPECT_EQ(h.sink.count(EventKind::Fault), 0U);
  h.cycle(kSwFault);
  h.cycle(kSwFault);
  h.cycle(kSwFault);
  ASSERT_EQ(h.sink.count(EventKind::Fault), 1U);
  EXPECT_EQ(find_event(h.sink, EventKind::Fault).text, "DC link overvoltage");
  EXPECT_EQ(h.io.acyclic_reads(), 1U);
}

TEST(Faults, DriveWithout603FStillReportsTheFault) {
  Harness h;
  h.io.unmap(obj::kErrorCode.id);
  h.io.abort_on(obj::kErrorCode.id, 0x06020000);  // NORD digest §9: no 603Fh
  h.io.set_latency(1);
  h.cycle(kSwFault);
  h.cycle(kSwFault);
  ASSERT_EQ(h.sink.count(EventKind::Fault), 1U);
  const auto ev = find_event(h.sink, EventKind::Fault);
  EXPECT_EQ(ev.code, 0U);
  EXPECT_EQ(ev.text, "drive fault (603Fh unreadable: object does not exist in the object dictionary)");
}

// A bus with its own fault channel (CANopen EMCY) gives code and text; 603Fh is not read.
TEST(Faults, DriveReportedFaultWinsOverReading603F) {
  Harness h;
  h.io.unmap(obj::kErrorCode.id);
  h.io.set_latency(3);
  h.cycle(kSwSwitchOnDisabled);
  h.cycle(kSwFault);  // 603Fh read submitted
  EXPECT_EQ(h.io.acyclic_reads(), 1U);
  h.io.set_fault_report({true, 0x7500, "0x7500 Communication (event 52, cause 1)"});
  h.cycle(kSwFault);
  ASSERT_EQ(h.sink.count(EventKind::Fault), 1U);
  EXPECT_EQ(find_event(h.sink, EventKind::Fault).code, 0x7500U);
  EXPECT_EQ(h.master.feedback().fault_text.view(), "0x7500 Communication (event 52, cause 1)");
  EXPECT_EQ(h.io.pending_requests(), 0U);  // the 603Fh read was cancelled
}

TEST(Faults, VendorTextsComeFirst) {
  Harness h;
  const std::array table = {FaultText{0xFF00, "F501 bus overvoltage"}};
  h.master.set_fault_table(table);
  h.io.set(obj::kErrorCode.id, 0xFF00);
  h.cycle(kSwFault);
  EXPECT_EQ(find_event(h.sink, EventKind::Fault).text, "F501 bus overvoltage");
}

TEST(Faults, StateChangedOnEveryChangeAndWarningEdges) {
  Harness h;
  h.enable();
  EXPECT_EQ(h.sink.count(EventKind::StateChanged), 4U);  // disabled, ready, switched on, enabled
  h.cycle(kSwEnabled | 0x0080);
  h.cycle(kSwEnabled | 0x0080);
  h.cycle(kSwEnabled);
  EXPECT_EQ(h.sink.count(EventKind::Warning), 2U);
  EXPECT_TRUE(h.sink.events.back().kind == EventKind::Warning && h.sink.events.back().code == 0U);
}

TEST(Faults, LosingOperationEnabledOnItsOwnFailsMotion) {
  Harness h;
  h.enable();
  auto c = command(7, CommandKind::Move);
  ASSERT_TRUE(h.submit(c).accepted);
  h.cycle(kSwEnabled);
  EXPECT_EQ(h.cycle(kSwSwitchOnDisabled), 0x0000);  // hardware enable lost
  EXPECT_EQ(h.sink.failure(7), "drive left operation enabled on its own (now switch_on_disabled): hardware enable lost?");
}

TEST(Faults, FaultDuringEnableFailsIt) {
  Harness h;
  h.cycle(kSwSwitchOnDisabled);
  ASSERT_TRUE(h.submit(command(1, CommandKind::Enable)).accepted);
  h.cycle(kSwSwitchOnDisabled);
  h.cycle(kSwFault);
  EXPECT_EQ(h.sink.failure(1).rfind("drive fault 0x", 0), 0U) << h.sink.failure(1);
}

TEST(Faults, MotionRejectedInFault) {
  Harness h;
  h.cycle(kSwFault);
  const auto a = h.submit(command(7, CommandKind::Move));
  EXPECT_FALSE(a.accepted);
  EXPECT_EQ(a.reason.view(), "axis is in fault: send fault_reset first");
}

}  // namespace
}  // namespace drivegate::cia402::test
