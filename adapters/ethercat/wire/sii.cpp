#include "adapters/ethercat/wire/sii.hpp"

#include <algorithm>

#include "core/bytes.hpp"

namespace drivegate::ethercat {

using core::get_u16;
using core::get_u32;
using core::put_u16;

std::string_view to_string(SiiCategory c) noexcept {
  switch (c) {
    case SiiCategory::Nop: return "NOP";
    case SiiCategory::Strings: return "strings";
    case SiiCategory::DataTypes: return "data types";
    case SiiCategory::General: return "general";
    case SiiCategory::Fmmu: return "FMMU";
    case SiiCategory::SyncM: return "SyncM";
    case SiiCategory::FmmuX: return "FMMUX";
    case SiiCategory::SyncUnit: return "SyncUnit";
    case SiiCategory::TxPdo: return "TXPDO";
    case SiiCategory::RxPdo: return "RXPDO";
    case SiiCategory::Dc: return "DC";
    case SiiCategory::End: return "end";
  }
  return "unknown category";
}

std::uint8_t sii_crc8(std::span<const std::uint8_t> bytes) noexcept {
  std::uint8_t crc = 0xFF;
  for (const std::uint8_t b : bytes) {
    crc = static_cast<std::uint8_t>(crc ^ b);
    for (int i = 0; i < 8; ++i) {
      crc = (crc & 0x80) ? static_cast<std::uint8_t>((crc << 1) ^ 0x07) : static_cast<std::uint8_t>(crc << 1);
    }
  }
  return crc;
}

std::string_view to_string(SiiProblem p) noexcept {
  switch (p) {
    case SiiProblem::ImageTooShort: return "image shorter than the 128-byte SII header";
    case SiiProblem::ChecksumMismatch: return "configuration area checksum (word 7) does not match the CRC of words 0-6";
    case SiiProblem::NoEndCategory: return "image ends without the end category (FFFFh)";
    case SiiProblem::CategoryBeyondImage: return "category size runs past the end of the image";
    case SiiProblem::StringBeyondCategory: return "string length runs past the strings category";
    case SiiProblem::GeneralTooShort: return "general category shorter than 32 bytes";
    case SiiProblem::PdoHeaderTruncated: return "PDO category ends inside a PDO header";
    case SiiProblem::PdoEntriesBeyondCategory: return "PDO entry count runs past the PDO category";
    case SiiProblem::SizeNotMultiple: return "category size not a multiple of its element size (rest ignored)";
    case SiiProblem::StringIndexOutOfRange: return "string index beyond the strings category";
    case SiiProblem::DuplicateCategory: return "category given twice (the first is used)";
    case SiiProblem::TooManyStrings: return "more strings than the parser keeps (255)";
    case SiiProblem::TooManyFmmus: return "more FMMUs than the parser keeps (16)";
    case SiiProblem::TooManySyncManagers: return "more sync managers than the parser keeps (16)";
    case SiiProblem::TooManyPdos: return "more PDOs than the parser keeps (64)";
    case SiiProblem::TooManyPdoEntries: return "more PDO entries than the parser keeps (512)";
    case SiiProblem::TooManyDcs: return "more DC entries than the parser keeps (8)";
  }
  return "?";
}

bool is_error(SiiProblem p) noexcept {
  switch (p) {
    case SiiProblem::ImageTooShort:
    case SiiProblem::CategoryBeyondImage:
    case SiiProblem::StringBeyondCategory:
    case SiiProblem::GeneralTooShort:
    case SiiProblem::PdoHeaderTruncated:
    case SiiProblem::PdoEntriesBeyondCategory: return true;
    default: return false;
  }
}

std::string_view SiiInfo::string(std::uint8_t index) const noexcept {
  if (index == 0 || index > string_count) return {};
  return strings[index - 1U];
}

std::span<const SiiPdoEntry> SiiInfo::entries_of(const SiiPdo& p) const noexcept {
  if (p.first_entry > entry_count || p.stored_entries > entry_count - p.first_entry) return {};
  return std::span<const SiiPdoEntry>(entries).subspan(p.first_entry, p.stored_entries);
}

bool SiiInfo::has(SiiProblem p) const noexcept {
  for (std::size_t i = 0; i < issue_count; ++i) {
    if (issues[i].problem == p) return true;
  }
  return false;
}

bool SiiInfo::ok() const noexcept {
  for (std::size_t i = 0; i < issue_count; ++i) {
    if (is_error(issues[i].problem)) return false;
  }
  return true;
}

namespace {

class Parser {
 public:
  Parser(std::span<const std::uint8_t> image, SiiInfo& out) noexcept : img_(image), out_(out) {}

