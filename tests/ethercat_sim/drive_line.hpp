#pragma once
// A one-slave line with a simulated CiA 402 drive (adapters/ethercat/sim/cia402_slave.hpp) and
// helpers: SDO by hand-built mailboxes, SM setup, one process data cycle as FPWR SM2 + FPRD SM3
// (no FMMUs), EMCYs collected while waiting for SDO answers.
#include <gtest/gtest.h>

#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include "adapters/ethercat/sim/cia402_slave.hpp"
#include "adapters/ethercat/wire/mailbox.hpp"
#include "tests/ethercat_sim/harness.hpp"

namespace drivegate::ethercat::sim::test {

struct Upload {
  std::uint32_t abort = 0;
  std::uint32_t value = 0;
  std::size_t size = 0;
};

struct DriveLine {
  explicit DriveLine(std::string_view persona) : dev(make_cia402_device(persona)) {
    bus.line().add(*dev.esc);
    bus.assign_addresses(1);
    set_time(1'000'000);
  }
  Cia402Slave& app() { return *dev.app; }
  EscSlave& esc() { return *dev.esc; }

  void set_time(std::uint64_t ns) {
    now = ns;
    bus.line().set_time(ns);
  }
  void preop() {
    bus.write_sm(st, 0, SmEntry{kDriveMailboxOut, kDriveMailboxSize, sm_control::kMailboxOut, 0, 1, 0});
    bus.write_sm(st, 1, SmEntry{kDriveMailboxIn, kDriveMailboxSize, sm_control::kMailboxIn, 0, 1, 0});
    ASSERT_EQ(bus.request(st, AlState::PreOp), 0x0002);
  }
  // SM2/SM3 as a master configures them for the mapped sizes (buffered, SM2 with the watchdog
  // trigger: 64h/20h, digest §8.2).
  void pd_sms(std::uint16_t out, std::uint16_t in) {
    bus.write_sm(st, 2, SmEntry{kDriveOutputs, out, sm_control::kOutputs, 0, 1, 0});
    bus.write_sm(st, 3, SmEntry{kDriveInputs, in, sm_control::kInputs, 0, 1, 0});
  }
  std::uint16_t request(AlState s, bool ack = false) { return bus.request(st, s, ack); }
  std::uint16_t al_code() { return bus.fprd(st, reg::kAlStatusCode, 2).u16(); }

  std::uint8_t next() { return counter = next_mailbox_counter(counter); }
  std::uint16_t put(std::span<const std::uint8_t> msg) {
    std::array<std::uint8_t, kDriveMailboxSize> box{};
    std::copy(msg.begin(), msg.end(), box.begin());
    return bus.fpwr(st, kDriveMailboxOut, box).wkc;
  }
  // The next mailbox from SM1 (polling its status); not returned when none came.
  Reply mailbox(int polls = 6) {
    for (int i = 0; i < polls; ++i) {
      const Reply s = bus.fprd(st, reg::sm_status(1), 1);
      if ((s.data[0] & sm_status::kMailboxFull) != 0) return bus.fprd(st, kDriveMailboxIn, kDriveMailboxSize);
    }
    return Reply{};
  }
  static bool is_emergency(const Reply& r) {
    const CoeView c = decode_coe(r.bytes());
    return c.error == MailboxError::None && c.service == static_cast<std::uint8_t>(CoeService::Emergency);
  }
  // Drains SM1 into `emcys` (raw mailboxes) until it is empty.
  void collect_emergencies() {
    for (Reply r = mailbox(); r.returned; r = mailbox()) {
      if (is_emergency(r)) emcys.push_back(r);
    }
  }
  // An SDO request and its answer; emergencies arriving first are kept in `emcys`.
  SdoView sdo(std::span<const std::uint8_t> request) {
    EXPECT_EQ(put(request), 1);
    for (int i = 0; i < 8; ++i) {
      reply = mailbox();
      if (!reply.returned) break;
      if (!is_emergency(reply)) return decode_sdo_response(reply.bytes());
      emcys.push_back(reply);
    }
    ADD_FAILURE() << "no SDO answer";
    return SdoView{};
  }
  // 0 = written, else the abort code.
  std::uint32_t download(std::uint16_t index, std::uint8_t sub, std::uint32_t value, std::size_t size) {
    const std::size_t n = encode_sdo_download_value(req, next(), index, sub, value, size);
    const SdoView v = sdo(std::span(req.data(), n));
    if (v.sdo.command == SdoCommand::Abort) return v.sdo.abort_code;
    EXPECT_EQ(v.sdo.command, SdoCommand::DownloadInitiateResponse);
    return 0;
  }
  Upload upload(std::uint16_t index, std::uint8_t sub) {
    const std::size_t n = encode_sdo_upload_request(req, next(), index, sub);
    const SdoView v = sdo(std::span(req.data(), n));
    if (v.sdo.command == SdoCommand::Abort) return {v.sdo.abort_code, 0, 0};
    Upload u;
    u.size = v.sdo.data.size();
    for (std::size_t k = 0; k < u.size && k < 4; ++k) u.value |= static_cast<std::uint32_t>(v.sdo.data[k]) << (8 * k);
    return u;
  }
  // One cycle `dt_ns` after the previous one: outputs written to SM2, inputs read from SM3.
  Reply cycle(std::span<const std::uint8_t> outputs, std::uint16_t in_len, std::uint64_t dt_ns = 1'000'000) {
    set_time(now + dt_ns);
    if (!outputs.empty()) {
      EXPECT_EQ(bus.fpwr(st, kDriveOutputs, outputs).wkc, 1);
    }
    return bus.fprd(st, kDriveInputs, in_len);
  }

  Bus bus;
  Cia402Device dev;
  std::uint16_t st = Bus::station(0);
  std::uint64_t now = 0;
  std::array<std::uint8_t, kDriveMailboxSize> req{};
  Reply reply;
  std::uint8_t counter = 0;
  std::vector<Reply> emcys;
};

}  // namespace drivegate::ethercat::sim::test
