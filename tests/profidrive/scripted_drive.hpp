#pragma once
// A small scripted PROFIdrive drive for the master tests: the AKD's general state machine driven by
// STW1 [akd-profinet-profidrive.md §7, §8], speed mode [§15], MDI, program mode, homing and
// real-time jog with their handshakes [§16], the fault buffer [§18.2] and a record-47 parameter
// manager answering with the profile's response encoder [§5]. Motion is a counter that moves a
// fixed step per cycle. Knobs inject what a real drive does wrong. The full AKD model lives in
// profiles/profidrive/sim; this one is only what the tests need, and it allocates nothing after
// construction (the no-allocation test runs it inside the measured scope).
#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdlib>
#include <initializer_list>
#include <span>
#include <string_view>
#include <vector>

#include "profiles/profidrive/control_words.hpp"
#include "profiles/profidrive/fault_buffer.hpp"
#include "profiles/profidrive/param_access.hpp"
#include "profiles/profidrive/param_channel.hpp"
#include "profiles/profidrive/telegram.hpp"
#include "profiles/profidrive/telegram_port.hpp"

namespace drivegate::profidrive::test {

class ScriptedDrive final : public TelegramPort, public ParamChannel {
 public:
  enum class State : std::uint8_t { S1, S2, S3, S4, S5Off1, S5Off3, Fault };

  struct Pnu {
    std::uint16_t pnu = 0;
    std::uint8_t format = format::kWord;
    std::uint32_t value = 0;
    bool writable = true;
  };

  explicit ScriptedDrive(std::uint16_t telegram)
      : layout(*standard_layout(telegram)), setpoint_(layout.setpoint_bytes()), actual_(layout.actual_bytes()) {
    publish();
  }

  // --- Knobs and observations ---
  TelegramLayout layout;
  bool valid = true;             // actual() empty when false
  bool fresh = true;             // actual_fresh()
  bool short_actual = false;     // actual() one byte short of the telegram
  bool stuck_in_s1 = false;      // never leaves S1 (STO, hardware enable off)
  bool refuse_tasks = false;     // MDI/program edges are not acknowledged (ZSW1 bit 12 stays 0)
  bool program_without_ack = false;  // program mode shows AKTSATZ and bit 14 only, never bit 12
  bool fault_persists = false;   // the fault acknowledge does not clear the fault
  bool ignores_stw1 = false;     // local control: STW1 changes nothing (ZSW1 bit 9 low)
  bool warning = false;
  int param_delay = 2;           // cycles before a response is ready
  bool param_hang = false;       // responses never become ready
  bool param_rpc_fails = false;  // the record exchange fails
  bool param_wrong_reference = false;
  bool param_garbage = false;    // a 3-byte response
  int stop_cycles = 5;           // S5 ramps
  int home_cycles = 5;
  std::int32_t move_step = 100;     // counts per cycle
  std::int16_t speed_step = 40;     // NSOLL_A units per cycle
  std::int32_t jog_step = 10;
  std::array<std::int32_t, 4> block_targets{1000, 2000, 3000, 4000};  // configured motion tasks 0..3
  std::array<Pnu, 6> pnus{{{1002, format::kWord, 16, true},
                           {1004, format::kWord, 0, true},
                           {930, format::kWord, 2, true},
                           {2157, format::kDWord, 9, false},
                           {2135, format::kByte, 2, true},
                           {3022, format::kDWord, 100, false}}};

  State state = State::S1;
  Setpoints last{};         // the controller's setpoints as the drive read them last
  std::int32_t position = 0;
  std::int16_t speed = 0;
  bool homed = false;
  bool ack = false;
  bool moving = false;
  bool homing = false;
  std::int32_t target = 0;
  std::uint16_t aktsatz = 0;
  std::uint16_t fault_counter = 0;
  std::array<std::uint16_t, kFaultBufferEntries> fault_buffer{};
  int requests = 0;
  int cancels = 0;
  int control_lost_calls = 0;
  std::array<std::uint8_t, kMaxParamRecord> last_request{};
  std::size_t last_request_size = 0;

  // A new fault situation with these fault numbers [§18.2].
  void raise_fault(std::initializer_list<std::uint16_t> numbers) {
    std::fill(fault_buffer.begin(), fault_buffer.begin() + kFaultsPerSituation, std::uint16_t{0});
    std::size_t i = 0;
    for (auto n : numbers) fault_buffer[i++] = n;
    ++fault_counter;
    state = State::Fault;
    stop_motion();
    publish();
  }
  // STW1 as the drive took it at its last step.
  [[nodiscard]] std::uint16_t stw1() const { return last.stw1; }
  // The setpoints the master wrote in its last update (the drive takes them at its next step).
  [[nodiscard]] Setpoints sent() const {
    Setpoints sp;
    (void)decode_setpoints(layout, setpoint_, sp);
    return sp;
  }
  [[nodiscard]] const Pnu* find(std::uint16_t pnu) const {
    for (const auto& p : pnus) {
      if (p.pnu == pnu) return &p;
    }
    return nullptr;
  }