  void run() noexcept {
    if (img_.size() < kSiiHeaderBytes) return issue(SiiProblem::ImageTooShort, 0);
    header();
    categories();
    check_string_indexes();
  }

 private:
  std::uint16_t word(std::size_t w) const noexcept { return get_u16(img_, 2 * w); }
  std::uint32_t dword(std::size_t w) const noexcept { return get_u32(img_, 2 * w); }

  void issue(SiiProblem p, std::size_t word_addr) noexcept {
    if (out_.issue_count < out_.issues.size()) {
      out_.issues[out_.issue_count++] = SiiIssue{p, static_cast<std::uint32_t>(word_addr)};
    }
  }

  void header() noexcept {
    out_.header.pdi_control = word(sii_word::kPdiControl);
    out_.header.pdi_configuration = word(sii_word::kPdiConfiguration);
    out_.header.sync_impulse_length = word(sii_word::kSyncImpulseLength);
    out_.header.pdi_configuration2 = word(sii_word::kPdiConfiguration2);
    out_.header.station_alias = word(sii_word::kStationAlias);
    out_.checksum = static_cast<std::uint8_t>(word(sii_word::kChecksum) & 0xFF);
    out_.checksum_computed = sii_crc8(img_.first(14));
    if (!out_.checksum_ok()) issue(SiiProblem::ChecksumMismatch, sii_word::kChecksum);
    out_.header.identity.vendor_id = dword(sii_word::kVendorId);
    out_.header.identity.product_code = dword(sii_word::kProductCode);
    out_.header.identity.revision = dword(sii_word::kRevision);
    out_.header.identity.serial = dword(sii_word::kSerial);
    out_.header.bootstrap_mailbox = {word(sii_word::kBootstrapRxMailboxOffset), word(sii_word::kBootstrapRxMailboxSize),
                              word(sii_word::kBootstrapTxMailboxOffset), word(sii_word::kBootstrapTxMailboxSize)};
    out_.header.standard_mailbox = {word(sii_word::kStandardRxMailboxOffset), word(sii_word::kStandardRxMailboxSize),
                             word(sii_word::kStandardTxMailboxOffset), word(sii_word::kStandardTxMailboxSize)};
    out_.header.mailbox_protocols = word(sii_word::kMailboxProtocols);
    out_.eeprom_size = word(sii_word::kEepromSize);
    out_.version = word(sii_word::kVersion);
    out_.header_valid = true;
  }

