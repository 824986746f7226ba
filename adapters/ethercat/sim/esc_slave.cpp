#include "adapters/ethercat/sim/esc_slave.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "adapters/ethercat/wire/al_status.hpp"
#include "core/bytes.hpp"

namespace drivegate::ethercat::sim {

using core::get_u16;
using core::get_u32;
using core::get_u64;
using core::put_u16;
using core::put_u32;
using core::put_u64;

namespace {

constexpr std::uint32_t kMemorySize = 0x10000;
// DL control bit 24: station alias enabled for FPxx addressing [ETG.1000.4 Table 31, 0100h].
constexpr std::uint32_t kDlControlAlias = 0x01000000;
// Watchdog tick: (divider + 2) × 40 ns [ETG.1000.4 watchdog divider 0400h; digest §8.2].
constexpr std::uint64_t kWatchdogBaseNs = 40;

bool overlaps(std::uint32_t a, std::uint32_t alen, std::uint32_t b, std::uint32_t blen) noexcept {
  return alen != 0 && blen != 0 && a < b + blen && b < a + alen;
}

}  // namespace

EscSlave::EscSlave(const EscConfig& config, std::span<const std::uint8_t> sii, SlaveApplication* app)
    : cfg_(config),
      app_(app),
      mem_(kMemorySize, 0),
      sii_(sii.begin(), sii.end()),
      sii_info_(std::make_unique<SiiInfo>()),
      outbox_(config.mailbox_queue, 0),
      coe_(app != nullptr ? app->object_dictionary() : nullptr, config.max_object_bytes) {
  parse_sii(sii_, *sii_info_);
  has_mailbox_ = sii_info_->header.standard_mailbox.present();
  if (has_mailbox_) {
    outbox_ = MailboxOutbox(config.mailbox_queue, sii_info_->header.standard_mailbox.tx_size);
    last_sent_.assign(sii_info_->header.standard_mailbox.tx_size, 0);
  }
  const std::size_t ram = static_cast<std::size_t>(cfg_.ram_kib) * 1024;
  inputs_.assign(ram, 0);
  zeros_.assign(ram, 0);

  // Register bytes the master may write [ETG.1000.4 Table 31: ECAT access r/w]; the rest of
  // 0000h-0FFFh is read-only for ECAT.
  auto allow = [this](std::uint32_t from, std::uint32_t count) {
    for (std::uint32_t a = from; a < from + count && a < 0x1000; ++a) writable_.set(a);
  };
  allow(reg::kStationAddress, 2);
  allow(reg::kWriteEnable, 2);
  allow(reg::kEscWriteEnable, 2);
  allow(reg::kEscResetEcat, 1);
  allow(reg::kDlControl, 4);
  allow(reg::kPhysicalRwOffset, 2);
  allow(reg::kAlControl, 2);
  allow(reg::kRunLedOverride, 2);
  allow(reg::kEcatEventMask, 2);
  allow(reg::kWatchdogDivider, 2);
  allow(reg::kWatchdogTimePdi, 2);
  allow(reg::kWatchdogTimeProcessData, 2);
  allow(reg::kSiiConfig, 1);
  allow(reg::kSiiAddress, 8);  // address and write data
  for (unsigned n = 0; n < cfg_.fmmu_count; ++n) allow(reg::fmmu(n), 13);  // 13-15 reserved
  for (unsigned n = 0; n < cfg_.sm_count; ++n) {
    allow(reg::sm(n), 5);      // start, length, control; 5 status is read-only
    allow(reg::sm_activation(n), 1);  // activate; PDI control is read-only
  }
  if (cfg_.dc_supported) {
    allow(reg::kDcSystemTimeOffset, 8);
    allow(reg::kDcSystemTimeDelay, 4);
    allow(reg::kDcSpeedCounterStart, 2);
    allow(reg::kDcTimeDifferenceFilterDepth, 2);
    allow(reg::kDcCyclicUnitControl, 2);
    allow(reg::kDcSync0StartTime, 8);
    allow(reg::kDcSync0CycleTime, 8);
    allow(reg::kDcLatch0Control, 2);
  }
  power_on();
  if (app_ != nullptr) app_->attach(*this);
}

std::uint16_t EscSlave::u16(std::uint16_t at) const noexcept { return get_u16(mem_, at); }
std::uint32_t EscSlave::u32(std::uint16_t at) const noexcept { return get_u32(mem_, at); }
std::uint64_t EscSlave::u64(std::uint16_t at) const noexcept { return get_u64(mem_, at); }
void EscSlave::set16(std::uint16_t at, std::uint16_t v) noexcept { put_u16(mem_, at, v); }
void EscSlave::set32(std::uint16_t at, std::uint32_t v) noexcept { put_u32(mem_, at, v); }
void EscSlave::set64(std::uint16_t at, std::uint64_t v) noexcept { put_u64(mem_, at, v); }

std::uint16_t EscSlave::al_status_code() const noexcept { return u16(reg::kAlStatusCode); }
std::uint16_t EscSlave::station_address() const noexcept { return u16(reg::kStationAddress); }

void EscSlave::power_on() noexcept {
  std::fill(mem_.begin(), mem_.end(), std::uint8_t{0});
  mem_[reg::kType] = cfg_.type;
  mem_[reg::kRevision] = cfg_.revision;
  set16(reg::kBuild, cfg_.build);
  mem_[reg::kFmmusSupported] = cfg_.fmmu_count;
  mem_[reg::kSmsSupported] = cfg_.sm_count;
  mem_[reg::kRamSize] = cfg_.ram_kib;
  mem_[reg::kPortDescriptor] = cfg_.port_descriptor;
  // ESC features 0008h: bit 2 distributed clocks, bit 3 DC 64-bit [ETG.1000.4 Table 31].
  std::uint16_t features = static_cast<std::uint16_t>(cfg_.features & ~0x000CU);
  if (cfg_.dc_supported) features = static_cast<std::uint16_t>(features | 0x0004U | (cfg_.dc_64bit ? 0x0008U : 0U));
  set16(reg::kEscFeatures, features);
  // What the ESC loads from the EEPROM at power-on [ETG.1000.6 §5.4: words 0-4].
  set16(reg::kStationAlias, sii_info_->header.station_alias);
  mem_[reg::kPdiControl] = static_cast<std::uint8_t>(sii_info_->header.pdi_control & 0xFF);
  mem_[reg::kEscConfiguration] = static_cast<std::uint8_t>(sii_info_->header.pdi_control >> 8);
  set16(reg::kPdiConfiguration, sii_info_->header.pdi_configuration);
  set32(reg::kDlControl, 0x00000001);  // forwarding rule; loops on auto
  set16(reg::kAlStatus, static_cast<std::uint16_t>(AlState::Init));
  // Watchdog defaults: divider 2498 (100 µs), times 1000 ticks = 100 ms [digest §8.2].
  set16(reg::kWatchdogDivider, 2498);
  set16(reg::kWatchdogTimePdi, 1000);
  set16(reg::kWatchdogTimeProcessData, 1000);
  std::uint16_t sii_ctl = cfg_.sii_read_8_bytes ? sii_control::kRead8Bytes : 0;
  if (sii_.size() > 2048) sii_ctl = static_cast<std::uint16_t>(sii_ctl | sii_control::kTwoAddressBytes);
  set16(reg::kSiiControl, sii_ctl);
  for (unsigned n = 0; n < cfg_.sm_count; ++n) mem_[reg::sm_pdi_control(n)] = sm_pdi_control::kDeactivate;
  sms_ = {};
  state_ = AlState::Init;
  sii_busy_ = 0;
  outbox_.clear();
  coe_.reset();
  last_sent_size_ = 0;
  last_rx_counter_ = 0;
  mailbox_pending_ = false;
  outputs_valid_ = false;
  wd_triggered_ = false;
  // The DC unit restarts with the ESC: a fresh local clock, SYNC0 off.
  clock_.reset(cfg_.clock_offset_ns, cfg_.drift_ppm);
  sync0_running_ = false;
  sync0_next_ = sync0_cycle_ = sync0_last_ = sync0_count_ = 0;
  sync0_fired_ = false;
  set_port1_link(port1_link_);
  fmmus_valid_ = false;
  system_time_fresh_ = false;
}

void EscSlave::set_port1_link(bool up) noexcept {
  if (port1_link_ && !up && mem_[reg::kLostLinkCounter + 1] < 0xFF) ++mem_[reg::kLostLinkCounter + 1];
  port1_link_ = up;
  // DL status 0110h [ETG.1000.4 Table 34]: PDI operational (EEPROM loaded), port 0 link and
  // communication; port 1 open with a link, closed without; ports 2 and 3 are not implemented
  // (closed).
  std::uint16_t s = static_cast<std::uint16_t>(dl_status::kPdiOperational | dl_status::link_on_port(0) |
                                               dl_status::communication_on_port(0) | dl_status::loop_closed_port(2) |
                                               dl_status::loop_closed_port(3));
  if (up) {
    s = static_cast<std::uint16_t>(s | dl_status::link_on_port(1) | dl_status::communication_on_port(1));
  } else {
    s = static_cast<std::uint16_t>(s | dl_status::loop_closed_port(1));
  }
  set16(reg::kDlStatus, s);
}

void EscSlave::count_rx_error() noexcept {
  if (mem_[reg::kRxErrorCounter] < 0xFF) ++mem_[reg::kRxErrorCounter];  // port 0 invalid frame counter
}

void EscSlave::begin_frame(std::uint64_t port0_ns, std::uint64_t port1_ns, bool downstream) noexcept {
  port0_ns_ = port0_ns;
  port1_ns_ = port1_ns;
  downstream_ = downstream;
  now_ns_ = port0_ns;
  system_time_fresh_ = false;
}

// ---- SyncManagers -----------------------------------------------------------------------------

SmEntry EscSlave::sm(unsigned n) const noexcept {
  // decode_sm() of the 8 register bytes, in place [ETG.1000.4 Table 59].
  const std::uint8_t* b = mem_.data() + reg::sm(n);
  SmEntry e;
  e.physical_start = static_cast<std::uint16_t>(b[0] | (b[1] << 8));
  e.length = static_cast<std::uint16_t>(b[2] | (b[3] << 8));
  e.control = b[4];
  e.status = b[5];
  e.activate = b[6];
  e.pdi_control = b[7];
  return e;
}

std::span<std::uint8_t> EscSlave::sm_buffer(const SmEntry& e) noexcept {
  if (static_cast<std::uint32_t>(e.physical_start) + e.length > kMemorySize) return {};
  return {mem_.data() + e.physical_start, e.length};
}

bool EscSlave::sm_active(const SmEntry& e) noexcept {
  return e.enabled() && (e.pdi_control & sm_pdi_control::kDeactivate) == 0 && e.length != 0;
}

bool EscSlave::sm_allows(std::uint32_t start, std::uint32_t len, Rw rw) const noexcept {
  for (unsigned n = 0; n < cfg_.sm_count; ++n) {
    const SmEntry e = sm(n);
    if (!e.enabled() || !overlaps(start, len, e.physical_start, e.length)) continue;
    // Enabled by the master but deactivated by the PDI (INIT, or the slave has not reached the
    // state that uses it): the area is locked [ETG.1000.4 Table 59, PDI control bit 0].
    if ((e.pdi_control & sm_pdi_control::kDeactivate) != 0) return false;
    const bool mailbox = (e.control & sm_control::kModeMask) == sm_control::kModeMailbox;
    const bool ecat_writes = (e.control & sm_control::kDirectionMask) == sm_control::kDirectionWrite;
    if (mailbox) {
      // 1-buffer: the master writes an empty write mailbox and reads a full read mailbox
      // [ETG.1000.4 SyncManager mailbox mode].
      if (ecat_writes && (rw != Rw::Write || sms_[n].mailbox_full)) return false;
      if (!ecat_writes && (rw != Rw::Read || !sms_[n].mailbox_full)) return false;
    } else if (!ecat_writes && rw == Rw::Write) {
      return false;  // inputs: the PDI writes, ECAT only reads
    }
  }
  return true;
}

void EscSlave::sm_after(std::uint32_t start, std::uint32_t len, Rw rw) noexcept {
  for (unsigned n = 0; n < cfg_.sm_count; ++n) {
    const SmEntry e = sm(n);
    if (!sm_active(e)) continue;
    const std::uint32_t last = static_cast<std::uint32_t>(e.physical_start) + e.length - 1U;
    if (!overlaps(start, len, last, 1)) continue;  // buffer state changes with the last byte
    const bool mailbox = (e.control & sm_control::kModeMask) == sm_control::kModeMailbox;
    const bool ecat_writes = (e.control & sm_control::kDirectionMask) == sm_control::kDirectionWrite;
    const std::uint16_t status_at = reg::sm_status(n);
    if (mailbox && ecat_writes && rw == Rw::Write) {
      sms_[n].mailbox_full = true;
      mem_[status_at] = static_cast<std::uint8_t>(mem_[status_at] | sm_status::kMailboxFull | sm_status::kInterruptWrite);
      if (n == 0) mailbox_pending_ = true;
    } else if (mailbox && !ecat_writes && rw == Rw::Read) {
      if (n == 1 && has_mailbox_) {
        // Keep what the master just read: a repeat request asks for exactly this mailbox again.
        const std::span<const std::uint8_t> buf = sm_buffer(e);
        last_sent_size_ = std::min(buf.size(), last_sent_.size());
        std::copy_n(buf.begin(), last_sent_size_, last_sent_.begin());
      }
      sms_[n].mailbox_full = false;
      mem_[status_at] = static_cast<std::uint8_t>(mem_[status_at] & ~(sm_status::kMailboxFull | sm_status::kInterruptRead));
    } else if (!mailbox && ecat_writes && rw == Rw::Write) {
      // A complete output buffer: triggers the SM watchdog when the SM asks for it [ETG.1000.4
      // Table 59 control bit 6; digest §8.2].
      mem_[status_at] = static_cast<std::uint8_t>(mem_[status_at] | sm_status::kInterruptWrite);
      outputs_valid_ = true;
      if ((e.control & sm_control::kWatchdogTrigger) != 0) {
        wd_triggered_ = true;
        wd_last_ns_ = now_ns_;
      }
    }
  }
}

void EscSlave::set_pdi_deactivate(unsigned n, bool deactivate) noexcept {
  if (n >= cfg_.sm_count) return;
  const auto at = reg::sm_pdi_control(n);
  mem_[at] = static_cast<std::uint8_t>(deactivate ? (mem_[at] | sm_pdi_control::kDeactivate) : (mem_[at] & ~sm_pdi_control::kDeactivate));
  if (deactivate) {
    sms_[n].mailbox_full = false;
    mem_[reg::sm_status(n)] = 0;
  }
}

// ---- Physical memory access -------------------------------------------------------------------

void EscSlave::refresh_dynamic_registers() noexcept {
  // The system time as the datagram passes (a read of 0910h gives it) [ETG.1000.4 §6 DC]. It
  // depends on the frame's time, the clock and 0920h only: computed once per frame at this slave
  // unless a register write (which may move the clock or 0920h) came in between.
  if (!cfg_.dc_supported || system_time_fresh_) return;
  set64(reg::kDcSystemTime, system_time(now_ns_));
  system_time_fresh_ = true;
}

bool EscSlave::phys_read(std::uint32_t ado, std::span<std::uint8_t> data, bool or_in) noexcept {
  const auto len = static_cast<std::uint32_t>(data.size());
  if (ado + len > kMemorySize) return false;
  if (!sm_allows(ado, len, Rw::Read)) return false;
  for (std::uint32_t i = 0; i < len; ++i) {
    const std::uint8_t v = mem_[ado + i];
    data[i] = or_in ? static_cast<std::uint8_t>(data[i] | v) : v;
  }
  sm_after(ado, len, Rw::Read);
  return true;
}

bool EscSlave::phys_write(std::uint32_t ado, std::span<const std::uint8_t> data) noexcept {
  const auto len = static_cast<std::uint32_t>(data.size());
  if (ado + len > kMemorySize) return false;
  if (!sm_allows(ado, len, Rw::Write)) return false;
  const std::uint32_t ram_end = reg::kProcessRam + static_cast<std::uint32_t>(cfg_.ram_kib) * 1024U;
  const std::uint16_t sii_before = u16(reg::kSiiControl);
  for (std::uint32_t i = 0; i < len; ++i) {
    const std::uint32_t a = ado + i;
    if (a < reg::kProcessRam ? writable_.test(a) : a < ram_end) mem_[a] = data[i];
  }
  if (ado < reg::kProcessRam) {
    system_time_fresh_ = false;
    if (overlaps(ado, len, reg::fmmu(0), 16U * kFmmuEntrySize)) fmmus_valid_ = false;
    // SII control: only write enable (bit 0) and the command (bits 8-10) are written; a command
    // while busy is ignored [ETG.1000.4 Table 48].
    if (overlaps(ado, len, reg::kSiiControl, 2)) {
      std::uint16_t written = sii_before;
      for (std::uint32_t b = 0; b < 2; ++b) {
        const std::uint32_t a = reg::kSiiControl + b;
        if (a >= ado && a < ado + len) {
          written = static_cast<std::uint16_t>((written & ~(0xFFU << (8 * b))) | (static_cast<std::uint32_t>(data[a - ado]) << (8 * b)));
        }
      }
      const std::uint16_t keep_mask = static_cast<std::uint16_t>(~(sii_control::kCommandMask | sii_control::kWriteEnable));
      if ((sii_before & sii_control::kBusy) == 0) {
        set16(reg::kSiiControl, static_cast<std::uint16_t>((sii_before & keep_mask) |
                                                           (written & (sii_control::kCommandMask | sii_control::kWriteEnable))));
        if ((written & sii_control::kCommandMask) != 0) sii_command();
      }
    }
    if (cfg_.dc_supported && ado <= reg::kDcSystemTime && ado + len >= reg::kDcSystemTime + 4U) {
      system_time_written(ado, data);
    }
    register_written(ado, len);
  }
  sm_after(ado, len, Rw::Write);
  return true;
}

void EscSlave::register_written(std::uint32_t start, std::uint32_t len) noexcept {
  if (overlaps(start, len, reg::kAlControl, 2)) al_control_written();
  // An SM the master disables is reset: its mailbox is empty again [ETG.1000.4 Table 59,
  // activate bit 0].
  for (unsigned n = 0; n < cfg_.sm_count; ++n) {
    if (overlaps(start, len, reg::sm(n), kSmEntrySize) && (mem_[reg::sm_activation(n)] & sm_activate::kEnable) == 0) {
      sms_[n].mailbox_full = false;
      mem_[reg::sm_status(n)] = 0;
    }
  }
  // A write to the error counters clears them [ETG.1000.4 Table 31, 0300h-0313h].
  if (overlaps(start, len, reg::kRxErrorCounter, 0x14)) {
    std::fill(mem_.begin() + reg::kRxErrorCounter, mem_.begin() + reg::kRxErrorCounter + 0x14, std::uint8_t{0});
  }
  if (cfg_.dc_supported && overlaps(start, len, reg::kDcReceiveTimePort0, 4)) {
    // Receive time latch: each port stores the local time the write passed it; the processing
    // unit's time goes to 0918h [ETG.1000.4 §6 DC, receive times].
    set32(reg::kDcReceiveTimePort0, static_cast<std::uint32_t>(local_time(port0_ns_)));
    if (downstream_) set32(reg::kDcReceiveTimePort1, static_cast<std::uint32_t>(local_time(port1_ns_)));
    set64(reg::kDcReceiveTimeProcessingUnit, local_time(port0_ns_));
  }
  if (cfg_.dc_supported) {
    // A write to the speed counter start restarts the control loop; a new offset or delay makes
    // the error jump [ETG.1000.4 §6 DC registers 0920h, 0928h, 0930h].
    if (overlaps(start, len, reg::kDcSpeedCounterStart, 2)) {
      clock_.advance(now_ns_);
      clock_.reset_loop();
    } else if (overlaps(start, len, reg::kDcSystemTimeOffset, 12)) {
      clock_.advance(now_ns_);
      clock_.restart_window();
    }
    if (overlaps(start, len, reg::kDcActivation, 1)) dc_activation_written();
  }
}

// ---- Distributed clocks [ETG.1000.4 §6 DC registers] ------------------------------------------

std::uint64_t EscSlave::system_time(std::uint64_t now_ns) const noexcept {
  // System time 0910h = local time + system time offset 0920h; 32 bits on a 32-bit DC unit.
  const std::uint64_t sys = local_time(now_ns) + u64(reg::kDcSystemTimeOffset);
  return cfg_.dc_64bit ? sys : (sys & 0xFFFFFFFFU);
}

bool EscSlave::time_reached(std::uint64_t a, std::uint64_t b) const noexcept {
  if (cfg_.dc_64bit) return a >= b;
  return static_cast<std::int32_t>(static_cast<std::uint32_t>(a) - static_cast<std::uint32_t>(b)) >= 0;
}

void EscSlave::system_time_written(std::uint32_t ado, std::span<const std::uint8_t> data) noexcept {
  // A written system time (FRMW/ARMW from the reference clock, or any write) is the reference's
  // time when the frame passed it; the frame reaches this ESC 0928h ns later. The difference of the
  // own system time against received + delay goes to 092Ch and drives the control loop
  // [ETG.1000.4 §6 DC: 0910h write, 0928h, 092Ch]. Compared over 64 bits when the write carries
  // 8 bytes and the unit is 64-bit, else over the low 32 bits.
  const auto len = static_cast<std::uint32_t>(data.size());
  const std::size_t at = reg::kDcSystemTime - ado;
  const bool wide = cfg_.dc_64bit && ado + len >= reg::kDcSystemTime + 8U;
  const std::uint64_t delay = u32(reg::kDcSystemTimeDelay);
  const std::uint64_t own = system_time(now_ns_);
  std::int64_t diff = 0;
  if (wide) {
    diff = static_cast<std::int64_t>(own - get_u64(data, at) - delay);
  } else {
    diff = static_cast<std::int32_t>(static_cast<std::uint32_t>(own) - get_u32(data, at) - static_cast<std::uint32_t>(delay));
  }
  const double error = static_cast<double>(diff) + clock_.fraction(now_ns_);
  set32(reg::kDcSystemTimeDifference, encode_system_time_difference(static_cast<std::int64_t>(std::llround(error))));
  clock_.sample(now_ns_, error);
}

void EscSlave::dc_activation_written() noexcept {
  // 0981h bit 0 cyclic operation + bit 1 SYNC0: on activation the unit takes the start time 0990h
  // and cycle 09A0h; a start time not in the future never fires (a 64-bit ESC waits for it
  // forever): 0984h bit 2 says so. 0984h bit 0: first pulse pending [ETG.1000.4 §6 DC, 0981h,
  // 0984h, 0990h, 09A0h].
  const std::uint8_t act = mem_[reg::kDcActivation];
  const bool on = (act & dc_activation::kCyclicOperation) != 0 && (act & dc_activation::kSync0) != 0;
  if (!on) {
    sync0_running_ = false;
    mem_[reg::kDcActivationStatus] = 0;
    return;
  }
  if (sync0_running_ || (mem_[reg::kDcActivationStatus] & 0x04U) != 0) return;  // already activated
  const std::uint64_t mask = cfg_.dc_64bit ? ~std::uint64_t{0} : 0xFFFFFFFFU;
  const std::uint64_t start = u64(reg::kDcSync0StartTime) & mask;
  sync0_cycle_ = u32(reg::kDcSync0CycleTime);
  if (time_reached(system_time(now_ns_), start)) {
    mem_[reg::kDcActivationStatus] = 0x04;
    return;
  }
  sync0_running_ = true;
  sync0_next_ = start;
  mem_[reg::kDcActivationStatus] = 0x01;
}

void EscSlave::sync0_cycle(std::uint64_t now_ns) noexcept {
  if (!sync0_running_) return;
  const std::uint64_t sys = system_time(now_ns);
  if (!time_reached(sys, sync0_next_)) return;
  const std::uint64_t mask = cfg_.dc_64bit ? ~std::uint64_t{0} : 0xFFFFFFFFU;
  if (sync0_cycle_ == 0) {  // cycle time 0: a single pulse
    sync0_last_ = sync0_next_;
    ++sync0_count_;
    sync0_running_ = false;
  } else {
    const std::uint64_t behind = (sys - sync0_next_) & mask;
    const std::uint64_t k = behind / sync0_cycle_;
    sync0_last_ = (sync0_next_ + k * sync0_cycle_) & mask;
    sync0_count_ += k + 1;
    sync0_next_ = (sync0_last_ + sync0_cycle_) & mask;
  }
  set64(reg::kDcSync0StartTime, sync0_next_);  // read: the next SYNC0 pulse
  mem_[reg::kDcActivationStatus] = static_cast<std::uint8_t>(mem_[reg::kDcActivationStatus] & ~0x01U);
  mem_[reg::kDcSync0Status] = 0x01;
  sync0_fired_ = true;
}

// ---- Datagrams --------------------------------------------------------------------------------

void EscSlave::decode_fmmus() noexcept {
  fmmu_n_ = 0;
  fmmu_lo_ = UINT64_MAX;
  fmmu_hi_ = 0;
  for (unsigned n = 0; n < cfg_.fmmu_count && n < fmmus_.size(); ++n) {
    const auto f = decode_fmmu(std::span<const std::uint8_t>(mem_).subspan(reg::fmmu(n), kFmmuEntrySize));
    if (!f || !f->active || f->length == 0) continue;
    if (f->logical_start_bit != 0 || f->logical_stop_bit != 7) continue;  // byte granularity only
    MappedFmmu& m = fmmus_[fmmu_n_++];
    m.lo = f->logical_start;
    m.hi = m.lo + f->length;
    m.physical = f->physical_start;
    m.type = f->type;
    m.index = static_cast<std::uint8_t>(n);
    fmmu_lo_ = std::min(fmmu_lo_, m.lo);
    fmmu_hi_ = std::max(fmmu_hi_, m.hi);
  }
  fmmus_valid_ = true;
}

bool EscSlave::logical(Command c, std::uint32_t address, std::span<std::uint8_t> data, std::uint16_t& wkc) noexcept {
  bool read_hit = false;
  bool write_hit = false;
  const bool reads = c == Command::LRD || c == Command::LRW;
  const bool writes = c == Command::LWR || c == Command::LRW;
  const std::uint64_t lo = address;
  const std::uint64_t hi = lo + data.size();
  if (!fmmus_valid_) decode_fmmus();
  // A datagram outside every FMMU's logical range passes untouched.
  if (hi <= fmmu_lo_ || lo >= fmmu_hi_) return false;
  // Writes first, from the data as the frame brought it; then reads into the frame, so an input
  // FMMU overlapping an output FMMU's logical range returns inputs [ETG.1000.4 §5.4 LRW].
  for (int pass = 0; pass < 2; ++pass) {
    const bool write_pass = pass == 0;
    if (write_pass ? !writes : !reads) continue;
    if (!fmmus_valid_) decode_fmmus();
    for (std::size_t k = 0; k < fmmu_n_; ++k) {
      const MappedFmmu f = fmmus_[k];
      if ((f.type & (write_pass ? fmmu_type::kWrite : fmmu_type::kRead)) == 0) continue;
      const std::uint64_t a = std::max(lo, f.lo);
      const std::uint64_t b = std::min(hi, f.hi);
      if (a >= b) continue;
      const auto phys = static_cast<std::uint32_t>(f.physical + (a - f.lo));
      const auto off = static_cast<std::size_t>(a - lo);
      const auto n_bytes = static_cast<std::size_t>(b - a);
      if (write_pass) {
        if (phys_write(phys, data.subspan(off, n_bytes))) write_hit = true;
        if (!fmmus_valid_) {
          // The write reached the FMMU registers themselves: go on with the FMMUs after this one
          // as they read now.
          decode_fmmus();
          k = 0;
          while (k < fmmu_n_ && fmmus_[k].index <= f.index) ++k;
          --k;  // the loop's ++k
        }
      } else if (phys_read(phys, data.subspan(off, n_bytes), false)) {
        read_hit = true;
      }
    }
  }
  // WKC: +1 for a read, +1 (LWR) or +2 (LRW) for a write [ETG.1000.4 §5.4 logical commands].
  if (read_hit) wkc = static_cast<std::uint16_t>(wkc + 1);
  if (write_hit) wkc = static_cast<std::uint16_t>(wkc + (c == Command::LRW ? 2 : 1));
  return read_hit || write_hit;
}

void EscSlave::process(std::span<std::uint8_t> header, std::span<std::uint8_t> data, std::span<std::uint8_t> wkc_bytes) noexcept {
  DatagramHeader h;
  if (!decode_datagram_header(header, h)) return;
  process(h, header, data, wkc_bytes);
}

void EscSlave::process(const DatagramHeader& decoded, std::span<std::uint8_t> header, std::span<std::uint8_t> data,
                       std::span<std::uint8_t> wkc_bytes) noexcept {
  if (header.size() < kDatagramHeaderSize || wkc_bytes.size() < 2) return;
  DatagramHeader h = decoded;
  h.address = get_u32(header, 2);  // the ADP as the slaves before this one left it
  std::uint16_t wkc = get_u16(wkc_bytes, 0);
  refresh_dynamic_registers();
  const std::uint16_t adp = h.adp();
  const std::uint16_t ado = h.ado();
  const Addressing addressing = addressing_of(h.command);
  bool addressed = false;
  if (addressing == Addressing::AutoIncrement || addressing == Addressing::Broadcast) {
    // Every slave increments ADP; an auto-increment datagram is for the one that sees 0
    // [ETG.1000.4 §5.4].
    addressed = addressing == Addressing::Broadcast || adp == 0;
    put_u16(header, 2, static_cast<std::uint16_t>(adp + 1));
  } else if (addressing == Addressing::Configured) {
    addressed = adp == station_address() ||
                ((u32(reg::kDlControl) & kDlControlAlias) != 0 && adp == u16(reg::kStationAlias));
  }
  switch (h.command) {
    case Command::APRD:
    case Command::FPRD:
    case Command::BRD:
      if (addressed && phys_read(ado, data, h.command == Command::BRD)) ++wkc;
      break;
    case Command::APWR:
    case Command::FPWR:
    case Command::BWR:
      if (addressed && phys_write(ado, data)) ++wkc;
      break;
    case Command::APRW:
    case Command::FPRW:
    case Command::BRW: {
      if (!addressed) break;
      // Read-write: the memory's content goes into the frame (ORed for BRW) and the frame's
      // data into memory; WKC +1 read, +2 write [ETG.1000.4 §5.4].
      std::copy(data.begin(), data.end(), scratch_.begin());
      const std::span<const std::uint8_t> incoming(scratch_.data(), data.size());
      if (phys_read(ado, data, h.command == Command::BRW)) wkc = static_cast<std::uint16_t>(wkc + 1);
      if (phys_write(ado, incoming)) wkc = static_cast<std::uint16_t>(wkc + 2);
      break;
    }
    case Command::ARMW:
    case Command::FRMW:
      // The addressed slave reads, every other slave writes; each counts once [ETG.1000.4 §5.4].
      if (addressed) {
        if (phys_read(ado, data, false)) ++wkc;
      } else if (phys_write(ado, data)) {
        ++wkc;
      }
      break;
    case Command::LRD:
    case Command::LWR:
    case Command::LRW:
      logical(h.command, h.address, data, wkc);
      break;
    default:
      break;  // NOP: nothing
  }
  put_u16(wkc_bytes, 0, wkc);
}

// ---- AL state machine [ETG.1000.6 §5.3] -------------------------------------------------------

void EscSlave::set_al(AlState s, std::uint16_t code, bool error) noexcept {
  state_ = s;
  set16(reg::kAlStatus, static_cast<std::uint16_t>(static_cast<std::uint16_t>(s) | (error ? kAlErrorBit : 0U)));
  set16(reg::kAlStatusCode, code);
}

void EscSlave::al_control_written() noexcept {
  const std::uint16_t control = u16(reg::kAlControl);
  const auto raw = static_cast<std::uint8_t>(control & kAlStateMask);
  const bool ack = (control & kAlErrorBit) != 0;
  const bool error = (u16(reg::kAlStatus) & kAlErrorBit) != 0;
  // With the error indication set, only an acknowledge or a request for a lower state is
  // processed [ETG.1000.6 §5.3.2: the master acknowledges the error with AL control bit 4].
  if (error && !ack && (!is_valid_state(raw) || raw >= static_cast<std::uint8_t>(state_))) return;
  if (ack) set_al(state_, 0, false);
  const bool keep_error = error && !ack;
  const std::uint16_t keep_code = keep_error ? u16(reg::kAlStatusCode) : 0;
  if (!is_valid_state(raw) || raw == 0) {
    set_al(state_, al_status_code::kUnknownState, true);
    return;
  }
  const auto to = static_cast<AlState>(raw);
  if (to == state_) return;
  const std::uint16_t code = check_transition(state_, to);
  if (code != 0) {
    set_al(state_, code, true);
    return;
  }
  const AlState from = state_;
  enter_state(from, to);
  set_al(to, keep_code, keep_error);
}

void EscSlave::limit_state(AlState highest, std::uint16_t code) noexcept {
  highest_ = highest;
  limit_code_ = code;
  if (static_cast<std::uint8_t>(state_) > static_cast<std::uint8_t>(highest)) {
    enter_state(state_, highest);
    set_al(highest, code, true);
  }
}

std::uint16_t EscSlave::check_transition(AlState from, AlState to) noexcept {
  if (to == AlState::Boot || from == AlState::Boot) return al_status_code::kBootstrapNotSupported;
  if (static_cast<std::uint8_t>(to) > static_cast<std::uint8_t>(highest_)) return limit_code_;
  const auto f = static_cast<std::uint8_t>(from);
  const auto t = static_cast<std::uint8_t>(to);
  if (t > f) {
    // Upward only one step: INIT -> PRE-OP -> SAFE-OP -> OP [ETG.1000.6 §5.3.1 ESM].
    const bool step = (from == AlState::Init && to == AlState::PreOp) ||
                      (from == AlState::PreOp && to == AlState::SafeOp) ||
                      (from == AlState::SafeOp && to == AlState::Op);
    if (!step) return al_status_code::kInvalidStateChange;
  }
  if (from == AlState::Init && to == AlState::PreOp && has_mailbox_) {
    // Mailbox SMs as the SII says: SM0 master -> slave, SM1 slave -> master, both 1-buffer and
    // enabled [ETG.1000.6 §5.3.2 transition IP, code 0016h].
    const SiiMailbox& mb = sii_info_->header.standard_mailbox;
    const SmEntry s0 = sm(0);
    const SmEntry s1 = sm(1);
    const bool ok0 = s0.enabled() && s0.physical_start == mb.rx_offset && s0.length == mb.rx_size &&
                     (s0.control & sm_control::kModeMask) == sm_control::kModeMailbox &&
                     (s0.control & sm_control::kDirectionMask) == sm_control::kDirectionWrite;
    const bool ok1 = s1.enabled() && s1.physical_start == mb.tx_offset && s1.length == mb.tx_size &&
                     (s1.control & sm_control::kModeMask) == sm_control::kModeMailbox &&
                     (s1.control & sm_control::kDirectionMask) == sm_control::kDirectionRead;
    if (!ok0 || !ok1) return al_status_code::kInvalidMailboxConfigPreOp;
  }
  if (from == AlState::PreOp && to == AlState::SafeOp && app_ != nullptr) {
    // Process data SMs: SM2 outputs, SM3 inputs, buffered, lengths equal to the mapped PDOs
    // [ETG.1000.6 §5.3.2 transition PS, codes 001Dh/001Eh; digest §5].
    const std::uint32_t ram_end = reg::kProcessRam + static_cast<std::uint32_t>(cfg_.ram_kib) * 1024U;
    auto valid = [&](unsigned n, std::size_t size, std::uint8_t direction) {
      const SmEntry s = sm(n);
      if (size == 0) return !s.enabled() || s.length == 0;
      return s.enabled() && s.length == size && (s.control & sm_control::kModeMask) == sm_control::kModeBuffered &&
             (s.control & sm_control::kDirectionMask) == direction && s.physical_start >= reg::kProcessRam &&
             static_cast<std::uint32_t>(s.physical_start) + s.length <= ram_end;
    };
    if (!valid(2, app_->output_size(), sm_control::kDirectionWrite)) return al_status_code::kInvalidOutputConfig;
    if (!valid(3, app_->input_size(), sm_control::kDirectionRead)) return al_status_code::kInvalidInputConfig;
  }
  if (app_ != nullptr) return app_->on_state_change(from, to);
  return 0;
}

void EscSlave::enter_state(AlState from, AlState to) noexcept {
  if (app_ != nullptr && from != to) app_->on_state_entered(from, to);
  switch (to) {
    case AlState::Init:
      // Back in INIT the PDI deactivates every SM and drops the mailbox [ETG.1000.6 §5.3.1].
      for (unsigned n = 0; n < cfg_.sm_count; ++n) set_pdi_deactivate(n, true);
      outbox_.clear();
      coe_.reset();
      last_sent_size_ = 0;
      last_rx_counter_ = 0;
      mailbox_pending_ = false;
      outputs_valid_ = false;
      break;
    case AlState::PreOp:
      set_pdi_deactivate(0, false);
      set_pdi_deactivate(1, false);
      set_pdi_deactivate(2, true);
      set_pdi_deactivate(3, true);
      outputs_valid_ = false;
      break;
    case AlState::SafeOp:
      set_pdi_deactivate(2, false);
      set_pdi_deactivate(3, false);
      outputs_valid_ = false;  // SAFE-OP: outputs are not applied [digest §5]
      break;
    case AlState::Op:
      wd_last_ns_ = now_ns_;  // the SM watchdog runs from here
      set16(reg::kWatchdogStatusProcessData, 1);
      break;
    default:
      break;
  }
}

// ---- SII EEPROM interface [ETG.1000.4 Table 48] -----------------------------------------------

void EscSlave::sii_command() noexcept {
  std::uint16_t ctl = u16(reg::kSiiControl);
  const std::uint16_t cmd = ctl & sii_control::kCommandMask;
  ctl = static_cast<std::uint16_t>(ctl & ~(sii_control::kCommandError | sii_control::kWriteError |
                                           sii_control::kChecksumError | sii_control::kDeviceInfoError));
  if (cmd == sii_control::kCommandRead) {
    const std::uint32_t word = u32(reg::kSiiAddress);
    const std::size_t n = cfg_.sii_read_8_bytes ? 8 : 4;
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint64_t at = static_cast<std::uint64_t>(word) * 2 + i;
      mem_[reg::kSiiData + i] = at < sii_.size() ? sii_[at] : 0xFF;  // unprogrammed beyond the image
    }
  } else if (cmd == sii_control::kCommandReload) {
    set16(reg::kStationAlias, sii_info_->header.station_alias);
  } else {
    ctl = static_cast<std::uint16_t>(ctl | sii_control::kCommandError);  // write or invalid: not offered
  }
  set16(reg::kSiiControl, static_cast<std::uint16_t>(ctl | sii_control::kBusy));
  sii_busy_ = static_cast<std::uint8_t>(cfg_.sii_busy_frames + 1);
}

