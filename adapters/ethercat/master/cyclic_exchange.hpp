#pragma once
// The cyclic process data exchange of a line (dunker-ethercat-coe.md "What a master must do",
// steps 6-8 and 11; ETG.1000.4 §5.4 logical commands and working counter):
//
//   queue(tx)     per cycle: optionally one FPRD 0130h (AL status) of one slave, round robin, then
//                 the image's datagrams (one LRW, LWR + LRD, or one per slave, in up to
//                 ProcessImage::kMaxFrames frames: see ProcessImage) with the output image as the
//                 application left it. The caller may queue other datagrams before or after (DC's
//                 FRMW first, mailbox polls); Transactions packs them into the same frames while
//                 they have room, as ProcessImage planned.
//   on_result()   copies the inputs of each datagram that came back with its expected working
//                 counter into the input image (so the input image holds the last good inputs),
//                 and counts the cycle: good, working counter wrong, or lost.
//
// Which slave answered: one LRW's working counter is a sum, so a short one cannot say who is
// missing. Two ways to know per slave:
//   - CyclicDatagrams::PerSlave (ProcessImage option): one datagram per slave, each with its own
//     working counter: exact every cycle, for 12 more bytes per slave in the frame.
//   - al_status_check (default on): one FPRD of AL status 0130h per cycle, round robin over the
//     slaves: a slave that does not answer it (WKC 0), has left SAFE-OP/OP or shows the error bit
//     is Missing. Every slave is checked once in slave_count() cycles; with a short working counter,
//     answered(k) says Missing/Answered from that slave's last check if it is at most
//     slave_count() cycles old, Unknown otherwise. A cycle with the full working counter makes
//     every slave Answered. The check also catches a slave that dropped its state while the
//     counter still looks right (digest step 11: "AL Status (an unsolicited drop ...)").
//
// The output image and the input image are fixed arrays (ProcessImage::kMaxBytes: the data of
// kMaxFrames frames); nothing here allocates. The ProcessImage must outlive the exchange.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "adapters/ethercat/master/process_image.hpp"
#include "adapters/ethercat/master/transactions.hpp"
#include "adapters/ethercat/wire/registers.hpp"

namespace drivegate::ethercat {

struct CyclicOptions {
  bool al_status_check = true;  // one FPRD 0130h per cycle, round robin (2 data bytes, 12 overhead)
};

struct CyclicCounters {
  std::uint64_t cycles = 0;        // queue() calls that queued the image
  std::uint64_t completed = 0;     // cycles whose datagrams all came back or were lost
  std::uint64_t good = 0;          // every datagram back with its expected working counter
  std::uint64_t wkc_errors = 0;    // back, but a working counter differed
  std::uint64_t lost = 0;          // a datagram lost (frame not back), or a cycle overrun
  std::uint64_t refused = 0;       // Transactions refused a datagram (no room)
  std::uint16_t last_wkc = 0;      // sum over the image datagrams of the last completed cycle
  std::uint16_t expected_wkc = 0;
  std::uint64_t al_checks = 0;
  std::uint64_t al_missing = 0;    // AL checks without an answer or showing a slave out of SAFE-OP/OP
};

enum class SlaveAnswer : std::uint8_t { Unknown, Answered, Missing };
std::string_view to_string(SlaveAnswer a) noexcept;

// The last AL status check of one slave that came back (or was lost). A check still in flight
// leaves the one before it here: the cycle and the status always belong to the same check (a
// cycle of the new one with the status of the old one took a slave just gone to OP for one that
// left it, when its answer came a cycle late).
struct SlaveAlCheck {
  std::uint64_t cycle = 0;     // cycle it was queued in (0: none came back yet)
  bool answered = false;       // WKC 1
  std::uint16_t raw = 0;       // 0130h as read
  [[nodiscard]] AlStatus status() const noexcept { return decode_al_status(raw); }
  // Answered, in SAFE-OP or OP, no error bit.
  [[nodiscard]] bool healthy() const noexcept {
    const AlStatus s = status();
    return answered && !s.error && (s.state() == AlState::SafeOp || s.state() == AlState::Op);
  }
};

class CyclicExchange final : public DatagramOwner {
 public:
  static constexpr std::size_t kRing = 8;  // cycles that may be in flight at once

  explicit CyclicExchange(const ProcessImage& image, CyclicOptions options = {}) noexcept;
  CyclicExchange(const CyclicExchange&) = delete;
  CyclicExchange& operator=(const CyclicExchange&) = delete;

  // The application's side. Spans into the images: write outputs before queue(); inputs are the
  // last good ones.
  [[nodiscard]] std::span<std::uint8_t> outputs(std::size_t slave) noexcept;
  [[nodiscard]] std::span<const std::uint8_t> inputs(std::size_t slave) const noexcept;
  [[nodiscard]] std::span<const std::uint8_t> input_image() const noexcept { return {in_.data(), image_.size()}; }
  // Cycle of the last good inputs of a slave (0: none yet).
  [[nodiscard]] std::uint64_t inputs_cycle(std::size_t slave) const noexcept { return slave < kMax ? in_cycle_[slave] : 0; }

  // Queues this cycle's datagrams. False when Transactions refused one (counted).
  bool queue(Transactions& tx) noexcept;
  void on_result(std::uint32_t tag, const DatagramAnswer& answer) noexcept override;

  [[nodiscard]] const CyclicCounters& counters() const noexcept { return counters_; }
  // The last completed cycle came back whole with the expected working counter.
  [[nodiscard]] bool last_cycle_good() const noexcept { return last_good_; }
  [[nodiscard]] std::uint64_t last_completed_cycle() const noexcept { return last_completed_; }
  // Whether slave k answered in the last completed cycle (see the header comment for how).
  [[nodiscard]] SlaveAnswer answered(std::size_t slave) const noexcept;
  [[nodiscard]] const SlaveAlCheck& al_check(std::size_t slave) const noexcept { return al_[slave < kMax ? slave : 0]; }

 private:
  static constexpr std::size_t kMax = ProcessImage::kMaxSlaves;
  static constexpr std::uint32_t kAlItem = 0x8000;
  struct CycleSlot {
    std::uint64_t cycle = 0;     // 0: free
    std::uint16_t expected = 0;  // results to wait for
    std::uint16_t results = 0;
    std::uint16_t wkc = 0;       // image datagrams' sum
    bool wkc_wrong = false;
    bool lost = false;
  };
  void complete(CycleSlot& c) noexcept;
  void copy_inputs(const CyclicDatagram& d, std::span<const std::uint8_t> data) noexcept;

  const ProcessImage& image_;
  CyclicOptions options_;
  std::array<std::uint8_t, ProcessImage::kMaxBytes> out_{};
  std::array<std::uint8_t, ProcessImage::kMaxBytes> in_{};
  std::array<std::uint64_t, kMax> in_cycle_{};
  std::array<std::uint64_t, kMax> slave_good_cycle_{};  // PerSlave: last cycle a datagram of it was right
  std::array<std::uint64_t, kMax> slave_bad_cycle_{};   // PerSlave: last cycle a datagram of it was wrong or lost
  std::array<SlaveAlCheck, kMax> al_{};
  std::array<std::uint64_t, kMax> al_queued_{};  // cycle of each slave's check in flight
  std::array<CycleSlot, kRing> ring_{};
  std::uint64_t cycle_ = 0;
  std::uint64_t last_completed_ = 0;
  bool last_good_ = false;
  std::size_t round_robin_ = 0;
  CyclicCounters counters_{};
};

}  // namespace drivegate::ethercat