  void categories() noexcept {
    const std::size_t words = img_.size() / 2;
    std::size_t w = sii_word::kFirstCategory;
    bool seen_strings = false;
    while (true) {
      if (words - w < 1) return issue(SiiProblem::NoEndCategory, w);
      const std::uint16_t type = word(w);
      if (type == static_cast<std::uint16_t>(SiiCategory::End)) {
        out_.end_seen = true;
        return;
      }
      if (words - w < 2) return issue(SiiProblem::NoEndCategory, w);
      const std::size_t size_words = word(w + 1);
      const std::size_t data_w = w + 2;
      if (size_words > words - data_w) return issue(SiiProblem::CategoryBeyondImage, w);
      const auto data = img_.subspan(2 * data_w, 2 * size_words);
      switch (static_cast<SiiCategory>(type)) {
        case SiiCategory::Strings:
          if (seen_strings) {
            issue(SiiProblem::DuplicateCategory, w);
          } else {
            seen_strings = true;
            strings(data, data_w);
          }
          break;
        case SiiCategory::General:
          if (out_.has_general) {
            issue(SiiProblem::DuplicateCategory, w);
          } else {
            general(data, w);
          }
          break;
        case SiiCategory::Fmmu: fmmus(data, w); break;
        case SiiCategory::SyncM: sync_managers(data, w); break;
        case SiiCategory::TxPdo: pdos(data, data_w, true); break;
        case SiiCategory::RxPdo: pdos(data, data_w, false); break;
        case SiiCategory::Dc: dcs(data, w); break;
        default: break;  // NOP, data types, FMMUX, SyncUnit, vendor categories: skipped
      }
      w = data_w + size_words;
    }
  }

  void strings(std::span<const std::uint8_t> d, std::size_t data_w) noexcept {
    if (d.empty()) return;
    const std::size_t n = d[0];
    std::size_t at = 1;
    for (std::size_t i = 0; i < n; ++i) {
      if (at >= d.size()) return issue(SiiProblem::StringBeyondCategory, data_w + at / 2);
      const std::size_t len = d[at];
      if (len > d.size() - at - 1) return issue(SiiProblem::StringBeyondCategory, data_w + at / 2);
      if (out_.string_count < out_.strings.size()) {
        const auto* p = reinterpret_cast<const char*>(d.data() + at + 1);
        out_.strings[out_.string_count++] = std::string_view(p, len);
      } else {
        return issue(SiiProblem::TooManyStrings, data_w + at / 2);
      }
      at += 1 + len;
    }
  }

  void general(std::span<const std::uint8_t> d, std::size_t w) noexcept {
    if (d.size() < kSiiGeneralBytes) return issue(SiiProblem::GeneralTooShort, w);
    SiiGeneral& g = out_.general;
    g.group_index = d[0];
    g.image_index = d[1];
    g.order_index = d[2];
    g.name_index = d[3];
    g.coe_details = d[5];
    g.foe_details = d[6];
    g.eoe_details = d[7];
    g.soe_channels = d[8];
    g.ds402_channels = d[9];
    g.sysman_class = d[10];
    g.flags = d[11];
    g.current_on_ebus = static_cast<std::int16_t>(get_u16(d, 12));
    g.physical_ports = get_u16(d, 16);
    g.physical_memory_address = get_u16(d, 18);
    out_.has_general = true;
  }

  void fmmus(std::span<const std::uint8_t> d, std::size_t w) noexcept {
    for (const std::uint8_t b : d) {
      if (out_.fmmu_count >= out_.fmmus.size()) return issue(SiiProblem::TooManyFmmus, w);
      out_.fmmus[out_.fmmu_count++] = b;
    }
  }

  void sync_managers(std::span<const std::uint8_t> d, std::size_t w) noexcept {
    if (d.size() % kSiiSyncManagerBytes != 0) issue(SiiProblem::SizeNotMultiple, w);
    for (std::size_t at = 0; d.size() - at >= kSiiSyncManagerBytes; at += kSiiSyncManagerBytes) {
      if (out_.sync_manager_count >= out_.sync_managers.size()) return issue(SiiProblem::TooManySyncManagers, w);
      SiiSyncManager& s = out_.sync_managers[out_.sync_manager_count++];
      s.physical_start = get_u16(d, at);
      s.length = get_u16(d, at + 2);
      s.control = d[at + 4];
      s.status = d[at + 5];
      s.enable = d[at + 6];
      s.type = d[at + 7];
    }
  }

