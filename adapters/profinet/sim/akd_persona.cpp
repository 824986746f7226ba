#include "adapters/profinet/sim/akd_persona.hpp"

#include <algorithm>
#include <stdexcept>

#include "adapters/profinet/wire/blocks_record.hpp"
#include "profiles/profidrive/telegram.hpp"

namespace drivegate::profinet {

namespace sim = profidrive::sim;

bool akd::offers_telegram(std::uint16_t telegram) noexcept {
  return telegram != 0 && profidrive::telegram_size(telegram).has_value();
}

AkdPersona::AkdPersona(const AkdPersonaConfig& config) : config_(config), telegram_(config.drive.telegram) {
  if (!akd::offers_telegram(telegram_)) {
    throw std::invalid_argument("AKD persona: no telegram module for telegram " + std::to_string(telegram_));
  }
  dap_subs_[0] = {1, akd::kDapSubmodule};
  slots_[0] = {0, 0, akd::kDapModule, dap_subs_};
  plug(telegram_);
  (void)encode_im1({}, im1_);
}

void AkdPersona::plug(std::uint16_t telegram) noexcept {
  telegram_ = telegram;
  sim::DriveModelConfig c = config_.drive;
  c.telegram = telegram;
  drive_.emplace(c);
  telegram_subs_[0] = {akd::kTelegramSubslot, akd::telegram_submodule(telegram)};
  slots_[1] = {akd::kProfidriveApi, akd::kTelegramSlot, akd::telegram_module(telegram), telegram_subs_};
}

PnPersona::IoLengths AkdPersona::lengths(std::uint32_t api, std::uint16_t slot, std::uint16_t subslot) const noexcept {
  if (api == 0 && slot == 0 && subslot == 1) return {true, 0, 0};
  if (api != akd::kProfidriveApi || slot != akd::kTelegramSlot || subslot != akd::kTelegramSubslot) return {};
  const auto size = profidrive::telegram_size(telegram_);  // offers_telegram() checked it
  return {true, static_cast<std::uint16_t>(size->actual_bytes), static_cast<std::uint16_t>(size->setpoint_bytes)};
}

void AkdPersona::fit(std::uint32_t api, std::uint16_t slot, std::uint32_t module_ident, std::uint16_t subslot,
                     std::uint32_t submodule_ident) noexcept {
  if (api != akd::kProfidriveApi || slot != akd::kTelegramSlot || subslot != akd::kTelegramSubslot) return;
  if (module_ident < akd::telegram_module(0) || module_ident > akd::telegram_module(0xFFFF)) return;
  const auto telegram = static_cast<std::uint16_t>(module_ident - akd::telegram_module(0));
  if (!akd::offers_telegram(telegram) || submodule_ident != akd::telegram_submodule(telegram)) return;
  // [sim] Another telegram module: the drive starts over with it (its PNU 922 is the module's).
  if (telegram != telegram_) plug(telegram);
}

PnioStatus AkdPersona::write_record(const RecordReqHeader& h, std::span<const std::uint8_t> data) noexcept {
  if (h.index == record_index::kIm0) return pniorw_status(true, pniorw_error::kAccessDenied);
  if (h.index == record_index::kIm1) {
    if (data.size() != im1_.size()) return pniorw_status(true, pniorw_error::kWriteLengthError);
    if (decode_im1(data).error != WireError::None) return pniorw_status(true, pniorw_error::kInvalidRange);
    std::copy(data.begin(), data.end(), im1_.begin());
    return {};
  }
  if (h.index != record_index::kAkdParameterAccess || h.slot != akd::kTelegramSlot) {
    return pniorw_status(true, pniorw_error::kInvalidIndex);
  }
  switch (drive_->write_parameter_record(data)) {
    case sim::RecordStatus::Ok: return {};
    case sim::RecordStatus::WriteLengthError: return pniorw_status(true, pniorw_error::kWriteLengthError);
    case sim::RecordStatus::StateConflict:
    case sim::RecordStatus::BufferTooSmall: break;
  }
  return pniorw_status(true, pniorw_error::kStateConflict);
}

PnioStatus AkdPersona::read_record(const RecordReqHeader& h, std::span<std::uint8_t> into, std::size_t& length) noexcept {
  if (h.index == record_index::kIm0) {
    Im0 im;
    im.vendor_id = config_.vendor_id;
    im.order_id = config_.order_id;
    im.serial_number = config_.serial_number;
    im.profile_id = static_cast<std::uint16_t>(akd::kProfidriveApi);
    im.im_supported = 0x0002;  // I&M1
    length = encode_im0(im, into);
    return length == 0 ? pniorw_status(false, pniorw_error::kInvalidRange) : PnioStatus{};
  }
  if (h.index == record_index::kIm1) {
    length = std::min(into.size(), im1_.size());
    std::copy_n(im1_.begin(), length, into.begin());
    return {};
  }
  if (h.index != record_index::kAkdParameterAccess || h.slot != akd::kTelegramSlot) {
    return pniorw_status(false, pniorw_error::kInvalidIndex);
  }
  const sim::RecordRead r = drive_->read_parameter_record(into);
  switch (r.status) {
    case sim::RecordStatus::Ok: length = r.size; return {};
    // The controller's RecordDataLength is shorter than the response (it stays waiting).
    case sim::RecordStatus::BufferTooSmall: return pniorw_status(false, pniorw_error::kInvalidRange);
    case sim::RecordStatus::WriteLengthError:
    case sim::RecordStatus::StateConflict: break;
  }
  return pniorw_status(false, pniorw_error::kStateConflict);
}

void AkdPersona::cycle(core::Duration dt, std::span<const PnSubmoduleIo> io) noexcept {
  const auto tg = std::find_if(io.begin(), io.end(), [](const PnSubmoduleIo& s) {
    return s.api == akd::kProfidriveApi && s.slot == akd::kTelegramSlot && s.subslot == akd::kTelegramSubslot;
  });
  // The telegram's submodule is not in the AR (or is not the plugged one): as without an AR.
  const bool carried = tg != io.end() && !tg->input.empty();
  const PnOutputs o = carried ? tg->outputs : PnOutputs::Lost;
  const std::span<std::uint8_t> actual =
      carried ? tg->input : std::span<std::uint8_t>(scratch_).first(drive_->layout().actual_bytes());
  if (o == PnOutputs::Valid) live_ = true;
  if (!live_) {
    // Nothing came from a controller since power-on: the drive waits in S1; show its status.
    (void)profidrive::encode_actuals(drive_->layout(), drive_->actuals(), actual);
    return;
  }
  switch (o) {
    case PnOutputs::Valid: drive_->set_outputs(sim::Outputs::Valid); break;
    case PnOutputs::Stop: drive_->set_outputs(sim::Outputs::ControllerStop); break;
    case PnOutputs::NotYet:
    case PnOutputs::Lost: drive_->set_outputs(sim::Outputs::Lost); break;
  }
  drive_->step(dt, carried ? tg->output : std::span<const std::uint8_t>{}, actual);
}

void AkdPersona::power_cycle() noexcept {
  live_ = false;
  plug(telegram_);
}

}  // namespace drivegate::profinet
