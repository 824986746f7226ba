#pragma once
// A one-slave line with the CoE test slave (adapters/ethercat/sim/coe_test_slave.hpp: 128-byte
// mailboxes at 1000h/1080h, 2 output and 2 input bytes at 1100h/1180h) and mailbox helpers for the
// tests.
#include <gtest/gtest.h>

#include <vector>

#include "adapters/ethercat/sim/coe_test_slave.hpp"
#include "adapters/ethercat/sim/object_dictionary.hpp"
#include "tests/ethercat_sim/harness.hpp"

namespace drivegate::ethercat::sim::test {

using coe_test::CoeApp;
using coe_test::kIn;
using coe_test::kMbxIn;
using coe_test::kMbxOut;
using coe_test::kMbxSize;
using coe_test::kOut;

inline std::vector<std::uint8_t> coe_sii() {
  std::vector<std::uint8_t> image = coe_test::coe_sii();
  EXPECT_FALSE(image.empty());  // build_sii took the profile
  return image;
}

struct CoeLine {
  CoeLine() : sii(coe_sii()), esc(EscConfig{}, sii, &app) {
    bus.line().add(esc);
    bus.assign_addresses(1);
  }
  void mailbox_sms() {
    bus.write_sm(st, 0, SmEntry{kMbxOut, kMbxSize, sm_control::kMailboxOut, 0, 1, 0});
    bus.write_sm(st, 1, SmEntry{kMbxIn, kMbxSize, sm_control::kMailboxIn, 0, 1, 0});
  }
  void preop() {
    mailbox_sms();
    ASSERT_EQ(bus.request(st, AlState::PreOp), 0x0002);
  }
  // Writes a whole mailbox into SM0 (the full SM length, so the last byte is written).
  std::uint16_t put(std::span<const std::uint8_t> msg) {
    std::array<std::uint8_t, kMbxSize> box{};
    std::copy(msg.begin(), msg.end(), box.begin());
    return bus.fpwr(st, kMbxOut, box).wkc;
  }
  // Polls SM1 status for "mailbox full", then reads SM1. Empty optional reply when nothing came.
  Reply get(int polls = 4) {
    for (int i = 0; i < polls; ++i) {
      const Reply s = bus.fprd(st, reg::sm_status(1), 1);
      if ((s.data[0] & sm_status::kMailboxFull) != 0) return bus.fprd(st, kMbxIn, kMbxSize);
    }
    return Reply{};
  }
  SdoView sdo(std::span<const std::uint8_t> request) {
    EXPECT_EQ(put(request), 1);
    reply = get();
    EXPECT_TRUE(reply.returned);
    return decode_sdo_response(reply.bytes());
  }
  std::uint8_t next() { return counter = next_mailbox_counter(counter); }

  Bus bus;
  CoeApp app;
  std::vector<std::uint8_t> sii;
  EscSlave esc;
  std::uint16_t st = Bus::station(0);
  std::array<std::uint8_t, kMbxSize> req{};
  Reply reply;
  std::uint8_t counter = 0;
};

}  // namespace drivegate::ethercat::sim::test
