#include "adapters/profinet/ar_layout.hpp"

#include <algorithm>
#include <stdexcept>

namespace drivegate::profinet {

namespace {

IoKind kind_of(const ArSubmodule& s) noexcept {
  if (s.input_bytes > 0 && s.output_bytes > 0) return IoKind::InputOutput;
  if (s.input_bytes > 0) return IoKind::Input;
  if (s.output_bytes > 0) return IoKind::Output;
  return IoKind::NoIo;
}

}  // namespace

ArLayout::ArLayout(std::vector<ArSubmodule> subs) : subs_(std::move(subs)) {
  for (std::size_t i = 0; i < subs_.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (subs_[i].slot == subs_[j].slot && subs_[i].subslot == subs_[j].subslot)
        throw std::invalid_argument("slot " + std::to_string(subs_[i].slot) + " subslot " +
                                    std::to_string(subs_[i].subslot) + " is given twice");
  for (const ArSubmodule& s : subs_) io_.push_back({kind_of(s), s.input_bytes, s.output_bytes});
  std::vector<IoPlacement> in_p(subs_.size()), out_p(subs_.size());
  const CsduLayout in_l = compute_csdu_layout(CrDirection::Input, io_, in_p);
  const CsduLayout out_l = compute_csdu_layout(CrDirection::Output, io_, out_p);
  if (!in_l.ok()) throw std::invalid_argument("input frame: " + std::string{to_string(in_l.error)});
  if (!out_l.ok()) throw std::invalid_argument("output frame: " + std::string{to_string(out_l.error)});
  input_length_ = in_l.length;
  output_length_ = out_l.length;

  // One ExpectedSlot per slot, its submodules in subslot order (subs_ is in slot, subslot order).
  std::vector<std::pair<std::size_t, std::size_t>> slot_runs;  // first submodule, count
  for (std::size_t i = 0; i < subs_.size(); ++i) {
    const ArSubmodule& s = subs_[i];
    ExpectedSubmodule e;
    e.subslot = s.subslot;
    e.ident = s.submodule_ident;
    e.properties = static_cast<std::uint16_t>(io_[i].kind);
    e.input = {s.input_bytes, 1, 1};
    e.output = {s.output_bytes, 1, 1};
    expected_subs_.push_back(e);
    if (!slot_runs.empty() && subs_[slot_runs.back().first].slot == s.slot && subs_[slot_runs.back().first].api == s.api)
      ++slot_runs.back().second;
    else
      slot_runs.emplace_back(i, 1);
  }
  for (const auto& [first, count] : slot_runs) {
    const ArSubmodule& s = subs_[first];
    expected_.push_back({s.api, s.slot, s.module_ident, 0,
                         std::span<const ExpectedSubmodule>(&expected_subs_[first], count)});
  }
  // Per API the IO data objects and IOCSs of each CR [IOCRBlockReq: per API NumberOfIODataObjects,
  // then NumberOfIOCS], in submodule order.
  std::vector<std::uint32_t> apis;
  for (const ArSubmodule& s : subs_)
    if (std::find(apis.begin(), apis.end(), s.api) == apis.end()) apis.push_back(s.api);
  for (const std::uint32_t api : apis) {
    std::vector<IoObjectRef> lists[4];
    for (std::size_t i = 0; i < subs_.size(); ++i) {
      if (subs_[i].api != api) continue;
      const auto add = [&](std::vector<IoObjectRef>& list, std::uint16_t at) {
        if (at != kNoOffset) list.push_back({subs_[i].slot, subs_[i].subslot, at});
      };
      add(lists[0], in_p[i].data_offset);
      add(lists[1], in_p[i].iocs_offset);
      add(lists[2], out_p[i].data_offset);
      add(lists[3], out_p[i].iocs_offset);
    }
    for (auto& l : lists) refs_.push_back(std::move(l));
    const std::size_t at = refs_.size() - 4;
    in_apis_.push_back({api, refs_[at], refs_[at + 1]});
    out_apis_.push_back({api, refs_[at + 2], refs_[at + 3]});
  }
}

std::size_t ArLayout::index(std::uint16_t slot, std::uint16_t subslot) const noexcept {
  for (std::size_t i = 0; i < subs_.size(); ++i)
    if (subs_[i].slot == slot && subs_[i].subslot == subslot) return i;
  return subs_.size();
}

}  // namespace drivegate::profinet
