#pragma once
// Distributed clocks (DC): setting up the slaves' clocks (DcSetup) and what the cyclic frame
// carries for them (DcCyclic) [ETG.1000.4 §6 DC registers 0900h-09A7h; ETG.1020 "Distributed
// clocks" start-up: propagation delay, offset, static and cyclic drift compensation, SYNC0].
//
// DcSetup, for the slaves of a line that support DC (sans-I/O: poll(now, tx) queues, on_result()
// takes the answers; all DC slaves in parallel, one datagram in flight each):
//   1. latch:    BWR 0900h: every ESC latches the local time the frame passed each of its ports
//                (0900h-090Fh, 32 bit) and its processing unit (0918h, 64 bit).
//   2. read:     FPRD 0900h, 32 bytes per DC slave: the four port times, system time and 0918h.
//   3. delays:   line topology only: the frame enters on port 0 and leaves on at most one other
//                open port (DL status 0110h), where it comes back; the round trip behind slave k is
//                rt_k = t(that port) - t(port 0) (0 at the end of the line, 32-bit wrap). The first
//                DC slave is the reference clock; the delay from it to DC slave k is
//                (rt_ref - rt_k) / 2 [ETG.1000.4 §6 DC receive times; ETG.1020 propagation delay].
//                A slave with two or more downstream ports open (a branch: junction, EK1100 port
//                3 with port 1) stops the setup: delays through branches are not computed.
//                Non-DC slaves in between need nothing: their hops are inside the DC slaves'
//                round trips.
//   4. offsets:  FPWR 0920h, 12 bytes: offset (u64) and delay 0928h (u32). The offset is the
//                master's system time at the latch (ns since 2000-01-01, from `now`) plus the
//                delay minus the slave's 0918h, so that every system time reads the reference's
//                at the same instant (SOEM and EtherCrab leave the delay to the control loop).
//   5. drift:    static drift compensation: N FRMW 0910h (8 bytes, 4 on a 32-bit reference) from
//                the reference clock, packed up to 32 to a frame, so that each ESC's control loop
//                has settled before SYNC0 starts [ETG.1020: about 15000 such datagrams; the ESC's
//                control loop adjusts by small steps, so it needs many].
//   6. SYNC0:    for each DC slave with a SYNC0 cycle: FPWR 0980h = 0000h (sync unit to ECAT, off);
//                FPRD 0910h of the reference (once); FPWR 09A0h cycle; FPWR 0990h start =
//                reference time + lead, rounded up to the cycle, + shift; FPWR 0981h = 03h (cyclic
//                operation + SYNC0); FPRD 0980h..09A3h: 0981h must read 03h, 0984h bit 2 clear (a
//                start time already past never fires), 09A0h the cycle, 0990h (the next pulse, once
//                running) start + k·cycle [ETG.1000.4 §6 DC, 0980h-09A3h].
// Each step has a timeout; a lost datagram is sent again up to `retries` times; a failing slave
// gets one sentence ("slave 3 (0x1003): DC: no answer to the port receive times (FPRD 0900h),
// frame lost 4 times") and is left out of the rest; a failing reference clock fails the setup.
// Run it after the slaves' PDO set-up and before SAFE-OP (a drive checks SYNC0 at PRE-OP ->
// SAFE-OP).
//
// DcCyclic, every cycle after the setup: one FRMW 0910h from the reference clock, queued first
// so that it is the first datagram of the cycle's first frame (the reference's time is read as the
// frame starts passing, every other DC slave compares it with its own: cyclic drift compensation);
// the reference time of the last cycle and how far the master's clock is from it (for the
// application and SYNC0 alignment); every `difference_every` cycles an FPRD 092Ch per DC slave, the
// largest |system time difference| as a status figure. Nothing allocates.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

#include "adapters/ethercat/master/transactions.hpp"
#include "adapters/ethercat/wire/registers.hpp"
#include "core/clock.hpp"
#include "core/fixed_string.hpp"

