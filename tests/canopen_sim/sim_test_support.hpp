#pragma once
// Helpers for the simulated-drive tests: a SlaveNode driven frame by frame in virtual time, the
// reference personas with the device profiles' settings written out by hand, and byte-exact frame
// checks.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <initializer_list>
#include <optional>
#include <string>
#include <vector>

#include "adapters/canopen/master/tx_queue.hpp"
#include "adapters/canopen/sim/persona.hpp"
#include "adapters/canopen/sim/slave_config.hpp"
#include "adapters/canopen/sim/slave_node.hpp"
#include "adapters/canopen/wire/can_frame.hpp"
#include "adapters/canopen/wire/cob_id.hpp"
#include "adapters/canopen/wire/nmt_codec.hpp"
#include "adapters/canopen/wire/sdo_codec.hpp"
#include "config/plan.hpp"
#include "core/clock.hpp"

namespace drivegate::canopen::sim::test {

using namespace std::chrono_literals;
using cia402::DataType;
using cia402::ObjectId;

// Virtual time starts away from 0 so that "never" and "at start" differ.
inline constexpr core::TimePoint kT0 = core::TimePoint{std::chrono::seconds(1000)};

inline std::vector<CanFrame> drain(TxQueue& tx) {
  std::vector<CanFrame> out;
  for (; !tx.empty(); tx.pop()) out.push_back(tx.front());
  return out;
}

inline ::testing::AssertionResult is_frame(const CanFrame& f, std::uint32_t id, std::initializer_list<std::uint8_t> bytes) {
  if (f.id != id || f.extended || f.remote || f.dlc != bytes.size()) {
    return ::testing::AssertionFailure() << std::hex << "frame " << f.id << " dlc " << int{f.dlc} << (f.remote ? " RTR" : "")
                                         << ", expected " << id << " dlc " << bytes.size();
  }
  std::size_t i = 0;
  for (const auto b : bytes) {
    if (f.data[i] != b) {
      return ::testing::AssertionFailure() << std::hex << "frame " << f.id << " byte " << i << " is " << int{f.data[i]}
                                           << ", expected " << int{b};
    }
    ++i;
  }
  return ::testing::AssertionSuccess();
}

inline std::vector<CanFrame> on_id(const std::vector<CanFrame>& frames, std::uint32_t id) {
  std::vector<CanFrame> out;
  for (const auto& f : frames) {
    if (f.id == id) out.push_back(f);
  }
  return out;
}

inline CanFrame nmt(NmtCommand c, NodeId node) { return make_frame(cob::kNmt, encode_nmt(c, node)); }
inline CanFrame sync_frame() { return make_frame(cob::kSync, std::initializer_list<std::uint8_t>{}); }
inline CanFrame rtr(std::uint32_t id) {
  CanFrame f;
  f.id = id;
  f.remote = true;
  f.dlc = 1;
  return f;
}

// --- Drive model settings and PDO maps of the reference device profiles ------------------------

inline cia402::sim::DriveModelConfig drive_with_modes(std::vector<std::int8_t> modes) {
  cia402::sim::DriveModelConfig c;
  c.supported_modes = std::move(modes);
  return c;
}

inline config::PdoEntrySpec entry(std::uint16_t index, std::uint8_t sub, DataType type) {
  return {{index, sub}, static_cast<std::uint8_t>(8 * cia402::size_of(type)), type};
}

inline config::PdoSpec pdo(int number, int type, std::vector<config::PdoEntrySpec> entries) {
  config::PdoSpec p;
  p.number = number;
  p.transmission_type = type;
  p.entries = std::move(entries);
  return p;
}

// profiles/devices/stoeber-sd6.yaml: RPDO1/2, TPDO1/2, type 1.
inline std::vector<config::PdoSpec> sd6_rpdos() {
  return {pdo(1, 1, {entry(0x6040, 0, DataType::U16), entry(0x6060, 0, DataType::I8), entry(0x607A, 0, DataType::I32)}),
          pdo(2, 1, {entry(0x60FF, 0, DataType::I32), entry(0x6081, 0, DataType::U32)})};
}
inline std::vector<config::PdoSpec> sd6_tpdos() {
  return {pdo(1, 1, {entry(0x6041, 0, DataType::U16), entry(0x6061, 0, DataType::I8), entry(0x6064, 0, DataType::I32)}),
          pdo(2, 1, {entry(0x606C, 0, DataType::I32)})};
}

// The drives of the reference personas, with the modes of their device profiles.
inline SlaveNodeConfig akd(NodeId node = 1) {
  return make_slave_config(node, persona_for("akd"), drive_with_modes({1, 3, 4, 6, 7, 8}));
}
inline SlaveNodeConfig nord(NodeId node = 0x20) {
  return make_slave_config(node, persona_for("nord-sk500p"), drive_with_modes({1, 2, 3, 4, 6}));
}
inline SlaveNodeConfig sd6(NodeId node = 5) {
  const auto r = sd6_rpdos();
  const auto t = sd6_tpdos();
  return make_slave_config(node, persona_for("stoeber-sd6"), drive_with_modes({1, 3, 6}), r, t);
}
inline SlaveNodeConfig generic(NodeId node = 1) {
  const std::vector<config::PdoSpec> r{pdo(1, 1, {entry(0x6040, 0, DataType::U16), entry(0x6060, 0, DataType::I8)})};
  const std::vector<config::PdoSpec> t{pdo(1, 1, {entry(0x6041, 0, DataType::U16), entry(0x6061, 0, DataType::I8)})};
  return make_slave_config(node, persona_for("generic"), cia402::sim::DriveModelConfig{}, r, t);
}

// --- One node in virtual time ------------------------------------------------------------------

struct SdoReply {
  std::uint32_t abort = 0;  // 0: the transfer succeeded
  std::uint32_t value = 0;
  CanFrame frame{};
};

class Drive {
 public:
  explicit Drive(SlaveNodeConfig config) : node(std::move(config)) {}

