#pragma once
// A generic digital I/O slave without a mailbox: `inputs` bytes in SM3 (TxPDO 1A00h), `outputs`
// bytes in SM2 (RxPDO 1600h), so a line works without drives. Its SII declares SM0/SM1 unused
// (no mailbox) and SM2/SM3 as process data, the layout EscSlave checks at PRE-OP -> SAFE-OP.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "adapters/ethercat/sim/esc_slave.hpp"
#include "adapters/ethercat/wire/sii.hpp"

namespace drivegate::ethercat::sim {

// Physical addresses of the generic slave's process data SMs.
inline constexpr std::uint16_t kGenericOutputsAddress = 0x1000;
inline constexpr std::uint16_t kGenericInputsAddress = 0x1100;

class GenericIoSlave final : public SlaveApplication {
 public:
  // At most 256 bytes each way.
  GenericIoSlave(std::size_t inputs, std::size_t outputs, const SiiIdentity& identity);

  std::size_t output_size() const noexcept override { return outputs_.size(); }
  std::size_t input_size() const noexcept override { return inputs_.size(); }
  void exchange(std::span<const std::uint8_t> outputs, std::span<std::uint8_t> inputs, AlState state,
                std::uint64_t now_ns) noexcept override;

  // The EEPROM image (build_sii) for EscSlave.
  std::span<const std::uint8_t> sii() const noexcept { return sii_; }
  // Inputs the next exchange publishes; outputs the master wrote (zero outside OP).
  std::span<std::uint8_t> inputs() noexcept { return inputs_; }
  std::span<const std::uint8_t> outputs() const noexcept { return outputs_; }
  std::uint64_t exchanges() const noexcept { return exchanges_; }

 private:
  std::vector<std::uint8_t> inputs_;
  std::vector<std::uint8_t> outputs_;
  std::vector<std::uint8_t> sii_;
  std::uint64_t exchanges_ = 0;
};

}  // namespace drivegate::ethercat::sim
