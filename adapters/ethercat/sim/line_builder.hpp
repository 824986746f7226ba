#pragma once
// A simulated line made from a config's ethercat bus (issue 9 "Simulator"): one slave per position
// of the plan, in position order, each made by the persona factory its device profile names
// (`ethercat.persona`; `io:` slaves are `generic-io`), each with its SII image. The line runs on
// its own MemoryLink (SimLine); the endpoint (sim_endpoint.hpp) puts it on a network interface,
// the daemon's `transport: sim` can drive the MemoryLink directly.
//
// BuiltLine also holds the line's faults as the console sets them (power, cable break, frames to
// drop and corrupt, stuck slaves) and counts the frames each slave saw, for `status`. Positions in
// its API are 0-based indexes into the line (index = position - 1).
//
// One thread: pass() and the fault calls run on the thread that owns the line. Nothing allocates
// after build_line().
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "adapters/ethercat/link/ethercat_link.hpp"
#include "adapters/ethercat/sim/esc_slave.hpp"
#include "adapters/ethercat/sim/sim_line.hpp"
#include "adapters/ethercat/sim/sim_personas.hpp"
#include "adapters/ethercat/wire/sii.hpp"
#include "config/plan.hpp"

namespace drivegate::ethercat::sim {

// A plan the builder cannot make a line of; what() is one sentence naming the bus and position.
class LineBuildError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// One slave of a built line.
struct SimSlave {
  std::size_t position = 0;  // 1 = next to the master
  std::string persona;
  std::string name;          // "io panel", "axis x", "axes x, y"
  SiiIdentity identity{};    // as its SII says
  SimSlaveParts parts;
  std::unique_ptr<EscSlave> esc;
  bool powered = true;
  std::uint64_t frames_seen = 0;  // frames that reached it (a corrupted one counts at the first slave)
};

class BuiltLine {
 public:
  // An empty line named after its bus; add() slaves, then open() before frames pass.
  explicit BuiltLine(std::string bus, SimLineConfig config = {});
  BuiltLine(const BuiltLine&) = delete;
  BuiltLine& operator=(const BuiltLine&) = delete;

  // Appends a slave made from `parts` (its EscSlave is made here); returns its index.
  std::size_t add(SlaveRequest request, SimSlaveParts parts);
  // Opens the MemoryLink (the answers wait in its receive queue).
  void open();

  [[nodiscard]] const std::string& bus() const noexcept { return bus_; }
  [[nodiscard]] std::size_t size() const noexcept { return slaves_.size(); }
  [[nodiscard]] SimSlave& slave(std::size_t index) noexcept { return *slaves_[index]; }
  [[nodiscard]] const SimSlave& slave(std::size_t index) const noexcept { return *slaves_[index]; }
  [[nodiscard]] MemoryLink& link() noexcept { return link_; }
  [[nodiscard]] SimLine& line() noexcept { return line_; }

  // One frame from the master through the line at `now_ns` (the line's time); the answer, when one
  // returns, waits in link()'s receive queue. Counts the frames each slave saw.
  void pass(FrameView frame, std::uint64_t now_ns) noexcept;
  // Runs every powered slave's PDI side at `now_ns` without a frame (watchdogs).
  void tick(std::uint64_t now_ns) noexcept { line_.advance(now_ns); }

  // Faults, by index. Out-of-range indexes are ignored (the console checks them first).
  void power_off(std::size_t index) noexcept;
  // Power back: the ESC restarts in INIT with station address 0, the application runs its own
  // power-on reset (SimSlaveParts::power_on).
  void power_on(std::size_t index);
  void break_after(std::size_t index) noexcept;
  void mend() noexcept;
  [[nodiscard]] std::optional<std::size_t> broken_after() const noexcept { return broken_after_; }
  void drop(std::size_t frames) noexcept { line_.drop_next(frames); }
  // The next `frames` frames are lost to a CRC error at the first slave.
  void corrupt(std::size_t frames) noexcept { corrupt_left_ = frames; }
  // The slave refuses every state above `highest` with `code`; unstick() lifts it.
  void stick(std::size_t index, AlState highest, std::uint16_t code) noexcept;
  void unstick(std::size_t index) noexcept { stick(index, AlState::Op, 0); }
  [[nodiscard]] std::optional<AlState> stuck_at(std::size_t index) const noexcept;

 private:
  std::string bus_;
  MemoryLink link_;
  SimLine line_;
  std::vector<std::unique_ptr<SimSlave>> slaves_;
  struct Stuck {
    AlState highest = AlState::Op;  // Op: not stuck
    std::uint16_t code = 0;
  };
  std::vector<Stuck> stuck_;  // per slave
  std::optional<std::size_t> broken_after_;
  std::size_t corrupt_left_ = 0;
  bool corrupt_armed_ = false;  // SimLine's corrupt_next() is set and no frame took it yet
};

// The line of `bus` (an ethercat plan): positions 1..N each with exactly one slave (the axes of a
// multi-axis slave share one), made by `personas`. Throws LineBuildError for a gap in the
// positions, a position with two slaves, an unknown persona (the message lists the known ones), a
// factory that fails, or an SII image that does not parse. The line is opened.
std::unique_ptr<BuiltLine> build_line(const config::BusPlan& bus,
                                      const PersonaRegistry& personas = PersonaRegistry::builtin(),
                                      SimLineConfig config = {});

}  // namespace drivegate::ethercat::sim
