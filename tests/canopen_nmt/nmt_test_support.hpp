#pragma once
// Helpers for the NMT / error-control / EMCY tests: virtual time points, byte-exact frame checks
// and a tiny in-process wire that runs master and slave engines against each other.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <functional>
#include <initializer_list>
#include <vector>

#include "adapters/canopen/master/tx_queue.hpp"
#include "adapters/canopen/wire/can_frame.hpp"
#include "core/clock.hpp"

namespace drivegate::canopen::test {

using std::chrono::milliseconds;
using std::chrono::nanoseconds;

// Virtual time: t0 is arbitrary but not zero, so "never set" and "at start" differ.
inline constexpr core::TimePoint kT0 = core::TimePoint{std::chrono::seconds(1000)};
inline core::TimePoint at_ms(std::int64_t ms) { return kT0 + milliseconds(ms); }

inline std::vector<CanFrame> drain(TxQueue& tx) {
  std::vector<CanFrame> out;
  while (!tx.empty()) {
    out.push_back(tx.front());
    tx.pop();
  }
  return out;
}

inline CanFrame rtr(std::uint32_t id, std::uint8_t dlc = 1) {
  CanFrame f;
  f.id = id;
  f.remote = true;
  f.dlc = dlc;
  return f;
}

// A data frame with exactly these bytes on this id.
inline ::testing::AssertionResult is_frame(const CanFrame& f, std::uint32_t id, std::initializer_list<std::uint8_t> bytes) {
  if (f.id != id || f.extended || f.remote || f.dlc != bytes.size()) {
    return ::testing::AssertionFailure() << "frame id " << std::hex << f.id << " dlc " << int{f.dlc}
                                         << (f.remote ? " RTR" : "") << ", expected id " << id << " dlc "
                                         << bytes.size();
  }
  std::size_t i = 0;
  for (const auto b : bytes) {
    if (f.data[i] != b) {
      return ::testing::AssertionFailure() << "byte " << i << " is " << std::hex << int{f.data[i]} << ", expected "
                                           << int{b};
    }
    ++i;
  }
  return ::testing::AssertionSuccess();
}

inline ::testing::AssertionResult is_rtr(const CanFrame& f, std::uint32_t id) {
  if (f.id != id || !f.remote || f.dlc != 1 || f.extended) {
    return ::testing::AssertionFailure() << "frame id " << std::hex << f.id << (f.remote ? " RTR" : " data")
                                         << " dlc " << int{f.dlc} << ", expected RTR DLC 1 on " << id;
  }
  return ::testing::AssertionSuccess();
}

// Engines on one bus: every frame any of them queues reaches all the others (not its sender), in
// order, at the time it was queued. Time advances from deadline to deadline.
struct Participant {
  std::function<void(core::TimePoint, TxQueue&)> poll;
  std::function<void(const CanFrame&, core::TimePoint)> on_frame;
  std::function<core::TimePoint()> next_deadline;
  bool alive = true;  // false: powered off (neither polled nor receiving)
};

class Wire {
 public:
  // Returns the index of the participant.
  std::size_t add(Participant p) {
    parts_.push_back(std::move(p));
    return parts_.size() - 1;
  }
  Participant& operator[](std::size_t i) { return parts_[i]; }
  [[nodiscard]] core::TimePoint now() const { return now_; }
  void start(core::TimePoint t) { now_ = t; }
  // Frames seen on the bus so far, with the time they were sent.
  std::vector<std::pair<core::TimePoint, CanFrame>> log;

  // Runs every due poll up to and including `until`.
  void run_until(core::TimePoint until) {
    for (;;) {
      auto next = core::TimePoint::max();
      for (auto& p : parts_) {
        if (p.alive) next = std::min(next, p.next_deadline());
      }
      if (next > until) break;
      now_ = std::max(now_, next);
      for (std::size_t i = 0; i < parts_.size(); ++i) {
        if (!parts_[i].alive) continue;
        TxQueue tx;
        parts_[i].poll(now_, tx);
        deliver(i, tx);
      }
    }
    now_ = until;
  }

 private:
  void deliver(std::size_t from, TxQueue& tx) {
    while (!tx.empty()) {
      const CanFrame f = tx.front();
      tx.pop();
      log.emplace_back(now_, f);
      for (std::size_t j = 0; j < parts_.size(); ++j) {
        if (j != from && parts_[j].alive) parts_[j].on_frame(f, now_);
      }
    }
  }

  std::vector<Participant> parts_;
  core::TimePoint now_{};
};

}  // namespace drivegate::canopen::test