// ---- Mailbox [ETG.1000.4 SM mailbox mode; ETG.1000.6 mailbox] ----------------------------------

void EscSlave::mailbox_received() noexcept {
  mailbox_pending_ = false;
  const std::span<const std::uint8_t> box = sm_buffer(0);
  const MailboxView v = decode_mailbox(box);
  // The PDI has read the mailbox: SM0 is empty again.
  sms_[0].mailbox_full = false;
  mem_[reg::sm_status(0)] = static_cast<std::uint8_t>(mem_[reg::sm_status(0)] & ~(sm_status::kMailboxFull | sm_status::kInterruptWrite));
  if (v.error != MailboxError::None) {
    outbox_.emit([](std::span<std::uint8_t> buf) { return encode_mailbox_error(buf, 0, mailbox_error_code::kInvalidSize); });
    return;
  }
  // A counter equal to the previous one is a repeated request (the master did not see the WKC)
  // and is discarded; 0 means "no counter" [ETG.1000.6 mailbox header, Cnt].
  if (v.header.counter != 0 && v.header.counter == last_rx_counter_) {
    ++duplicates_;
    return;
  }
  last_rx_counter_ = v.header.counter;
  if (v.header.type == static_cast<std::uint8_t>(MailboxType::CoE) &&
      (sii_info_->header.mailbox_protocols & mailbox_protocol::kCoE) != 0) {
    coe_.on_request(box, state_, outbox_);
    return;
  }
  outbox_.emit([](std::span<std::uint8_t> buf) {
    return encode_mailbox_error(buf, 0, mailbox_error_code::kUnsupportedProtocol);
  });
}

