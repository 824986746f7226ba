#include "adapters/ethercat/master/line_boot.hpp"

#include <algorithm>
#include <cstdarg>

#include "adapters/ethercat/wire/al_status.hpp"
#include "core/bytes.hpp"

namespace drivegate::ethercat {

using core::get_u16;
using core::put_u16;
using core::put_u32;

namespace {

// Tag layout: bits 24-31 actor (slave position, or the line), 16-23 item of a group, 12-15 run
// generation (start() counts it up: answers of a previous run are ignored), 0-11 sequence number
// (answers of an abandoned datagram are recognised and ignored).
constexpr std::uint16_t kSeqMask = 0x0FFF;
constexpr std::uint32_t make_tag(std::uint32_t actor, std::uint32_t item, std::uint8_t run, std::uint16_t seq) noexcept {
  return (actor << 24) | ((item & 0xFF) << 16) | (static_cast<std::uint32_t>(run & 0x0F) << 12) | (seq & kSeqMask);
}
constexpr std::uint16_t next_seq(std::uint16_t seq) noexcept { return static_cast<std::uint16_t>((seq + 1) & kSeqMask); }

// Reset group items.
enum ResetItem : std::uint32_t {
  kResetFmmus, kResetSms, kResetDcActivation, kResetDcTime, kResetDcOffset, kResetDcDelay, kResetDcSpeed,
  kResetDcFilter, kResetAlias, kResetAlControl, kResetEepromForce, kResetEepromMaster, kResetCount,
};

constexpr std::size_t kFmmuBlockBytes = 16 * reg::kFmmuSize;  // 16 FMMUs [ETG.1000.4 Table 56]
constexpr std::size_t kSmBlockBytes = 16 * reg::kSmSize;      // 16 SyncManagers [ETG.1000.4 Table 59]
constexpr std::array<std::uint8_t, kFmmuBlockBytes> kZeros{};

// End of the SII category list within the bytes read so far: the category list starts at word
// 40h, each category is type, size (words), data [ETG.1000.6 §5.4]. `at` is the offset of the next
// category header not yet walked (kSiiHeaderBytes at first); it is advanced over the categories
// whose header has been read, so each chunk walks only what is new. Returns true when the end
// marker (type FFFFh) has been read.
bool sii_end_seen(std::span<const std::uint8_t> image, std::size_t& at) noexcept {
  while (at + 2 <= image.size()) {
    if (get_u16(image, at) == static_cast<std::uint16_t>(SiiCategory::End)) return true;
    if (at + 4 > image.size()) return false;
    at += 4 + 2 * static_cast<std::size_t>(get_u16(image, at + 2));
  }
  return false;
}

}  // namespace

std::string_view to_string(BootStep s) noexcept {
  switch (s) {
    case BootStep::Count: return "count";
    case BootStep::Reset: return "reset";
    case BootStep::Address: return "station address";
    case BootStep::Sii: return "SII";
    case BootStep::Identity: return "identity";
    case BootStep::Mailbox: return "mailbox";
    case BootStep::Transition: return "state transition";
  }
  return "?";
}

std::string_view to_string(SlaveStatus s) noexcept {
  switch (s) {
    case SlaveStatus::Pending: return "pending";
    case SlaveStatus::Busy: return "busy";
    case SlaveStatus::Ready: return "ready";
    case SlaveStatus::Failed: return "failed";
    case SlaveStatus::Extra: return "not configured";
  }
  return "?";
}

LineBoot::LineBoot(std::span<const ExpectedSlave> expected, LineBootConfig config) : config_(config) {
  expected_count_ = std::min(expected.size(), kMaxSlaves);
  std::copy_n(expected.begin(), expected_count_, expected_.begin());
  capacity_ = std::min(kMaxSlaves, std::max(kMinSlots, expected_count_ + kSpareSlots));
  slaves_ = std::make_unique<Slave[]>(capacity_);
}

LineBoot::~LineBoot() = default;

void LineBoot::start(core::TimePoint now) noexcept {
  now_ = now;
  run_ = static_cast<std::uint8_t>((run_ + 1) & 0x0F);
  line_ = LinePhase::Count;
  line_text_.assign("");
  found_ = 0;
  group_left_ = 0;
  group_due_ = false;
  for (auto& s : std::span<Slave>(slaves_.get(), capacity_)) {
    s.phase = Phase::Idle;
    s.pending = Pending{};
    s.report = SlaveReport{};
    s.restart = false;
  }
  line_pending_ = Pending{};
  set(line_pending_, Command::BRD, physical_address(0, reg::kType), 2);
}

void LineBoot::set(Pending& p, Command command, std::uint32_t address, std::uint16_t length,
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

void LineBoot::send(Pending& p, std::uint32_t actor, Transactions& tx) noexcept {
  if (!p.due || p.waiting) return;
  p.seq = next_seq(p.seq);
  if (tx.queue(this, make_tag(actor, 0, run_, p.seq), p.command, p.address, p.length,
               std::span<const std::uint8_t>(p.data.data(), p.data_size))) {
    p.due = false;
    p.waiting = true;
  }  // else: no room this cycle, stays due
}

void LineBoot::queue_reset(Transactions& tx) noexcept {
  // One frame of broadcast writes bringing every slave to a known state (the registers SOEM's and
  // EtherCrab's start-ups reset), processed by each slave in this order: FMMUs and SMs off
  // [ETG.1000.4 Tables 56, 59], DC off and its filters at their reset values [ETG.1000.4 §6 DC
  // registers], the station alias off (DL control byte 0103h bit 0 [ETG.1000.4 Table 31]), and
  // only then AL control INIT + acknowledge [ETG.1000.6 §5.3.2], so no SM or FMMU is left active
  // while the slave goes to INIT. Last the EEPROM interface is taken for EtherCAT: 0500h = 2 forces
  // the PDI's access off, 0500h = 0 leaves it with EtherCAT [ETG.1000.4 §6.4.2, Table 47].
  group_seq_ = next_seq(group_seq_);
  group_left_ = 0;
  group_lost_ = group_bad_ = false;
  const auto bwr = [&](std::uint32_t item, std::uint16_t reg, std::span<const std::uint8_t> data) {
    if (tx.queue(this, make_tag(kLineActor, item, run_, group_seq_), Command::BWR, physical_address(0, reg),
                 static_cast<std::uint16_t>(data.size()), data)) {
      ++group_left_;
    } else {
      group_lost_ = true;
    }
  };
  const auto zeros = [](std::size_t n) { return std::span<const std::uint8_t>(kZeros).first(n); };
  bwr(kResetFmmus, reg::kFmmu0, kZeros);
  bwr(kResetSms, reg::kSm0, zeros(kSmBlockBytes));
  bwr(kResetDcActivation, reg::kDcActivation, zeros(1));
  bwr(kResetDcTime, reg::kDcSystemTime, zeros(8));
  bwr(kResetDcOffset, reg::kDcSystemTimeOffset, zeros(8));
  bwr(kResetDcDelay, reg::kDcSystemTimeDelay, zeros(4));
  std::array<std::uint8_t, 2> speed{};
  put_u16(speed, 0, 0x1000);  // speed counter start: the ESC's reset value
  bwr(kResetDcSpeed, reg::kDcSpeedCounterStart, speed);
  // 0934h system time difference filter depth 0, 0935h speed counter filter depth 0Ch: the u16
  // 0C00h SOEM writes at 0934h.
  const std::array<std::uint8_t, 2> filter{0x00, 0x0C};
  bwr(kResetDcFilter, reg::kDcTimeDifferenceFilterDepth, filter);
  bwr(kResetAlias, static_cast<std::uint16_t>(reg::kDlControl + 3), zeros(1));
  std::array<std::uint8_t, 2> al{};
  put_u16(al, 0, al_control(AlState::Init, true));
  bwr(kResetAlControl, reg::kAlControl, al);
  const std::array<std::uint8_t, 1> force{0x02};
  bwr(kResetEepromForce, reg::kSiiConfig, force);
  bwr(kResetEepromMaster, reg::kSiiConfig, zeros(1));
  group_due_ = false;
  if (group_left_ == 0) line_group_done();
}

void LineBoot::queue_addresses(Transactions& tx) noexcept {
  group_seq_ = next_seq(group_seq_);
  group_left_ = 0;
  group_lost_ = group_bad_ = false;
  for (std::size_t pos = 0; pos < found_; ++pos) {
    std::array<std::uint8_t, 2> station{};
    put_u16(station, 0, static_cast<std::uint16_t>(config_.first_station + pos));
    const auto p = static_cast<std::uint16_t>(pos);
    if (tx.queue(this, make_tag(kLineActor, static_cast<std::uint32_t>(pos), run_, group_seq_), Command::APWR,
                 physical_address(auto_increment_adp(p), reg::kStationAddress), 2, station)) {
      ++group_left_;
    } else {
      group_lost_ = true;
    }
  }
  group_due_ = false;
  if (group_left_ == 0) line_group_done();
}

void LineBoot::poll(core::TimePoint now, Transactions& tx) noexcept {
  now_ = now;
  switch (line_) {
    case LinePhase::Count:
      send(line_pending_, kLineActor, tx);
      break;
    case LinePhase::Reset:
      if (group_due_) queue_reset(tx);
      break;
    case LinePhase::ResetWait:
      if (!line_pending_.waiting && now >= reset_deadline_) {
        fail_line("reset: not every slave in INIT after %lld ms (BRD 0x0130: AL status 0x%04X OR-ed over %u of %zu "
                  "slaves)",
                  static_cast<long long>(std::chrono::duration_cast<std::chrono::milliseconds>(config_.to_lower_state).count()), reset_status_, reset_wkc_,
                  found_);
        break;
      }
      send(line_pending_, kLineActor, tx);
      break;
    case LinePhase::Address:
      if (group_due_) queue_addresses(tx);
      break;
    case LinePhase::Slaves:
    case LinePhase::Done:
      for (std::size_t i = 0; i < found_; ++i) {
        Slave& s = slaves_[i];
        if (s.report.status != SlaveStatus::Busy) continue;
        // Timeouts of the polling phases are checked when an answer comes in and here, so that a
        // slave that keeps answering "busy" cannot hold the step forever.
        if ((s.phase == Phase::AlPoll || s.phase == Phase::AlAckPoll || s.phase == Phase::SiiBusy ||
             s.phase == Phase::SiiStatus) &&
            now >= s.deadline && !s.pending.waiting) {
          if (s.phase == Phase::SiiBusy || s.phase == Phase::SiiStatus) {
            fail(s, BootStep::Sii, "SII read of word 0x%04X timed out (EEPROM busy)", s.sii_word);
          } else if (s.phase == Phase::AlAckPoll) {
            const std::string_view why = al_status_text(s.report.al_code);
            fail(s, BootStep::Transition,
                 "%.*s -> %.*s: error indication not cleared by the acknowledge (AL status 0x%04X, code 0x%04X %.*s)",
                 static_cast<int>(to_string(s.from).size()), to_string(s.from).data(),
                 static_cast<int>(to_string(s.report.target).size()), to_string(s.report.target).data(),
                 s.al_status_raw, s.report.al_code, static_cast<int>(why.size()), why.data());
          } else {
            const AlStatus st = decode_al_status(s.al_status_raw);
            fail(s, BootStep::Transition, "%.*s -> %.*s timed out (AL status 0x%04X %.*s)",
                 static_cast<int>(to_string(s.from).size()), to_string(s.from).data(),
                 static_cast<int>(to_string(s.report.target).size()), to_string(s.report.target).data(),
                 s.al_status_raw, static_cast<int>(to_string(st.state()).size()), to_string(st.state()).data());
          }
          continue;
        }
        send(s.pending, static_cast<std::uint32_t>(i), tx);
      }
      if (line_ == LinePhase::Slaves &&
          std::none_of(slaves_.get(), slaves_.get() + found_,
                       [](const Slave& s) { return s.report.status == SlaveStatus::Busy; })) {
        line_ = LinePhase::Done;
      }
      break;
    case LinePhase::Idle:
    case LinePhase::Failed:
      break;
  }
}

void LineBoot::on_result(std::uint32_t tag, const DatagramAnswer& a) noexcept {
  const std::uint32_t actor = tag >> 24;
  const auto seq = static_cast<std::uint16_t>(tag & kSeqMask);
  if (((tag >> 12) & 0x0F) != run_) return;  // queued by an earlier run (start() since)
  if (actor == kLineActor) {
    if (line_ == LinePhase::Count) {
      if (!line_pending_.waiting || seq != line_pending_.seq) return;
      line_pending_.waiting = false;
      line_answer(a);
      return;
    }
    if (line_ == LinePhase::ResetWait) {
      if (!line_pending_.waiting || seq != line_pending_.seq) return;
      line_pending_.waiting = false;
      reset_wait_answer(a);
      return;
    }
    if ((line_ != LinePhase::Reset && line_ != LinePhase::Address) || seq != group_seq_ || group_left_ == 0) return;
    const std::uint32_t item = (tag >> 16) & 0xFF;
    if (a.outcome == DatagramOutcome::Lost) {
      group_lost_ = true;
    } else if (line_ == LinePhase::Reset && item == kResetAlControl && a.wkc != found_) {
      group_bad_ = true;
      line_text_.format("reset: %u of %zu slaves took AL control INIT", a.wkc, found_);
    } else if (line_ == LinePhase::Address && a.wkc != 1) {
      group_bad_ = true;
      line_text_.format("slave %u (position %u): no answer to its station address write (WKC %u)", item + 1, item,
                        a.wkc);
    }
    if (--group_left_ == 0) line_group_done();
    return;
  }
  if (actor >= found_) return;
  Slave& s = slaves_[actor];
  if (!s.pending.waiting || seq != s.pending.seq) return;
  s.pending.waiting = false;
  if (a.outcome == DatagramOutcome::Lost) {
    if (s.pending.retries_left-- > 0) {
      s.pending.due = true;
      return;
    }
    fail(s, step_of(s.phase), "no answer to %.*s 0x%04X (frame lost %d times)", static_cast<int>(command_name(a.command).size()),
         command_name(a.command).data(), static_cast<unsigned>(a.address >> 16), config_.retries + 1);
    return;
  }
  slave_answer(s, a);
}

void LineBoot::line_answer(const DatagramAnswer& a) noexcept {
  if (a.outcome == DatagramOutcome::Lost) {
    if (line_pending_.retries_left-- > 0) {
      line_pending_.due = true;
    } else {
      fail_line("count: no answer to BRD 0x0000 (frame lost %d times): is the line connected?", config_.retries + 1);
    }
    return;
  }
  if (a.wkc == 0) {
    fail_line("count: no slave answered BRD 0x0000 (WKC 0)");
    return;
  }
  if (a.wkc > capacity_) {
    fail_line("count: %u slaves on the line, at most %zu supported with %zu configured", a.wkc, capacity_,
              expected_count_);
    return;
  }
  found_ = a.wkc;
  for (std::size_t i = 0; i < found_; ++i) {
    Slave& s = slaves_[i];
    s.report = SlaveReport{};
    s.report.position = static_cast<std::uint16_t>(i);
    s.report.station = static_cast<std::uint16_t>(config_.first_station + i);
  }
  line_ = LinePhase::Reset;
  group_due_ = true;
  group_retries_ = config_.retries;
}

void LineBoot::reset_wait_answer(const DatagramAnswer& a) noexcept {
  line_pending_.due = true;  // unless done: read again at the next poll (the deadline bounds it)
  if (a.outcome == DatagramOutcome::Lost || a.data.size() < 2) return;
  reset_status_ = get_u16(a.data, 0);
  reset_wkc_ = a.wkc;
  // INIT is 1: any other state bit in the OR means some slave is elsewhere [ETG.1000.6 §5.3.2].
  if (a.wkc == found_ && (reset_status_ & 0x0F) == static_cast<std::uint16_t>(AlState::Init)) {
    line_pending_.due = false;
    line_ = LinePhase::Address;
    group_due_ = true;
  }
}

void LineBoot::line_group_done() noexcept {
  const BootStep step = line_ == LinePhase::Reset ? BootStep::Reset : BootStep::Address;
  if (group_bad_) {
    line_ = LinePhase::Failed;
    for (std::size_t i = 0; i < found_; ++i) {
      slaves_[i].report.status = SlaveStatus::Failed;
      slaves_[i].report.step = step;
    }
    return;
  }
  if (group_lost_) {
    if (group_retries_-- > 0) {
      group_due_ = true;
    } else {
      fail_line("%.*s: frame lost %d times", static_cast<int>(to_string(step).size()), to_string(step).data(),
                config_.retries + 1);
    }
    return;
  }
  group_retries_ = config_.retries;
  if (line_ == LinePhase::Reset) {
    // Wait until every slave is in INIT (BRD of AL status: the states OR-ed, WKC = slaves read).
    line_ = LinePhase::ResetWait;
    reset_deadline_ = now_ + config_.to_lower_state;
    reset_status_ = 0;
    reset_wkc_ = 0;
    set(line_pending_, Command::BRD, physical_address(0, reg::kAlStatus), 2);
    return;
  }
  // Addresses set: every slave starts its own steps.
  line_ = LinePhase::Slaves;
  if (expected_count_ > found_) {
    line_text_.format("%zu slave(s) configured, %zu found: position %zu and after missing", expected_count_, found_,
                      found_);
  }
  for (std::size_t i = 0; i < found_; ++i) start_sii(slaves_[i]);
}

void LineBoot::start_sii(Slave& s) noexcept {
  s.report.status = SlaveStatus::Busy;
  s.report.step = BootStep::Sii;
  s.image_size = 0;
  s.sii_word = 0;
  s.sii_next_category = kSiiHeaderBytes;
  s.sii_tries_left = config_.retries;
  s.phase = Phase::SiiStatus;
  s.deadline = now_ + config_.sii_timeout;
  slave_phase(s);
}

void LineBoot::reached(Slave& s) noexcept {
  s.phase = Phase::Idle;
  s.report.status = SlaveStatus::Ready;
  if (s.restart && s.report.target == AlState::Init) {
    s.restart = false;
    start_sii(s);
  }
}

void LineBoot::accept_identities(std::size_t position, std::span<const SiiIdentity> also, bool any) noexcept {
  if (position >= capacity_) return;
  slaves_[position].also = also;
  slaves_[position].any_identity = any;
}

bool LineBoot::identity_accepted(const Slave& s, const SiiIdentity& f) const noexcept {
  if (s.any_identity) return true;
  const ExpectedSlave& e = expected_[s.report.position];
  const auto same = [&](std::uint32_t v, std::uint32_t p, std::uint32_t r) {
    return f.vendor_id == v && f.product_code == p && (r == 0 || f.revision == r);
  };
  if (same(e.vendor_id, e.product_code, e.revision)) return true;
  return std::any_of(s.also.begin(), s.also.end(),
                     [&](const SiiIdentity& a) { return same(a.vendor_id, a.product_code, a.revision); });
}

bool LineBoot::restart_slave(std::size_t position, core::TimePoint now) noexcept {
  if (line_ != LinePhase::Slaves && line_ != LinePhase::Done) return false;
  if (position >= expected_count_) return false;
  now_ = now;
  // A slave missing at the boot (and those before it that were missing too) joins the line.
  for (std::size_t k = found_; k <= position; ++k) {
    Slave& m = slaves_[k];
    m.report = SlaveReport{};
    m.report.position = static_cast<std::uint16_t>(k);
    m.report.station = static_cast<std::uint16_t>(config_.first_station + k);
    m.report.status = SlaveStatus::Failed;
    m.report.step = BootStep::Address;
    m.phase = Phase::Idle;
    m.pending = Pending{};
  }
  found_ = std::max(found_, position + 1);
  Slave& s = slaves_[position];
  if (s.report.status == SlaveStatus::Busy) return false;
  s.report.status = SlaveStatus::Busy;
  s.report.step = BootStep::Address;
  s.report.text.assign("");
  s.report.al_code = 0;
  s.restart = true;
  s.pending.waiting = false;  // an answer to an earlier datagram of this slave is ignored (seq)
  s.phase = Phase::Probe;
  slave_phase(s);
  if (line_ == LinePhase::Done) line_ = LinePhase::Slaves;
  return true;
}

void LineBoot::slave_phase(Slave& s) noexcept {
  const std::uint16_t station = s.report.station;
  switch (s.phase) {
    case Phase::Probe:
      set(s.pending, Command::FPRD, physical_address(station, reg::kAlStatus), 2);
      break;
    case Phase::Readdress: {
      // A slave back from power loss has station address 0: give it its station by position
      // [ETG.1000.4 §5.4 APWR; register 0010h].
      std::array<std::uint8_t, 2> addr{};
      put_u16(addr, 0, station);
      set(s.pending, Command::APWR, physical_address(auto_increment_adp(s.report.position), reg::kStationAddress), 2,
          addr);
      break;
    }
    case Phase::SiiStatus:
    case Phase::SiiBusy:
      set(s.pending, Command::FPRD, physical_address(station, reg::kSiiControl), 2);
      break;
    case Phase::SiiCommand: {
      // Read command and word address in one write of 0502h..0507h [ETG.1000.4 Table 48]; the
      // ESC starts the read when the frame has passed.
      std::array<std::uint8_t, 6> cmd{};
      put_u16(cmd, 0, sii_control::kCommandRead);
      put_u32(cmd, 2, s.sii_word);
      set(s.pending, Command::FPWR, physical_address(station, reg::kSiiControl), 6, cmd);
      s.deadline = now_ + config_.sii_timeout;
      break;
    }
    case Phase::SiiClear: {
      // NOP command: clears the error bits [ETG.1000.4 Table 48].
      const std::array<std::uint8_t, 2> nop{};
      set(s.pending, Command::FPWR, physical_address(station, reg::kSiiControl), 2, nop);
      break;
    }
    case Phase::SiiData:
      set(s.pending, Command::FPRD, physical_address(station, reg::kSiiData),
          static_cast<std::uint16_t>(s.eight_byte_reads ? 8 : 4));
      break;
    case Phase::Mailbox: {
      // SM0 mailbox out (master -> slave), SM1 mailbox in, from the SII standard mailbox
      // [ETG.1000.6 §5.4 words 18h-1Bh]; control bytes from the SyncM category when it lists them,
      // else the usual 26h / 22h [ETG.1000.4 Table 59].
      const SiiMailbox& mb = s.info.header.standard_mailbox;
      std::uint8_t out_control = sm_control::kMailboxOut;
      std::uint8_t in_control = sm_control::kMailboxIn;
      for (std::size_t i = 0; i < s.info.sync_manager_count; ++i) {
        const auto& sm = s.info.sync_managers[i];
        if (sm.type == sii_sm_type::kMailboxOut && sm.control != 0) out_control = sm.control;
        if (sm.type == sii_sm_type::kMailboxIn && sm.control != 0) in_control = sm.control;
      }
      std::array<std::uint8_t, 16> sms{};
      const auto sm0 = encode_sm(SmEntry{mb.rx_offset, mb.rx_size, out_control, 0, sm_activate::kEnable, 0});
      const auto sm1 = encode_sm(SmEntry{mb.tx_offset, mb.tx_size, in_control, 0, sm_activate::kEnable, 0});
      std::copy(sm0.begin(), sm0.end(), sms.begin());
      std::copy(sm1.begin(), sm1.end(), sms.begin() + 8);
      set(s.pending, Command::FPWR, physical_address(station, reg::kSm0), 16, sms);
      break;
    }
    case Phase::AlRequest: {
      std::array<std::uint8_t, 2> ctl{};
      put_u16(ctl, 0, al_control(s.report.target));
      set(s.pending, Command::FPWR, physical_address(station, reg::kAlControl), 2, ctl);
      s.deadline = now_ + timeout_of(s.from, s.report.target);
      break;
    }
    case Phase::AlCheck:
    case Phase::AlPoll:
    case Phase::AlAckPoll:
      set(s.pending, Command::FPRD, physical_address(station, reg::kAlStatus), 2);
      break;
    case Phase::AlCode:
      set(s.pending, Command::FPRD, physical_address(station, reg::kAlStatusCode), 2);
      break;
    case Phase::AlAck: {
      // Acknowledge the error [ETG.1000.6 §5.3.2, AL control bit 4].
      std::array<std::uint8_t, 2> ctl{};
      put_u16(ctl, 0, s.ack_control);
      set(s.pending, Command::FPWR, physical_address(station, reg::kAlControl), 2, ctl);
      break;
    }
    case Phase::Idle:
      break;
  }
}

BootStep LineBoot::step_of(Phase p) noexcept {
  if (p == Phase::Mailbox) return BootStep::Mailbox;
  if (p == Phase::Probe || p == Phase::Readdress) return BootStep::Address;
  return p >= Phase::AlCheck ? BootStep::Transition : BootStep::Sii;
}

void LineBoot::slave_answer(Slave& s, const DatagramAnswer& a) noexcept {
  if (s.phase == Phase::Probe) {
    // Answered at its station: it kept its address; else re-address it by position.
    s.phase = a.wkc == 1 ? Phase::Idle : Phase::Readdress;
    if (a.wkc == 1) {
      begin_transition(s, AlState::Init);
    } else {
      slave_phase(s);
    }
    return;
  }
  if (s.phase == Phase::Readdress) {
    if (a.wkc != 1) {
      fail(s, BootStep::Address, "no answer at position %u (APWR 0x0010 WKC %u)", s.report.position + 1U, a.wkc);
      return;
    }
    begin_transition(s, AlState::Init);
    return;
  }
  // Every datagram here addresses one slave by its station address: WKC 1 when it executed it.
  if (a.wkc != 1) {
    fail(s, step_of(s.phase), "%.*s 0x%04X not executed (WKC %u)", static_cast<int>(command_name(a.command).size()),
         command_name(a.command).data(), static_cast<unsigned>(a.address >> 16), a.wkc);
    return;
  }
  switch (s.phase) {
    case Phase::SiiStatus:
    case Phase::SiiBusy: {
      if (a.data.size() < 2) return;
      const std::uint16_t ctl = get_u16(a.data, 0);
      if (s.phase == Phase::SiiStatus) s.eight_byte_reads = (ctl & sii_control::kRead8Bytes) != 0;
      if ((ctl & sii_control::kBusy) != 0) {
        slave_phase(s);  // poll again (the timeout is checked in poll())
        return;
      }
      constexpr std::uint16_t kNack = sii_control::kCommandError | sii_control::kWriteError;
      if (s.phase == Phase::SiiBusy && (ctl & kNack) != 0) {
        // The EEPROM did not acknowledge (bit 13) or a write-enable error (bit 14) [ETG.1000.4
        // Table 48]: clear the error bits with a NOP command and give the read again, a few times.
        if (s.sii_tries_left-- > 0) {
          s.phase = Phase::SiiClear;
          slave_phase(s);
          return;
        }
        fail(s, BootStep::Sii, "SII read of word 0x%04X failed %d times (control 0x%04X: the EEPROM did not acknowledge)",
             s.sii_word, config_.retries + 1, ctl);
        return;
      }
      if (s.phase == Phase::SiiBusy && (ctl & sii_control::kDeviceInfoError) != 0) {
        fail(s, BootStep::Sii, "SII read of word 0x%04X failed (control 0x%04X)", s.sii_word, ctl);
        return;
      }
      s.phase = s.phase == Phase::SiiStatus ? Phase::SiiCommand : Phase::SiiData;
      slave_phase(s);
      return;
    }
    case Phase::SiiCommand:
      s.phase = Phase::SiiBusy;
      slave_phase(s);
      return;
    case Phase::SiiClear:
      s.phase = Phase::SiiCommand;
      slave_phase(s);
      return;
    case Phase::SiiData:
      sii_chunk(s, a.data);
      return;
    case Phase::Mailbox:
      begin_transition(s, AlState::PreOp);
      return;
    case Phase::AlCheck: {
      // Where the slave is before anything is requested: an error indication left from before
      // (e.g. SAFE-OP + error after a watchdog) is acknowledged first, else the request would be
      // ignored and the old error taken for a refusal [ETG.1000.6 §5.3.2].
      if (a.data.size() < 2) return;
      s.al_status_raw = get_u16(a.data, 0);
      const AlStatus st = decode_al_status(s.al_status_raw);
      s.report.state = s.from = st.state();
      if (st.error) {
        // Going down: acknowledge with the target itself (e.g. INIT | 10h); else stay where it is.
        const bool down = static_cast<std::uint8_t>(s.report.target) < static_cast<std::uint8_t>(st.state());
        acknowledge(s, down ? s.report.target : st.state(), false);
        return;
      }
      if (st.state() == s.report.target) {
        reached(s);
        return;
      }
      s.phase = Phase::AlRequest;
      slave_phase(s);
      return;
    }
    case Phase::AlRequest:
      s.phase = Phase::AlPoll;
      slave_phase(s);
      return;
    case Phase::AlPoll: {
      if (a.data.size() < 2) return;
      s.al_status_raw = get_u16(a.data, 0);
      const AlStatus st = decode_al_status(s.al_status_raw);
      s.report.state = st.state();
      if (st.error) {  // refused: read why [ETG.1000.6 §5.3.2, AL status code 0134h]
        s.phase = Phase::AlCode;
        slave_phase(s);
        return;
      }
      if (st.state() == s.report.target) {  // the target, no error: done
        reached(s);
        return;
      }
      slave_phase(s);  // not there yet: poll again (timeout in poll())
      return;
    }
    case Phase::AlCode:
      if (a.data.size() < 2) return;
      s.report.al_code = get_u16(a.data, 0);
      acknowledge(s, decode_al_status(s.al_status_raw).state(), true);
      return;
    case Phase::AlAck:
      s.phase = Phase::AlAckPoll;
      slave_phase(s);
      return;
    case Phase::AlAckPoll: {
      if (a.data.size() < 2) return;
      s.al_status_raw = get_u16(a.data, 0);
      const AlStatus st = decode_al_status(s.al_status_raw);
      s.report.state = st.state();
      if (st.error) {
        slave_phase(s);  // not cleared yet: poll again (timeout in poll())
        return;
      }
      if (s.refused) {
        fail_refused(s);
        return;
      }
      // An earlier error acknowledged: go on with the transition.
      if (st.state() == s.report.target) {
        reached(s);
      } else if ((s.ack_control & 0x0F) == static_cast<std::uint16_t>(s.report.target)) {
        s.phase = Phase::AlPoll;  // the acknowledge requested the target already (going down)
        slave_phase(s);
      } else {
        s.phase = Phase::AlRequest;
        slave_phase(s);
      }
      return;
    }
    case Phase::Probe:
    case Phase::Readdress:
    case Phase::Idle:
      return;
  }
}

void LineBoot::sii_chunk(Slave& s, std::span<const std::uint8_t> data) noexcept {
  const std::size_t n = std::min(data.size(), kMaxSiiBytes - s.image_size);
  std::copy_n(data.begin(), n, s.image.begin() + static_cast<std::ptrdiff_t>(s.image_size));
  s.image_size += n;
  s.sii_word += static_cast<std::uint32_t>(data.size() / 2);
  s.sii_tries_left = config_.retries;
  const std::span<const std::uint8_t> image(s.image.data(), s.image_size);
  if (s.image_size >= kSiiHeaderBytes && sii_end_seen(image, s.sii_next_category)) {
    parse_sii(image, s.info);
    if (!s.info.ok()) {
      SiiProblem first = SiiProblem::ImageTooShort;
      for (std::size_t i = 0; i < std::min(s.info.issue_count, kSiiMaxIssues); ++i) {
        if (is_error(s.info.issues[i].problem)) {
          first = s.info.issues[i].problem;
          break;
        }
      }
      fail(s, BootStep::Sii, "SII image invalid: %.*s", static_cast<int>(to_string(first).size()),
           to_string(first).data());
      return;
    }
    s.report.found = s.info.header.identity;
    identify(s);
    return;
  }
  if (s.image_size >= kMaxSiiBytes) {
    fail(s, BootStep::Sii, "SII has no category end within %zu bytes", kMaxSiiBytes);
    return;
  }
  s.phase = Phase::SiiCommand;
  slave_phase(s);
}

void LineBoot::identify(Slave& s) noexcept {
  const SiiIdentity& f = s.info.header.identity;
  if (s.report.position >= expected_count_) {
    s.phase = Phase::Idle;
    s.report.status = SlaveStatus::Extra;
    s.report.step = BootStep::Identity;
    const std::string_view name = name_of(s);
    s.report.text.format("slave %u (0x%04X, %.*s): not configured (vendor 0x%08X product 0x%08X revision 0x%08X), "
                         "left in INIT",
                         s.report.position + 1U, s.report.station, static_cast<int>(name.size()), name.data(),
                         f.vendor_id, f.product_code, f.revision);
    return;
  }
  const ExpectedSlave& e = expected_[s.report.position];
  if (!identity_accepted(s, f)) {
    fail(s, BootStep::Identity,
         "identity mismatch: expected vendor 0x%08X product 0x%08X revision 0x%08X, found vendor 0x%08X product "
         "0x%08X revision 0x%08X",
         e.vendor_id, e.product_code, e.revision, f.vendor_id, f.product_code, f.revision);
    return;
  }
  if (s.info.header.standard_mailbox.present()) {
    s.report.step = BootStep::Mailbox;
    s.phase = Phase::Mailbox;
    slave_phase(s);
  } else {
    begin_transition(s, AlState::PreOp);
  }
}

void LineBoot::begin_transition(Slave& s, AlState target) noexcept {
  s.report.status = SlaveStatus::Busy;
  s.report.step = BootStep::Transition;
  s.report.al_code = 0;
  s.report.text.assign("");
  s.from = s.report.state;
  s.report.target = target;
  s.refused = false;
  s.deadline = now_ + timeout_of(s.from, target);
  s.phase = Phase::AlCheck;
  slave_phase(s);
}

void LineBoot::acknowledge(Slave& s, AlState state, bool refused) noexcept {
  s.refused = refused;
  s.ack_control = al_control(state, true);
  s.deadline = now_ + config_.to_lower_state;  // the error bit must clear within this
  s.phase = Phase::AlAck;
  slave_phase(s);
}

void LineBoot::fail_refused(Slave& s) noexcept {
  const std::string_view from = to_string(s.from);
  const std::string_view to = to_string(s.report.target);
  const std::string_view why = al_status_text(s.report.al_code);
  fail(s, BootStep::Transition, "%.*s -> %.*s refused: 0x%04X %.*s", static_cast<int>(from.size()), from.data(),
       static_cast<int>(to.size()), to.data(), s.report.al_code, static_cast<int>(why.size()), why.data());
}

bool LineBoot::request_state(std::size_t position, AlState target, core::TimePoint now) noexcept {
  if (position >= found_) return false;
  const SlaveReport& r = slaves_[position].report;
  const bool again = r.status == SlaveStatus::Failed && r.step == BootStep::Transition;  // refused or timed out
  if (r.status != SlaveStatus::Ready && !again) return false;
  now_ = now;
  begin_transition(slaves_[position], target);
  if (line_ == LinePhase::Done) line_ = LinePhase::Slaves;
  return true;
}

core::Duration LineBoot::timeout_of(AlState from, AlState to) const noexcept {
  if (static_cast<std::uint8_t>(to) < static_cast<std::uint8_t>(from)) return config_.to_lower_state;
  switch (to) {
    case AlState::SafeOp: return config_.preop_to_safeop;
    case AlState::Op: return config_.safeop_to_op;
    default: return config_.init_to_preop;
  }
}

std::string_view LineBoot::name_of(const Slave& s) const noexcept {
  if (s.report.position < expected_count_ && !expected_[s.report.position].name.empty()) {
    return expected_[s.report.position].name;
  }
  if (s.info.has_general) {
    const std::string_view n = s.info.string(s.info.general.name_index);
    if (!n.empty()) return n;
  }
  return "unnamed";
}

void LineBoot::fail(Slave& s, BootStep step, const char* fmt, ...) noexcept {
  std::array<char, 200> why{};
  va_list args;
  va_start(args, fmt);
  std::vsnprintf(why.data(), why.size(), fmt, args);
  va_end(args);
  const std::string_view name = name_of(s);
  s.report.status = SlaveStatus::Failed;
  s.report.step = step;
  s.phase = Phase::Idle;
  s.pending.due = false;
  s.report.text.format("slave %u (0x%04X, %.*s): %s", s.report.position + 1U, s.report.station,
                       static_cast<int>(name.size()), name.data(), why.data());
}

void LineBoot::fail_line(const char* fmt, ...) noexcept {
  va_list args;
  va_start(args, fmt);
  line_text_.vformat(fmt, args);
  va_end(args);
  line_ = LinePhase::Failed;
}

LineStatus LineBoot::status() const noexcept {
  switch (line_) {
    case LinePhase::Idle: return LineStatus::Idle;
    case LinePhase::Done: return LineStatus::Done;
    case LinePhase::Failed: return LineStatus::Failed;
    default: return LineStatus::Running;
  }
}

bool LineBoot::ok() const noexcept {
  if (line_ != LinePhase::Done || found_ != expected_count_) return false;
  return std::all_of(slaves_.get(), slaves_.get() + found_, [](const Slave& s) {
    return s.report.status == SlaveStatus::Ready && s.report.state != AlState::Init;
  });
}

}  // namespace drivegate::ethercat
