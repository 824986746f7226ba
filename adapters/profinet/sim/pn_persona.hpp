#pragma once
// What a simulated PROFINET IO device is (PnDevice, pn_device.hpp): its slots and modules, its
// records and what it does with the cyclic data each cycle. Two personas: AkdPersona (the
// Kollmorgen AKD with a PROFIdrive telegram module in slot 1) and GenericIoPersona (configurable
// I/O slots).
//
// Every call runs on the device's thread from PnDevice; none may allocate, lock or log.
#include <cstddef>
#include <cstdint>
#include <span>

#include "adapters/profinet/sim/cm_server.hpp"
#include "core/clock.hpp"

namespace drivegate::profinet {

// What the controller's outputs are worth this cycle [IEC 61158-6-10 §4.7: the output CR's
// DataStatus and IOPS, the consumer's data-hold watchdog].
enum class PnOutputs : std::uint8_t {
  NotYet,  // the AR is being set up: no valid output frame yet
  Valid,  // the output CR runs, provider RUN, the submodule's IOPS good
  Stop,   // the output CR runs but the controller is in STOP or the IOPS is bad
  Lost,   // no AR, or its output CR is not (yet) running
};

// One submodule of the running AR, in the Connect's order. The spans point into the device's
// cyclic engines and stay valid for the AR.
struct PnSubmoduleIo {
  std::uint32_t api = 0;
  std::uint16_t slot = 0;
  std::uint16_t subslot = 0;
  std::span<const std::uint8_t> output{};  // the last valid output data (controller -> device)
  PnOutputs outputs = PnOutputs::Lost;
  std::span<std::uint8_t> input{};  // the input data the device sends next (device -> controller)
};

class PnPersona {
 public:
  virtual ~PnPersona() = default;

  // The slots and submodules the device has now (CmServer compares a Connect with them). The
  // spans must stay valid while the persona lives; fit() may change what they hold.
  [[nodiscard]] virtual std::span<const CmModelSlot> slots() const noexcept = 0;
  // The data lengths of a submodule the device has (for the Connect's data descriptions).
  struct IoLengths {
    bool found = false;
    std::uint16_t input = 0;
    std::uint16_t output = 0;
  };
  [[nodiscard]] virtual IoLengths lengths(std::uint32_t api, std::uint16_t slot, std::uint16_t subslot) const noexcept = 0;
  // A Connect asks for `module_ident` with `submodule_ident` in `slot`: a modular device plugs
  // it when it can (the AKD: a telegram module in slot 1), others ignore it.
  virtual void fit(std::uint32_t api, std::uint16_t slot, std::uint32_t module_ident, std::uint16_t subslot,
                   std::uint32_t submodule_ident) noexcept = 0;
  // The shortest CR period (send clock x reduction ratio) the device runs; a Connect asking for a
  // faster one is refused.
  [[nodiscard]] virtual core::Duration min_update_time() const noexcept = 0;

  // A Connect set up the cyclic data; `watchdog` is the output CR's data hold time.
  virtual void on_ar_start(core::Duration watchdog) noexcept = 0;

  virtual PnioStatus write_record(const RecordReqHeader& h, std::span<const std::uint8_t> data) noexcept = 0;
  virtual PnioStatus read_record(const RecordReqHeader& h, std::span<std::uint8_t> into,
                                 std::size_t& length) noexcept = 0;

  // One cycle of `dt`: the AR's submodules (empty without an AR; then the device ticks on its
  // own at idle_period()).
  virtual void cycle(core::Duration dt, std::span<const PnSubmoduleIo> io) noexcept = 0;
  // Power lost and back: the persona starts over from its configuration (what a power cycle keeps).
  virtual void power_cycle() noexcept = 0;

 protected:
  PnPersona() = default;
  PnPersona(const PnPersona&) = default;
  PnPersona& operator=(const PnPersona&) = default;
};

// PNIORW statuses the personas answer with.
constexpr PnioStatus pniorw_status(bool write, std::uint8_t code1) noexcept {
  return {write ? pnio_error_code::kWrite : pnio_error_code::kRead, pnio_error_decode::kPniorw, code1, 0};
}

}  // namespace drivegate::profinet