void EscSlave::load_sm1() noexcept {
  if (!has_mailbox_ || !sm_active(1) || sms_[1].mailbox_full || outbox_.empty()) return;
  const std::span<std::uint8_t> buf = sm_buffer(1);
  const auto msg = outbox_.front();
  if (msg.size() > buf.size()) {  // SM1 shorter than the SII's (or outside memory): drop, never cut
    outbox_.drop_front();
    return;
  }
  std::fill(buf.begin(), buf.end(), std::uint8_t{0});
  std::copy(msg.begin(), msg.end(), buf.begin());
  outbox_.pop();
  sms_[1].mailbox_full = true;
  mem_[reg::sm_status(1)] = static_cast<std::uint8_t>(mem_[reg::sm_status(1)] | sm_status::kMailboxFull);
}

void EscSlave::sm1_repeat() noexcept {
  // Repeat request: the master toggled SM1 activate bit 1; the slave puts the last mailbox back
  // into SM1 and answers with PDI control bit 1 = the request [ETG.1000.4 Table 59; ETG.1000.6
  // mailbox repeat].
  const auto pdi_at = reg::sm_pdi_control(1);
  const bool request = (mem_[reg::sm_activation(1)] & sm_activate::kRepeat) != 0;
  ++repeats_;
  const std::span<std::uint8_t> buf = sm_buffer(1);
  if (sms_[1].mailbox_full) {
    // A newer mailbox waiting in SM1 goes back to the front of the queue (its counter kept).
    const MailboxView v = decode_mailbox(buf);
    if (v.error == MailboxError::None) outbox_.push_front(buf.first(kMailboxHeaderSize + v.header.length));
    sms_[1].mailbox_full = false;
  }
  if (last_sent_size_ > 0 && last_sent_size_ <= buf.size()) {
    std::fill(buf.begin(), buf.end(), std::uint8_t{0});
    std::copy(last_sent_.begin(), last_sent_.begin() + static_cast<std::ptrdiff_t>(last_sent_size_), buf.begin());
    sms_[1].mailbox_full = true;
    mem_[reg::sm_status(1)] = static_cast<std::uint8_t>(mem_[reg::sm_status(1)] | sm_status::kMailboxFull);
  }
  mem_[pdi_at] = static_cast<std::uint8_t>(request ? (mem_[pdi_at] | sm_pdi_control::kRepeatAck) : (mem_[pdi_at] & ~sm_pdi_control::kRepeatAck));
}

