// parse_sii (adapters/ethercat/wire/sii.hpp) on any EEPROM image a slave may hold. Invariants:
// counts within the capacities, every string view inside the image, every PDO's entries inside the
// entry table; and what was read is built again with build_sii and parsed back to the same header,
// mailboxes, sync managers, FMMUs, PDOs (names compared as text) and DC entries, with a valid CRC.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include "adapters/ethercat/wire/sii.hpp"

namespace {

using namespace drivegate::ethercat;

void check_bounds(const SiiInfo& s, std::span<const std::uint8_t> img) {
  if (s.string_count > s.strings.size() || s.pdo_count > s.pdos.size() || s.entry_count > s.entries.size() ||
      s.sync_manager_count > s.sync_managers.size() || s.fmmu_count > s.fmmus.size() || s.dc_count > s.dcs.size() ||
      s.issue_count > s.issues.size()) {
    std::abort();
  }
  for (std::size_t i = 0; i < s.string_count; ++i) {
    const auto* p = reinterpret_cast<const std::uint8_t*>(s.strings[i].data());
    if (p < img.data() || p + s.strings[i].size() > img.data() + img.size()) std::abort();
  }
  for (std::size_t i = 0; i < s.pdo_count; ++i) {
    const SiiPdo& p = s.pdos[i];
    if (p.first_entry + p.stored_entries > s.entry_count || p.stored_entries > p.entry_count) std::abort();
  }
  if (!s.header_valid && s.ok()) std::abort();
}

void round_trip(const SiiInfo& s) {
  if (!s.header_valid) return;
  SiiProfile p;
  p.header = s.header;
  p.general = s.general;
  p.group = s.string(s.general.group_index);
  p.image = s.string(s.general.image_index);
  p.order = s.string(s.general.order_index);
  p.name = s.string(s.general.name_index);
  p.fmmus = std::span<const std::uint8_t>(s.fmmus).first(s.fmmu_count);
  p.sync_managers = std::span<const SiiSyncManager>(s.sync_managers).first(s.sync_manager_count);
  std::vector<SiiBuildEntry> entries;
  entries.reserve(s.entry_count);
  std::vector<SiiBuildPdo> tx, rx;
  for (std::size_t i = 0; i < s.pdo_count; ++i) {
    const SiiPdo& pd = s.pdos[i];
    if (pd.stored_entries != pd.entry_count) return;  // a broken PDO is not rebuilt
    const std::size_t first = entries.size();
    for (const SiiPdoEntry& e : s.entries_of(pd)) {
      entries.push_back({e.index, e.subindex, s.string(e.name_index), e.data_type, e.bit_length, e.flags});
    }
    const SiiBuildPdo b{pd.index, pd.sm, pd.sync, s.string(pd.name_index), pd.flags,
                        std::span<const SiiBuildEntry>(entries).subspan(first, pd.stored_entries)};
    (pd.tx ? tx : rx).push_back(b);
  }
  p.tx_pdos = tx;
  p.rx_pdos = rx;
  std::vector<SiiBuildDc> dcs;
  for (std::size_t i = 0; i < s.dc_count; ++i) dcs.push_back({s.dcs[i], s.string(s.dcs[i].name_index)});
  p.dcs = dcs;
  p.eeprom_bytes = 64 * 1024;
  std::vector<std::uint8_t> img(p.eeprom_bytes);
  const SiiBuildResult r = build_sii(p, img);
  // Input is at most 16 KiB, so what it holds always fits 64 KiB and 255 strings.
  if (!r.ok()) std::abort();
  auto again = std::make_unique<SiiInfo>();
  parse_sii(img, *again);
  const SiiInfo& a = *again;
  if (!a.ok() || !a.checksum_ok() || a.header != s.header) {
    std::abort();
  }
  if (a.sync_manager_count != s.sync_manager_count || a.pdo_count != s.pdo_count || a.dc_count != s.dc_count) std::abort();
  for (std::size_t i = 0; i < s.sync_manager_count; ++i) {
    if (a.sync_managers[i] != s.sync_managers[i]) std::abort();
  }
  if (a.string(a.general.name_index) != s.string(s.general.name_index)) std::abort();
  // Builder order: all TxPDOs, then all RxPDOs.
  std::size_t k = 0;
  for (const bool want_tx : {true, false}) {
    for (std::size_t i = 0; i < s.pdo_count; ++i) {
      const SiiPdo& o = s.pdos[i];
      if (o.tx != want_tx) continue;
      const SiiPdo& n = a.pdos[k++];
      if (n.tx != o.tx || n.index != o.index || n.sm != o.sm || n.entry_count != o.entry_count ||
          a.string(n.name_index) != s.string(o.name_index)) {
        std::abort();
      }
      const auto oe = s.entries_of(o);
      const auto ne = a.entries_of(n);
      for (std::size_t j = 0; j < oe.size(); ++j) {
        if (ne[j].index != oe[j].index || ne[j].bit_length != oe[j].bit_length ||
            a.string(ne[j].name_index) != s.string(oe[j].name_index)) {
          std::abort();
        }
      }
    }
  }
  for (std::size_t i = 0; i < s.dc_count; ++i) {
    if (a.dcs[i].cycle_time0 != s.dcs[i].cycle_time0 || a.string(a.dcs[i].name_index) != s.string(s.dcs[i].name_index)) {
      std::abort();
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 16384) return 0;
  const std::span<const std::uint8_t> img(data, size);
  auto info = std::make_unique<SiiInfo>();
  parse_sii(img, *info);
  check_bounds(*info, img);
  round_trip(*info);
  return 0;
}
