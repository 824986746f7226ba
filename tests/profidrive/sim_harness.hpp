#pragma once
// Drives the simulated AKD PROFIdrive drive the way the PROFINET device will: the setpoint image
// built with the controller-side encoder, the actual image read back with its decoder.
#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "profiles/profidrive/control_words.hpp"
#include "profiles/profidrive/param_access.hpp"
#include "profiles/profidrive/sim/drive_model.hpp"
#include "profiles/profidrive/telegram.hpp"

namespace drivegate::profidrive::sim::test {

using namespace std::chrono_literals;
using Bytes = std::vector<std::uint8_t>;

class Harness {
 public:
  explicit Harness(const DriveModelConfig& config, core::Duration cycle = 1ms) : drive(config), cycle_(cycle) {}

  // One cycle with `sp` (re-encoded with the drive's current layout).
  void cycle() {
    const TelegramLayout& l = drive.layout();
    out_.fill(0);
    ASSERT_EQ(encode_setpoints(l, sp, std::span(out_).first(l.setpoint_bytes())), TelegramError::None);
    drive.step(cycle_, std::span(out_).first(l.setpoint_bytes()), std::span(in_).first(l.actual_bytes()));
    ASSERT_EQ(decode_actuals(l, std::span(in_).first(l.actual_bytes()), act), TelegramError::None);
  }
  void cycles(int n) {
    for (int i = 0; i < n; ++i) cycle();
  }
  // Cycles until `done` holds, at most `max`; false when it never did.
  bool until(const std::function<bool()>& done, int max = 20000) {
    for (int i = 0; i < max; ++i) {
      cycle();
      if (done()) return true;
    }
    return false;
  }
  // STW1 `word`, one cycle.
  void send(std::uint16_t word) {
    sp.stw1 = word;
    cycle();
  }
  // The §20.2 walk to S4 with `mode_bits` on every word.
  void enable(std::uint16_t mode_bits = 0) {
    for (const std::uint16_t w : {stw1_word::kIdle, stw1_word::kShutdown, stw1_word::kSwitchOn, stw1_word::kEnableOperation})
      send(static_cast<std::uint16_t>(w | mode_bits));
    ASSERT_EQ(drive.state(), State::S4Operation);
  }
  [[nodiscard]] std::span<const std::uint8_t> actual_image() const {
    return std::span(in_).first(drive.layout().actual_bytes());
  }

  // Record 47: write `request`, read the response.
  Bytes parameter(std::span<const std::uint8_t> request) {
    EXPECT_EQ(drive.write_parameter_record(request), RecordStatus::Ok);
    std::array<std::uint8_t, kMaxParamRecord> buf{};
    const RecordRead r = drive.read_parameter_record(buf);
    EXPECT_EQ(r.status, RecordStatus::Ok);
    return Bytes(buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(r.size));
  }
  // Change one parameter; the decoded response.
  ParamResponse change(std::uint16_t pnu, std::uint8_t fmt, std::uint32_t value, std::uint16_t subindex = 0) {
    const std::array<std::uint32_t, 1> values{value};
    const std::array<ParamChange, 1> p{ParamChange{{Attribute::Value, 1, pnu, subindex}, fmt, values}};
    std::array<std::uint8_t, kMaxParamRecord> buf{};
    const EncodeResult e = encode_change_request(buf, 0x11, p);
    EXPECT_EQ(e.error, ParamError::None);
    return decode(parameter(std::span(buf).first(e.size)));
  }
  // Read `elements` of one parameter; the decoded response.
  ParamResponse read(std::uint16_t pnu, std::uint8_t elements = 1, std::uint16_t subindex = 0) {
    const std::array<ParamAddress, 1> p{ParamAddress{Attribute::Value, elements, pnu, subindex}};
    std::array<std::uint8_t, kMaxParamRecord> buf{};
    const EncodeResult e = encode_read_request(buf, 0x12, p);
    EXPECT_EQ(e.error, ParamError::None);
    return decode(parameter(std::span(buf).first(e.size)));
  }
  // The value of a one-element read (nullopt-like 0xFFFFFFFF on an error).
  std::uint32_t value(std::uint16_t pnu) {
    const ParamResponse r = read(pnu);
    if (!r.positive() || r.block_count != 1) return 0xFFFFFFFF;
    return r.blocks[0].value(0);
  }

  DriveModel drive;
  Setpoints sp;
  Actuals act;

 private:
  ParamResponse decode(const Bytes& bytes) {
    last_ = bytes;  // the views point into it
    const ResponseResult r = decode_param_response(last_);
    EXPECT_EQ(r.error, ParamError::None) << to_string(r.error);
    return r.response;
  }

  core::Duration cycle_;
  std::array<std::uint8_t, 2 * kMaxTelegramWords> out_{};
  std::array<std::uint8_t, 2 * kMaxTelegramWords> in_{};
  Bytes last_;
};

inline DriveModelConfig config_for(std::uint16_t telegram) {
  DriveModelConfig c;
  c.telegram = telegram;
  return c;
}

}  // namespace drivegate::profidrive::sim::test
