#include "adapters/ethercat/master/pdo_setup.hpp"

#include <algorithm>
#include <cstdarg>
#include <string>

#include "profiles/cia402/sdo_abort.hpp"

namespace drivegate::ethercat {

namespace {

// PDO assignment objects [ETG.1000.6: 1C12h SM2 (RxPDOs), 1C13h SM3 (TxPDOs); digest §7.4].
constexpr std::uint16_t kAssignSm2 = 0x1C12;
constexpr std::uint16_t kAssignSm3 = 0x1C13;

// Tag: bits 16-31 generation of start(), 0-15 register write index.
constexpr std::uint32_t make_tag(std::uint16_t generation, std::size_t item) noexcept {
  return (std::uint32_t{generation} << 16) | static_cast<std::uint32_t>(item & 0xFFFF);
}

// Hex digits for a value of `size` bytes (0x01, 0x1600, 0x60710010).
int digits(std::uint8_t size) noexcept { return 2 * std::clamp<int>(size, 1, 4); }

bool length_abort(std::uint32_t code) noexcept {
  return code == cia402::sdo_abort_code::kTypeMismatch || code == cia402::sdo_abort_code::kTooLong ||
         code == cia402::sdo_abort_code::kTooShort;
}

}  // namespace

std::string_view to_string(PdoSetupStatus s) noexcept {
  switch (s) {
    case PdoSetupStatus::Idle: return "idle";
    case PdoSetupStatus::Running: return "running";
    case PdoSetupStatus::Done: return "done";
    case PdoSetupStatus::Failed: return "failed";
  }
  return "?";
}

std::string_view to_string(PdoSetupStep s) noexcept {
  switch (s) {
    case PdoSetupStep::StartupWrites: return "start-up writes";
    case PdoSetupStep::Assignment: return "PDO assignment and mapping";
    case PdoSetupStep::Verify: return "verify";
    case PdoSetupStep::Registers: return "SM and FMMU registers";
    case PdoSetupStep::Finished: return "finished";
  }
  return "?";
}

const char* PdoSetup::area_name(Area a) noexcept {
  switch (a) {
    case Area::Startup: return "start-up write";
    case Area::Assignment: return "PDO assignment";
    case Area::Mapping: return "PDO mapping";
  }
  return "?";
}

void PdoSetup::add_op(Area area, std::uint16_t index, std::uint8_t subindex, std::uint32_t value, std::uint8_t size,
                      std::uint8_t entry_sm, std::uint32_t final_value) noexcept {
  if (op_count_ >= ops_.size()) return;  // start() checked the capacities
  ops_[op_count_++] = Op{area, index, subindex, size, value, entry_sm, is_ignored(index, subindex), final_value};
}

bool PdoSetup::add_direction(std::uint16_t assign_index, std::span<const PdoConfig> pdos, std::uint8_t sm) noexcept {
  // Count 0, the mapping objects, the assignment entries, the count [digest §7.2/§7.4, TV-6].
  add_op(Area::Assignment, assign_index, 0, 0, 1, 0, static_cast<std::uint32_t>(pdos.size()));
  for (const PdoConfig& p : pdos) {
    if (p.entries.size() > 254) return false;  // sub-index 0 is UNSIGNED8, 255 reserved
    add_op(Area::Mapping, p.index, 0, 0, 1, 0, static_cast<std::uint32_t>(p.entries.size()));
    for (std::size_t i = 0; i < p.entries.size(); ++i) {
      add_op(Area::Mapping, p.index, static_cast<std::uint8_t>(i + 1), p.entries[i].value(), 4, sm);
    }
    add_op(Area::Mapping, p.index, 0, static_cast<std::uint32_t>(p.entries.size()), 1);
  }
  for (std::size_t i = 0; i < pdos.size(); ++i) {
    add_op(Area::Assignment, assign_index, static_cast<std::uint8_t>(i + 1), pdos[i].index, 2);
  }
  add_op(Area::Assignment, assign_index, 0, static_cast<std::uint32_t>(pdos.size()), 1);
  return true;
}

void PdoSetup::add_reg(std::uint16_t ado, std::span<const std::uint8_t> data, const char* what) noexcept {
  if (reg_count_ >= regs_.size()) return;
  RegWrite& r = regs_[reg_count_++];
  r = RegWrite{};
  r.ado = ado;
  r.length = static_cast<std::uint8_t>(std::min(data.size(), r.data.size()));
  std::copy_n(data.begin(), r.length, r.data.begin());
  r.what = what;
  r.retries_left = retries_;
}

bool PdoSetup::is_ignored(std::uint16_t index, std::uint8_t subindex) const noexcept {
  return std::any_of(ignored_.begin(), ignored_.begin() + static_cast<std::ptrdiff_t>(ignored_count_),
                     [&](const CoeObjectId& o) { return o.index == index && o.subindex == subindex; });
}

bool PdoSetup::start(CoeSdoClient* coe, const PdoSetupConfig& config, const SlaveImage& image, core::TimePoint now) noexcept {
  now_ = now;
  if (coe_ != nullptr && sdo_id_ != 0) {
    abandoned_client_ = coe_;
    abandoned_ = sdo_id_;
  }
  coe_ = coe;
  ++generation_;
  slave_number_ = static_cast<std::uint16_t>(config.position + 1);
  station_ = image.station;
  image_ = image;
  map_pdos_ = config.map_pdos;
  retries_ = std::max(config.retries, 0);
  status_ = PdoSetupStatus::Running;
  step_ = PdoSetupStep::StartupWrites;
  counters_ = PdoSetupCounters{};
  text_.clear();
  warning_count_ = 0;
  op_count_ = 0;
  op_ = 0;
  reg_count_ = 0;
  bits_ = {};
  sdo_phase_ = SdoPhase::Download;
  sdo_id_ = 0;

  std::size_t entries = 0;
  for (const PdoConfig& p : config.rx_pdos) entries += p.entries.size();
  for (const PdoConfig& p : config.tx_pdos) entries += p.entries.size();
  const std::size_t pdos = config.rx_pdos.size() + config.tx_pdos.size();
  if (config.startup_writes.size() > kMaxStartupWrites || config.ignored_writes.size() > kMaxIgnored ||
      pdos > kMaxPdos || entries > kMaxEntries) {
    fail("slave %u (0x%04X): process data set-up: %zu start-up writes, %zu ignored objects, %zu PDOs, %zu entries; at "
         "most %zu, %zu, %zu, %zu",
         slave_number_, station_, config.startup_writes.size(), config.ignored_writes.size(), pdos, entries,
         kMaxStartupWrites, kMaxIgnored, kMaxPdos, kMaxEntries);
    return false;
  }
  ignored_count_ = config.ignored_writes.size();
  std::copy(config.ignored_writes.begin(), config.ignored_writes.end(), ignored_.begin());
  const bool needs_coe = !config.startup_writes.empty() || config.map_pdos;
  if (coe_ == nullptr && needs_coe) {
    // A slave without CoE cannot take start-up writes or a mapping: only its registers are set
    // (map_pdos = false for plain I/O slaves).
    if (!config.startup_writes.empty() || !config.rx_pdos.empty() || !config.tx_pdos.empty()) {
      fail("slave %u (0x%04X): process data set-up: CoE writes configured, but the slave has no mailbox", slave_number_,
           station_);
      return false;
    }
    map_pdos_ = false;
  }
  for (const CoeStartupWrite& w : config.startup_writes) {
    if (w.size < 1 || w.size > 4) {
      fail("slave %u (0x%04X): start-up write %04Xh:%02X has %u bytes (1..4 supported)", slave_number_, station_, w.index,
           w.subindex, w.size);
      return false;
    }
    add_op(Area::Startup, w.index, w.subindex, w.value, w.size);
  }
  if (map_pdos_) {
    if (!add_direction(kAssignSm2, config.rx_pdos, 2) || !add_direction(kAssignSm3, config.tx_pdos, 3)) {
      fail("slave %u (0x%04X): PDO mapping: a PDO with more than 254 entries", slave_number_, station_);
      return false;
    }
  }

  // Registers [ETG.1000.4 Table 31, Table 56 FMMU, Table 59 SyncManager].
  add_reg(reg::sm(2), encode_sm(image.sm2), "SM2");
  add_reg(reg::sm(3), encode_sm(image.sm3), "SM3");
  add_reg(reg::fmmu(image.fmmu_outputs_index), encode_fmmu(image.fmmu_outputs), "output FMMU");
  add_reg(reg::fmmu(image.fmmu_inputs_index), encode_fmmu(image.fmmu_inputs), "input FMMU");
  if (config.sm_watchdog.count() > 0) {
    const std::int64_t ticks = std::clamp<std::int64_t>((config.sm_watchdog.count() + kWatchdogTickNs - 1) / kWatchdogTickNs, 1, 0xFFFF);
    const std::array<std::uint8_t, 2> divider{static_cast<std::uint8_t>(kWatchdogDivider & 0xFF),
                                              static_cast<std::uint8_t>(kWatchdogDivider >> 8)};
    const std::array<std::uint8_t, 2> time{static_cast<std::uint8_t>(ticks & 0xFF), static_cast<std::uint8_t>(ticks >> 8)};
    add_reg(reg::kWatchdogDivider, divider, "watchdog divider");
    add_reg(reg::kWatchdogTimeProcessData, time, "SM watchdog time");
  }
  if (op_count_ == 0) {
    step_ = PdoSetupStep::Registers;
    for (std::size_t i = 0; i < reg_count_; ++i) regs_[i].due = true;
  } else {
    step_ = ops_[0].area == Area::Startup ? PdoSetupStep::StartupWrites : PdoSetupStep::Assignment;
    write_size_ = ops_[0].size;
  }
  return true;
}

void PdoSetup::poll(core::TimePoint now, Transactions& tx) noexcept {
  now_ = now;
  if (abandoned_ != 0) {
    const CoeSdoStatus s = abandoned_client_->result(abandoned_).status;
    if (s != CoeSdoStatus::Queued && s != CoeSdoStatus::InFlight) {
      abandoned_client_->take(abandoned_);
      abandoned_ = 0;
    }
  }
  if (status_ != PdoSetupStatus::Running) return;
  if (step_ == PdoSetupStep::StartupWrites || step_ == PdoSetupStep::Assignment) step_sdo();
  if (status_ != PdoSetupStatus::Running || step_ != PdoSetupStep::Registers) return;
  for (std::size_t i = 0; i < reg_count_; ++i) {
    RegWrite& r = regs_[i];
    if (!r.due) continue;
    if (tx.queue(this, make_tag(generation_, i), Command::FPWR, physical_address(station_, r.ado), r.length,
                 std::span<const std::uint8_t>(r.data.data(), r.length))) {
      r.due = false;
      r.waiting = true;
      ++counters_.register_writes;
    }
  }
}

void PdoSetup::on_result(std::uint32_t tag, const DatagramAnswer& answer) noexcept {
  if ((tag >> 16) != generation_ || status_ != PdoSetupStatus::Running || step_ != PdoSetupStep::Registers) return;
  const std::size_t i = tag & 0xFFFF;
  if (i >= reg_count_ || !regs_[i].waiting) return;
  RegWrite& r = regs_[i];
  r.waiting = false;
  if (answer.outcome == DatagramOutcome::Lost) {
    if (r.retries_left-- > 0) {
      ++counters_.register_retries;
      r.due = true;
      return;
    }
    fail("slave %u (0x%04X): %s (FPWR %04Xh): no answer after %d tries", slave_number_, station_, r.what, r.ado,
         retries_ + 1);
    return;
  }
  if (answer.wkc != 1) {
    fail("slave %u (0x%04X): %s (FPWR %04Xh): working counter %u, expected 1: the slave did not take the write",
         slave_number_, station_, r.what, r.ado, answer.wkc);
    return;
  }
  r.done = true;
  const bool all = std::all_of(regs_.begin(), regs_.begin() + static_cast<std::ptrdiff_t>(reg_count_),
                               [](const RegWrite& w) { return w.done; });
  if (all) {
    step_ = PdoSetupStep::Finished;
    status_ = PdoSetupStatus::Done;
  }
}

void PdoSetup::step_sdo() noexcept {
  // At most a few transitions per poll: a request finished, the next one submitted.
  for (int guard = 0; guard < 8 && status_ == PdoSetupStatus::Running && op_ < op_count_; ++guard) {
    const Op& op = ops_[op_];
    switch (sdo_phase_) {
      case SdoPhase::Download:
        sdo_id_ = coe_->download_value(op.index, op.subindex, op.value, write_size_);
        if (sdo_id_ == 0) return;  // the client's queue is full: again at the next poll
        ++counters_.sdo_writes;
        sdo_phase_ = SdoPhase::WaitDownload;
        break;
      case SdoPhase::WaitDownload: {
        const CoeSdoResult r = coe_->result(sdo_id_);
        if (r.status != CoeSdoStatus::Done && r.status != CoeSdoStatus::Failed) return;
        coe_->take(sdo_id_);
        sdo_id_ = 0;
        download_ok_ = r.status == CoeSdoStatus::Done;
        download_abort_ = r.abort_code;
        // A 1-byte count refused for its length: try 2 bytes (digest TV-6 note).
        if (!download_ok_ && write_size_ == 1 && op.subindex == 0 && length_abort(r.abort_code)) {
          write_size_ = 2;
          ++counters_.retried_two_bytes;
          sdo_phase_ = SdoPhase::Download;
          break;
        }
        sdo_phase_ = SdoPhase::Upload;
        break;
      }
      case SdoPhase::Upload:
        sdo_id_ = coe_->upload_value(op.index, op.subindex);
        if (sdo_id_ == 0) return;
        ++counters_.sdo_reads;
        sdo_phase_ = SdoPhase::WaitUpload;
        break;
      case SdoPhase::WaitUpload: {
        const CoeSdoResult r = coe_->result(sdo_id_);
        if (r.status != CoeSdoStatus::Done && r.status != CoeSdoStatus::Failed) return;
        coe_->take(sdo_id_);
        sdo_id_ = 0;
        finish_op(download_ok_, download_abort_, r);
        break;
      }
    }
  }
}

void PdoSetup::finish_op(bool download_ok, std::uint32_t download_abort, const CoeSdoResult& read) noexcept {
  const Op& op = ops_[op_];
  const int w = digits(op.size);
  const char* area = area_name(op.area);
  const bool read_ok = read.status == CoeSdoStatus::Done;
  const bool same = read_ok && (read.value == op.value || (!download_ok && op.subindex == 0 && op.value == 0 &&
                                                           op.area != Area::Startup && read.value == op.final_value));
  if (same) {
    if (!download_ok) ++counters_.refused_but_set;  // a fixed mapping: refused, but already so
    if (op.entry_sm == 2 || op.entry_sm == 3) bits_[op.entry_sm - 2U] += read.value & 0xFF;
    next_op();
    return;
  }
  // Why the read-back failed, if it did.
  core::FixedString<120> read_text{};
  if (!read_ok) {
    if (read.mailbox_error != 0) {
      read_text.format("mailbox error 0x%04X", read.mailbox_error);
    } else {
      const std::string_view t = cia402::sdo_abort_text(read.abort_code);
      read_text.format("0x%08X %.*s", read.abort_code, static_cast<int>(t.size()), t.data());
    }
  }
  if (op.ignored) {
    // Listed as accepted and ignored by the device (digest quirk 8): a warning, the set-up goes on.
    if (read_ok) {
      warn("slave %u (0x%04X): %s: %04Xh:%02X reads 0x%0*X after writing 0x%0*X (listed as ignored by the drive)",
           slave_number_, station_, area, op.index, op.subindex, w, read.value, w, op.value);
    } else {
      warn("slave %u (0x%04X): %s: %04Xh:%02X written, read-back failed (%s; listed as ignored by the drive)",
           slave_number_, station_, area, op.index, op.subindex, read_text.c_str());
    }
    next_op();
    return;
  }
  if (download_ok) {
    if (read_ok) {
      fail("slave %u (0x%04X): %s: %04Xh:%02X reads 0x%0*X after writing 0x%0*X (the drive ignored the write)",
           slave_number_, station_, area, op.index, op.subindex, w, read.value, w, op.value);
    } else {
      fail("slave %u (0x%04X): %s: %04Xh:%02X := 0x%0*X written, read-back failed: %s", slave_number_, station_, area,
           op.index, op.subindex, w, op.value, read_text.c_str());
    }
    return;
  }
  const std::string_view why = cia402::sdo_abort_text(download_abort);
  if (read_ok) {
    fail("slave %u (0x%04X): %s: %04Xh:%02X := 0x%0*X refused (0x%08X %.*s); it reads 0x%0*X", slave_number_, station_,
         area, op.index, op.subindex, w, op.value, download_abort, static_cast<int>(why.size()), why.data(), w,
         read.value);
  } else {
    fail("slave %u (0x%04X): %s: %04Xh:%02X := 0x%0*X refused (0x%08X %.*s); read-back failed: %s", slave_number_,
         station_, area, op.index, op.subindex, w, op.value, download_abort, static_cast<int>(why.size()), why.data(),
         read_text.c_str());
  }
}

void PdoSetup::next_op() noexcept {
  ++op_;
  sdo_phase_ = SdoPhase::Download;
  if (op_ < op_count_) {
    write_size_ = ops_[op_].size;
    if (ops_[op_].area != Area::Startup) step_ = PdoSetupStep::Assignment;
    return;
  }
  verify();
}

void PdoSetup::verify() noexcept {
  step_ = PdoSetupStep::Verify;
  if (map_pdos_) {
    // The mapped bits per SM, in bytes, are the SM lengths the image planned [digest §7.4: a
    // mismatch is refused at PRE-OP -> SAFE-OP with A000h / AL 001Dh, 001Eh].
    const std::array<std::uint16_t, 2> planned{image_.output_bytes, image_.input_bytes};
    for (unsigned i = 0; i < 2; ++i) {
      if (bytes_of_bits(bits_[i]) != planned[i]) {
        fail("slave %u (0x%04X): PDO mapping: SM%u carries %u bits (%u bytes) after the mapping, the process image "
             "plans %u bytes",
             slave_number_, station_, i + 2, bits_[i], bytes_of_bits(bits_[i]), planned[i]);
        return;
      }
    }
  }
  step_ = PdoSetupStep::Registers;
  for (std::size_t i = 0; i < reg_count_; ++i) regs_[i].due = true;
}

void PdoSetup::warn(const char* fmt, ...) noexcept {
  if (warning_count_ >= warnings_.size()) return;
  va_list args;
  va_start(args, fmt);
  warnings_[warning_count_++].vformat(fmt, args);
  va_end(args);
}

void PdoSetup::fail(const char* fmt, ...) noexcept {
  va_list args;
  va_start(args, fmt);
  text_.vformat(fmt, args);
  va_end(args);
  status_ = PdoSetupStatus::Failed;
}

}  // namespace drivegate::ethercat
