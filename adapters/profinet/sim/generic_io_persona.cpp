#include "adapters/profinet/sim/generic_io_persona.hpp"

#include <algorithm>
#include <stdexcept>

#include "adapters/profinet/wire/blocks_record.hpp"
#include "adapters/profinet/wire/rt.hpp"

namespace drivegate::profinet {

GenericIoPersona::GenericIoPersona(GenericIoPersonaConfig config) : config_(std::move(config)) {
  std::size_t total = 0;
  for (const GenericSlotConfig& s : config_.slots) total += s.submodules.size();
  submodules_.reserve(total);  // the model's spans point into it
  for (const GenericSlotConfig& s : config_.slots) {
    const std::size_t first = submodules_.size();
    for (const GenericSubmoduleConfig& m : s.submodules) {
      if (find(s.api, s.slot, m.subslot) != nullptr) {
        throw std::invalid_argument("generic IO persona: slot " + std::to_string(s.slot) + " subslot " +
                                    std::to_string(m.subslot) + " given twice");
      }
      if (m.input_length > kMaxCsduLength || m.output_length > kMaxCsduLength) {
        throw std::invalid_argument("generic IO persona: slot " + std::to_string(s.slot) + " subslot " +
                                    std::to_string(m.subslot) + " has more than 1440 octets of data");
      }
      submodules_.push_back({m.subslot, m.ident});
      data_.push_back({s.api, s.slot, m.subslot, std::vector<std::uint8_t>(m.input_length),
                       std::vector<std::uint8_t>(m.output_length), PnOutputs::Lost});
    }
    if (std::any_of(model_.begin(), model_.end(), [&s](const CmModelSlot& m) { return m.api == s.api && m.slot == s.slot; })) {
      throw std::invalid_argument("generic IO persona: slot " + std::to_string(s.slot) + " given twice");
    }
    model_.push_back({s.api, s.slot, s.module_ident,
                      std::span<const CmModelSubmodule>(submodules_).subspan(first, s.submodules.size())});
  }
}

const GenericIoPersona::Data* GenericIoPersona::find(std::uint32_t api, std::uint16_t slot, std::uint16_t subslot) const noexcept {
  const auto it = std::find_if(data_.begin(), data_.end(), [&](const Data& d) {
    return d.api == api && d.slot == slot && d.subslot == subslot;
  });
  return it == data_.end() ? nullptr : &*it;
}

PnPersona::IoLengths GenericIoPersona::lengths(std::uint32_t api, std::uint16_t slot, std::uint16_t subslot) const noexcept {
  const Data* d = find(api, slot, subslot);
  if (d == nullptr) return {};
  return {true, static_cast<std::uint16_t>(d->input.size()), static_cast<std::uint16_t>(d->output.size())};
}

PnioStatus GenericIoPersona::write_record(const RecordReqHeader& h, std::span<const std::uint8_t>) noexcept {
  return pniorw_status(true, h.index == record_index::kIm0 ? pniorw_error::kAccessDenied : pniorw_error::kInvalidIndex);
}

PnioStatus GenericIoPersona::read_record(const RecordReqHeader& h, std::span<std::uint8_t> into, std::size_t& length) noexcept {
  if (h.index != record_index::kIm0) return pniorw_status(false, pniorw_error::kInvalidIndex);
  Im0 im;
  im.vendor_id = config_.vendor_id;
  im.order_id = config_.order_id;
  im.serial_number = config_.serial_number;
  length = encode_im0(im, into);
  return length == 0 ? pniorw_status(false, pniorw_error::kInvalidRange) : PnioStatus{};
}

void GenericIoPersona::cycle(core::Duration, std::span<const PnSubmoduleIo> io) noexcept {
  for (Data& d : data_) {
    const auto s = std::find_if(io.begin(), io.end(), [&d](const PnSubmoduleIo& x) {
      return x.api == d.api && x.slot == d.slot && x.subslot == d.subslot;
    });
    // Not in the AR, or not the submodule the AR expected there.
    if (s == io.end() || s->input.size() != d.input.size() || s->output.size() != d.output.size()) {
      d.outputs = PnOutputs::Lost;
      continue;
    }
    d.outputs = s->outputs;
    if (s->outputs == PnOutputs::Valid) std::copy(s->output.begin(), s->output.end(), d.output.begin());
    std::copy(d.input.begin(), d.input.end(), s->input.begin());
  }
}

void GenericIoPersona::power_cycle() noexcept {
  for (Data& d : data_) {
    std::fill(d.input.begin(), d.input.end(), std::uint8_t{0});
    std::fill(d.output.begin(), d.output.end(), std::uint8_t{0});
    d.outputs = PnOutputs::Lost;
  }
}

bool GenericIoPersona::set_input(std::uint32_t api, std::uint16_t slot, std::uint16_t subslot,
                                 std::span<const std::uint8_t> data) noexcept {
  Data* d = find(api, slot, subslot);
  if (d == nullptr || data.size() != d->input.size()) return false;
  std::copy(data.begin(), data.end(), d->input.begin());
  return true;
}

std::span<const std::uint8_t> GenericIoPersona::input(std::uint32_t api, std::uint16_t slot, std::uint16_t subslot) const noexcept {
  const Data* d = find(api, slot, subslot);
  return d == nullptr ? std::span<const std::uint8_t>{} : std::span<const std::uint8_t>(d->input);
}

std::span<const std::uint8_t> GenericIoPersona::output(std::uint32_t api, std::uint16_t slot, std::uint16_t subslot) const noexcept {
  const Data* d = find(api, slot, subslot);
  return d == nullptr ? std::span<const std::uint8_t>{} : std::span<const std::uint8_t>(d->output);
}

PnOutputs GenericIoPersona::outputs(std::uint32_t api, std::uint16_t slot, std::uint16_t subslot) const noexcept {
  const Data* d = find(api, slot, subslot);
  return d == nullptr ? PnOutputs::Lost : d->outputs;
}

}  // namespace drivegate::profinet
