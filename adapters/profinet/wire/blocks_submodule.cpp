#include "adapters/profinet/wire/blocks_submodule.hpp"

#include <array>

namespace drivegate::profinet {

namespace {

// [IEC 61158-6-10 "DataDescription"]
constexpr std::uint16_t kDataInput = 1;
constexpr std::uint16_t kDataOutput = 2;

void put_description(Writer& w, std::uint16_t kind, const DataDescription& d) noexcept {
  w.u16(kind);
  w.u16(d.length);
  w.u8(d.iocs_length);
  w.u8(d.iops_length);
}

// Reads the data descriptions a submodule of `type` carries into `s`.
void read_descriptions(Reader& r, ExpectedSubmodule& s) noexcept {
  const SubmoduleType type = s.type();
  const int count = type == SubmoduleType::InputOutput ? 2 : 1;
  for (int i = 0; i < count && r.ok(); ++i) {
    const std::uint16_t kind = r.u16();
    DataDescription d;
    d.length = r.u16();
    d.iocs_length = r.u8();
    d.iops_length = r.u8();
    // NO_IO and input submodules describe their input; output ones their output; an input-output
    // submodule one of each [IEC 61158-6-10 §5.2.2.4].
    const bool want_input = type == SubmoduleType::NoIo || type == SubmoduleType::Input ||
                            (type == SubmoduleType::InputOutput && i == 0);
    if (kind != (want_input ? kDataInput : kDataOutput)) {
      r.fail(WireError::BadDataDescription);
      return;
    }
    (want_input ? s.input : s.output) = d;
  }
}

}  // namespace

std::size_t encode_expected_submodule_block(std::span<const ExpectedSlot> slots, std::span<std::uint8_t> out) noexcept {
  if (slots.size() > 0xFFFF) return 0;
  Writer w(out, ByteOrder::Big);
  const std::size_t start = begin_block(w, block_type::kExpectedSubmoduleBlockReq);
  w.u16(static_cast<std::uint16_t>(slots.size()));
  for (const ExpectedSlot& s : slots) {
    if (s.submodules.size() > 0xFFFF) return 0;
    w.u32(s.api);
    w.u16(s.slot);
    w.u32(s.module_ident);
    w.u16(s.module_properties);
    w.u16(static_cast<std::uint16_t>(s.submodules.size()));
    for (const ExpectedSubmodule& m : s.submodules) {
      w.u16(m.subslot);
      w.u32(m.ident);
      w.u16(m.properties);
      switch (m.type()) {
        case SubmoduleType::NoIo: put_description(w, kDataInput, DataDescription{0, m.input.iocs_length, m.input.iops_length}); break;
        case SubmoduleType::Input: put_description(w, kDataInput, m.input); break;
        case SubmoduleType::Output: put_description(w, kDataOutput, m.output); break;
        case SubmoduleType::InputOutput:
          put_description(w, kDataInput, m.input);
          put_description(w, kDataOutput, m.output);
          break;
      }
    }
  }
  end_block(w, start);
  return w.size_or_zero();
}

ExpectedSubmoduleBlockView decode_expected_submodule_block(std::span<const std::uint8_t> in) noexcept {
  ExpectedSubmoduleBlockView v;
  const BlockBody bb = open_block(in, block_type::kExpectedSubmoduleBlockReq, 2);
  if (bb.error != WireError::None) {
    v.error = bb.error;
    return v;
  }
  Reader r(bb.body, ByteOrder::Big);
  v.api_count = r.u16();
  for (std::uint16_t a = 0; a < v.api_count && r.ok(); ++a) {
    r.skip(4 + 2 + 4 + 2);
    const std::uint16_t subs = r.u16();
    for (std::uint16_t s = 0; s < subs && r.ok(); ++s) {
      ExpectedSubmodule m;
      m.subslot = r.u16();
      m.ident = r.u32();
      m.properties = r.u16();
      read_descriptions(r, m);
    }
  }
  v.error = finish_block(r);
  if (v.error == WireError::None) v.apis = bb.body.subspan(2);
  v.size = bb.size;
  return v;
}

bool ExpectedSubmoduleReader::next(ExpectedEntry& out) noexcept {
  if (!r_.ok()) return false;
  if (submodules_left_ == 0) {
    if (apis_left_ == 0) return false;
    --apis_left_;
    slot_ = ExpectedEntry{};
    slot_.api = r_.u32();
    slot_.slot = r_.u16();
    slot_.module_ident = r_.u32();
    slot_.module_properties = r_.u16();
    submodules_left_ = r_.u16();
    if (submodules_left_ == 0) {
      out = slot_;
      return r_.ok();
    }
  }
  --submodules_left_;
  out = slot_;
  out.has_submodule = true;
  out.submodule.subslot = r_.u16();
  out.submodule.ident = r_.u32();
  out.submodule.properties = r_.u16();
  read_descriptions(r_, out.submodule);
  return r_.ok();
}

// ---- ModuleDiff ----------------------------------------------------------------------------------

std::string_view to_string(ModuleState s) noexcept {
  switch (s) {
    case ModuleState::NoModule: return "no module";
    case ModuleState::WrongModule: return "wrong module";
    case ModuleState::ProperModule: return "proper module";
    case ModuleState::Substitute: return "substitute module";
  }
  return "unknown module state";
}

std::size_t encode_module_diff_block(std::span<const ModuleDiffApi> apis, std::span<std::uint8_t> out) noexcept {
  if (apis.size() > 0xFFFF) return 0;
  Writer w(out, ByteOrder::Big);
  const std::size_t start = begin_block(w, block_type::kModuleDiffBlock);
  w.u16(static_cast<std::uint16_t>(apis.size()));
  for (const ModuleDiffApi& a : apis) {
    if (a.modules.size() > 0xFFFF) return 0;
    w.u32(a.api);
    w.u16(static_cast<std::uint16_t>(a.modules.size()));
    for (const ModuleDiffModule& m : a.modules) {
      if (m.submodules.size() > 0xFFFF) return 0;
      w.u16(m.slot);
      w.u32(m.ident);
      w.u16(static_cast<std::uint16_t>(m.state));
      w.u16(static_cast<std::uint16_t>(m.submodules.size()));
      for (const ModuleDiffSubmodule& s : m.submodules) {
        w.u16(s.subslot);
        w.u32(s.ident);
        w.u16(s.state);
      }
    }
  }
  end_block(w, start);
  return w.size_or_zero();
}

ModuleDiffBlockView decode_module_diff_block(std::span<const std::uint8_t> in) noexcept {
  ModuleDiffBlockView v;
  const BlockBody bb = open_block(in, block_type::kModuleDiffBlock, 2);
  if (bb.error != WireError::None) {
    v.error = bb.error;
    return v;
  }
  Reader r(bb.body, ByteOrder::Big);
  v.api_count = r.u16();
  for (std::uint16_t a = 0; a < v.api_count && r.ok(); ++a) {
    r.skip(4);
    const std::uint16_t modules = r.u16();
    for (std::uint16_t m = 0; m < modules && r.ok(); ++m) {
      r.skip(2 + 4 + 2);
      const std::uint16_t subs = r.u16();
      r.skip(std::size_t{subs} * 8);
    }
  }
  v.error = finish_block(r);
  if (v.error == WireError::None) v.apis = bb.body.subspan(2);
  v.size = bb.size;
  return v;
}

bool ModuleDiffReader::next(ModuleDiffEntry& out) noexcept {
  for (;;) {
    if (!r_.ok()) return false;
    if (submodules_left_ > 0) {
      --submodules_left_;
      out = module_;
      out.has_submodule = true;
      out.submodule.subslot = r_.u16();
      out.submodule.ident = r_.u32();
      out.submodule.state = r_.u16();
      return r_.ok();
    }
    if (modules_left_ > 0) {
      --modules_left_;
      const std::uint32_t api = module_.api;
      module_ = ModuleDiffEntry{};
      module_.api = api;
      module_.slot = r_.u16();
      module_.module_ident = r_.u32();
      module_.module_state = r_.u16();
      submodules_left_ = r_.u16();
      if (submodules_left_ == 0) {
        out = module_;
        return r_.ok();
      }
      continue;
    }
    if (apis_left_ == 0) return false;
    --apis_left_;
    module_.api = r_.u32();
    modules_left_ = r_.u16();
  }
}

namespace {

struct TextOut {
  std::span<char> out;
  std::size_t n = 0;
  void put(std::string_view s) noexcept {
    for (const char c : s) {
      if (n == out.size()) return;
      out[n++] = c;
    }
  }
  void dec(std::uint32_t v) noexcept {
    std::array<char, 10> d{};
    std::size_t k = 0;
    do {
      d[k++] = static_cast<char>('0' + v % 10);
      v /= 10;
    } while (v != 0);
    while (k > 0) put(std::string_view(&d[--k], 1));
  }
  void hex8(std::uint32_t v) noexcept {
    static constexpr std::string_view kDigits = "0123456789ABCDEF";
    put("0x");
    for (int shift = 28; shift >= 0; shift -= 4) put(kDigits.substr((v >> shift) & 0xF, 1));
  }
};

const ExpectedSlot* find_slot(std::span<const ExpectedSlot> expected, std::uint32_t api, std::uint16_t slot) noexcept {
  for (const ExpectedSlot& s : expected) {
    if (s.api == api && s.slot == slot) return &s;
  }
  return nullptr;
}

const ExpectedSubmodule* find_submodule(const ExpectedSlot* s, std::uint16_t subslot) noexcept {
  if (s == nullptr) return nullptr;
  for (const ExpectedSubmodule& m : s->submodules) {
    if (m.subslot == subslot) return &m;
  }
  return nullptr;
}

void where(TextOut& t, const ModuleDiffEntry& e, bool with_subslot) noexcept {
  t.put("slot ");
  t.dec(e.slot);
  if (with_subslot) {
    t.put(" subslot ");
    t.dec(e.submodule.subslot);
  }
  if (e.api != 0) {
    t.put(" (API ");
    t.hex8(e.api);
    t.put(")");
  }
  t.put(": ");
}

}  // namespace

std::string_view module_diff_report(const ModuleDiffBlockView& v, std::span<const ExpectedSlot> expected,
                                    std::span<char> out) noexcept {
  TextOut t{out};
  if (v.error != WireError::None) {
    t.put("ModuleDiffBlock unreadable: ");
    t.put(to_string(v.error));
    return {out.data(), t.n};
  }
  ModuleDiffReader reader(v);
  ModuleDiffEntry e;
  bool reported_module = false;
  std::uint32_t last_api = 0;
  std::uint16_t last_slot = 0xFFFF;
  auto line_end = [&t]() { t.put("\n"); };
  while (reader.next(e)) {
    const ExpectedSlot* slot = find_slot(expected, e.api, e.slot);
    if (e.api != last_api || e.slot != last_slot) {
      last_api = e.api;
      last_slot = e.slot;
      reported_module = false;
    }
    // The module line once per slot, when the module itself differs.
    if (!reported_module && e.module_state != static_cast<std::uint16_t>(ModuleState::ProperModule)) {
      reported_module = true;
      where(t, e, false);
      t.put(to_string(static_cast<ModuleState>(e.module_state)));
      if (e.module_state > 3) {
        t.put(" ");
        t.dec(e.module_state);
      }
      if (e.module_state != static_cast<std::uint16_t>(ModuleState::NoModule)) {
        t.put(" (ident ");
        t.hex8(e.module_ident);
        if (slot != nullptr) {
          t.put(", expected ");
          t.hex8(slot->module_ident);
        }
        t.put(")");
      }
      line_end();
    }
    if (!e.has_submodule) continue;
    const std::uint16_t st = e.submodule.state;
    const ExpectedSubmodule* sub = find_submodule(slot, e.submodule.subslot);
    if ((st & submodule_state::kFormatIndicator) == 0) {
      // The old format (bit 15 = 0) only says whether details are available [IEC 61158-6-10
      // "SubmoduleState", FormatIndicator].
      where(t, e, true);
      t.put("submodule state 0x");
      static constexpr std::string_view kDigits = "0123456789ABCDEF";
      for (int shift = 12; shift >= 0; shift -= 4) t.put(kDigits.substr((st >> shift) & 0xF, 1));
      t.put(" (old format)");
      line_end();
      continue;
    }
    switch (submodule_state::ident_info(st)) {
      case submodule_state::kIdentOk: break;
      case submodule_state::kIdentSubstitute:
      case submodule_state::kIdentWrong:
        where(t, e, true);
        t.put(submodule_state::ident_info(st) == submodule_state::kIdentWrong ? "wrong submodule" : "substitute submodule");
        t.put(" (ident ");
        t.hex8(e.submodule.ident);
        if (sub != nullptr) {
          t.put(", expected ");
          t.hex8(sub->ident);
        }
        t.put(")");
        line_end();
        break;
      case submodule_state::kIdentNoSubmodule:
        where(t, e, true);
        t.put("no submodule");
        line_end();
        break;
      default:
        where(t, e, true);
        t.put("unknown ident info ");
        t.dec(submodule_state::ident_info(st));
        line_end();
        break;
    }
    switch (submodule_state::ar_info(st)) {
      case submodule_state::kArOwn: break;
      case submodule_state::kArApplicationReadyPending:
        where(t, e, true);
        t.put("application ready pending");
        line_end();
        break;
      case submodule_state::kArSuperordinatedLocked:
        where(t, e, true);
        t.put("superordinated locked");
        line_end();
        break;
      case submodule_state::kArLockedByController:
        where(t, e, true);
        t.put("locked by another IO controller");
        line_end();
        break;
      case submodule_state::kArLockedBySupervisor:
        where(t, e, true);
        t.put("locked by an IO supervisor");
        line_end();
        break;
      default:
        where(t, e, true);
        t.put("unknown AR info ");
        t.dec(submodule_state::ar_info(st));
        line_end();
        break;
    }
    if ((st & submodule_state::kDiagInfo) != 0) {
      where(t, e, true);
      t.put("diagnosis available");
      line_end();
    }
    if ((st & (submodule_state::kMaintenanceRequired | submodule_state::kMaintenanceDemanded)) != 0) {
      where(t, e, true);
      t.put((st & submodule_state::kMaintenanceDemanded) != 0 ? "maintenance demanded" : "maintenance required");
      line_end();
    }
  }
  // Without the trailing newline.
  if (t.n > 0 && out[t.n - 1] == '\n') --t.n;
  return {out.data(), t.n};
}

}  // namespace drivegate::profinet
