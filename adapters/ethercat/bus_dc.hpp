#pragma once
// Distributed clocks for the EtherCAT bus (EthercatBus' DC step; master/dc.hpp does the work):
//
//   line:    once every DC slave of the line (`wanted`: the bus option distributed_clocks and the
//            device profile's distributed_clocks) has finished its PDO set-up (the bus' Sync
//            phase; slaves that are lost are not waited for), the ESC of each configured position
//            is read: features 0008h (DC unit, 64 bit) and DL status 0110h (open ports)
//            [ETG.1000.4 Table 31, Table 34]. A wanted slave whose ESC has no DC runs free (one
//            warning). Then DcSetup for the wanted DC slaves: delays, offsets, static drift,
//            SYNC0 (cycle = the bus cycle, shift = sync0_shift). Done: DcCyclic from here on.
//   rejoin:  a wanted slave that comes back after a loss (power cycle: its DC registers are
//            zero) gets its own run, one slave at a time, while the others keep running: 0008h,
//            0110h, BWR 0900h latch, FPRD 0900h (44 bytes: port times, 0918h, 0920h) of it and of
//            the reference clock; delay = (rt_ref - rt_k) / 2, offset = the reference's system
//            time at the latch (its 0918h + 0920h) + delay - its 0918h [ETG.1000.4 §6 DC];
//            FPWR 0920h; the cyclic FRMW settles its control loop for `settle` cycles; then
//            0980h off, its 0910h read, 09A0h, 0990h on the common grid (sync0_start_time()),
//            0981h = 03h and the read-back of 0980h..09A3h as DcSetup does it. The reference clock
//            itself: offset from the master's time minus the last master-minus-reference.
//   cyclic:  DcCyclic's FRMW first in every frame (poll_cyclic()), paused while the reference
//            clock is not synchronized (a FRMW nobody reads would hand every other DC slave a
//            wrong time to compare); its 092Ch rounds give the largest |system time difference|.
// Nothing here allocates after construction; the bus owns one BusDc for the life of the bus.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

#include "adapters/ethercat/master/dc.hpp"
#include "adapters/ethercat/master/line_boot.hpp"
#include "adapters/ethercat/master/transactions.hpp"
#include "core/clock.hpp"
#include "core/fixed_string.hpp"

namespace drivegate::ethercat {

struct BusDcConfig {
  bool enabled = false;             // the bus option distributed_clocks
  std::uint32_t cycle_ns = 0;       // SYNC0 cycle = the bus cycle
  std::int32_t shift_ns = 0;        // sync0_shift
  std::uint32_t difference_every = 1000;  // cycles between 092Ch rounds
  std::uint32_t settle_cycles = 100;      // a rejoining slave's control loop, before SYNC0
  DcConfig setup{};                 // system_time_base_ns is set by set_base()
};

// What the bus' slave k is doing, once per cycle.
struct BusDcView {
  bool present = false;      // found on the line (its station answers)
  bool at_sync = false;      // in the bus' DC step (PDO set-up done, before SAFE-OP)
  bool configuring = false;  // before it: boot, restart, 1000h, PDO set-up
  bool running = false;      // past it: SAFE-OP, OP (its DC set up or free)
};

enum class BusDcLine : std::uint8_t { Off, Idle, Probe, Setup, Running };
std::string_view to_string(BusDcLine s) noexcept;

class BusDc final : public DatagramOwner {
 public:
  static constexpr std::size_t kMaxSlaves = LineBoot::kMaxSlaves;

  // Per slave: 0: not decided yet; Free: no DC (not wanted, or no DC unit); Sync0: DC set up and
  // SYNC0 running; Failed: text() says why (the bus fails the slave; it comes back as a rejoin).
  enum class Verdict : std::uint8_t { Wait, Free, Sync0, Failed };

  // `tx`: the bus' Transactions (a DcSetup made anew forgets the old one's datagrams there).
  BusDc(Transactions& tx, std::span<const std::uint16_t> stations, std::span<const bool> wanted,
        BusDcConfig config) noexcept;

  // From open(): ns since 2000 = to_ns(now) + base.
  void set_base(std::int64_t system_time_base_ns) noexcept;
  // A line boot: every slave's DC again.
  void restart_line() noexcept;
  // Slave k restarts (lost, power cycle): its DC again when it reaches the DC step.
  void forget(std::size_t k) noexcept;

  // Once per cycle before the slaves advance.
  void step(core::TimePoint now, std::span<const BusDcView> views) noexcept;
  [[nodiscard]] Verdict verdict(std::size_t k) const noexcept { return slaves_[k].verdict; }
  [[nodiscard]] std::string_view text(std::size_t k) const noexcept { return slaves_[k].text.view(); }
  [[nodiscard]] bool wanted(std::size_t k) const noexcept { return k < count_ && slaves_[k].wanted; }
  // Line sentences for bus events (setup done or failed, a wanted slave without DC), oldest
  // first; false when there is none.
  bool take_event(core::FixedString<240>& out, bool& warning) noexcept;

