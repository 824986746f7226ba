#pragma once
// What one device's AR holds, laid out once when the bus is built: the submodules in the order
// the Connect names them (slot 0 first), the ExpectedSubmoduleBlockReq entries, both IOCRs' API
// lists with every data object's and IOCS's frame offset (wire/rt.hpp compute_csdu_layout: the
// layout the RT frames use, so the Connect and the cyclic engines cannot disagree), and the list
// the cyclic engines take (RtIocrConfig::submodules). Every span handed out points into the
// layout, which does not move once built (keep it behind a pointer).
#include <cstddef>
#include <cstdint>
#include <deque>
#include <span>
#include <string>
#include <vector>

#include "adapters/profinet/wire/blocks.hpp"
#include "adapters/profinet/wire/blocks_submodule.hpp"
#include "adapters/profinet/wire/rt.hpp"

namespace drivegate::profinet {

struct ArSubmodule {
  std::uint32_t api = 0;
  std::uint16_t slot = 0;
  std::uint16_t subslot = 1;
  std::uint32_t module_ident = 0;
  std::uint32_t submodule_ident = 0;
  std::uint16_t input_bytes = 0;   // device -> controller
  std::uint16_t output_bytes = 0;  // controller -> device
};

class ArLayout {
 public:
  // `subs` in slot, subslot order. Throws std::invalid_argument with the reason when a CR does
  // not lay out (too long) or a slot/subslot is given twice.
  explicit ArLayout(std::vector<ArSubmodule> subs);
  ArLayout(const ArLayout&) = delete;
  ArLayout& operator=(const ArLayout&) = delete;

  [[nodiscard]] const std::vector<ArSubmodule>& submodules() const noexcept { return subs_; }
  [[nodiscard]] std::span<const IoSubmodule> io() const noexcept { return io_; }
  [[nodiscard]] std::span<const ExpectedSlot> expected() const noexcept { return expected_; }
  [[nodiscard]] std::span<const IocrApiSpec> input_apis() const noexcept { return in_apis_; }
  [[nodiscard]] std::span<const IocrApiSpec> output_apis() const noexcept { return out_apis_; }
  // The C_SDU lengths of the input and output CR.
  [[nodiscard]] std::uint16_t input_length() const noexcept { return input_length_; }
  [[nodiscard]] std::uint16_t output_length() const noexcept { return output_length_; }
  // The submodule's index in submodules() (and the engines' data(i)); size() when absent.
  [[nodiscard]] std::size_t index(std::uint16_t slot, std::uint16_t subslot) const noexcept;

 private:
  std::vector<ArSubmodule> subs_;
  std::vector<IoSubmodule> io_;
  std::deque<ExpectedSubmodule> expected_subs_;  // one per submodule, stable addresses
  std::vector<ExpectedSlot> expected_;
  std::deque<std::vector<IoObjectRef>> refs_;    // per API: in data, in IOCS, out data, out IOCS
  std::vector<IocrApiSpec> in_apis_, out_apis_;
  std::uint16_t input_length_ = 0;
  std::uint16_t output_length_ = 0;
};

}  // namespace drivegate::profinet