  // The first step: the boot-up and whatever else is due.
  std::vector<CanFrame> boot() { return step(); }

  std::vector<CanFrame> step() {
    node.step(now, tx_);
    return drain(tx_);
  }
  // Advance in 1 ms steps, collecting what the node sends.
  std::vector<CanFrame> run(core::Duration d) {
    std::vector<CanFrame> out;
    for (const auto end = now + d; now < end;) {
      now += 1ms;
      const auto got = step();
      out.insert(out.end(), got.begin(), got.end());
    }
    return out;
  }
  // A frame from the bus, then one step at the same time.
  std::vector<CanFrame> send(const CanFrame& f) {
    node.on_frame(f, now);
    return step();
  }

  SdoReply sdo(const SdoBytes& request, int channel = 1) {
    const auto frames = send(make_frame(cob::sdo_rx(channel, node.node()), request));
    const auto replies = on_id(frames, cob::sdo_tx(channel, node.node()));
    SdoReply r;
    if (replies.size() != 1) {
      ADD_FAILURE() << "expected one SDO reply, got " << replies.size();
      r.abort = 0xFFFFFFFF;
      return r;
    }
    r.frame = replies.front();
    const auto d = decode_sdo_response(r.frame.payload());
    if (d.error != SdoDecodeError::None) {
      ADD_FAILURE() << "undecodable SDO reply";
      r.abort = 0xFFFFFFFF;
    } else if (d.message.command == SdoCommand::Abort) {
      r.abort = d.message.abort_code;
    } else {
      r.value = get_le(d.message.data, 0, 4);
    }
    return r;
  }
  SdoReply read(ObjectId o, int channel = 1) { return sdo(sdo_upload_request(o), channel); }
  std::uint32_t write(ObjectId o, std::uint32_t value, std::uint8_t size) {
    return sdo(sdo_download_expedited(o, value, size)).abort;
  }
  // A value the test needs: fails the test on an abort.
  std::uint32_t value(ObjectId o) {
    const auto r = read(o);
    EXPECT_EQ(r.abort, 0U) << std::hex << "reading " << o.index << ":" << int{o.sub};
    return r.value;
  }
  std::uint16_t statusword() { return static_cast<std::uint16_t>(value({0x6041, 0})); }
  // Controlword by SDO, then a few model steps for the state machine to follow.
  void controlword(std::uint16_t cw, core::Duration settle = 5ms) {
    EXPECT_EQ(write({0x6040, 0}, cw, 2), 0U);
    run(settle);
  }
  // Shutdown, switch on, enable operation.
  void enable() {
    controlword(0x06);
    controlword(0x07);
    controlword(0x0F);
  }

  SlaveNode node;
  core::TimePoint now = kT0;

 private:
  TxQueue tx_;
};

}  // namespace drivegate::canopen::sim::test