namespace drivegate::ethercat {

// ---- System time and register decoding ------------------------------------------------------

// 1970-01-01 to 2000-01-01 in ns: the DC system time counts from 2000-01-01 00:00 [ETG.1000.4 §6].
inline constexpr std::int64_t kEtherCatEpochUnixNs = 946'684'800'000'000'000;

// The base that makes master_system_time() ns since 2000 from a monotonic `now`: the bus thread
// reads CLOCK_REALTIME and CLOCK_MONOTONIC once and passes both (the engines read no clock).
constexpr std::int64_t system_time_base(std::int64_t realtime_ns, std::int64_t monotonic_ns) noexcept {
  return realtime_ns - kEtherCatEpochUnixNs - monotonic_ns;
}
inline std::uint64_t master_system_time(core::TimePoint now, std::int64_t base_ns) noexcept {
  return static_cast<std::uint64_t>(core::to_ns(now) + base_ns);
}

// ESC features 0008h: bit 2 distributed clocks, bit 3 DC 64 bit [ETG.1000.4 Table 31].
constexpr bool features_dc(std::uint16_t esc_features) noexcept { return (esc_features & 0x0004U) != 0; }
constexpr bool features_dc_64bit(std::uint16_t esc_features) noexcept { return (esc_features & 0x0008U) != 0; }
// Open ports from DL status 0110h: bit p set when port p has communication and its loop is open
// (the frame goes out there and comes back) [ETG.1000.4 Table 34].
constexpr std::uint8_t open_ports(std::uint16_t dl_status) noexcept {
  std::uint8_t ports = 0;
  for (unsigned p = 0; p < 4; ++p) {
    if ((dl_status & dl_status::communication_on_port(p)) != 0 && (dl_status & dl_status::loop_closed_port(p)) == 0) {
      ports = static_cast<std::uint8_t>(ports | (1U << p));
    }
  }
  return ports;
}

// Round trip behind a slave of a line: receive time of its one open downstream port minus port 0
// (32-bit wrap), 0 with none; nullopt with two or more (a branch). `port_times` as in 0900h-090Fh.
std::optional<std::uint32_t> line_round_trip(const std::array<std::uint32_t, 4>& port_times,
                                             std::uint8_t open_ports_mask) noexcept;
// SYNC0 start: reference time + lead rounded up to a multiple of the cycle, plus the shift (the
// first pulse on the common cycle grid; SOEM/IgH do the same). cycle 0: reference + lead + shift.
std::uint64_t sync0_start_time(std::uint64_t reference_time, std::uint64_t lead_ns, std::uint32_t cycle_ns,
                               std::int32_t shift_ns) noexcept;

// ---- DcSetup --------------------------------------------------------------------------------

// What the caller knows of each position of the line (from LineBoot's reads or the SII).
struct DcSlaveInfo {
  std::uint16_t station = 0;
  bool dc = false;            // ESC features 0008h bit 2 (features_dc) or the SII's DC category
  bool dc_64bit = true;       // 0008h bit 3
  std::uint8_t open_ports = 0x01;  // bit p: port p open (open_ports(DL status 0110h))
  std::uint32_t sync0_cycle_ns = 0;  // 0: SYNC0 not activated on this slave
  std::int32_t sync0_shift_ns = 0;   // added to the start time (the pulse comes this much later)
};

struct DcConfig {
  std::int64_t system_time_base_ns = 0;  // master_system_time(now, base): ns since 2000
  // Static drift compensation: FRMW 0910h datagrams, and how many are queued per poll (two
  // frames: 74 FRMWs of the 64-bit time fit in one). 15000 as ETG.1020 and the Beckhoff ESC documentation recommend; EtherCrab's default.
  std::uint32_t static_drift_datagrams = 15000;
  std::uint16_t static_drift_per_poll = 128;
  // Start time lead: SYNC0 starts at least this long after the reference time is read. The
  // activation follows within four round trips (40 ms at a 10 ms cycle); a start time already
  // past when 0981h is written never fires on a 64-bit ESC.
  core::Duration sync0_lead = std::chrono::milliseconds(100);
  core::Duration step_timeout = std::chrono::milliseconds(500);
  core::Duration static_drift_timeout = std::chrono::seconds(30);
  int retries = 3;  // a lost datagram is sent again this often
};

enum class DcStep : std::uint8_t {
  Latch, ReceiveTimes, Delays, Offsets, StaticDrift, Sync0Off, ReferenceTime, Sync0Cycle, Sync0Start, Sync0Activate,
  Sync0Check, Done,
};
// What the step sends, for texts: "the port receive times (FPRD 0900h)".
std::string_view to_string(DcStep s) noexcept;

enum class DcSlaveStatus : std::uint8_t {
  NotDc,         // no DC unit: skipped
  Busy,          // in the setup
  Synchronized,  // offset and delay written, drift compensated, SYNC0 running if configured
  Failed,        // stopped at `step`, `text` says why
};
std::string_view to_string(DcSlaveStatus s) noexcept;

struct DcSlaveReport {
  std::uint16_t position = 0;
  std::uint16_t station = 0;
  DcSlaveStatus status = DcSlaveStatus::NotDc;
  DcStep step = DcStep::Latch;
  bool reference = false;
  std::array<std::uint32_t, 4> port_times{};  // 0900h-090Fh as latched
  std::uint64_t receive_time = 0;             // 0918h
  std::uint32_t round_trip_ns = 0;            // behind this slave
  std::uint32_t delay_ns = 0;                 // from the reference clock (0928h)
  std::uint64_t offset_ns = 0;                // 0920h as written
  std::uint64_t sync0_start = 0;              // 0990h as written (0: SYNC0 not configured)
  core::FixedString<200> text{};
};

enum class DcSetupStatus : std::uint8_t { Idle, Running, Done, Failed };
std::string_view to_string(DcSetupStatus s) noexcept;

class DcSetup final : public DatagramOwner {
 public:
  static constexpr std::size_t kMaxSlaves = 64;