bool EscSlave::post_emergency(const CoeEmergency& e) noexcept {
  if (!has_mailbox_) return false;
  return outbox_.emit([&](std::span<std::uint8_t> buf) { return encode_emergency(buf, 0, e); });
}

// ---- PDI cycle --------------------------------------------------------------------------------

void EscSlave::watchdog_check(std::uint64_t now_ns) noexcept {
  if (state_ != AlState::Op || app_ == nullptr || app_->output_size() == 0) return;
  const SmEntry s2 = sm(2);
  if ((s2.control & sm_control::kWatchdogTrigger) == 0) return;
  const std::uint64_t ticks = u16(reg::kWatchdogTimeProcessData);
  if (ticks == 0) return;  // 0 disables the watchdog
  const std::uint64_t timeout = (static_cast<std::uint64_t>(u16(reg::kWatchdogDivider)) + 2) * kWatchdogBaseNs * ticks;
  if (now_ns < wd_last_ns_ || now_ns - wd_last_ns_ <= timeout) return;
  // Expired: status 0440h bit 0 = 0, counter 0442h + 1, OP -> SAFE-OP with 001Bh, outputs off
  // [ETG.1000.4 Table 31; ETG.1000.6 §5.3.2; digest §8.2].
  set16(reg::kWatchdogStatusProcessData, 0);
  if (mem_[reg::kWatchdogCounterProcessData] < 0xFF) ++mem_[reg::kWatchdogCounterProcessData];
  enter_state(AlState::Op, AlState::SafeOp);
  set_al(AlState::SafeOp, al_status_code::kSmWatchdog, true);
}