  // The drive's cycle: take the setpoints the controller wrote last, react, publish the actuals.
  void step() {
    if (delay_left_ > 0) --delay_left_;
    Setpoints sp = last;
    if (decode_setpoints(layout, setpoint_, sp) != TelegramError::None) return;
    const std::uint16_t prev = last.stw1;
    last = sp;
    if ((sp.stw1 & stw1::kControlByPlc) != 0 && !ignores_stw1) run_state_machine(sp.stw1, prev);  // bit 10 [§8.1]
    if (state == State::S4 || state == State::S5Off1 || state == State::S5Off3)
      run_motion(sp, prev);
    else
      stop_motion();
    publish();
  }

  // --- TelegramPort ---
  [[nodiscard]] std::span<const std::uint8_t> actual() const noexcept override {
    if (!valid) return {};
    return std::span<const std::uint8_t>(actual_).first(actual_.size() - (short_actual ? 1 : 0));
  }
  [[nodiscard]] bool actual_fresh() const noexcept override { return fresh; }
  [[nodiscard]] std::span<std::uint8_t> setpoint() noexcept override { return setpoint_; }
  void control_lost(std::string_view /*why*/) noexcept override { ++control_lost_calls; }

  // --- ParamChannel ---
  ParamTicket submit(std::span<const std::uint8_t> request) noexcept override {
    if (pending_ != kNoTicket || request.size() > last_request.size()) return kNoTicket;
    std::copy(request.begin(), request.end(), last_request.begin());
    last_request_size = request.size();
    pending_ = ++tickets_;
    delay_left_ = param_delay;
    ++requests;
    return pending_;
  }
  ParamResult poll(ParamTicket ticket) noexcept override {
    if (ticket == kNoTicket || ticket != pending_) return {};
    if (param_hang || delay_left_ > 0) return {ParamState::Pending, {}, {}};
    pending_ = kNoTicket;
    if (param_rpc_fails) return {ParamState::Failed, {}, "IODReadReq timed out"};
    if (param_garbage) return {ParamState::Done, std::span<const std::uint8_t>(response_).first(3), {}};
    return {ParamState::Done, std::span<const std::uint8_t>(response_).first(answer()), {}};
  }
  void cancel(ParamTicket ticket) noexcept override {
    if (ticket != kNoTicket && ticket == pending_) pending_ = kNoTicket;
    ++cancels;
  }

 private:
  void run_state_machine(std::uint16_t w, std::uint16_t prev) {
    const bool on = (w & stw1::kOn) != 0;
    const bool no_coast = (w & stw1::kNoCoastStop) != 0;
    const bool no_quick = (w & stw1::kNoQuickStop) != 0;
    const bool ack_edge = (w & stw1::kFaultAcknowledge) != 0 && (prev & stw1::kFaultAcknowledge) == 0;
    switch (state) {
      case State::Fault:
        // Acknowledged on the 0->1 edge of bit 7; the AKD lands in S1 [§18.2, §25.17].
        if (ack_edge && !fault_persists) {
          std::copy_backward(fault_buffer.begin(), fault_buffer.end() - kFaultsPerSituation, fault_buffer.end());
          std::fill(fault_buffer.begin(), fault_buffer.begin() + kFaultsPerSituation, std::uint16_t{0});
          state = State::S1;
        }
        return;
      case State::S1:
        if (!stuck_in_s1 && !on && no_coast && no_quick) state = State::S2;
        return;
      case State::S2:
        if (!no_coast || !no_quick) state = State::S1;
        else if (on) state = State::S3;
        return;
      case State::S3:
        if (!no_coast || !no_quick) state = State::S1;
        else if (!on) state = State::S2;
        else if ((w & stw1::kEnableOperation) != 0) state = State::S4;
        return;
      case State::S4:
        if (!no_coast) {
          state = State::S1;
        } else if (!no_quick) {
          state = State::S5Off3;
          stop_left_ = stop_cycles;
        } else if (!on) {
          state = State::S5Off1;
          stop_left_ = stop_cycles;
        } else if ((w & stw1::kEnableOperation) == 0) {
          state = State::S3;
        }
        return;
      case State::S5Off1:
      case State::S5Off3:
        if (!no_coast || --stop_left_ <= 0) state = state == State::S5Off1 && no_coast ? State::S2 : State::S1;
        return;
    }
  }

