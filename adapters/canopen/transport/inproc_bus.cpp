#include "adapters/canopen/transport/inproc_bus.hpp"

#include <algorithm>
#include <stdexcept>
#include <vector>

#include "adapters/canopen/transport/controller_tracker.hpp"
#include "adapters/canopen/transport/counter_cells.hpp"
#include "adapters/canopen/wire/bit_timing.hpp"

namespace drivegate::canopen {
namespace {

constexpr std::size_t kMaxHooks = 16;

// A fixed-capacity FIFO over storage allocated once.
template <typename T>
class Ring {
 public:
  void allocate(std::size_t capacity) { items_.assign(capacity, T{}); }
  bool push(const T& v) noexcept {
    if (size_ == items_.size()) return false;
    items_[(head_ + size_) % items_.size()] = v;
    ++size_;
    return true;
  }
  [[nodiscard]] const T& front() const noexcept { return items_[head_]; }
  void pop() noexcept {
    head_ = (head_ + 1) % items_.size();
    --size_;
  }
  [[nodiscard]] std::size_t size() const noexcept { return size_; }
  [[nodiscard]] bool empty() const noexcept { return size_ == 0; }
  void clear() noexcept { head_ = size_ = 0; }

 private:
  std::vector<T> items_;
  std::size_t head_ = 0;
  std::size_t size_ = 0;
};

// The arbitration field as the bits go on the wire, dominant (0) first, packed so that the
// numerically lower key wins: base id (11), RTR or SRR (1), IDE (1), id extension (18), RTR (1).
// SRR and IDE are recessive in an extended frame, so a base frame with the same 11 leading bits
// wins; the RTR bit is recessive, so a data frame beats a remote frame of the same id.
constexpr std::uint32_t arbitration_key(const CanFrame& f) noexcept {
  if (!f.extended) return (f.id << 21) | (f.remote ? 1U << 20 : 0U);
  return ((f.id >> 18) << 21) | (1U << 20) | (1U << 19) | ((f.id & 0x3FFFFU) << 1) | (f.remote ? 1U : 0U);
}
static_assert(arbitration_key(CanFrame{.id = 0x100}) < arbitration_key(CanFrame{.id = 0x100, .remote = true}));
static_assert(arbitration_key(CanFrame{.id = 0x100}) < arbitration_key(CanFrame{.id = 0x100U << 18, .extended = true}));
static_assert(arbitration_key(CanFrame{.id = 0x0FFU << 18, .extended = true}) < arbitration_key(CanFrame{.id = 0x100}));

}  // namespace

struct InprocBus::Slot {
  struct Queued {
    CanFrame frame;
    core::TimePoint at;  // when send() queued it
  };
  bool open = false;
  std::size_t tx_limit = 0;
  Ring<Queued> tx;
  Ring<CanFrame> rx;
  CounterCells counters;
  ControllerTracker controller;
  [[nodiscard]] bool bus_off() const noexcept { return controller.state() == ControllerState::BusOff; }
};

struct InprocBus::Hook {
  std::uint32_t id = 0;
  std::size_t remaining = 0;
  bool drop = false;
  Corruption how;
};

struct InprocBus::Transmission {
  bool active = false;
  std::size_t sender = 0;
  CanFrame frame;
  core::TimePoint start{};
  core::TimePoint end{};
};

InprocBus::InprocBus(std::uint32_t bitrate, InprocBusOptions options)
    : bitrate_(bitrate),
      options_(options),
      slots_(std::make_unique<Slot[]>(options.max_endpoints)),
      hooks_(std::make_unique<Hook[]>(kMaxHooks)),
      wire_(std::make_unique<Transmission>()) {}

InprocBus::~InprocBus() = default;

std::unique_ptr<InprocEndpoint> InprocBus::connect() {
  if (slot_count_ == options_.max_endpoints) {
    throw std::length_error("inproc bus: all " + std::to_string(options_.max_endpoints) + " endpoints are taken");
  }
  Slot& s = slots_[slot_count_];
  s.tx.allocate(options_.tx_queue_capacity);
  s.rx.allocate(options_.rx_queue_capacity);
  s.tx_limit = options_.tx_queue_capacity;
  return std::unique_ptr<InprocEndpoint>(new InprocEndpoint(*this, slot_count_++));
}

void InprocBus::advance(core::TimePoint now) noexcept {
  now = std::max(now, last_now_);
  last_now_ = now;
  for (;;) {
    if (wire_->active) {
      if (wire_->end > now) return;
      finish();
    }
    if (!start_next(now)) return;
  }
}

bool InprocBus::start_next(core::TimePoint now) noexcept {
  // The medium is free from free_since_; the next transmission starts when it is free and a frame
  // is waiting, among the frames waiting by then. A bus-off controller has nothing queued.
  bool any = false;
  core::TimePoint first{};
  for (std::size_t i = 0; i < slot_count_; ++i) {
    const Slot& s = slots_[i];
    if (s.tx.empty()) continue;
    if (!any || s.tx.front().at < first) first = s.tx.front().at;
    any = true;
  }
  if (!any) return false;
  const core::TimePoint start = std::max(free_since_, first);
  // Frames sent at `start` itself may still be coming (same instant, later call): wait until time
  // has moved past it. An instant bus has no arbitration window to wait for.
  if (bitrate_ != 0 ? start >= now : start > now) return false;

  std::size_t winner = slot_count_;
  std::uint32_t best = 0;
  for (std::size_t i = 0; i < slot_count_; ++i) {
    const Slot& s = slots_[i];
    if (s.tx.empty() || s.tx.front().at > start) continue;
    const auto key = arbitration_key(s.tx.front().frame);
    if (winner == slot_count_ || key < best) {
      winner = i;
      best = key;
    }
  }
  Slot& s = slots_[winner];
  Transmission& w = *wire_;
  w.active = true;
  w.sender = winner;
  w.frame = s.tx.front().frame;
  s.tx.pop();
  w.start = start;
  w.end = start + frame_time(w.frame.dlc, bitrate_, w.frame.extended, w.frame.remote);
  if (w.start >= window_start_) window_busy_ += w.end - w.start;
  return true;
}

void InprocBus::finish() noexcept {
  Transmission& w = *wire_;
  w.active = false;
  free_since_ = w.end;
  ++stats_.frames;
  stats_.busy += w.end - w.start;
  CanFrame f = w.frame;
  f.timestamp = w.end;
  for (std::size_t h = 0; h < kMaxHooks; ++h) {
    Hook& hook = hooks_[h];
    if (hook.remaining == 0 || hook.id != f.id) continue;
    --hook.remaining;
    if (hook.drop) {
      ++stats_.dropped;
      return;
    }
    for (std::size_t i = 0; i < f.data.size(); ++i) f.data[i] ^= hook.how.xor_mask[i];
    if (hook.how.dlc) f.dlc = *hook.how.dlc;
    ++stats_.corrupted;
    break;
  }
  for (std::size_t i = 0; i < slot_count_; ++i) {
    Slot& s = slots_[i];
    if (i == w.sender || !s.open || s.bus_off()) continue;
    if (!s.rx.push(f)) ++stats_.rx_overruns;
  }
}

SendResult InprocBus::enqueue(std::size_t slot, const CanFrame& frame, core::TimePoint now) noexcept {
  Slot& s = slots_[slot];
  if (!s.open || s.bus_off()) return SendResult::Down;
  if (!frame.valid()) return SendResult::Invalid;
  advance(now);  // frames that have left by now make room in the queue
  if (s.tx.size() >= s.tx_limit) {
    s.counters.tx_overflows.add();
    return SendResult::Busy;
  }
  s.tx.push({frame, last_now_});
  s.counters.tx_frames.add();
  if (bitrate_ == 0) advance(now);
  return SendResult::Sent;
}

std::size_t InprocBus::take(std::size_t slot, std::span<CanFrame> out, core::TimePoint now) noexcept {
  advance(now);
  Slot& s = slots_[slot];
  std::size_t n = 0;
  while (n < out.size() && !s.rx.empty()) {
    out[n++] = s.rx.front();
    s.rx.pop();
  }
  s.counters.rx_frames.add(n);
  return n;
}

void InprocBus::set_tx_queue_limit(const InprocEndpoint& endpoint, std::size_t limit) noexcept {
  slots_[endpoint.index()].tx_limit = std::min(limit, options_.tx_queue_capacity);
}

void InprocBus::set_bus_off(const InprocEndpoint& endpoint, bool bus_off) noexcept {
  Slot& s = slots_[endpoint.index()];
  if (s.bus_off() == bus_off) return;
  if (bus_off) {
    // A controller that goes bus-off abandons its pending transmissions (the kernel flushes them).
    stats_.flushed += s.tx.size();
    s.tx.clear();
    s.controller.report({ControllerState::BusOff, false}, s.counters);
  } else {
    s.controller.report({ControllerState::Active, true}, s.counters);
  }
}

void InprocBus::add_hook(std::uint32_t id, std::size_t count, bool drop, const Corruption& how) {
  for (std::size_t h = 0; h < kMaxHooks; ++h) {
    if (hooks_[h].remaining != 0) continue;
    hooks_[h] = Hook{id, count, drop, how};
    return;
  }
  throw std::length_error("inproc bus: more than 16 drop/corrupt hooks pending");
}

void InprocBus::drop_next(std::uint32_t id, std::size_t count) { add_hook(id, count, true, {}); }

void InprocBus::corrupt_next(std::uint32_t id, std::size_t count, Corruption how) {
  if (how.dlc && *how.dlc > kMaxDlc) throw std::invalid_argument("inproc bus: a corrupted dlc must be 0..8");
  add_hook(id, count, false, how);
}

InprocBusStats InprocBus::stats() const noexcept { return stats_; }

void InprocBus::start_load_window(core::TimePoint now) noexcept {
  advance(now);
  window_start_ = last_now_;
  // The frame on the wire counts from the window start on.
  window_busy_ = wire_->active ? wire_->end - window_start_ : core::Duration::zero();
}

double InprocBus::load(core::TimePoint now) noexcept {
  advance(now);
  const auto elapsed = last_now_ - window_start_;
  if (elapsed <= core::Duration::zero()) return 0.0;
  auto busy = window_busy_;
  if (wire_->active) busy -= wire_->end - last_now_;  // the part still to come
  return static_cast<double>(busy.count()) / static_cast<double>(elapsed.count());
}

bool InprocBus::idle() const noexcept {
  if (wire_->active) return false;
  for (std::size_t i = 0; i < slot_count_; ++i) {
    if (!slots_[i].tx.empty()) return false;
  }
  return true;
}

core::TimePoint InprocBus::next_change() const noexcept {
  if (wire_->active) return wire_->end;
  core::TimePoint first = core::TimePoint::max();
  for (std::size_t i = 0; i < slot_count_; ++i) {
    if (!slots_[i].tx.empty()) first = std::min(first, slots_[i].tx.front().at);
  }
  if (first == core::TimePoint::max()) return first;
  // start_next() starts a transmission once time has moved past its start.
  return std::max(free_since_, first) + (bitrate_ != 0 ? core::Duration{1} : core::Duration::zero());
}

// --- InprocEndpoint ----------------------------------------------------------------------------

InprocEndpoint::~InprocEndpoint() { close(); }

void InprocEndpoint::open() { bus_->slots_[index_].open = true; }

void InprocEndpoint::close() noexcept {
  auto& s = bus_->slots_[index_];
  s.open = false;
  s.tx.clear();
  s.rx.clear();
}

bool InprocEndpoint::is_open() const noexcept { return bus_->slots_[index_].open; }

std::size_t InprocEndpoint::available() const noexcept { return bus_->slots_[index_].rx.size(); }

std::size_t InprocEndpoint::receive(std::span<CanFrame> out, core::TimePoint now) noexcept {
  return bus_->take(index_, out, now);
}

SendResult InprocEndpoint::send(const CanFrame& frame, core::TimePoint now) noexcept {
  return bus_->enqueue(index_, frame, now);
}

ControllerState InprocEndpoint::controller_state() const noexcept { return bus_->slots_[index_].controller.state(); }

TransportCounters InprocEndpoint::counters() const noexcept { return bus_->slots_[index_].counters.snapshot(); }

std::string InprocEndpoint::describe() const {
  const auto rate = bus_->bitrate_;
  return "inproc bus " + (rate == 0 ? std::string("(instant)") : "@ " + std::to_string(rate / 1000) + " kbit/s") +
         ", endpoint " + std::to_string(index_);
}

}  // namespace drivegate::canopen
