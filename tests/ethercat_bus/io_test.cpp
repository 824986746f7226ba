// The `io:` slaves as core::Bus I/O slaves (issue 9): the panel of bus_harness.hpp (a simulated
// generic I/O slave, 2 bytes each way, at position 2) read and written through the BusRunner as
// the daemon's control plane does it.
#include <gtest/gtest.h>

#include <array>
#include <vector>

#include "tests/ethercat_bus/bus_harness.hpp"

namespace drivegate::ethercat::test {
namespace {

using core::IoWriteStatus;

core::IoWrite io_write(std::uint64_t id, std::uint16_t slave, std::uint16_t offset, std::vector<std::uint8_t> bytes) {
  core::IoWrite w;
  w.id = id;
  w.slave = slave;
  w.offset = offset;
  w.size = static_cast<std::uint16_t>(bytes.size());
  std::copy(bytes.begin(), bytes.end(), w.data.begin());
  return w;
}

// Pushes the write and runs until its reply.
IoWriteStatus write(EcatHarness& h, const core::IoWrite& w) {
  EXPECT_TRUE(h.runner->push_io_write(w));
  core::IoWriteReply r;
  EXPECT_TRUE(h.run_until([&] { return h.runner->pop_io_reply(r); }, 100ms));
  EXPECT_EQ(r.id, w.id);
  EXPECT_EQ(r.slave, w.slave);
  return r.status;
}

std::vector<std::uint8_t> bytes(const std::array<std::uint8_t, core::kMaxIoBytes>& a, std::size_t n) {
  return {a.begin(), a.begin() + static_cast<std::ptrdiff_t>(n)};
}
std::vector<std::uint8_t> bytes(std::span<const std::uint8_t> s) { return {s.begin(), s.end()}; }

TEST(EthercatBusIo, TheIoSlavesAreListedWithTheirConfiguredSizes) {
  EcatHarness h;
  ASSERT_EQ(h.bus->io_count(), 1U);
  ASSERT_EQ(h.runner->io_count(), 1U);
  const core::IoInfo info = h.bus->io_info(0);
  EXPECT_EQ(info.name, "panel");
  EXPECT_EQ(info.address, 2U);  // position 2 of kLine
  EXPECT_TRUE(info.sized);
  EXPECT_EQ(info.input_size, 2U);
  EXPECT_EQ(info.output_size, 2U);
}

TEST(EthercatBusIo, WritesReachTheSlaveAndItsInputsComeBack) {
  EcatHarness h;
  // Before the line is up: no fresh inputs, writes refused.
  h.cycle();
  EXPECT_FALSE(h.runner->io_snapshot(0).valid);
  EXPECT_EQ(write(h, io_write(1, 0, 0, {0x01})), IoWriteStatus::SlaveLost);
  ASSERT_TRUE(h.run_until([&] { return h.all_up() && h.runner->io_snapshot(0).valid; }, 5s)) << h.details();
  EXPECT_EQ(h.panel_esc->state(), AlState::Op);

  // Outputs zero until written; the slave's inputs in the snapshot.
  h.panel->inputs()[0] = 0xA5;
  h.panel->inputs()[1] = 0x3C;
  h.run_until([] { return false; }, 5ms);
  core::IoSnapshot s = h.runner->io_snapshot(0);
  EXPECT_TRUE(s.valid);
  EXPECT_EQ(s.input_size, 2U);
  EXPECT_EQ(s.output_size, 2U);
  EXPECT_EQ(bytes(s.inputs, 2), (std::vector<std::uint8_t>{0xA5, 0x3C}));
  EXPECT_EQ(bytes(s.outputs, 2), (std::vector<std::uint8_t>{0x00, 0x00}));
  EXPECT_EQ(s.stamp_ns, core::to_ns(h.now));
  EXPECT_EQ(bytes(h.panel->outputs()), (std::vector<std::uint8_t>{0x00, 0x00}));

  // A write of byte 1 reaches the slave's SM2 and the snapshot's outputs; byte 0 stays.
  EXPECT_EQ(write(h, io_write(2, 0, 1, {0x81})), IoWriteStatus::Ok);
  h.run_until([] { return false; }, 5ms);
  EXPECT_EQ(bytes(h.panel->outputs()), (std::vector<std::uint8_t>{0x00, 0x81}));
  EXPECT_EQ(bytes(h.runner->io_snapshot(0).outputs, 2), (std::vector<std::uint8_t>{0x00, 0x81}));
  EXPECT_EQ(write(h, io_write(3, 0, 0, {0x12, 0x34})), IoWriteStatus::Ok);
  h.run_until([] { return false; }, 5ms);
  EXPECT_EQ(bytes(h.panel->outputs()), (std::vector<std::uint8_t>{0x12, 0x34}));

  // Refusals leave the outputs alone.
  EXPECT_EQ(write(h, io_write(4, 0, 1, {0x01, 0x02})), IoWriteStatus::OutOfRange);
  EXPECT_EQ(write(h, io_write(5, 0, 2, {0x01})), IoWriteStatus::OutOfRange);
  EXPECT_EQ(write(h, io_write(6, 0, 0, {})), IoWriteStatus::OutOfRange);
  EXPECT_EQ(write(h, io_write(7, 1, 0, {0x01})), IoWriteStatus::UnknownSlave);
  h.run_until([] { return false; }, 5ms);
  EXPECT_EQ(bytes(h.panel->outputs()), (std::vector<std::uint8_t>{0x12, 0x34}));
}

TEST(EthercatBusIo, ALostSlavesInputsAreStaleWritesRefusedAndItComesBackWithZeroOutputs) {
  EcatHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up() && h.runner->io_snapshot(0).valid; }, 5s)) << h.details();
  h.panel->inputs()[0] = 0x5A;
  ASSERT_EQ(write(h, io_write(1, 0, 0, {0x77, 0x66})), IoWriteStatus::Ok);
  h.run_until([] { return false; }, 5ms);
  EXPECT_EQ(bytes(h.panel->outputs()), (std::vector<std::uint8_t>{0x77, 0x66}));
  h.line->power_off(1);  // the panel (0-based line index 1)
  ASSERT_TRUE(h.run_until([&] { return !h.runner->io_snapshot(0).valid; }, 100ms));
  const core::IoSnapshot s = h.runner->io_snapshot(0);
  EXPECT_EQ(s.inputs[0], 0x5A);  // the last good inputs, marked stale
  h.run_until([] { return false; }, 10ms);  // lost after lost_cycles
  EXPECT_EQ(write(h, io_write(2, 0, 0, {0x01})), IoWriteStatus::SlaveLost);
  EXPECT_EQ(h.bus->link_state(h.axis("esr")), core::LinkState::Operational);  // the drives keep cycling

  // Back: restarted and reconfigured with its outputs zero (ethercat_bus.cpp configure()), then
  // writable again.
  h.line->power_on(1);
  ASSERT_TRUE(h.run_until([&] { return h.runner->io_snapshot(0).valid; }, 5s)) << h.details();
  EXPECT_EQ(h.bus->restarts(1), 1U);
  EXPECT_EQ(bytes(h.runner->io_snapshot(0).outputs, 2), (std::vector<std::uint8_t>{0x00, 0x00}));
  EXPECT_EQ(write(h, io_write(3, 0, 1, {0x42})), IoWriteStatus::Ok);
  h.run_until([] { return false; }, 5ms);
  EXPECT_EQ(bytes(h.panel->outputs()), (std::vector<std::uint8_t>{0x00, 0x42}));
}

}  // namespace
}  // namespace drivegate::ethercat::test