  // `slaves`: one entry per position, front first (at most kMaxSlaves are used).
  DcSetup(std::span<const DcSlaveInfo> slaves, DcConfig config) noexcept;

  void start(core::TimePoint now) noexcept;
  void poll(core::TimePoint now, Transactions& tx) noexcept;
  void on_result(std::uint32_t tag, const DatagramAnswer& answer) noexcept override;

  // Done: every step ran (slaves may have failed: ok()); Failed: a line step or the reference
  // clock failed (line_text()).
  [[nodiscard]] DcSetupStatus status() const noexcept { return status_; }
  [[nodiscard]] bool ok() const noexcept;
  [[nodiscard]] std::string_view line_text() const noexcept { return line_text_.view(); }
  [[nodiscard]] DcStep step() const noexcept { return phase_; }
  [[nodiscard]] std::size_t slave_count() const noexcept { return count_; }
  [[nodiscard]] const DcSlaveReport& slave(std::size_t position) const noexcept { return slaves_[position].report; }
  // The reference clock (first DC slave); nullopt on a line without DC.
  [[nodiscard]] std::optional<std::size_t> reference() const noexcept { return reference_; }
  [[nodiscard]] std::uint16_t reference_station() const noexcept;
  [[nodiscard]] bool reference_64bit() const noexcept;
  // The reference's system time read for the SYNC0 start (0 when no slave has a SYNC0 cycle).
  [[nodiscard]] std::uint64_t reference_time() const noexcept { return reference_time_; }
  // Static drift compensation: FRMW answered and lost so far.
  [[nodiscard]] std::uint32_t drift_answered() const noexcept { return drift_answered_; }
  [[nodiscard]] std::uint32_t drift_lost() const noexcept { return drift_lost_; }
  // FRMW the static drift compensation keeps in flight now (see drift_window_).
  [[nodiscard]] std::uint32_t drift_window() const noexcept { return drift_window_; }
  // Stations of the synchronized DC slaves, front first, into `out`; returns how many.
  std::size_t synchronized_stations(std::span<std::uint16_t> out) const noexcept;

 private:
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
    DcSlaveInfo info{};
    DcSlaveReport report{};
    Pending pending{};
    bool done = false;  // the current step finished for this slave
  };
  static constexpr std::uint32_t kLineActor = 0xFF;
  static constexpr std::uint32_t kDriftActor = 0xFE;

  void set(Pending& p, Command command, std::uint32_t address, std::uint16_t length,
           std::span<const std::uint8_t> data = {}) noexcept;
  void send(Pending& p, std::uint32_t actor, Transactions& tx) noexcept;
  void enter(DcStep step) noexcept;
  void slave_step(Slave& s) noexcept;  // sets the pending datagram of the slave's current step
  void slave_answer(Slave& s, const DatagramAnswer& a) noexcept;
  void line_answer(const DatagramAnswer& a) noexcept;
  void drift_answer(const DatagramAnswer& a) noexcept;
  void compute_delays() noexcept;
  void check_sync0(Slave& s, std::span<const std::uint8_t> d) noexcept;
  void advance_if_done() noexcept;
  void timeout() noexcept;
  [[nodiscard]] bool active(const Slave& s) const noexcept { return s.report.status == DcSlaveStatus::Busy; }
  void fail(Slave& s, const char* fmt, ...) noexcept __attribute__((format(printf, 3, 4)));
  void fail_line(const char* fmt, ...) noexcept __attribute__((format(printf, 2, 3)));
  [[nodiscard]] std::uint64_t master_time(core::TimePoint t) const noexcept {
    return master_system_time(t, config_.system_time_base_ns);
  }

  DcConfig config_;
  std::size_t count_ = 0;
  std::array<Slave, kMaxSlaves> slaves_{};
  std::optional<std::size_t> reference_;
  DcSetupStatus status_ = DcSetupStatus::Idle;
  DcStep phase_ = DcStep::Latch;
  std::uint8_t run_ = 0;  // start() count: answers of an earlier run are ignored
  core::TimePoint now_{};
  core::TimePoint deadline_{};
  Pending line_pending_{};
  core::TimePoint latch_sent_{};
  std::uint64_t reference_time_ = 0;
  std::uint32_t drift_in_flight_ = 0;
  std::uint32_t drift_answered_ = 0;
  std::uint32_t drift_lost_ = 0;
  // Static drift: FRMW kept in flight at once. Halved (down to kMinDriftWindow) in a poll that
  // follows losses, one more after a poll without (up to static_drift_per_poll): a line or a peer
  // that cannot take the whole burst gets fewer at a time instead of failing the setup.
  static constexpr std::uint32_t kMinDriftWindow = 4;
  std::uint32_t drift_window_ = 0;
  std::uint32_t drift_lost_seen_ = 0;
  core::FixedString<240> line_text_{};
};

