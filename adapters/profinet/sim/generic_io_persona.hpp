#pragma once
// A generic PROFINET IO device persona: the slots, modules and submodules of its configuration,
// each submodule with its input and output lengths (both 0: no IO, like a DAP). A test or console
// sets the inputs it sends and reads the outputs it received; I&M0 (AFF0h) reads on every
// subslot; other records are refused (PNIORW "invalid index"). Fixed: no module is plugged by a
// Connect (a different expectation shows in the ModuleDiffBlock).
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "adapters/profinet/sim/pn_persona.hpp"

namespace drivegate::profinet {

struct GenericSubmoduleConfig {
  std::uint16_t subslot = 1;
  std::uint32_t ident = 0;
  std::uint16_t input_length = 0;   // octets device -> controller
  std::uint16_t output_length = 0;  // octets controller -> device
};
struct GenericSlotConfig {
  std::uint32_t api = 0;
  std::uint16_t slot = 0;
  std::uint32_t module_ident = 0;
  std::vector<GenericSubmoduleConfig> submodules;
};
struct GenericIoPersonaConfig {
  std::vector<GenericSlotConfig> slots;
  std::uint16_t vendor_id = 0;  // I&M0
  std::string order_id = "SIM-GENERIC-IO";
  std::string serial_number = "SIM0000001";
  core::Duration min_update_time = std::chrono::milliseconds(1);  // PnPersona::min_update_time
};

class GenericIoPersona final : public PnPersona {
 public:
  // Throws std::invalid_argument for a slot or subslot given twice or data longer than 1440 octets.
  explicit GenericIoPersona(GenericIoPersonaConfig config);

  [[nodiscard]] std::span<const CmModelSlot> slots() const noexcept override { return model_; }
  [[nodiscard]] IoLengths lengths(std::uint32_t api, std::uint16_t slot, std::uint16_t subslot) const noexcept override;
  void fit(std::uint32_t, std::uint16_t, std::uint32_t, std::uint16_t, std::uint32_t) noexcept override {}
  void on_ar_start(core::Duration) noexcept override {}
  [[nodiscard]] core::Duration min_update_time() const noexcept override { return config_.min_update_time; }
  PnioStatus write_record(const RecordReqHeader& h, std::span<const std::uint8_t> data) noexcept override;
  PnioStatus read_record(const RecordReqHeader& h, std::span<std::uint8_t> into, std::size_t& length) noexcept override;
  void cycle(core::Duration dt, std::span<const PnSubmoduleIo> io) noexcept override;
  void power_cycle() noexcept override;

  // The input data a submodule sends from the next cycle on (false: no such submodule or another
  // length), and what it sends now (empty: no such submodule); the last output data it received and
  // what it was worth then.
  bool set_input(std::uint32_t api, std::uint16_t slot, std::uint16_t subslot, std::span<const std::uint8_t> data) noexcept;
  [[nodiscard]] std::span<const std::uint8_t> input(std::uint32_t api, std::uint16_t slot, std::uint16_t subslot) const noexcept;
  [[nodiscard]] std::span<const std::uint8_t> output(std::uint32_t api, std::uint16_t slot, std::uint16_t subslot) const noexcept;
  [[nodiscard]] PnOutputs outputs(std::uint32_t api, std::uint16_t slot, std::uint16_t subslot) const noexcept;

 private:
  struct Data {
    std::uint32_t api = 0;
    std::uint16_t slot = 0;
    std::uint16_t subslot = 0;
    std::vector<std::uint8_t> input;
    std::vector<std::uint8_t> output;
    PnOutputs outputs = PnOutputs::Lost;
  };
  [[nodiscard]] const Data* find(std::uint32_t api, std::uint16_t slot, std::uint16_t subslot) const noexcept;
  [[nodiscard]] Data* find(std::uint32_t api, std::uint16_t slot, std::uint16_t subslot) noexcept {
    return const_cast<Data*>(std::as_const(*this).find(api, slot, subslot));
  }

  GenericIoPersonaConfig config_;
  std::vector<CmModelSubmodule> submodules_;
  std::vector<CmModelSlot> model_;
  std::vector<Data> data_;
};

}  // namespace drivegate::profinet