  // First in the cycle's frame: DcCyclic's FRMW.
  void poll_cyclic(core::TimePoint now, Transactions& tx) noexcept;
  // Later in the frame: the probe, DcSetup, a rejoin.
  void poll(core::TimePoint now, Transactions& tx) noexcept;
  void on_result(std::uint32_t tag, const DatagramAnswer& answer) noexcept override;
  void forget_all() noexcept;  // the bus goes away

  // Diagnostics.
  [[nodiscard]] BusDcLine line() const noexcept { return line_; }
  [[nodiscard]] const DcCyclic& cyclic() const noexcept { return cyclic_; }
  [[nodiscard]] const DcSetup* setup() const noexcept { return setup_ ? &*setup_ : nullptr; }
  [[nodiscard]] std::optional<std::size_t> reference() const noexcept { return reference_; }
  [[nodiscard]] std::uint64_t sync0_start(std::size_t k) const noexcept { return slaves_[k].sync0_start; }
  [[nodiscard]] std::uint64_t rejoins() const noexcept { return rejoins_; }

 private:
  enum class Probe : std::uint8_t { None, Features, DlStatus, Done };
  enum class Rejoin : std::uint8_t {
    None, Features, DlStatus, Latch, ReadSlave, ReadReference, Offset, Settle, Sync0Off, ReadTime, Cycle, Start,
    Activate, Check,
  };
  struct Pending {
    bool due = false;
    bool waiting = false;
    std::uint16_t seq = 0;
    int retries_left = 0;
    Command command = Command::NOP;
    std::uint32_t address = 0;
    std::uint16_t length = 0;
    std::array<std::uint8_t, 12> data{};
    std::size_t data_size = 0;
  };
  struct Slave {
    std::uint16_t station = 0;
    bool wanted = false;
    Verdict verdict = Verdict::Wait;
    Probe probe = Probe::None;
    bool dc = false, dc_64bit = true;
    std::uint8_t open_ports = 0x01;
    bool in_setup = false;   // part of the running line setup
    bool synced = false;     // DC set up (offset, delay, SYNC0)
    bool in_cyclic = false;  // its 092Ch is read
    std::uint64_t sync0_start = 0;
    Pending pending{};
    core::FixedString<200> text{};
  };

  void set(Pending& p, Command command, std::uint32_t address, std::uint16_t length,
           std::span<const std::uint8_t> data = {}) noexcept;
  void send(Pending& p, std::uint32_t actor, Transactions& tx) noexcept;
  void start_line(std::span<const BusDcView> views) noexcept;
  void probe_answer(std::size_t k, const DatagramAnswer& a) noexcept;
  void probes_done() noexcept;
  void setup_done() noexcept;
  void start_rejoin(std::size_t k) noexcept;
  void rejoin_step() noexcept;
  void rejoin_answer(const DatagramAnswer& a) noexcept;
  void rejoin_fail(const char* what) noexcept;
  void refresh_cyclic() noexcept;
  void fail(Slave& s, std::string_view why) noexcept;
  void event(bool warning, std::string_view text) noexcept;
  [[nodiscard]] std::uint64_t master_time(core::TimePoint t) const noexcept {
    return master_system_time(t, config_.setup.system_time_base_ns);
  }

  void drop_setup() noexcept;

  Transactions* tx_;
  BusDcConfig config_;
  std::size_t count_ = 0;
  std::array<Slave, kMaxSlaves> slaves_{};
  BusDcLine line_ = BusDcLine::Off;
  std::optional<DcSetup> setup_;
  DcCyclic cyclic_;
  std::optional<std::size_t> reference_;
  std::uint64_t reference_offset_ = 0;  // 0920h written to the reference
  std::uint8_t run_ = 0;
  core::TimePoint now_{};
  core::TimePoint deadline_{};
  // Rejoin (one slave at a time).
  std::optional<std::size_t> rejoin_;
  Rejoin rstep_ = Rejoin::None;
  Pending rpending_{};
  std::uint32_t rsettle_ = 0;
  core::TimePoint rlatch_{};
  std::array<std::uint32_t, 4> rk_ports_{}, rref_ports_{};
  std::uint64_t rk_receive_ = 0, rref_receive_ = 0, rref_offset_ = 0;
  std::uint64_t rjoin_offset_ = 0;
  std::uint32_t rjoin_delay_ = 0;
  std::uint64_t rejoins_ = 0;
  struct LineEvent {
    core::FixedString<240> text{};
    bool warning = false;
  };
  std::array<LineEvent, 4> events_{};
  std::size_t event_count_ = 0;
};

}  // namespace drivegate::ethercat