// ---- DcCyclic -------------------------------------------------------------------------------

struct DcCyclicConfig {
  std::int64_t system_time_base_ns = 0;
  // Cycles between FPRD 092Ch rounds (1 s at 1 kHz); 0: never.
  std::uint32_t difference_every = 1000;
};

struct DcCyclicCounters {
  std::uint64_t cycles = 0;        // FRMW queued
  std::uint64_t answered = 0;      // FRMW back with the reference's time
  std::uint64_t lost = 0;          // FRMW frame lost
  std::uint64_t no_reference = 0;  // FRMW back with WKC 0: the reference clock did not read
  std::uint64_t not_queued = 0;    // Transactions had no room
  std::uint64_t difference_rounds = 0;  // 092Ch rounds with every slave answered
};

class DcCyclic final : public DatagramOwner {
 public:
  static constexpr std::size_t kMaxSlaves = DcSetup::kMaxSlaves;

  // The reference clock (station, 64/32-bit) and the DC slaves whose 092Ch is read.
  void configure(std::uint16_t reference_station, bool reference_64bit, std::span<const std::uint16_t> stations,
                 DcCyclicConfig config) noexcept;
  // From a finished DcSetup: its reference and synchronized slaves. False when it has none.
  bool configure(const DcSetup& setup, DcCyclicConfig config) noexcept;
  [[nodiscard]] bool configured() const noexcept { return configured_; }

  // Once per cycle, before every other engine, so that the FRMW is the cycle's first datagram.
  void poll(core::TimePoint now, Transactions& tx) noexcept;
  void on_result(std::uint32_t tag, const DatagramAnswer& answer) noexcept override;

  // The reference's system time (ns since 2000; 32-bit references extended) when the last
  // answered cycle's frame passed it, and the master's system time at that cycle's poll minus it
  // (positive: the master's clock is ahead of the reference).
  [[nodiscard]] bool has_reference_time() const noexcept { return has_time_; }
  [[nodiscard]] std::uint64_t reference_time() const noexcept { return reference_time_; }
  [[nodiscard]] std::int64_t master_minus_reference_ns() const noexcept { return master_minus_reference_; }
  [[nodiscard]] std::uint16_t last_wkc() const noexcept { return last_wkc_; }
  // Where `time` lies in a SYNC0 cycle that started at `sync0_start`: 0..cycle-1 ns.
  static std::uint32_t sync0_phase(std::uint64_t time, std::uint64_t sync0_start, std::uint32_t cycle_ns) noexcept;

  // 092Ch: the last value read per DC slave (index as configured) and the largest magnitude of
  // the last complete round; difference_valid() once a round completed.
  [[nodiscard]] bool difference_valid() const noexcept { return counters_.difference_rounds > 0; }
  [[nodiscard]] std::uint32_t max_abs_difference_ns() const noexcept { return max_abs_difference_; }
  [[nodiscard]] std::int32_t difference_ns(std::size_t index) const noexcept { return differences_[index]; }
  [[nodiscard]] std::size_t station_count() const noexcept { return station_count_; }
  [[nodiscard]] const DcCyclicCounters& counters() const noexcept { return counters_; }

 private:
  void frmw_answer(const DatagramAnswer& a) noexcept;

  bool configured_ = false;
  DcCyclicConfig config_{};
  std::uint16_t reference_station_ = 0;
  bool reference_64bit_ = true;
  std::array<std::uint16_t, kMaxSlaves> stations_{};
  std::size_t station_count_ = 0;
  std::uint16_t seq_ = 0;
  std::uint64_t master_at_poll_ = 0;  // master system time of the cycle in flight
  std::uint32_t until_difference_ = 0;
  std::uint16_t round_seq_ = 0;
  std::size_t round_left_ = 0;
  std::uint32_t round_max_ = 0;
  bool has_time_ = false;
  std::uint64_t reference_time_ = 0;
  std::int64_t master_minus_reference_ = 0;
  std::uint16_t last_wkc_ = 0;
  std::array<std::int32_t, kMaxSlaves> differences_{};
  std::uint32_t max_abs_difference_ = 0;
  DcCyclicCounters counters_{};
};

}  // namespace drivegate::ethercat
