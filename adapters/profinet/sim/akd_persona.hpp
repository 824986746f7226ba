#pragma once
// The Kollmorgen AKD PROFINET as a simulated IO device's persona (akd-profinet-profidrive.md, cited
// as §n), on the PROFIdrive drive model (profiles/profidrive/sim):
//
//   slot 0     the DAP, API 0, one submodule without IO in subslot 1 [§4.1: "Sub 0", the device]
//   slot 1     one telegram module, API 3A00h [§2, §4.1], subslot 1; the Connect's expected
//              module picks which: a modular device plugs the module the controller configured
//              [§4.2 step 4: exactly one telegram module in slot 1]. The idents are [sim]: the
//              digest gives none (§4.1: they are in the GSDML only): module 100h + telegram,
//              submodule = telegram number, for telegrams 1, 7, 9, 350..353 and 400 (telegram 0's
//              I/O length is not stated, §13, so no module offers it). A module ident that is no
//              telegram leaves the plugged one, and the ModuleDiffBlock says "wrong module".
//   PN.TIMEOUTFTHRESH  PNU 3022 reads the output CR's data hold time of the running AR (§19.3).
//   record 47  on slot 1 subslot 1: the PROFIdrive parameter channel [§5.1] (write the request,
//              read the response; a read with nothing waiting or a second write before the read
//              is PNIORW "state conflict", a request over 240 bytes "write length error").
//   I&M0       index AFF0h on every subslot (profile ID 3A00h).
//   I&M1       index AFF1h on every subslot [sim]: the device's one pair of tags, written and read
//              back (a write that is no I&M1 block is refused: PNIORW write length error or
//              invalid range); it survives a power cycle.
//   cycle      the drive model steps each cycle with the received setpoint image and its actual
//              image is the telegram's input data. The outputs' worth goes to
//              DriveModel::set_outputs: STOP / bad IOPS is ControllerStop (F702 with FBUS.PARAM02
//              bit 0, §18.4), a lost AR Lost (F702, §18.3); before an AR ever ran the drive waits
//              in S1 untouched. Without an AR the drive keeps stepping (it brakes) at the device's
//              idle period.
//
// The AKD's fastest update time is 16 ms [§2]: a Connect with a faster CR is refused (IOCRBlockReq,
// [sim] the field ReductionRatio: the digest does not say what the AKD answers; its GSDML would not
// offer the controller such a ratio).
#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include "adapters/profinet/sim/pn_persona.hpp"
#include "profiles/profidrive/sim/drive_model.hpp"

namespace drivegate::profinet {

namespace akd {
inline constexpr std::uint32_t kProfidriveApi = 0x3A00;  // §2
inline constexpr std::uint32_t kDapModule = 0x00000001;     // [sim]
inline constexpr std::uint32_t kDapSubmodule = 0x00000001;  // [sim]
inline constexpr std::uint16_t kTelegramSlot = 1;
inline constexpr std::uint16_t kTelegramSubslot = 1;
inline constexpr core::Duration kMinUpdateTime = std::chrono::milliseconds(16);  // §2
// [sim] idents of the telegram modules (above).
constexpr std::uint32_t telegram_module(std::uint16_t telegram) noexcept { return 0x100U + telegram; }
constexpr std::uint32_t telegram_submodule(std::uint16_t telegram) noexcept { return telegram; }
// Whether the simulated AKD offers a module for `telegram`.
bool offers_telegram(std::uint16_t telegram) noexcept;
}  // namespace akd

struct AkdPersonaConfig {
  profidrive::sim::DriveModelConfig drive{};  // drive.telegram: the module plugged at power-on
  std::uint16_t vendor_id = 0;                // I&M0
  std::string order_id = "AKD-P00306-NBPN-0000";  // [sim] an AKD PROFINET order code
  std::string serial_number = "SIM0000001";
};

class AkdPersona final : public PnPersona {
 public:
  // Throws std::invalid_argument when drive.telegram has no module (akd::offers_telegram).
  explicit AkdPersona(const AkdPersonaConfig& config);

  [[nodiscard]] std::span<const CmModelSlot> slots() const noexcept override { return slots_; }
  [[nodiscard]] IoLengths lengths(std::uint32_t api, std::uint16_t slot, std::uint16_t subslot) const noexcept override;
  void fit(std::uint32_t api, std::uint16_t slot, std::uint32_t module_ident, std::uint16_t subslot,
           std::uint32_t submodule_ident) noexcept override;
  [[nodiscard]] core::Duration min_update_time() const noexcept override { return akd::kMinUpdateTime; }
  // PN.TIMEOUTFTHRESH (PNU 3022) reads the watchdog the controller assigned [§18.3, §19.3].
  void on_ar_start(core::Duration watchdog) noexcept override {
    drive_->set_watchdog_ms(static_cast<std::uint32_t>(std::chrono::duration_cast<std::chrono::milliseconds>(watchdog).count()));
  }
  PnioStatus write_record(const RecordReqHeader& h, std::span<const std::uint8_t> data) noexcept override;
  PnioStatus read_record(const RecordReqHeader& h, std::span<std::uint8_t> into, std::size_t& length) noexcept override;
  void cycle(core::Duration dt, std::span<const PnSubmoduleIo> io) noexcept override;
  void power_cycle() noexcept override;

  // Fault injection: an AKD fault number into the drive's fault situation (§18.2).
  void inject_drive_fault(std::uint16_t number, bool persistent = false) noexcept {
    drive_->inject_fault(number, persistent);
  }
  [[nodiscard]] std::uint16_t telegram() const noexcept { return telegram_; }
  [[nodiscard]] profidrive::sim::DriveModel& drive() noexcept { return *drive_; }
  [[nodiscard]] const profidrive::sim::DriveModel& drive() const noexcept { return *drive_; }

 private:
  void plug(std::uint16_t telegram) noexcept;

  AkdPersonaConfig config_;
  std::uint16_t telegram_;
  std::optional<profidrive::sim::DriveModel> drive_;
  bool live_ = false;  // the outputs were valid once since power-on
  std::array<CmModelSubmodule, 1> dap_subs_{};
  std::array<CmModelSubmodule, 1> telegram_subs_{};
  std::array<CmModelSlot, 2> slots_{};
  std::array<std::uint8_t, 2 * profidrive::kMaxTelegramWords> scratch_{};  // actual image without an AR
  std::array<std::uint8_t, kIm1Size> im1_{};  // the I&M1 record as last written
};

}  // namespace drivegate::profinet