  void pdos(std::span<const std::uint8_t> d, std::size_t data_w, bool tx) noexcept {
    std::size_t at = 0;
    while (at < d.size()) {
      if (d.size() - at < kSiiPdoHeaderBytes) return issue(SiiProblem::PdoHeaderTruncated, data_w + at / 2);
      if (out_.pdo_count >= out_.pdos.size()) return issue(SiiProblem::TooManyPdos, data_w + at / 2);
      SiiPdo p;
      p.tx = tx;
      p.index = get_u16(d, at);
      p.entry_count = d[at + 2];
      p.sm = d[at + 3];
      p.sync = d[at + 4];
      p.name_index = d[at + 5];
      p.flags = get_u16(d, at + 6);
      p.first_entry = out_.entry_count;
      const std::size_t entries_at = at + kSiiPdoHeaderBytes;
      if (static_cast<std::size_t>(p.entry_count) * kSiiPdoEntryBytes > d.size() - entries_at) {
        out_.pdos[out_.pdo_count++] = p;  // keep the header so the caller sees which PDO is broken
        return issue(SiiProblem::PdoEntriesBeyondCategory, data_w + at / 2);
      }
      for (std::size_t i = 0; i < p.entry_count; ++i) {
        if (out_.entry_count >= out_.entries.size()) {
          issue(SiiProblem::TooManyPdoEntries, data_w + at / 2);
          break;
        }
        const std::size_t e = entries_at + i * kSiiPdoEntryBytes;
        SiiPdoEntry& x = out_.entries[out_.entry_count++];
        x.index = get_u16(d, e);
        x.subindex = d[e + 2];
        x.name_index = d[e + 3];
        x.data_type = d[e + 4];
        x.bit_length = d[e + 5];
        x.flags = get_u16(d, e + 6);
        ++p.stored_entries;
      }
      out_.pdos[out_.pdo_count++] = p;
      at = entries_at + static_cast<std::size_t>(p.entry_count) * kSiiPdoEntryBytes;
    }
  }

  void dcs(std::span<const std::uint8_t> d, std::size_t w) noexcept {
    if (d.size() % kSiiDcBytes != 0) issue(SiiProblem::SizeNotMultiple, w);
    for (std::size_t at = 0; d.size() - at >= kSiiDcBytes; at += kSiiDcBytes) {
      if (out_.dc_count >= out_.dcs.size()) return issue(SiiProblem::TooManyDcs, w);
      SiiDc& x = out_.dcs[out_.dc_count++];
      x.cycle_time0 = get_u32(d, at);
      x.shift_time0 = get_u32(d, at + 4);
      x.shift_time1 = get_u32(d, at + 8);
      x.sync1_cycle_factor = static_cast<std::int16_t>(get_u16(d, at + 12));
      x.assign_activate = get_u16(d, at + 14);
      x.sync0_cycle_factor = static_cast<std::int16_t>(get_u16(d, at + 16));
      x.name_index = d[at + 18];
      x.description_index = d[at + 19];
    }
  }

  void check_string_indexes() noexcept {
    auto check = [this](std::uint8_t idx) {
      if (idx > out_.string_count) {
        issue(SiiProblem::StringIndexOutOfRange, 0);
        return false;
      }
      return true;
    };
    if (out_.has_general) {
      const SiiGeneral& g = out_.general;
      if (!check(g.group_index) || !check(g.image_index) || !check(g.order_index) || !check(g.name_index)) return;
    }
    for (std::size_t i = 0; i < out_.pdo_count; ++i) {
      if (!check(out_.pdos[i].name_index)) return;
    }
    for (std::size_t i = 0; i < out_.entry_count; ++i) {
      if (!check(out_.entries[i].name_index)) return;
    }
  }