void EscSlave::pdi_cycle(std::uint64_t now_ns) noexcept {
  now_ns_ = now_ns;
  system_time_fresh_ = false;
  if (cfg_.dc_supported) {
    clock_.advance(now_ns);
    sync0_cycle(now_ns);
  }
  if (sii_busy_ > 0 && --sii_busy_ == 0) {
    set16(reg::kSiiControl, static_cast<std::uint16_t>(u16(reg::kSiiControl) & ~(sii_control::kBusy | sii_control::kCommandMask)));
  }
  if (has_mailbox_ && state_ != AlState::Init) {
    if (mailbox_pending_) mailbox_received();
    const bool request = (mem_[reg::sm_activation(1)] & sm_activate::kRepeat) != 0;
    const bool acked = (mem_[reg::sm_pdi_control(1)] & sm_pdi_control::kRepeatAck) != 0;
    if (request != acked && sm_active(1)) sm1_repeat();
    load_sm1();
  }
  if (wd_triggered_) {
    wd_triggered_ = false;
    set16(reg::kWatchdogStatusProcessData, 1);
  }
  watchdog_check(now_ns);
  const bool sync0 = sync0_fired_;
  sync0_fired_ = false;
  if (app_ == nullptr) return;
  if (sync0) app_->on_sync0(sync0_last_, now_ns);
  const std::size_t out_n = std::min(app_->output_size(), zeros_.size());
  const std::size_t in_n = std::min(app_->input_size(), inputs_.size());
  std::span<const std::uint8_t> outputs(zeros_.data(), out_n);
  if (state_ == AlState::Op && outputs_valid_ && out_n > 0) {
    const std::span<const std::uint8_t> s2 = sm_buffer(2);
    if (s2.size() >= out_n) outputs = s2.first(out_n);
  }
  app_->exchange(outputs, std::span<std::uint8_t>(inputs_.data(), in_n), state_, now_ns);
  if ((state_ == AlState::SafeOp || state_ == AlState::Op) && in_n > 0 && sm_active(3)) {
    const std::span<std::uint8_t> s3 = sm_buffer(3);
    std::copy_n(inputs_.begin(), std::min(in_n, s3.size()), s3.begin());
  }
}

}  // namespace drivegate::ethercat::sim
