#pragma once
// A line of simulated slaves behind one MemoryLink [ETG.1000.4 §4 topology: a frame passes the
// slaves in order on the way out (each processes the datagrams, ADP increments, WKC counts) and
// returns through them to the master].
//
// Timing for DC: the frame leaves the master at the line's time `now`; the hop into slave j (cable
// + forwarding) takes h_j ns (`hop_delay_ns`, or per slave given to add()), the same out and back.
// With S_k = h_0 + ... + h_k, slave k sees the frame on port 0 at now + S_k and, with a downstream
// neighbour, on port 1 at now + S_last + (S_last - S_k); port 1 minus port 0 is the round trip
// 2·(S_last - S_k) behind it, and half the difference of two slaves' round trips is the delay
// between them (what the master's propagation-delay computation finds) [ETG.1000.4 §6 DC receive
// times]. Each ESC's clock (offset, drift, control loop) is its own: EscConfig / DcClock.
//
// Faults: slave k powered off (it and everything behind it unreachable; slave k-1 closes its
// port 1, as a real ESC does on link loss); power back = the slave restarts (INIT, station
// address 0); cable break after slave k; drop the next N frames; corrupt the next frame (a CRC
// error: slave 0 counts it in 0300h and discards it, so it never returns). A frame that reaches no
// slave does not return either.
//
// One thread: on_frame() runs inside MemoryLink::send() and delivers the answer from there.
// Nothing allocates after add().
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "adapters/ethercat/link/ethercat_link.hpp"
#include "adapters/ethercat/sim/esc_slave.hpp"
#include "adapters/ethercat/wire/frame.hpp"

namespace drivegate::ethercat::sim {

struct SimLineConfig {
  std::uint32_t hop_delay_ns = 300;
};

struct SimLineCounters {
  std::uint64_t frames = 0;      // frames sent to the line
  std::uint64_t returned = 0;    // frames delivered back
  std::uint64_t dropped = 0;     // dropped on request
  std::uint64_t corrupted = 0;   // lost to an injected CRC error
  std::uint64_t malformed = 0;   // not a valid EtherCAT frame (discarded)
  std::uint64_t unreachable = 0; // no slave reachable: nothing came back
};

class SimLine final : public FrameSink {
 public:
  // Installs itself as `link`'s sink.
  SimLine(MemoryLink& link, SimLineConfig config = {});
  ~SimLine() override;
  SimLine(const SimLine&) = delete;
  SimLine& operator=(const SimLine&) = delete;

  // Appends a slave at the end of the line (before frames pass); returns its position. The hop
  // into it takes the configured hop_delay_ns, or `hop_delay_ns`.
  std::size_t add(EscSlave& slave);
  std::size_t add(EscSlave& slave, std::uint32_t hop_delay_ns);
  std::size_t size() const noexcept { return slaves_.size(); }
  EscSlave& slave(std::size_t k) noexcept { return *slaves_[k].esc; }

  // The time frames pass at; advance() also runs every powered slave's PDI cycle (watchdogs) with
  // no frame.
  void set_time(std::uint64_t now_ns) noexcept { now_ = now_ns; }
  void advance(std::uint64_t now_ns) noexcept;

  void on_frame(FrameView frame) noexcept override;

  // Faults.
  void power_off(std::size_t k) noexcept;
  void power_on(std::size_t k) noexcept;
  void break_after(std::size_t k) noexcept;  // cable between k and k+1 cut
  void repair_cable() noexcept;
  void drop_next(std::size_t frames) noexcept { drop_ = frames; }
  void corrupt_next() noexcept { corrupt_ = true; }
  // Slave k stuck at `highest` (refuses higher states with `code`); AlState::Op lifts it.
  void stick(std::size_t k, AlState highest, std::uint16_t code) noexcept {
    if (k < slaves_.size()) slaves_[k].esc->limit_state(highest, code);
  }
  // Slaves a frame reaches now.
  std::size_t reachable() const noexcept;

  const SimLineCounters& counters() const noexcept { return counters_; }

 private:
  struct Entry {
    EscSlave* esc = nullptr;
    bool powered = true;
    std::uint32_t hop_ns = 0;  // master or previous slave -> this one
  };
  void update_links() noexcept;
  void run_pdi() noexcept;

  MemoryLink& link_;
  SimLineConfig cfg_;
  std::vector<Entry> slaves_;
  std::size_t break_after_ = SIZE_MAX;
  std::size_t drop_ = 0;
  bool corrupt_ = false;
  std::uint64_t now_ = 0;
  std::array<std::uint8_t, kMaxFrameSize> buf_{};
  // Datagram offsets of the frame being processed (at most 1514 / 12 datagrams).
  std::array<Datagram, kMaxFrameSize / kDatagramOverhead> datagrams_{};
  SimLineCounters counters_;
};

}  // namespace drivegate::ethercat::sim