  std::span<const std::uint8_t> img_;
  SiiInfo& out_;
};

}  // namespace

void parse_sii(std::span<const std::uint8_t> image, SiiInfo& out) noexcept {
  out = SiiInfo{};
  Parser(image, out).run();
}

// ---- Build ------------------------------------------------------------------------------------

std::string_view to_string(SiiBuildError e) noexcept {
  switch (e) {
    case SiiBuildError::None: return "no error";
    case SiiBuildError::InvalidEepromSize: return "EEPROM size is not a positive multiple of 128 bytes up to 1 MiB";
    case SiiBuildError::OutputTooSmall: return "output buffer smaller than the EEPROM size";
    case SiiBuildError::ContentTooLarge: return "categories do not fit in the EEPROM size";
    case SiiBuildError::TooManyStrings: return "more than 255 distinct strings";
    case SiiBuildError::StringTooLong: return "a string is longer than 255 bytes";
    case SiiBuildError::TooManyEntries: return "a PDO has more than 255 entries";
  }
  return "?";
}

namespace {

// Distinct strings in first-use order; index 0 = no string.
class StringTable {
 public:
  SiiBuildError add(std::string_view s, std::uint8_t& index) noexcept {
    index = 0;
    if (s.empty()) return SiiBuildError::None;
    if (s.size() > 255) return SiiBuildError::StringTooLong;
    for (std::size_t i = 0; i < count_; ++i) {
      if (items_[i] == s) {
        index = static_cast<std::uint8_t>(i + 1);
        return SiiBuildError::None;
      }
    }
    if (count_ >= items_.size()) return SiiBuildError::TooManyStrings;
    items_[count_++] = s;
    index = static_cast<std::uint8_t>(count_);
    return SiiBuildError::None;
  }
  std::size_t count() const noexcept { return count_; }
  std::string_view operator[](std::size_t i) const noexcept { return items_[i]; }

 private:
  std::array<std::string_view, 255> items_{};
  std::size_t count_ = 0;
};

// Appends bytes at `pos` while room lasts; remembers overflow.
class Writer {
 public:
  explicit Writer(std::span<std::uint8_t> out) noexcept : out_(out) {}
  void u8(std::uint8_t v) noexcept {
    if (pos_ < out_.size()) out_[pos_] = v;
    else overflow_ = true;
    ++pos_;
  }
  void u16(std::uint16_t v) noexcept {
    u8(static_cast<std::uint8_t>(v & 0xFF));
    u8(static_cast<std::uint8_t>(v >> 8));
  }
  void u32(std::uint32_t v) noexcept {
    u16(static_cast<std::uint16_t>(v & 0xFFFF));
    u16(static_cast<std::uint16_t>(v >> 16));
  }
  // Starts a category: type and a size placeholder; returns where the size goes.
  std::size_t begin(SiiCategory c) noexcept {
    u16(static_cast<std::uint16_t>(c));
    const std::size_t at = pos_;
    u16(0);
    return at;
  }
  // Pads to a word and writes the size in words.
  void end(std::size_t size_at) noexcept {
    if (pos_ % 2) u8(0);
    const std::size_t words = (pos_ - size_at - 2) / 2;
    if (size_at + 1 < out_.size()) put_u16(out_, size_at, static_cast<std::uint16_t>(words));
  }
  std::size_t pos() const noexcept { return pos_; }
  bool overflow() const noexcept { return overflow_; }

