#include "adapters/ethercat/master/dc.hpp"

#include <algorithm>
#include <bit>
#include <cstdarg>
#include <cstdio>

#include "core/bytes.hpp"

namespace drivegate::ethercat {

using core::get_u32;
using core::get_u64;
using core::put_u32;
using core::put_u64;

namespace {

// Tag layout: bits 24-31 actor (slave position, the line, static drift), 16-23 run, 0-15 sequence.
constexpr std::uint32_t make_tag(std::uint32_t actor, std::uint8_t run, std::uint16_t seq) noexcept {
  return (actor << 24) | (static_cast<std::uint32_t>(run) << 16) | seq;
}

// FPRD 0900h covers the port receive times (0900h-090Fh), the system time (0910h) and the receive
// time of the processing unit (0918h) in one datagram [ETG.1000.4 Table 31].
constexpr std::uint16_t kReceiveTimesBytes = 32;
// FPRD 0980h..09A3h: cyclic unit control, activation, activation status (0984h), start time /
// next pulse (0990h), SYNC0 cycle (09A0h).
constexpr std::uint16_t kSyncBlockBytes = 0x24;
constexpr std::uint8_t kActivationStatusStartPast = 0x04;  // 0984h bit 2

long long ms(core::Duration d) noexcept { return std::chrono::duration_cast<std::chrono::milliseconds>(d).count(); }

std::uint64_t width_mask(bool bits64) noexcept { return bits64 ? ~std::uint64_t{0} : 0xFFFFFFFFU; }

}  // namespace

std::optional<std::uint32_t> line_round_trip(const std::array<std::uint32_t, 4>& port_times,
                                             std::uint8_t open_ports_mask) noexcept {
  const auto downstream = static_cast<std::uint8_t>(open_ports_mask & 0x0EU);
  if (downstream == 0) return 0U;                    // end of the line: nothing behind it
  if (std::popcount(downstream) > 1) return std::nullopt;  // a branch
  const auto port = static_cast<std::size_t>(std::countr_zero(downstream));
  return static_cast<std::uint32_t>(port_times[port] - port_times[0]);  // 32-bit receive times wrap
}

std::uint64_t sync0_start_time(std::uint64_t reference_time, std::uint64_t lead_ns, std::uint32_t cycle_ns,
                               std::int32_t shift_ns) noexcept {
  std::uint64_t t = reference_time + lead_ns;
  if (cycle_ns != 0) t = (t + cycle_ns - 1) / cycle_ns * cycle_ns;
  return t + static_cast<std::uint64_t>(static_cast<std::int64_t>(shift_ns));
}

std::string_view to_string(DcStep s) noexcept {
  switch (s) {
    case DcStep::Latch: return "the receive time latch (BWR 0900h)";
    case DcStep::ReceiveTimes: return "the port receive times (FPRD 0900h)";
    case DcStep::Delays: return "the propagation delays";
    case DcStep::Offsets: return "the offset and delay write (FPWR 0920h)";
    case DcStep::StaticDrift: return "static drift compensation (FRMW 0910h)";
    case DcStep::Sync0Off: return "the SYNC0 deactivation (FPWR 0980h)";
    case DcStep::ReferenceTime: return "the reference time read (FPRD 0910h)";
    case DcStep::Sync0Cycle: return "the SYNC0 cycle time write (FPWR 09A0h)";
    case DcStep::Sync0Start: return "the SYNC0 start time write (FPWR 0990h)";
    case DcStep::Sync0Activate: return "the SYNC0 activation (FPWR 0981h)";
    case DcStep::Sync0Check: return "the SYNC0 read-back (FPRD 0980h)";
    case DcStep::Done: return "done";
  }
  return "?";
}

std::string_view to_string(DcSlaveStatus s) noexcept {
  switch (s) {
    case DcSlaveStatus::NotDc: return "no DC";
    case DcSlaveStatus::Busy: return "busy";
    case DcSlaveStatus::Synchronized: return "synchronized";
    case DcSlaveStatus::Failed: return "failed";
  }
  return "?";
}

std::string_view to_string(DcSetupStatus s) noexcept {
  switch (s) {
    case DcSetupStatus::Idle: return "idle";
    case DcSetupStatus::Running: return "running";
    case DcSetupStatus::Done: return "done";
    case DcSetupStatus::Failed: return "failed";
  }
  return "?";
}

// ---- DcSetup --------------------------------------------------------------------------------

DcSetup::DcSetup(std::span<const DcSlaveInfo> slaves, DcConfig config) noexcept : config_(config) {
  count_ = std::min(slaves.size(), kMaxSlaves);
  for (std::size_t i = 0; i < count_; ++i) slaves_[i].info = slaves[i];
}

std::uint16_t DcSetup::reference_station() const noexcept {
  return reference_ ? slaves_[*reference_].info.station : std::uint16_t{0};
}

bool DcSetup::reference_64bit() const noexcept { return reference_ ? slaves_[*reference_].info.dc_64bit : true; }

bool DcSetup::ok() const noexcept {
  if (status_ != DcSetupStatus::Done) return false;
  return std::none_of(slaves_.begin(), slaves_.begin() + static_cast<std::ptrdiff_t>(count_),
                      [](const Slave& s) { return s.report.status == DcSlaveStatus::Failed; });
}

std::size_t DcSetup::synchronized_stations(std::span<std::uint16_t> out) const noexcept {
  std::size_t n = 0;
  for (std::size_t i = 0; i < count_ && n < out.size(); ++i) {
    if (slaves_[i].report.status == DcSlaveStatus::Synchronized) out[n++] = slaves_[i].info.station;
  }
  return n;
}

void DcSetup::start(core::TimePoint now) noexcept {
  now_ = now;
  ++run_;
  line_text_.clear();
  reference_.reset();
  reference_time_ = 0;
  drift_in_flight_ = drift_answered_ = drift_lost_ = drift_lost_seen_ = 0;
  drift_window_ = config_.static_drift_per_poll;
  for (std::size_t i = 0; i < count_; ++i) {
    Slave& s = slaves_[i];
    s.report = DcSlaveReport{};
    s.report.position = static_cast<std::uint16_t>(i);
    s.report.station = s.info.station;
    s.report.status = s.info.dc ? DcSlaveStatus::Busy : DcSlaveStatus::NotDc;
    s.pending = Pending{};
    s.done = false;
    if (s.info.dc && !reference_) {
      reference_ = i;
      s.report.reference = true;
    }
  }
  status_ = DcSetupStatus::Running;
  if (!reference_) {  // no DC slave: nothing to do
    phase_ = DcStep::Done;
    status_ = DcSetupStatus::Done;
    return;
  }
  enter(DcStep::Latch);
}

void DcSetup::set(Pending& p, Command command, std::uint32_t address, std::uint16_t length,
                  std::span<const std::uint8_t> data) noexcept {
  p.due = true;
  p.waiting = false;
  p.retries_left = config_.retries;
  p.command = command;
  p.address = address;
  p.length = length;
  p.data_size = std::min(data.size(), p.data.size());
  std::copy_n(data.begin(), p.data_size, p.data.begin());
}

void DcSetup::send(Pending& p, std::uint32_t actor, Transactions& tx) noexcept {
  if (!p.due || p.waiting) return;
  ++p.seq;
  if (tx.queue(this, make_tag(actor, run_, p.seq), p.command, p.address, p.length,
               std::span<const std::uint8_t>(p.data.data(), p.data_size))) {
    p.due = false;
    p.waiting = true;
    if (actor == kLineActor && phase_ == DcStep::Latch) latch_sent_ = now_;
  }  // else: no room this cycle, stays due
}

void DcSetup::enter(DcStep step) noexcept {
  phase_ = step;
  deadline_ = now_ + (step == DcStep::StaticDrift ? config_.static_drift_timeout : config_.step_timeout);
  for (std::size_t i = 0; i < count_; ++i) {
    Slave& s = slaves_[i];
    s.done = !active(s);
    if (!active(s)) continue;
    s.report.step = step;
  }
  const Slave& ref = slaves_[*reference_];
  switch (step) {
    case DcStep::Latch: {
      // A write to 0900h latches the receive times in every ESC it passes [ETG.1000.4 §6 DC].
      const std::array<std::uint8_t, 4> zero{};
      set(line_pending_, Command::BWR, physical_address(0, reg::kDcReceiveTimePort0), 4, zero);
      return;
    }
    case DcStep::Delays:
      compute_delays();
      if (status_ == DcSetupStatus::Running) enter(DcStep::Offsets);
      return;
    case DcStep::StaticDrift:
      if (config_.static_drift_datagrams == 0) enter(DcStep::Sync0Off);
      return;
    case DcStep::ReferenceTime: {
      const bool any_sync0 = std::any_of(slaves_.begin(), slaves_.begin() + static_cast<std::ptrdiff_t>(count_),
                                         [this](const Slave& s) { return active(s) && s.info.sync0_cycle_ns != 0; });
      if (!any_sync0) {
        enter(DcStep::Done);
        return;
      }
      set(line_pending_, Command::FPRD, physical_address(ref.info.station, reg::kDcSystemTime),
          static_cast<std::uint16_t>(ref.info.dc_64bit ? 8 : 4));
      return;
    }
    case DcStep::Sync0Cycle:
      // Slaves without a SYNC0 cycle are finished here.
      for (std::size_t i = 0; i < count_; ++i) {
        if (active(slaves_[i]) && slaves_[i].info.sync0_cycle_ns == 0) slaves_[i].done = true;
      }
      break;
    case DcStep::Done:
      for (std::size_t i = 0; i < count_; ++i) {
        Slave& s = slaves_[i];
        if (!active(s)) continue;
        s.report.status = DcSlaveStatus::Synchronized;
        s.report.step = DcStep::Done;
      }
      status_ = DcSetupStatus::Done;
      return;
    default:
      break;
  }
  for (std::size_t i = 0; i < count_; ++i) {
    if (!slaves_[i].done) slave_step(slaves_[i]);
  }
  advance_if_done();
}

void DcSetup::slave_step(Slave& s) noexcept {
  const std::uint16_t st = s.info.station;
  switch (s.report.step) {
    case DcStep::ReceiveTimes:
      set(s.pending, Command::FPRD, physical_address(st, reg::kDcReceiveTimePort0), kReceiveTimesBytes);
      return;
    case DcStep::Offsets: {
      // Offset 0920h (u64) and delay 0928h (u32) in one write [ETG.1000.4 §6 DC].
      std::array<std::uint8_t, 12> d{};
      put_u64(d, 0, s.report.offset_ns);
      put_u32(d, 8, s.report.delay_ns);
      set(s.pending, Command::FPWR, physical_address(st, reg::kDcSystemTimeOffset), 12, d);
      return;
    }
    case DcStep::Sync0Off: {
      // 0980h = 0: the sync unit belongs to ECAT; 0981h = 0: off, before it is set up again.
      const std::array<std::uint8_t, 2> off{};
      set(s.pending, Command::FPWR, physical_address(st, reg::kDcCyclicUnitControl), 2, off);
      return;
    }
    case DcStep::Sync0Cycle: {
      std::array<std::uint8_t, 4> d{};
      put_u32(d, 0, s.info.sync0_cycle_ns);
      set(s.pending, Command::FPWR, physical_address(st, reg::kDcSync0CycleTime), 4, d);
      return;
    }
    case DcStep::Sync0Start: {
      std::array<std::uint8_t, 8> d{};
      put_u64(d, 0, s.report.sync0_start);
      set(s.pending, Command::FPWR, physical_address(st, reg::kDcSync0StartTime), 8, d);
      return;
    }
    case DcStep::Sync0Activate: {
      const std::array<std::uint8_t, 1> act{dc_activation::kCyclicOperation | dc_activation::kSync0};
      set(s.pending, Command::FPWR, physical_address(st, reg::kDcActivation), 1, act);
      return;
    }
    case DcStep::Sync0Check:
      set(s.pending, Command::FPRD, physical_address(st, reg::kDcCyclicUnitControl), kSyncBlockBytes);
      return;
    default:
      return;
  }
}

void DcSetup::poll(core::TimePoint now, Transactions& tx) noexcept {
  now_ = now;
  if (status_ != DcSetupStatus::Running) return;
  if (now >= deadline_) {
    timeout();
    if (status_ != DcSetupStatus::Running) return;
  }
  switch (phase_) {
    case DcStep::Latch:
    case DcStep::ReferenceTime:
      send(line_pending_, kLineActor, tx);
      return;
    case DcStep::StaticDrift: {
      // As many FRMW as the budget allows, until enough have been answered.
      const Slave& ref = slaves_[*reference_];
      const auto len = static_cast<std::uint16_t>(ref.info.dc_64bit ? 8 : 4);
      if (drift_lost_ > drift_lost_seen_) {
        drift_window_ = std::max(kMinDriftWindow, drift_window_ / 2);
        drift_lost_seen_ = drift_lost_;
      } else if (drift_window_ < config_.static_drift_per_poll) {
        ++drift_window_;
      }
      while (drift_in_flight_ < std::min<std::uint32_t>(drift_window_, config_.static_drift_per_poll) &&
             drift_answered_ + drift_in_flight_ < config_.static_drift_datagrams) {
        if (!tx.queue(this, make_tag(kDriftActor, run_, 0), Command::FRMW,
                      physical_address(ref.info.station, reg::kDcSystemTime), len)) {
          break;
        }
        ++drift_in_flight_;
      }
      return;
    }
    default:
      for (std::size_t i = 0; i < count_; ++i) {
        if (active(slaves_[i]) && !slaves_[i].done) send(slaves_[i].pending, static_cast<std::uint32_t>(i), tx);
      }
      return;
  }
}

void DcSetup::timeout() noexcept {
  const std::string_view what = to_string(phase_);
  switch (phase_) {
    case DcStep::Latch:
    case DcStep::ReferenceTime:
      fail_line("no answer to %.*s within %lld ms", static_cast<int>(what.size()), what.data(),
                ms(config_.step_timeout));
      return;
    case DcStep::StaticDrift:
      fail_line("%.*s: %u of %u answered within %lld ms", static_cast<int>(what.size()), what.data(), drift_answered_,
                config_.static_drift_datagrams, ms(config_.static_drift_timeout));
      return;
    default:
      for (std::size_t i = 0; i < count_; ++i) {
        Slave& s = slaves_[i];
        if (active(s) && !s.done) {
          const std::string_view step = to_string(s.report.step);
          fail(s, "no answer to %.*s within %lld ms", static_cast<int>(step.size()), step.data(),
               ms(config_.step_timeout));
        }
      }
      advance_if_done();
      return;
  }
}

void DcSetup::on_result(std::uint32_t tag, const DatagramAnswer& a) noexcept {
  if (((tag >> 16) & 0xFF) != run_ || status_ != DcSetupStatus::Running) return;
  const std::uint32_t actor = tag >> 24;
  const auto seq = static_cast<std::uint16_t>(tag & 0xFFFF);
  if (actor == kDriftActor) {
    if (phase_ == DcStep::StaticDrift) drift_answer(a);
    return;
  }
  Pending& p = actor == kLineActor ? line_pending_ : slaves_[std::min<std::size_t>(actor, kMaxSlaves - 1)].pending;
  if (actor != kLineActor && (actor >= count_ || !active(slaves_[actor]))) return;
  if (!p.waiting || seq != p.seq) return;
  p.waiting = false;
  if (a.outcome == DatagramOutcome::Lost) {
    if (p.retries_left-- > 0) {
      p.due = true;
      return;
    }
    const std::string_view what = to_string(actor == kLineActor ? phase_ : slaves_[actor].report.step);
    if (actor == kLineActor) {
      fail_line("no answer to %.*s, frame lost %d times", static_cast<int>(what.size()), what.data(),
                config_.retries + 1);
    } else {
      fail(slaves_[actor], "no answer to %.*s, frame lost %d times", static_cast<int>(what.size()), what.data(),
           config_.retries + 1);
      advance_if_done();
    }
    return;
  }
  if (actor == kLineActor) {
    line_answer(a);
  } else {
    slave_answer(slaves_[actor], a);
  }
}

void DcSetup::line_answer(const DatagramAnswer& a) noexcept {
  if (phase_ == DcStep::Latch) {
    // Every DC slave must have latched (non-DC ESCs may count too).
    const auto dc = static_cast<std::size_t>(std::count_if(
        slaves_.begin(), slaves_.begin() + static_cast<std::ptrdiff_t>(count_), [](const Slave& s) { return s.info.dc; }));
    if (a.wkc < dc) {
      fail_line("the receive time latch (BWR 0900h) reached %u slaves, %zu DC slaves expected", a.wkc, dc);
      return;
    }
    enter(DcStep::ReceiveTimes);
    return;
  }
  if (phase_ == DcStep::ReferenceTime) {
    const Slave& ref = slaves_[*reference_];
    if (a.wkc != 1 || a.data.size() < 4) {
      fail_line("reference clock slave %u (0x%04X): FPRD 0910h not executed (WKC %u)", ref.report.position + 1U,
                ref.info.station, a.wkc);
      return;
    }
    if (ref.info.dc_64bit && a.data.size() >= 8) {
      reference_time_ = get_u64(a.data, 0);
    } else {
      // A 32-bit reference: the high half from the master's own system time (offsets made them
      // equal, they are milliseconds apart at most).
      const std::uint64_t m = master_time(now_);
      reference_time_ = m + static_cast<std::uint64_t>(static_cast<std::int64_t>(
                                static_cast<std::int32_t>(get_u32(a.data, 0) - static_cast<std::uint32_t>(m))));
    }
    const auto lead = static_cast<std::uint64_t>(config_.sync0_lead.count());
    for (std::size_t i = 0; i < count_; ++i) {
      Slave& s = slaves_[i];
      if (active(s) && s.info.sync0_cycle_ns != 0) {
        s.report.sync0_start = sync0_start_time(reference_time_, lead, s.info.sync0_cycle_ns, s.info.sync0_shift_ns);
      }
    }
    enter(DcStep::Sync0Cycle);
  }
}

void DcSetup::drift_answer(const DatagramAnswer& a) noexcept {
  if (drift_in_flight_ > 0) --drift_in_flight_;
  if (a.outcome == DatagramOutcome::Lost) {
    ++drift_lost_;
    // A lost FRMW only means one comparison less; the setup fails when losses dominate (a dead
    // reference clock or line), not when a slow peer drops some now and then (the window shrinks,
    // static_drift_timeout bounds the whole step).
    if (drift_lost_ > static_cast<std::uint32_t>(config_.retries) + config_.static_drift_datagrams / 10 &&
        drift_lost_ > drift_answered_) {
      fail_line("static drift compensation (FRMW 0910h): %u datagrams lost (%u answered)", drift_lost_,
                drift_answered_);
    }
    return;
  }
  if (a.wkc == 0) {
    const Slave& ref = slaves_[*reference_];
    fail_line("reference clock slave %u (0x%04X) did not execute FRMW 0910h (WKC 0)", ref.report.position + 1U,
              ref.info.station);
    return;
  }
  ++drift_answered_;
  if (drift_answered_ >= config_.static_drift_datagrams) enter(DcStep::Sync0Off);
}

void DcSetup::slave_answer(Slave& s, const DatagramAnswer& a) noexcept {
  // Every datagram here addresses one slave by its station address: WKC 1 when it executed it.
  if (a.wkc != 1) {
    const std::string_view cmd = command_name(a.command);
    fail(s, "%.*s 0x%04X not executed (WKC %u)", static_cast<int>(cmd.size()), cmd.data(),
         static_cast<unsigned>(a.address >> 16), a.wkc);
    advance_if_done();
    return;
  }
  switch (s.report.step) {
    case DcStep::ReceiveTimes:
      if (a.data.size() < kReceiveTimesBytes) return;
      for (std::size_t p = 0; p < 4; ++p) s.report.port_times[p] = get_u32(a.data, 4 * p);
      s.report.receive_time = get_u64(a.data, reg::kDcReceiveTimeProcessingUnit - reg::kDcReceiveTimePort0);
      if (!s.info.dc_64bit) s.report.receive_time &= 0xFFFFFFFFU;
      s.done = true;
      break;
    case DcStep::Sync0Cycle:
      s.report.step = DcStep::Sync0Start;
      slave_step(s);
      return;
    case DcStep::Sync0Start:
      s.report.step = DcStep::Sync0Activate;
      slave_step(s);
      return;
    case DcStep::Sync0Activate:
      s.report.step = DcStep::Sync0Check;
      slave_step(s);
      return;
    case DcStep::Sync0Check:
      check_sync0(s, a.data);
      break;
    default:  // Offsets, Sync0Off: written
      s.done = true;
      break;
  }
  advance_if_done();
}

void DcSetup::check_sync0(Slave& s, std::span<const std::uint8_t> d) noexcept {
  if (d.size() < kSyncBlockBytes) return;
  // Offsets in the block read from 0980h.
  const std::uint8_t activation = d[reg::kDcActivation - reg::kDcCyclicUnitControl];
  const std::uint8_t status = d[reg::kDcActivationStatus - reg::kDcCyclicUnitControl];
  const std::uint64_t mask = width_mask(s.info.dc_64bit);
  const std::uint64_t next = get_u64(d, reg::kDcSync0StartTime - reg::kDcCyclicUnitControl) & mask;
  const std::uint32_t cycle = get_u32(d, reg::kDcSync0CycleTime - reg::kDcCyclicUnitControl);
  const std::uint64_t start = s.report.sync0_start & mask;
  const std::uint8_t want = dc_activation::kCyclicOperation | dc_activation::kSync0;
  if ((activation & want) != want) {
    fail(s, "SYNC0 activation did not take: 0981h reads 0x%02X, 0x%02X written", activation, want);
  } else if ((status & kActivationStatusStartPast) != 0) {
    fail(s, "SYNC0 start time %llu ns was already past when activated (0984h 0x%02X): the lead of %lld ms is too "
            "short for this line",
         static_cast<unsigned long long>(start), status, ms(config_.sync0_lead));
  } else if (cycle != s.info.sync0_cycle_ns) {
    fail(s, "SYNC0 cycle time reads %u ns, %u ns written", cycle, s.info.sync0_cycle_ns);
  } else {
    // 0990h reads the next pulse: the start time, or start + k·cycle once pulses run.
    const std::uint64_t since = (next - start) & mask;
    const bool on_grid = s.info.dc_64bit ? next >= start : static_cast<std::int32_t>(since) >= 0;
    if (!on_grid || (cycle != 0 && since % cycle != 0) || (cycle == 0 && since != 0)) {
      fail(s, "SYNC0 next pulse at %llu ns is not on the start time %llu ns + k * %u ns",
           static_cast<unsigned long long>(next), static_cast<unsigned long long>(start), cycle);
    } else {
      s.done = true;
    }
  }
}

void DcSetup::compute_delays() noexcept {
  // Line topology only [ETG.1000.4 §6 DC receive times]: a branch anywhere makes round-trip
  // differences meaningless for the slaves behind it.
  for (std::size_t i = 0; i < count_; ++i) {
    const Slave& s = slaves_[i];
    const auto downstream = static_cast<unsigned>(s.info.open_ports & 0x0EU);
    if (std::popcount(downstream) > 1) {
      std::array<char, 16> ports{};  // "1 and 3", "1, 2 and 3"
      std::size_t n = 0;
      int left = std::popcount(downstream);
      for (unsigned p = 1; p < 4; ++p) {
        if ((downstream & (1U << p)) == 0) continue;
        const char* sep = left == 1 ? " and " : (n == 0 ? "" : ", ");
        n += static_cast<std::size_t>(std::snprintf(ports.data() + n, ports.size() - n, "%s%u", sep, p));
        --left;
      }
      fail_line("slave %zu (0x%04X): ports %s open: a branch; propagation delays are computed for a line topology "
                "only",
                i + 1, s.info.station, ports.data());
      return;
    }
  }
  Slave& ref = slaves_[*reference_];
  const std::uint32_t rt_ref = line_round_trip(ref.report.port_times, ref.info.open_ports).value_or(0);
  const std::uint64_t latch = master_time(latch_sent_);
  for (std::size_t i = 0; i < count_; ++i) {
    Slave& s = slaves_[i];
    if (!active(s)) continue;
    s.report.round_trip_ns = line_round_trip(s.report.port_times, s.info.open_ports).value_or(0);
    if (s.report.round_trip_ns > rt_ref) {
      fail(s, "inconsistent receive times: round trip %u ns behind it, %u ns behind the reference clock",
           s.report.round_trip_ns, rt_ref);
      continue;
    }
    s.report.delay_ns = (rt_ref - s.report.round_trip_ns) / 2;
    // At the latch the reference read `latch` (the master's time); this slave latched delay ns
    // later, when the reference read latch + delay.
    s.report.offset_ns = latch + s.report.delay_ns - s.report.receive_time;
  }
}

void DcSetup::advance_if_done() noexcept {
  if (status_ != DcSetupStatus::Running) return;
  // The step ends when every slave finished it (or failed); then a failed reference clock ends the
  // setup (every slave's own failure is in its report by then).
  const bool all = std::all_of(slaves_.begin(), slaves_.begin() + static_cast<std::ptrdiff_t>(count_),
                               [](const Slave& s) { return s.done; });
  if (!all) return;
  const Slave& ref = slaves_[*reference_];
  if (ref.report.status == DcSlaveStatus::Failed) {
    const std::string_view why = ref.report.text.view();
    fail_line("reference clock failed: %.*s", static_cast<int>(why.size()), why.data());
    return;
  }
  switch (phase_) {
    case DcStep::ReceiveTimes: enter(DcStep::Delays); return;
    case DcStep::Offsets: enter(DcStep::StaticDrift); return;
    case DcStep::Sync0Off: enter(DcStep::ReferenceTime); return;
    case DcStep::Sync0Cycle:
    case DcStep::Sync0Start:
    case DcStep::Sync0Activate:
    case DcStep::Sync0Check: enter(DcStep::Done); return;
    default: return;
  }
}

void DcSetup::fail(Slave& s, const char* fmt, ...) noexcept {
  std::array<char, 180> why{};
  va_list args;
  va_start(args, fmt);
  std::vsnprintf(why.data(), why.size(), fmt, args);
  va_end(args);
  s.report.status = DcSlaveStatus::Failed;
  s.pending.due = false;
  s.pending.waiting = false;
  s.done = true;
  s.report.text.format("slave %u (0x%04X): DC: %s", s.report.position + 1U, s.info.station, why.data());
}

void DcSetup::fail_line(const char* fmt, ...) noexcept {
  std::array<char, 220> why{};
  va_list args;
  va_start(args, fmt);
  std::vsnprintf(why.data(), why.size(), fmt, args);
  va_end(args);
  line_text_.format("DC: %s", why.data());
  status_ = DcSetupStatus::Failed;
  line_pending_.due = false;
  for (std::size_t i = 0; i < count_; ++i) slaves_[i].pending.due = false;
}

// ---- DcCyclic -------------------------------------------------------------------------------

namespace {
constexpr std::uint32_t kCyclicFrmw = 1;
constexpr std::uint32_t kCyclicDifference = 2;
// Tag: bits 24-31 kind, 16-23 station index, 0-15 sequence.
constexpr std::uint32_t cyclic_tag(std::uint32_t kind, std::size_t index, std::uint16_t seq) noexcept {
  return (kind << 24) | ((static_cast<std::uint32_t>(index) & 0xFFU) << 16) | seq;
}
}  // namespace

void DcCyclic::configure(std::uint16_t reference_station, bool reference_64bit, std::span<const std::uint16_t> stations,
                         DcCyclicConfig config) noexcept {
  *this = DcCyclic{};
  config_ = config;
  reference_station_ = reference_station;
  reference_64bit_ = reference_64bit;
  station_count_ = std::min(stations.size(), kMaxSlaves);
  std::copy_n(stations.begin(), station_count_, stations_.begin());
  until_difference_ = config.difference_every;
  configured_ = true;
}

bool DcCyclic::configure(const DcSetup& setup, DcCyclicConfig config) noexcept {
  if (setup.status() != DcSetupStatus::Done || !setup.reference()) {
    configured_ = false;
    return false;
  }
  std::array<std::uint16_t, kMaxSlaves> stations{};
  const std::size_t n = setup.synchronized_stations(stations);
  configure(setup.reference_station(), setup.reference_64bit(), std::span<const std::uint16_t>(stations.data(), n),
            config);
  return true;
}

std::uint32_t DcCyclic::sync0_phase(std::uint64_t time, std::uint64_t sync0_start, std::uint32_t cycle_ns) noexcept {
  if (cycle_ns == 0) return 0;
  const auto since = static_cast<std::int64_t>(time - sync0_start);
  const std::int64_t c = cycle_ns;
  return static_cast<std::uint32_t>(((since % c) + c) % c);
}

void DcCyclic::poll(core::TimePoint now, Transactions& tx) noexcept {
  if (!configured_) return;
  ++seq_;
  ++counters_.cycles;
  master_at_poll_ = master_system_time(now, config_.system_time_base_ns);
  // FRMW 0910h: the reference reads its system time into the frame, every other DC slave compares
  // it with its own (cyclic drift compensation) [ETG.1000.4 §5.4 FRMW, §6 DC 0910h].
  if (!tx.queue(this, cyclic_tag(kCyclicFrmw, 0, seq_), Command::FRMW,
                physical_address(reference_station_, reg::kDcSystemTime),
                static_cast<std::uint16_t>(reference_64bit_ ? 8 : 4))) {
    ++counters_.not_queued;
  }
  if (config_.difference_every == 0 || station_count_ == 0) return;
  if (--until_difference_ > 0) return;
  until_difference_ = config_.difference_every;
  ++round_seq_;
  round_left_ = station_count_;
  round_max_ = 0;
  for (std::size_t i = 0; i < station_count_; ++i) {
    if (!tx.queue(this, cyclic_tag(kCyclicDifference, i, round_seq_), Command::FPRD,
                  physical_address(stations_[i], reg::kDcSystemTimeDifference), 4)) {
      ++counters_.not_queued;
      round_left_ = 0;  // this round cannot complete
    }
  }
}

void DcCyclic::on_result(std::uint32_t tag, const DatagramAnswer& a) noexcept {
  const std::uint32_t kind = tag >> 24;
  const std::size_t index = (tag >> 16) & 0xFFU;
  const auto seq = static_cast<std::uint16_t>(tag & 0xFFFF);
  if (kind == kCyclicFrmw) {
    frmw_answer(a);
    return;
  }
  if (kind != kCyclicDifference || seq != round_seq_ || round_left_ == 0 || index >= station_count_) return;
  if (a.outcome == DatagramOutcome::Lost || a.wkc != 1 || a.data.size() < 4) {
    round_left_ = 0;  // incomplete round: the figure keeps the last complete one
    return;
  }
  const std::int32_t diff = decode_system_time_difference(get_u32(a.data, 0));
  differences_[index] = diff;
  round_max_ = std::max(round_max_, static_cast<std::uint32_t>(diff < 0 ? -static_cast<std::int64_t>(diff) : diff));
  if (--round_left_ == 0) {
    max_abs_difference_ = round_max_;
    ++counters_.difference_rounds;
  }
}

void DcCyclic::frmw_answer(const DatagramAnswer& a) noexcept {
  {
    if (a.outcome == DatagramOutcome::Lost) {
      ++counters_.lost;
      return;
    }
    last_wkc_ = a.wkc;
    if (a.wkc == 0 || a.data.size() < 4) {
      ++counters_.no_reference;
      return;
    }
    // The poll that sent it is the latest one unless frames overtake cycles; then the master's
    // time is off by whole cycles and the figure says so.
    const std::uint64_t master = master_at_poll_;
    std::uint64_t t = 0;
    if (reference_64bit_ && a.data.size() >= 8) {
      t = get_u64(a.data, 0);
    } else {
      // 32-bit reference: extended around the previous time (or the master's).
      const std::uint64_t around = has_time_ ? reference_time_ : master;
      t = around + static_cast<std::uint64_t>(static_cast<std::int64_t>(
                       static_cast<std::int32_t>(get_u32(a.data, 0) - static_cast<std::uint32_t>(around))));
    }
    reference_time_ = t;
    master_minus_reference_ = static_cast<std::int64_t>(master - t);
    has_time_ = true;
    ++counters_.answered;
  }
}

}  // namespace drivegate::ethercat