  void stop_motion() {
    speed = 0;
    moving = false;
    homing = false;
    jogging_ = false;
    ack = false;
  }

  void run_motion(const Setpoints& sp, std::uint16_t prev) {
    const std::uint16_t w = state == State::S4 ? sp.stw1 : 0;  // S5 ramps everything down
    if (layout.carries(Signal::NsollA)) {
      // Speed mode [§8.2]: bits 4..6 run the ramp to NSOLL_A; bit 6 low ramps to 0, bit 4 low stops.
      std::int16_t goal = (w & stw1::kEnableSetpoint) != 0 ? sp.nsoll_a : std::int16_t{0};
      if ((w & stw1::kEnableRampGenerator) == 0) speed = 0;
      if ((w & stw1::kUnfreezeRampGenerator) == 0) goal = speed;
      const int diff = goal - speed;
      speed = static_cast<std::int16_t>(speed + std::clamp(diff, -static_cast<int>(speed_step), static_cast<int>(speed_step)));
      position += speed;
      return;
    }
    // Homing: bit 11 level; bits 10, 11, 13 are 0 while it runs [§16.4].
    if ((w & stw1::kStartHoming) != 0) {
      if (!homing && !home_latch_) {
        homing = true;
        homed = false;
        home_left_ = home_cycles;
      }
      if (homing && --home_left_ <= 0) {
        homing = false;
        homed = true;
        home_latch_ = true;
        position = sp.home_dist;
        reached_ = true;
      }
    } else {
      homing = false;  // cleared while running: aborted, not homed
      home_latch_ = false;
    }
    // Task start on the bit 6 edge with bits 4 and 5 [§16.2, §16.3]; bit 12 follows bit 6.
    const bool edge = (w & stw1::kActivateTask) != 0 && (prev & stw1::kActivateTask) == 0;
    const bool run_bits = (w & (stw1::kDoNotRejectTask | stw1::kNoIntermediateStop)) ==
                          (stw1::kDoNotRejectTask | stw1::kNoIntermediateStop);
    if (edge && run_bits && homed && !refuse_tasks) {
      if ((sp.satzanw & 0x8000U) != 0) {
        target = (sp.mdi_mod & 1U) != 0 ? sp.mdi_tarpos : position + sp.mdi_tarpos;
        start_task(sp.satzanw);
      } else if (sp.satzanw < block_targets.size()) {
        target = block_targets[sp.satzanw];
        start_task(sp.satzanw);
      }
    }
    if ((w & stw1::kActivateTask) == 0) ack = false;
    if ((w & stw1::kDoNotRejectTask) == 0) moving = false;  // task rejected: stop
    paused_ = (w & stw1::kNoIntermediateStop) == 0;
    if (moving && !paused_) {
      const std::int32_t d = target - position;
      position += std::clamp(d, -move_step, move_step);
      if (position == target) {
        moving = false;
        reached_ = true;
      }
    }
    // Real-time jog with MDI_VELOCITY, direction bit 13 [§16.5].
    jogging_ = (w & stw1::kRealTimeJog) != 0 && sp.mdi_velocity != 0;
    if (jogging_) position += (w & stw1::kRealTimeJogCcw) != 0 ? -jog_step : jog_step;
  }

  void start_task(std::uint16_t satzanw) {
    moving = true;
    reached_ = false;
    ack = (satzanw & 0x8000U) != 0 || !program_without_ack;
    aktsatz = satzanw;
  }

  std::uint16_t zsw1() const {
    std::uint16_t z = ignores_stw1 ? std::uint16_t{0} : zsw1::kControlRequested;
    switch (state) {
      case State::S1:
        z |= zsw1::kSwitchingOnInhibited;
        if ((last.stw1 & stw1::kNoCoastStop) != 0) z |= zsw1::kNoCoastStop;
        if ((last.stw1 & stw1::kNoQuickStop) != 0) z |= zsw1::kNoQuickStop;
        break;
      case State::S2: z |= 0x0031; break;
      case State::S3: z |= 0x0033; break;
      case State::S4:
      case State::S5Off1: z |= 0x0037; break;  // 0x0237 [§9.4]; an OFF1 ramp shows as S4
      case State::S5Off3: z |= 0x0017; break;  // bit 5 low: quick stop
      case State::Fault: z |= zsw1::kFault | 0x0030; break;
    }
    if (warning) z |= zsw1::kWarning;
    if (state == State::S4 || state == State::S5Off1 || state == State::S5Off3) {
      if (layout.carries(Signal::NsollA)) {
        if (speed == (last.stw1 & stw1::kEnableSetpoint ? last.nsoll_a : 0)) z |= zsw1::kSpeedReached;
      } else {
        const bool still = (!moving || paused_) && !homing && !jogging_;
        if (!homing && homed) z |= zsw1::kHomed;
        if (!homing && still && reached_) z |= zsw1::kTargetReached;
        if (!homing && still) z |= zsw1::kDriveStopped;
        if (ack) z |= zsw1::kTaskAcknowledge;
        if (moving) z |= zsw1::kMotionTaskActive;
      }
    } else if (!layout.carries(Signal::NsollA)) {
      z |= zsw1::kDriveStopped;
      if (homed) z |= zsw1::kHomed;
    }
    return z;
  }

