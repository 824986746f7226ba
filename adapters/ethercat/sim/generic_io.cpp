#include "adapters/ethercat/sim/generic_io.hpp"

#include <algorithm>
#include <array>

namespace drivegate::ethercat::sim {

GenericIoSlave::GenericIoSlave(std::size_t inputs, std::size_t outputs, const SiiIdentity& identity)
    : inputs_(std::min<std::size_t>(inputs, 256), 0), outputs_(std::min<std::size_t>(outputs, 256), 0), sii_(2048, 0) {
  // One UNSIGNED8 entry per byte (data type 0005h) [ETG.1000.6 §5.4 TXPDO/RXPDO categories].
  std::vector<SiiBuildEntry> in_entries;
  std::vector<SiiBuildEntry> out_entries;
  for (std::size_t i = 0; i < inputs_.size(); ++i) {
    in_entries.push_back(SiiBuildEntry{0x6000, static_cast<std::uint8_t>(i + 1), "Input", 0x05, 8, 0});
  }
  for (std::size_t i = 0; i < outputs_.size(); ++i) {
    out_entries.push_back(SiiBuildEntry{0x7000, static_cast<std::uint8_t>(i + 1), "Output", 0x05, 8, 0});
  }
  const std::array<SiiBuildPdo, 1> tx{SiiBuildPdo{0x1A00, 3, 0, "Inputs", 0, in_entries}};
  const std::array<SiiBuildPdo, 1> rx{SiiBuildPdo{0x1600, 2, 0, "Outputs", 0, out_entries}};
  const std::array<std::uint8_t, 3> fmmus{sii_fmmu_usage::kOutputs, sii_fmmu_usage::kInputs, sii_fmmu_usage::kUnused};
  const std::array<SiiSyncManager, 4> sms{
      SiiSyncManager{0, 0, 0, 0, 0, sii_sm_type::kUnused},
      SiiSyncManager{0, 0, 0, 0, 0, sii_sm_type::kUnused},
      SiiSyncManager{kGenericOutputsAddress, static_cast<std::uint16_t>(outputs_.size()), sm_control::kOutputs, 0,
                     outputs_.empty() ? std::uint8_t{0} : std::uint8_t{1}, sii_sm_type::kOutputs},
      SiiSyncManager{kGenericInputsAddress, static_cast<std::uint16_t>(inputs_.size()), sm_control::kInputs, 0,
                     inputs_.empty() ? std::uint8_t{0} : std::uint8_t{1}, sii_sm_type::kInputs},
  };
  SiiProfile p;
  p.header.identity = identity;
  p.group = "IO";
  p.image = "";
  p.order = "SIM-IO";
  p.name = "Generic I/O";
  p.fmmus = fmmus;
  p.sync_managers = sms;
  p.tx_pdos = inputs_.empty() ? std::span<const SiiBuildPdo>{} : std::span<const SiiBuildPdo>(tx);
  p.rx_pdos = outputs_.empty() ? std::span<const SiiBuildPdo>{} : std::span<const SiiBuildPdo>(rx);
  p.general.physical_ports = 0x0011;  // ports 0 and 1 MII
  const SiiBuildResult r = build_sii(p, sii_);
  sii_.resize(r.ok() ? r.size : 0);
}

void GenericIoSlave::exchange(std::span<const std::uint8_t> outputs, std::span<std::uint8_t> inputs, AlState /*state*/,
                              std::uint64_t /*now_ns*/) noexcept {
  ++exchanges_;
  std::copy_n(outputs.begin(), std::min(outputs.size(), outputs_.size()), outputs_.begin());
  std::copy_n(inputs_.begin(), std::min(inputs.size(), inputs_.size()), inputs.begin());
}

}  // namespace drivegate::ethercat::sim