 private:
  std::span<std::uint8_t> out_;
  std::size_t pos_ = 0;
  bool overflow_ = false;
};

void write_pdos(Writer& w, SiiCategory cat, std::span<const SiiBuildPdo> pdos, std::span<const std::uint8_t> pdo_names, std::span<const std::uint8_t> entry_names) noexcept {
  std::size_t e = 0;
  for (std::size_t i = 0; i < pdos.size(); ++i) {
    // One category per PDO, as ESI tools write them.
    const SiiBuildPdo& p = pdos[i];
    const std::size_t at = w.begin(cat);
    w.u16(p.index);
    w.u8(static_cast<std::uint8_t>(p.entries.size()));
    w.u8(p.sm);
    w.u8(p.sync);
    w.u8(pdo_names[i]);
    w.u16(p.flags);
    for (const SiiBuildEntry& x : p.entries) {
      w.u16(x.index);
      w.u8(x.subindex);
      w.u8(entry_names[e++]);
      w.u8(x.data_type);
      w.u8(x.bit_length);
      w.u16(x.flags);
    }
    w.end(at);
  }
}

}  // namespace

SiiBuildResult build_sii(const SiiProfile& p, std::span<std::uint8_t> out) noexcept {
  const std::size_t size = p.eeprom_bytes;
  // Word 3Eh holds KiBit - 1 in 16 bits; keep to 1 MiB (8 MiBit), far beyond any real SII.
  if (size == 0 || size % 128 != 0 || size > 1024 * 1024) return {SiiBuildError::InvalidEepromSize, 0};
  if (out.size() < size) return {SiiBuildError::OutputTooSmall, 0};
  std::span<std::uint8_t> img = out.first(size);

  // Strings: general names first, then PDO and entry names, then DC names.
  StringTable st;
  SiiGeneral g = p.general;
  auto add = [&st](std::string_view s, std::uint8_t& idx) { return st.add(s, idx); };
  for (auto [s, idx] : {std::pair{p.group, &g.group_index}, std::pair{p.image, &g.image_index},
                        std::pair{p.order, &g.order_index}, std::pair{p.name, &g.name_index}}) {
    if (const auto e = add(s, *idx); e != SiiBuildError::None) return {e, 0};
  }
  // Name indexes of PDOs and entries, kept on the stack (capacities as the parser's).
  std::array<std::uint8_t, kSiiMaxPdos> tx_names{}, rx_names{};
  std::array<std::uint8_t, kSiiMaxPdoEntries> tx_entry_names{}, rx_entry_names{};
  auto names_of = [&](std::span<const SiiBuildPdo> pdos, std::span<std::uint8_t> pdo_names,
                      std::span<std::uint8_t> entry_names) -> SiiBuildError {
    if (pdos.size() > pdo_names.size()) return SiiBuildError::ContentTooLarge;
    std::size_t e = 0;
    for (std::size_t i = 0; i < pdos.size(); ++i) {
      if (pdos[i].entries.size() > 255) return SiiBuildError::TooManyEntries;
      if (const auto err = add(pdos[i].name, pdo_names[i]); err != SiiBuildError::None) return err;
      for (const auto& x : pdos[i].entries) {
        if (e >= entry_names.size()) return SiiBuildError::ContentTooLarge;
        if (const auto err = add(x.name, entry_names[e++]); err != SiiBuildError::None) return err;
      }
    }
    return SiiBuildError::None;
  };
  if (const auto e = names_of(p.tx_pdos, tx_names, tx_entry_names); e != SiiBuildError::None) return {e, 0};
  if (const auto e = names_of(p.rx_pdos, rx_names, rx_entry_names); e != SiiBuildError::None) return {e, 0};
  std::array<std::uint8_t, kSiiMaxDcs> dc_names{};
  if (p.dcs.size() > dc_names.size()) return {SiiBuildError::ContentTooLarge, 0};
  for (std::size_t i = 0; i < p.dcs.size(); ++i) {
    if (const auto e = add(p.dcs[i].name, dc_names[i]); e != SiiBuildError::None) return {e, 0};
  }

  std::fill(img.begin(), img.end(), std::uint8_t{0xFF});
  std::fill(img.begin(), img.begin() + kSiiHeaderBytes, std::uint8_t{0});
  Writer w(img);
  // Fixed header [ETG.1000.6 §5.4].
  w.u16(p.header.pdi_control);
  w.u16(p.header.pdi_configuration);
  w.u16(p.header.sync_impulse_length);
  w.u16(p.header.pdi_configuration2);
  w.u16(p.header.station_alias);
  w.u16(0);
  w.u16(0);
  w.u16(sii_crc8(img.first(14)));  // checksum word: CRC in the low byte, 0 in the high byte
  w.u32(p.header.identity.vendor_id);
  w.u32(p.header.identity.product_code);
  w.u32(p.header.identity.revision);
  w.u32(p.header.identity.serial);
  for (int i = 0; i < 4; ++i) w.u16(0);  // words 10h-13h reserved
  for (const SiiMailbox* m : {&p.header.bootstrap_mailbox, &p.header.standard_mailbox}) {
    w.u16(m->rx_offset);
    w.u16(m->rx_size);
    w.u16(m->tx_offset);
    w.u16(m->tx_size);
  }
  w.u16(p.header.mailbox_protocols);
  while (w.pos() < 2 * sii_word::kEepromSize) w.u16(0);  // words 1Dh-3Dh reserved
  w.u16(static_cast<std::uint16_t>(size / 128 - 1));
  w.u16(1);  // version

  // Categories.
  if (st.count() > 0) {
    const std::size_t at = w.begin(SiiCategory::Strings);
    w.u8(static_cast<std::uint8_t>(st.count()));
    for (std::size_t i = 0; i < st.count(); ++i) {
      w.u8(static_cast<std::uint8_t>(st[i].size()));
      for (const char c : st[i]) w.u8(static_cast<std::uint8_t>(c));
    }
    w.end(at);
  }
  {
    const std::size_t at = w.begin(SiiCategory::General);
    w.u8(g.group_index);
    w.u8(g.image_index);
    w.u8(g.order_index);
    w.u8(g.name_index);
    w.u8(0);
    w.u8(g.coe_details);
    w.u8(g.foe_details);
    w.u8(g.eoe_details);
    w.u8(g.soe_channels);
    w.u8(g.ds402_channels);
    w.u8(g.sysman_class);
    w.u8(g.flags);
    w.u16(static_cast<std::uint16_t>(g.current_on_ebus));
    w.u8(g.group_index);  // duplicate group index for compatibility [ETG.1000.6 Table 21]
    w.u8(0);
    w.u16(g.physical_ports);
    w.u16(g.physical_memory_address);
    for (int i = 0; i < 12; ++i) w.u8(0);
    w.end(at);
  }
  if (!p.fmmus.empty()) {
    const std::size_t at = w.begin(SiiCategory::Fmmu);
    for (const std::uint8_t f : p.fmmus) w.u8(f);
    w.end(at);
  }
  if (!p.sync_managers.empty()) {
    const std::size_t at = w.begin(SiiCategory::SyncM);
    for (const SiiSyncManager& s : p.sync_managers) {
      w.u16(s.physical_start);
      w.u16(s.length);
      w.u8(s.control);
      w.u8(s.status);
      w.u8(s.enable);
      w.u8(s.type);
    }
    w.end(at);
  }
  write_pdos(w, SiiCategory::TxPdo, p.tx_pdos, tx_names, tx_entry_names);
  write_pdos(w, SiiCategory::RxPdo, p.rx_pdos, rx_names, rx_entry_names);
  if (!p.dcs.empty()) {
    const std::size_t at = w.begin(SiiCategory::Dc);
    for (std::size_t i = 0; i < p.dcs.size(); ++i) {
      const SiiDc& d = p.dcs[i].dc;
      w.u32(d.cycle_time0);
      w.u32(d.shift_time0);
      w.u32(d.shift_time1);
      w.u16(static_cast<std::uint16_t>(d.sync1_cycle_factor));
      w.u16(d.assign_activate);
      w.u16(static_cast<std::uint16_t>(d.sync0_cycle_factor));
      w.u8(dc_names[i]);
      w.u8(d.description_index);
      w.u32(0);
    }
    w.end(at);
  }
  w.u16(static_cast<std::uint16_t>(SiiCategory::End));
  if (w.overflow()) return {SiiBuildError::ContentTooLarge, 0};
  return {SiiBuildError::None, size};
}

}  // namespace drivegate::ethercat
