#include "adapters/ethercat/bus_dc.hpp"

#include <algorithm>
#include <cstdio>

#include "core/bytes.hpp"

namespace drivegate::ethercat {

using core::get_u16;
using core::get_u32;
using core::get_u64;
using core::put_u32;
using core::put_u64;

namespace {

// Tag: bits 30-31 kind, 24-29 slave (6 bits: a line has up to 64; 4 bits sent the answers of
// slaves 17.. to slaves 1.. and timed the others out), 16-23 run, 0-15 sequence.
constexpr std::uint32_t kProbe = 1;
constexpr std::uint32_t kRejoin = 2;
static_assert(BusDc::kMaxSlaves <= 64, "the tag has 6 bits for the slave");
constexpr std::uint32_t make_tag(std::uint32_t kind, std::size_t k, std::uint8_t run, std::uint16_t seq) noexcept {
  return (kind << 30) | ((static_cast<std::uint32_t>(k) & 0x3FU) << 24) | (static_cast<std::uint32_t>(run) << 16) | seq;
}
// FPRD 0900h..092Bh: port receive times, system time, 0918h receive time of the processing unit,
// 0920h offset, 0928h delay [ETG.1000.4 Table 31].
constexpr std::uint16_t kRejoinReadBytes = 0x2C;
// FPRD 0980h..09A3h, as DcSetup's read-back.
constexpr std::uint16_t kSyncBlockBytes = 0x24;
constexpr std::uint8_t kActivationStatusStartPast = 0x04;  // 0984h bit 2
constexpr std::uint8_t kSync0On = dc_activation::kCyclicOperation | dc_activation::kSync0;

std::uint64_t width_mask(bool bits64) noexcept { return bits64 ? ~std::uint64_t{0} : 0xFFFFFFFFU; }

}  // namespace

std::string_view to_string(BusDcLine s) noexcept {
  switch (s) {
    case BusDcLine::Off: return "off";
    case BusDcLine::Idle: return "waiting for the DC slaves' PDO set-up";
    case BusDcLine::Probe: return "reading the ESCs' DC features";
    case BusDcLine::Setup: return "setting up the clocks";
    case BusDcLine::Running: return "running";
  }
  return "?";
}

BusDc::BusDc(Transactions& tx, std::span<const std::uint16_t> stations, std::span<const bool> wanted,
             BusDcConfig config) noexcept
    : tx_(&tx), config_(config) {
  count_ = std::min({stations.size(), wanted.size(), kMaxSlaves});
  bool any = false;
  for (std::size_t k = 0; k < count_; ++k) {
    slaves_[k].station = stations[k];
    slaves_[k].wanted = config.enabled && wanted[k];
    any = any || slaves_[k].wanted;
  }
  line_ = any ? BusDcLine::Idle : BusDcLine::Off;
  restart_line();
}

void BusDc::set_base(std::int64_t system_time_base_ns) noexcept { config_.setup.system_time_base_ns = system_time_base_ns; }

void BusDc::restart_line() noexcept {
  ++run_;
  for (std::size_t k = 0; k < count_; ++k) {
    Slave& s = slaves_[k];
    s.verdict = s.wanted ? Verdict::Wait : Verdict::Free;
    s.probe = Probe::None;
    s.in_setup = s.synced = s.in_cyclic = false;
    s.sync0_start = 0;
    s.pending = Pending{};
    s.text.clear();
  }
  if (line_ != BusDcLine::Off) line_ = BusDcLine::Idle;
  drop_setup();
  tx_->forget(&cyclic_);  // answers of the earlier run
  cyclic_ = DcCyclic{};
  reference_.reset();
  rejoin_.reset();
  rstep_ = Rejoin::None;
}

void BusDc::forget(std::size_t k) noexcept {
  if (k >= count_) return;
  Slave& s = slaves_[k];
  if (!s.wanted) return;
  s.verdict = Verdict::Wait;
  s.synced = false;
  s.in_setup = false;
  s.text.clear();
  if (rejoin_ == k) {
    rejoin_.reset();
    rstep_ = Rejoin::None;
    rpending_ = Pending{};
  }
}

void BusDc::event(bool warning, std::string_view text) noexcept {
  if (event_count_ == events_.size()) return;
  events_[event_count_].text.assign(text);
  events_[event_count_].warning = warning;
  ++event_count_;
}

bool BusDc::take_event(core::FixedString<240>& out, bool& warning) noexcept {
  if (event_count_ == 0) return false;
  out = events_[0].text;
  warning = events_[0].warning;
  for (std::size_t i = 1; i < event_count_; ++i) events_[i - 1] = events_[i];
  --event_count_;
  return true;
}

void BusDc::fail(Slave& s, std::string_view why) noexcept {
  s.verdict = Verdict::Failed;
  s.synced = false;
  s.in_setup = false;
  s.text.assign(why);
}

void BusDc::set(Pending& p, Command command, std::uint32_t address, std::uint16_t length,
                std::span<const std::uint8_t> data) noexcept {
  p.due = true;
  p.waiting = false;
  p.retries_left = config_.setup.retries;
  p.command = command;
  p.address = address;
  p.length = length;
  p.data_size = std::min(data.size(), p.data.size());
  std::copy_n(data.begin(), p.data_size, p.data.begin());
}

void BusDc::send(Pending& p, std::uint32_t actor, Transactions& tx) noexcept {
  if (!p.due || p.waiting) return;
  ++p.seq;
  const std::uint32_t kind = actor >> 8;
  if (tx.queue(this, make_tag(kind, actor & 0xFFU, run_, p.seq), p.command, p.address, p.length,
               std::span<const std::uint8_t>(p.data.data(), p.data_size))) {
    p.due = false;
    p.waiting = true;
  }
}

// ---- Line ---------------------------------------------------------------------------------------

void BusDc::step(core::TimePoint now, std::span<const BusDcView> views) noexcept {
  now_ = now;
  if (line_ == BusDcLine::Off) return;
  const std::size_t n = std::min(views.size(), count_);
  if (line_ == BusDcLine::Idle) {
    bool any_at_sync = false;
    bool any_configuring = false;
    for (std::size_t k = 0; k < n; ++k) {
      if (!slaves_[k].wanted) continue;
      any_at_sync = any_at_sync || views[k].at_sync;
      any_configuring = any_configuring || views[k].configuring;
    }
    // The line's setup waits for every wanted slave that is on its way (lost ones come later).
    if (any_at_sync && !any_configuring) start_line(views);
    return;
  }
  if (line_ == BusDcLine::Setup) {
    if (setup_ && setup_->status() != DcSetupStatus::Running) setup_done();
    return;
  }
  if (line_ != BusDcLine::Running) return;
  if (rejoin_) {
    if (now >= deadline_ && rstep_ != Rejoin::Settle) {
      rejoin_fail("no answer in time");
    } else if (rstep_ == Rejoin::Settle && rsettle_ > 0 && --rsettle_ == 0) {
      rstep_ = Rejoin::Sync0Off;
      rejoin_step();
    }
    return;
  }
  // A wanted slave in the DC step after the line's setup: its own run, one at a time. It needs
  // the reference clock running (or is the reference).
  for (std::size_t k = 0; k < n; ++k) {
    const Slave& s = slaves_[k];
    if (!s.wanted || s.verdict != Verdict::Wait || !views[k].at_sync) continue;
    if (reference_ && *reference_ != k && !(slaves_[*reference_].synced && views[*reference_].running)) continue;
    start_rejoin(k);
    return;
  }
}

void BusDc::start_line(std::span<const BusDcView> views) noexcept {
  ++run_;
  line_ = BusDcLine::Probe;
  deadline_ = now_ + config_.setup.step_timeout;
  for (std::size_t k = 0; k < count_; ++k) {
    Slave& s = slaves_[k];
    s.in_setup = false;
    s.probe = Probe::None;
    s.dc = false;
    s.open_ports = 0x01;
    if (k >= views.size() || !views[k].present) continue;
    // Every present slave: its open ports matter to the delays (a branch anywhere is refused).
    s.in_setup = s.wanted && views[k].at_sync;
    s.probe = Probe::Features;
    set(s.pending, Command::FPRD, physical_address(s.station, reg::kEscFeatures), 2);
  }
}

void BusDc::probe_answer(std::size_t k, const DatagramAnswer& a) noexcept {
  Slave& s = slaves_[k];
  if (a.outcome == DatagramOutcome::Lost && s.pending.retries_left-- > 0) {
    s.pending.due = true;
    return;
  }
  const bool ok = a.outcome == DatagramOutcome::Answered && a.wkc == 1 && a.data.size() >= 2;
  if (s.probe == Probe::Features) {
    if (ok) {
      const std::uint16_t f = get_u16(a.data, 0);
      s.dc = features_dc(f);
      s.dc_64bit = features_dc_64bit(f);
    }
    s.probe = Probe::DlStatus;
    set(s.pending, Command::FPRD, physical_address(s.station, reg::kDlStatus), 2);
  } else if (s.probe == Probe::DlStatus) {
    if (ok) s.open_ports = open_ports(get_u16(a.data, 0));
    s.probe = Probe::Done;
  }
  if (!ok && s.in_setup) {
    core::FixedString<200> why;
    why.format("DC: no answer to the ESC feature / DL status read (FPRD 0x%04X)", static_cast<unsigned>(a.address >> 16));
    fail(s, why.view());
  }
  if (std::all_of(slaves_.begin(), slaves_.begin() + static_cast<std::ptrdiff_t>(count_),
                  [](const Slave& x) { return x.probe == Probe::None || x.probe == Probe::Done; })) {
    probes_done();
  }
}

void BusDc::probes_done() noexcept {
  std::array<DcSlaveInfo, kMaxSlaves> infos{};
  for (std::size_t k = 0; k < count_; ++k) {
    Slave& s = slaves_[k];
    infos[k].station = s.station;
    infos[k].open_ports = s.open_ports;
    infos[k].dc_64bit = s.dc_64bit;
    if (!s.in_setup || s.verdict == Verdict::Failed) continue;
    if (!s.dc) {
      // The profile asks for SYNC0, the ESC has no DC unit (0008h bit 2 clear): free run.
      s.in_setup = false;
      s.verdict = Verdict::Free;
      core::FixedString<240> w;
      w.format("slave %zu (0x%04X): its device profile asks for distributed clocks, its ESC has none (0008h bit 2): "
               "it runs free",
               k + 1, s.station);
      event(true, w.view());
      continue;
    }
    infos[k].dc = true;
    infos[k].sync0_cycle_ns = config_.cycle_ns;
    infos[k].sync0_shift_ns = config_.shift_ns;
  }
  drop_setup();
  setup_.emplace(std::span<const DcSlaveInfo>(infos.data(), count_), config_.setup);
  setup_->start(now_);
  line_ = BusDcLine::Setup;
  if (setup_->status() != DcSetupStatus::Running) setup_done();
}

void BusDc::setup_done() noexcept {
  const DcSetup& d = *setup_;
  if (d.status() == DcSetupStatus::Failed) {
    for (std::size_t k = 0; k < count_; ++k) {
      Slave& s = slaves_[k];
      if (s.in_setup) fail(s, d.line_text());
    }
    event(true, d.line_text());
    line_ = BusDcLine::Idle;  // again when the slaves come back
    return;
  }
  reference_ = d.reference();
  std::size_t synced = 0;
  for (std::size_t k = 0; k < count_; ++k) {
    Slave& s = slaves_[k];
    if (!s.in_setup) continue;
    s.in_setup = false;
    const DcSlaveReport& r = d.slave(k);
    if (r.status == DcSlaveStatus::Synchronized) {
      s.verdict = Verdict::Sync0;
      s.synced = true;
      s.sync0_start = r.sync0_start;
      if (r.reference) reference_offset_ = r.offset_ns;
      ++synced;
    } else if (r.status == DcSlaveStatus::Failed) {
      fail(s, r.text.view());
    }
  }
  if (!reference_) {  // no DC slave took part (none with a DC unit)
    line_ = BusDcLine::Idle;
    return;
  }
  line_ = BusDcLine::Running;
  refresh_cyclic();
  core::FixedString<240> t;
  t.format("distributed clocks: reference clock slave %zu (0x%04X), SYNC0 every %u ns (shift %d ns) on %zu slave%s",
           *reference_ + 1, slaves_[*reference_].station, config_.cycle_ns, config_.shift_ns, synced,
           synced == 1 ? "" : "s");
  event(false, t.view());
}

void BusDc::refresh_cyclic() noexcept {
  if (!reference_) return;
  std::array<std::uint16_t, kMaxSlaves> stations{};
  std::size_t n = 0;
  bool changed = false;
  // The reference clock's own 092Ch compares nothing (it reads the FRMW, it does not take it): it
  // holds whatever the last write to 0910h left, e.g. the line reset's [ETG.1000.4 §6 DC 092Ch].
  for (std::size_t k = 0; k < count_; ++k) {
    Slave& s = slaves_[k];
    const bool in = k != *reference_ && (s.synced || s.in_cyclic);  // once synced, stays in the rounds
    changed = changed || in != s.in_cyclic;
    s.in_cyclic = in;
    if (in) stations[n++] = s.station;
  }
  if (!changed && cyclic_.configured()) return;
  DcCyclicConfig c;
  c.system_time_base_ns = config_.setup.system_time_base_ns;
  c.difference_every = config_.difference_every;
  cyclic_.configure(slaves_[*reference_].station, slaves_[*reference_].dc_64bit,
                    std::span<const std::uint16_t>(stations.data(), n), c);
}

// ---- Cycle --------------------------------------------------------------------------------------

void BusDc::poll_cyclic(core::TimePoint now, Transactions& tx) noexcept {
  if (line_ != BusDcLine::Running || !reference_ || !cyclic_.configured()) return;
  const std::size_t r = *reference_;
  const bool reference_time_valid =
      slaves_[r].synced || (rejoin_ == r && rstep_ >= Rejoin::Settle);
  if (reference_time_valid) cyclic_.poll(now, tx);
}

void BusDc::poll(core::TimePoint now, Transactions& tx) noexcept {
  now_ = now;
  switch (line_) {
    case BusDcLine::Probe:
      if (now >= deadline_) {
        for (std::size_t k = 0; k < count_; ++k) {
          Slave& s = slaves_[k];
          if (s.probe == Probe::None || s.probe == Probe::Done) continue;
          s.probe = Probe::Done;
          s.pending = Pending{};
          if (s.in_setup) fail(s, "DC: no answer to the ESC feature / DL status read in time");
        }
        probes_done();
        return;
      }
      for (std::size_t k = 0; k < count_; ++k) send(slaves_[k].pending, (kProbe << 8) | static_cast<std::uint32_t>(k), tx);
      return;
    case BusDcLine::Setup:
      setup_->poll(now, tx);
      return;
    case BusDcLine::Running:
      if (rejoin_) send(rpending_, (kRejoin << 8) | static_cast<std::uint32_t>(*rejoin_), tx);
      return;
    default:
      return;
  }
}

void BusDc::on_result(std::uint32_t tag, const DatagramAnswer& a) noexcept {
  const std::uint32_t kind = tag >> 30;
  const std::size_t k = (tag >> 24) & 0x3FU;
  if (((tag >> 16) & 0xFFU) != run_ || k >= count_) return;
  const auto seq = static_cast<std::uint16_t>(tag & 0xFFFF);
  if (kind == kProbe) {
    Slave& s = slaves_[k];
    if (line_ != BusDcLine::Probe || !s.pending.waiting || seq != s.pending.seq) return;
    s.pending.waiting = false;
    probe_answer(k, a);
  } else if (kind == kRejoin) {
    if (rejoin_ != k || !rpending_.waiting || seq != rpending_.seq) return;
    rpending_.waiting = false;
    if (a.outcome == DatagramOutcome::Lost && rpending_.retries_left-- > 0) {
      rpending_.due = true;
      return;
    }
    rejoin_answer(a);
  }
}

void BusDc::drop_setup() noexcept {
  // Its datagrams still in flight must not reach a destroyed (or a new) DcSetup.
  if (setup_) tx_->forget(&*setup_);
  setup_.reset();
}

void BusDc::forget_all() noexcept {
  tx_->forget(this);
  drop_setup();
  tx_->forget(&cyclic_);
}

// ---- Rejoin -------------------------------------------------------------------------------------

void BusDc::start_rejoin(std::size_t k) noexcept {
  rejoin_ = k;
  ++rejoins_;
  rstep_ = Rejoin::Features;
  rejoin_step();
}

void BusDc::rejoin_fail(const char* what) noexcept {
  const std::size_t k = *rejoin_;
  core::FixedString<200> why;
  why.format("slave %zu (0x%04X): DC: %s", k + 1, slaves_[k].station, what);
  fail(slaves_[k], why.view());
  rejoin_.reset();
  rstep_ = Rejoin::None;
  rpending_ = Pending{};
}

void BusDc::rejoin_step() noexcept {
  const Slave& s = slaves_[*rejoin_];
  const std::uint16_t st = s.station;
  deadline_ = now_ + config_.setup.step_timeout;
  switch (rstep_) {
    case Rejoin::Features: set(rpending_, Command::FPRD, physical_address(st, reg::kEscFeatures), 2); return;
    case Rejoin::DlStatus: set(rpending_, Command::FPRD, physical_address(st, reg::kDlStatus), 2); return;
    case Rejoin::Latch: {
      // A write to 0900h latches the receive times in every ESC the frame passes [ETG.1000.4 §6].
      const std::array<std::uint8_t, 4> zero{};
      set(rpending_, Command::BWR, physical_address(0, reg::kDcReceiveTimePort0), 4, zero);
      rlatch_ = now_;
      return;
    }
    case Rejoin::ReadSlave:
      set(rpending_, Command::FPRD, physical_address(st, reg::kDcReceiveTimePort0), kRejoinReadBytes);
      return;
    case Rejoin::ReadReference:
      set(rpending_, Command::FPRD, physical_address(slaves_[*reference_].station, reg::kDcReceiveTimePort0),
          kRejoinReadBytes);
      return;
    case Rejoin::Offset: {
      std::array<std::uint8_t, 12> d{};
      put_u64(d, 0, rjoin_offset_);
      put_u32(d, 8, rjoin_delay_);
      set(rpending_, Command::FPWR, physical_address(st, reg::kDcSystemTimeOffset), 12, d);
      return;
    }
    case Rejoin::Settle:
      rsettle_ = std::max<std::uint32_t>(config_.settle_cycles, 1);
      return;
    case Rejoin::Sync0Off: {
      const std::array<std::uint8_t, 2> off{};
      set(rpending_, Command::FPWR, physical_address(st, reg::kDcCyclicUnitControl), 2, off);
      return;
    }
    case Rejoin::ReadTime:
      set(rpending_, Command::FPRD, physical_address(st, reg::kDcSystemTime),
          static_cast<std::uint16_t>(s.dc_64bit ? 8 : 4));
      return;
    case Rejoin::Cycle: {
      std::array<std::uint8_t, 4> d{};
      put_u32(d, 0, config_.cycle_ns);
      set(rpending_, Command::FPWR, physical_address(st, reg::kDcSync0CycleTime), 4, d);
      return;
    }
    case Rejoin::Start: {
      std::array<std::uint8_t, 8> d{};
      put_u64(d, 0, s.sync0_start);
      set(rpending_, Command::FPWR, physical_address(st, reg::kDcSync0StartTime), 8, d);
      return;
    }
    case Rejoin::Activate: {
      const std::array<std::uint8_t, 1> act{kSync0On};
      set(rpending_, Command::FPWR, physical_address(st, reg::kDcActivation), 1, act);
      return;
    }
    case Rejoin::Check:
      set(rpending_, Command::FPRD, physical_address(st, reg::kDcCyclicUnitControl), kSyncBlockBytes);
      return;
    case Rejoin::None: return;
  }
}

void BusDc::rejoin_answer(const DatagramAnswer& a) noexcept {
  const std::size_t k = *rejoin_;
  Slave& s = slaves_[k];
  const bool is_reference = reference_ == k;
  if (a.outcome != DatagramOutcome::Answered) {
    rejoin_fail("no answer (frame lost)");
    return;
  }
  if (rstep_ == Rejoin::Latch) {
    if (a.wkc == 0) {
      rejoin_fail("the receive time latch (BWR 0900h) reached no slave");
      return;
    }
    rstep_ = Rejoin::ReadSlave;
    rejoin_step();
    return;
  }
  if (a.wkc != 1) {
    core::FixedString<80> w;
    w.format("%s 0x%04X not executed (WKC %u)", command_name(a.command).data(), static_cast<unsigned>(a.address >> 16),
             a.wkc);
    rejoin_fail(w.c_str());
    return;
  }
  switch (rstep_) {
    case Rejoin::Features: {
      const std::uint16_t f = a.data.size() >= 2 ? get_u16(a.data, 0) : 0;
      s.dc = features_dc(f);
      s.dc_64bit = features_dc_64bit(f);
      if (!s.dc) {  // another device now, or the ESC has no DC unit
        s.verdict = Verdict::Free;
        rejoin_.reset();
        rstep_ = Rejoin::None;
        core::FixedString<240> w;
        w.format("slave %zu (0x%04X): its device profile asks for distributed clocks, its ESC has none (0008h bit 2): "
                 "it runs free",
                 k + 1, s.station);
        event(true, w.view());
        return;
      }
      rstep_ = Rejoin::DlStatus;
      break;
    }
    case Rejoin::DlStatus:
      s.open_ports = a.data.size() >= 2 ? open_ports(get_u16(a.data, 0)) : std::uint8_t{0x01};
      if (reference_ && *reference_ > k) {
        // In front of the reference clock: its delay would count against the frame's direction.
        // A line restart makes it the reference; until then it runs free.
        s.verdict = Verdict::Free;
        rejoin_.reset();
        rstep_ = Rejoin::None;
        core::FixedString<240> w;
        w.format("slave %zu (0x%04X): in front of the DC reference clock (slave %zu): it runs free until the line "
                 "starts again",
                 k + 1, s.station, *reference_ + 1);
        event(true, w.view());
        return;
      }
      rstep_ = Rejoin::Latch;
      break;
    case Rejoin::ReadSlave:
      if (a.data.size() < kRejoinReadBytes) return;
      for (std::size_t p = 0; p < 4; ++p) rk_ports_[p] = get_u32(a.data, 4 * p);
      rk_receive_ = get_u64(a.data, reg::kDcReceiveTimeProcessingUnit - reg::kDcReceiveTimePort0) & width_mask(s.dc_64bit);
      if (is_reference) {
        // The reference clock itself: the master's time at the latch, corrected by how far the
        // master's clock was from the reference's before it was lost.
        const std::int64_t m = cyclic_.has_reference_time() ? cyclic_.master_minus_reference_ns() : 0;
        rjoin_delay_ = 0;
        rjoin_offset_ = (master_time(rlatch_) - static_cast<std::uint64_t>(m) - rk_receive_) & width_mask(s.dc_64bit);
        reference_offset_ = rjoin_offset_;
        rstep_ = Rejoin::Offset;
      } else {
        rstep_ = Rejoin::ReadReference;
      }
      break;
    case Rejoin::ReadReference: {
      if (a.data.size() < kRejoinReadBytes) return;
      const Slave& ref = slaves_[*reference_];
      for (std::size_t p = 0; p < 4; ++p) rref_ports_[p] = get_u32(a.data, 4 * p);
      rref_receive_ = get_u64(a.data, reg::kDcReceiveTimeProcessingUnit - reg::kDcReceiveTimePort0);
      rref_offset_ = get_u64(a.data, reg::kDcSystemTimeOffset - reg::kDcReceiveTimePort0);
      const auto rt_ref = line_round_trip(rref_ports_, ref.open_ports);
      const auto rt_k = line_round_trip(rk_ports_, s.open_ports);
      if (!rt_ref || !rt_k || *rt_k > *rt_ref) {
        rejoin_fail("inconsistent receive times or a branch: the propagation delay cannot be computed");
        return;
      }
      rjoin_delay_ = (*rt_ref - *rt_k) / 2;
      // The reference's system time at the latch (0918h + 0920h), reached here delay ns later.
      const std::uint64_t ref_time = (rref_receive_ + rref_offset_) & width_mask(ref.dc_64bit);
      rjoin_offset_ = (ref_time + rjoin_delay_ - rk_receive_) & width_mask(s.dc_64bit);
      rstep_ = Rejoin::Offset;
      break;
    }
    case Rejoin::Offset: rstep_ = Rejoin::Settle; break;
    case Rejoin::Sync0Off: rstep_ = Rejoin::ReadTime; break;
    case Rejoin::ReadTime: {
      std::uint64_t t = 0;
      if (s.dc_64bit && a.data.size() >= 8) {
        t = get_u64(a.data, 0);
      } else if (a.data.size() >= 4) {
        const std::uint64_t around = cyclic_.has_reference_time() ? cyclic_.reference_time() : master_time(now_);
        t = around + static_cast<std::uint64_t>(static_cast<std::int64_t>(
                         static_cast<std::int32_t>(get_u32(a.data, 0) - static_cast<std::uint32_t>(around))));
      }
      s.sync0_start = sync0_start_time(t, static_cast<std::uint64_t>(config_.setup.sync0_lead.count()), config_.cycle_ns,
                                       config_.shift_ns);
      rstep_ = Rejoin::Cycle;
      break;
    }
    case Rejoin::Cycle: rstep_ = Rejoin::Start; break;
    case Rejoin::Start: rstep_ = Rejoin::Activate; break;
    case Rejoin::Activate: rstep_ = Rejoin::Check; break;
    case Rejoin::Check: {
      if (a.data.size() < kSyncBlockBytes) return;
      const std::uint8_t act = a.data[reg::kDcActivation - reg::kDcCyclicUnitControl];
      const std::uint8_t status = a.data[reg::kDcActivationStatus - reg::kDcCyclicUnitControl];
      const std::uint32_t cycle = get_u32(a.data, reg::kDcSync0CycleTime - reg::kDcCyclicUnitControl);
      if ((act & kSync0On) != kSync0On) {
        rejoin_fail("SYNC0 activation did not take (0981h)");
      } else if ((status & kActivationStatusStartPast) != 0) {
        rejoin_fail("SYNC0 start time was already past when activated (0984h bit 2)");
      } else if (cycle != config_.cycle_ns) {
        rejoin_fail("SYNC0 cycle time read back differs (09A0h)");
      } else {
        s.verdict = Verdict::Sync0;
        s.synced = true;
        rejoin_.reset();
        rstep_ = Rejoin::None;
        refresh_cyclic();
      }
      return;
    }
    case Rejoin::Latch:
    case Rejoin::Settle:
    case Rejoin::None: return;
  }
  rejoin_step();
}

}  // namespace drivegate::ethercat