  void publish() {
    Actuals a;
    a.zsw1 = zsw1();
    a.nist_a = speed;
    a.xist_a = position;
    a.aktsatz = aktsatz;
    a.itist_glatt = static_cast<std::int16_t>(speed == 0 ? 0 : -182);  // §17.4
    (void)encode_actuals(layout, a, actual_);
  }

  // The parameter manager: one parameter per request, as the master sends them.
  std::size_t answer() noexcept {
    const RequestResult req = decode_param_request(std::span<const std::uint8_t>(last_request).first(last_request_size));
    ParamResponse r;
    r.reference = static_cast<std::uint8_t>(req.request.reference + (param_wrong_reference ? 1 : 0));
    r.count = 1;
    r.block_count = 1;
    const ParamAddress& a = req.request.params[0];
    const bool change = req.request.id == RequestId::Change;
    const auto fail = [&](std::uint16_t error) {
      r.response_id = change ? response_id::kChangeFailed : response_id::kReadFailed;
      data_[0] = 0;
      data_[1] = static_cast<std::uint8_t>(error);
      r.blocks[0] = ValueBlock{format::kError, 1, std::span<const std::uint8_t>(data_).first(2)};
    };
    const auto words = [&](std::span<const std::uint16_t> values) {
      r.response_id = response_id::kReadOk;
      for (std::size_t i = 0; i < values.size(); ++i) {
        data_[2 * i] = static_cast<std::uint8_t>(values[i] >> 8);
        data_[2 * i + 1] = static_cast<std::uint8_t>(values[i]);
      }
      r.blocks[0] = ValueBlock{format::kWord, static_cast<std::uint8_t>(values.size()),
                               std::span<const std::uint8_t>(data_).first(2 * values.size())};
    };
    if (req.error != ParamError::None || req.request.count != 1) {
      fail(0x16);
    } else if (a.pnu == kPnuFaultCounter && !change) {
      const std::array<std::uint16_t, 1> v{fault_counter};
      words(v);
    } else if (a.pnu == kPnuFaultNumbers && !change) {
      if (a.subindex + a.elements > fault_buffer.size()) fail(0x03);
      else words(std::span<const std::uint16_t>(fault_buffer).subspan(a.subindex, a.elements));
    } else {
      Pnu* p = nullptr;
      for (auto& e : pnus) {
        if (e.pnu == a.pnu) p = &e;
      }
      if (p == nullptr) {
        fail(0x00);  // impermissible parameter number [§5.4]
      } else if (change) {
        if (!p->writable) {
          fail(0x01);
        } else {
          p->value = req.request.values[0].value(0);
          // The AKD's positive change reply carries "00 00" after the header [§5.3].
          r.response_id = response_id::kChangeOk;
          r.blocks[0] = ValueBlock{format::kAkdNone, 0, {}};
        }
      } else {
        r.response_id = response_id::kReadOk;
        const std::size_t n = format_size(p->format);
        for (std::size_t i = 0; i < n; ++i) data_[i] = static_cast<std::uint8_t>(p->value >> (8 * (n - 1 - i)));
        r.blocks[0] = ValueBlock{p->format, 1, std::span<const std::uint8_t>(data_).first(n)};
      }
    }
    const EncodeResult e = encode_param_response(response_, r);
    return e.error == ParamError::None ? e.size : 0;
  }

  std::vector<std::uint8_t> setpoint_;
  std::vector<std::uint8_t> actual_;
  int stop_left_ = 0;
  int home_left_ = 0;
  bool home_latch_ = false;
  bool reached_ = false;
  bool jogging_ = false;
  bool paused_ = false;
  ParamTicket pending_ = kNoTicket;
  ParamTicket tickets_ = 0;
  int delay_left_ = 0;
  std::array<std::uint8_t, 2 * kFaultBufferEntries> data_{};
  std::array<std::uint8_t, kMaxParamRecord> response_{};
};

}  // namespace drivegate::profidrive::test
