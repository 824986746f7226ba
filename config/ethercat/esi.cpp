#include "config/ethercat/esi.hpp"

#include <tinyxml2.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cstdio>
#include <map>
#include <utility>

#include "config/text_util.hpp"
#include "config/xml_text.hpp"
#include "config/yaml_reader.hpp"

namespace drivegate::config {

namespace {

using tinyxml2::XMLElement;

std::string_view trim(std::string_view s) noexcept {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front())) != 0) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back())) != 0) s.remove_suffix(1);
  return s;
}

bool same_text(std::string_view a, std::string_view b) noexcept {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
         });
}

std::string upper(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(), [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  return out;
}

// Base types as ESI files name them (IEC 61131-3 names, ETG.2000 §5.4.2 and ETG.1020 base data
// types), with the CiA 301 code CoE gives them [CiA 301 §7.4.7.1]. BYTE/WORD/DWORD are bit strings
// read as the unsigned type of their size. The CiA 301 names are accepted too: some tools write them.
struct BaseType {
  std::string_view name;
  std::uint16_t code;
  int bits;
};
constexpr std::array<BaseType, 38> kBaseTypes{{
    {"BOOL", 0x0001, 1},       {"BIT", 0x0001, 1},       {"SINT", 0x0002, 8},       {"INT", 0x0003, 16},
    {"DINT", 0x0004, 32},      {"USINT", 0x0005, 8},     {"UINT", 0x0006, 16},      {"UDINT", 0x0007, 32},
    {"REAL", 0x0008, 32},      {"INT24", 0x0010, 24},    {"LREAL", 0x0011, 64},     {"INT40", 0x0012, 40},
    {"INT48", 0x0013, 48},     {"INT56", 0x0014, 56},    {"LINT", 0x0015, 64},      {"UINT24", 0x0016, 24},
    {"UINT40", 0x0018, 40},    {"UINT48", 0x0019, 48},   {"UINT56", 0x001A, 56},    {"ULINT", 0x001B, 64},
    {"BYTE", 0x0005, 8},       {"WORD", 0x0006, 16},     {"DWORD", 0x0007, 32},     {"LWORD", 0x001B, 64},
    {"BOOLEAN", 0x0001, 1},    {"INTEGER8", 0x0002, 8},  {"INTEGER16", 0x0003, 16}, {"INTEGER32", 0x0004, 32},
    {"INTEGER64", 0x0015, 64}, {"UNSIGNED8", 0x0005, 8}, {"UNSIGNED16", 0x0006, 16}, {"UNSIGNED32", 0x0007, 32},
    {"UNSIGNED64", 0x001B, 64}, {"REAL32", 0x0008, 32},  {"REAL64", 0x0011, 64},    {"UNSIGNED24", 0x0016, 24},
    {"INTEGER24", 0x0010, 24}, {"VISIBLE_STRING", 0x0009, 0},
}};

// A type resolved to its base.
struct Resolved {
  std::string name;  // the base type's name as written ("UINT", "STRING(8)", "BIT3")
  std::uint16_t code = 0;
  int bits = 0;  // 0: not known from the type alone
  bool known = false;
};

// "STRING(8)" (8 characters), "BIT1".."BIT8".
std::optional<Resolved> sized_base(std::string_view name) {
  const std::string u = upper(name);
  if (u.size() > 7 && u.rfind("STRING(", 0) == 0 && u.back() == ')') {
    int n = 0;
    const auto digits = std::string_view{u}.substr(7, u.size() - 8);
    const auto r = std::from_chars(digits.data(), digits.data() + digits.size(), n);
    if (r.ec == std::errc{} && r.ptr == digits.data() + digits.size() && n > 0 && n <= 65535)
      return Resolved{std::string{name}, 0x0009, n * 8, true};
  }
  if (u.size() == 4 && u.rfind("BIT", 0) == 0 && u[3] >= '1' && u[3] <= '8')
    return Resolved{std::string{name}, 0, u[3] - '0', true};
  return std::nullopt;
}

std::optional<Resolved> base_type(std::string_view name) {
  for (const auto& b : kBaseTypes)
    if (same_text(b.name, name)) return Resolved{std::string{name}, b.code, b.bits, true};
  return sized_base(name);
}

// An element's text; "" for an element without text and for a missing element (nullptr).
const char* text_of(const XMLElement* e) noexcept {
  const char* t = e == nullptr ? nullptr : e->GetText();
  return t == nullptr ? "" : t;
}

std::string trimmed(const XMLElement* e) { return std::string{trim(text_of(e))}; }

// The Name child in English (LcId 1033) when there is one, else the first [ETG.2000 NameType].
std::string name_of(const XMLElement* e) {
  const XMLElement* first = e->FirstChildElement("Name");
  for (const XMLElement* n = first; n != nullptr; n = n->NextSiblingElement("Name")) {
    const char* lcid = n->Attribute("LcId");
    if (lcid != nullptr && trim(lcid) == "1033") return trimmed(n);
  }
  return trimmed(first);
}

class Parser {
 public:
  Parser(const std::string& label, Problems& problems) : label_(label), problems_(problems) {}

  std::optional<EsiFile> run(std::string_view text) {
    tinyxml2::XMLDocument doc;
    if (doc.Parse(text.data(), text.size()) != tinyxml2::XML_SUCCESS) {
      report(true, doc.ErrorLineNum(), "", xml_parse_problem(doc));
      return finish(std::nullopt);
    }
    const XMLElement* root = doc.RootElement();
    if (root == nullptr || std::string_view{root->Name()} != "EtherCATInfo") {
      report(true, root ? root->GetLineNum() : 0, "",
             "the root element is <" + std::string{root ? root->Name() : ""} +
                 ">, not <EtherCATInfo>: this is not an ESI file (ETG.2000)");
      return finish(std::nullopt);
    }
    EsiFile out;
    const XMLElement* vendor = root->FirstChildElement("Vendor");
    if (vendor == nullptr) {
      error(root, "EtherCATInfo", "has no Vendor");
    } else {
      out.vendor_name = name_of(vendor);
      if (const auto id = required_number(vendor, "Vendor", "Id", 0xFFFFFFFF)) out.vendor_id = static_cast<std::uint32_t>(*id);
    }
    const XMLElement* devices = root->FirstChildElement("Descriptions");
    if (devices) devices = devices->FirstChildElement("Devices");
    int position = 0;
    for (const XMLElement* d = devices ? devices->FirstChildElement("Device") : nullptr; d != nullptr;
         d = d->NextSiblingElement("Device"))
      out.devices.push_back(device(d, xml_child_path("", "Device", ++position)));
    if (out.devices.empty()) error(devices ? devices : root, devices ? "Descriptions/Devices" : "EtherCATInfo", "lists no Device");
    return finish(std::move(out));
  }

 private:
  std::optional<EsiFile> finish(std::optional<EsiFile> out) {
    if (warnings_ > kMaxEsiWarnings)
      problems_.warning(Diagnostic{label_, 0, 0, "", "... and " + std::to_string(warnings_ - kMaxEsiWarnings) + " more warnings"});
    if (errors_ > 0) return std::nullopt;
    return out;
  }

  void report(bool is_error, int line, const std::string& path, std::string message) {
    Diagnostic d{label_, line, line > 0 ? 1 : 0, path, std::move(message)};
    if (is_error) {
      ++errors_;
      problems_.error(std::move(d));
    } else if (++warnings_ <= kMaxEsiWarnings) {
      problems_.warning(std::move(d));
    }
  }
  void error(const XMLElement* at, const std::string& path, std::string message) {
    report(true, at ? at->GetLineNum() : 0, path, std::move(message));
  }
  void warning(const XMLElement* at, const std::string& path, std::string message) {
    report(false, at ? at->GetLineNum() : 0, path, std::move(message));
  }

  // A HexDecValue in `text` (an element's text or an attribute) at most `max`.
  std::optional<std::uint64_t> number(const XMLElement* at, const std::string& path, std::string_view text,
                                      std::uint64_t max) {
    const auto v = parse_esi_number(text);
    if (!v) {
      error(at, path, "must be a number (decimal or #x hex), got " + in_quotes(trim(text)));
      return std::nullopt;
    }
    if (*v > max) {
      char buf[24];
      std::snprintf(buf, sizeof buf, "%llX", static_cast<unsigned long long>(max));
      error(at, path, in_quotes(trim(text)) + " is beyond " + std::to_string(max) + " (#x" + buf + ")");
      return std::nullopt;
    }
    return v;
  }
  std::optional<std::int64_t> signed_number(const XMLElement* at, const std::string& path, std::string_view text,
                                            std::int64_t min, std::int64_t max) {
    const auto v = parse_esi_signed(text);
    if (!v || *v < min || *v > max) {
      error(at, path, "must be a number in " + std::to_string(min) + ".." + std::to_string(max) + ", got " +
                          in_quotes(trim(text)));
      return std::nullopt;
    }
    return v;
  }
  // The number in child element `name` of `parent`; an error when it is missing.
  std::optional<std::uint64_t> required_number(const XMLElement* parent, const std::string& path, const char* name,
                                               std::uint64_t max) {
    const XMLElement* e = parent->FirstChildElement(name);
    if (e == nullptr) {
      error(parent, path, std::string{"has no "} + name);
      return std::nullopt;
    }
    return number(e, xml_child_path(path, name), text_of(e), max);
  }
  std::optional<std::uint64_t> optional_number(const XMLElement* parent, const std::string& path, const char* name,
                                               std::uint64_t max) {
    const XMLElement* e = parent->FirstChildElement(name);
    if (e == nullptr) return std::nullopt;
    return number(e, xml_child_path(path, name), text_of(e), max);
  }
  std::optional<std::uint64_t> attribute_number(const XMLElement* e, const std::string& path, const char* name,
                                                std::uint64_t max) {
    const char* a = e->Attribute(name);
    if (a == nullptr) return std::nullopt;
    return number(e, path + "/@" + name, a, max);
  }
  // xs:boolean: true, false, 1, 0. Anything else is a warning and `otherwise`.
  bool attribute_bool(const XMLElement* e, const std::string& path, const char* name, bool otherwise) {
    const char* a = e->Attribute(name);
    if (a == nullptr) return otherwise;
    const std::string_view v = trim(a);
    if (v == "true" || v == "1") return true;
    if (v == "false" || v == "0") return false;
    warning(e, path + "/@" + name, "must be true, false, 1 or 0, got " + in_quotes(v) + "; taken as " +
                                       (otherwise ? "true" : "false"));
    return otherwise;
  }

  EsiDevice device(const XMLElement* d, const std::string& path) {
    EsiDevice dev;
    dev.line = d->GetLineNum();
    if (const XMLElement* type = d->FirstChildElement("Type"); type == nullptr) {
      error(d, path, "has no Type (its product code and revision)");
    } else {
      dev.type = trimmed(type);
      const std::string tpath = xml_child_path(path, "Type");
      if (type->Attribute("ProductCode") == nullptr)
        error(type, tpath, "has no ProductCode");
      else if (const auto v = attribute_number(type, tpath, "ProductCode", 0xFFFFFFFF))
        dev.product_code = static_cast<std::uint32_t>(*v);
      if (const auto v = attribute_number(type, tpath, "RevisionNo", 0xFFFFFFFF)) dev.revision = static_cast<std::uint32_t>(*v);
    }
    dev.name = name_of(d);
    // The first Profile names the device profile; the dictionary is in the first that has one.
    const XMLElement* dictionary = nullptr;
    std::string dictionary_path;
    int position = 0;
    for (const XMLElement* p = d->FirstChildElement("Profile"); p != nullptr; p = p->NextSiblingElement("Profile")) {
      const std::string ppath = xml_child_path(path, "Profile", ++position);
      if (position == 1)
        if (const auto no = optional_number(p, ppath, "ProfileNo", 0xFFFFFFFF)) dev.profile_no = static_cast<std::uint32_t>(*no);
      if (dictionary == nullptr && (dictionary = p->FirstChildElement("Dictionary")) != nullptr)
        dictionary_path = xml_child_path(ppath, "Dictionary");
      if (const XMLElement* f = p->FirstChildElement("DictionaryFile"); f != nullptr && dictionary == nullptr)
        warning(f, xml_child_path(ppath, "DictionaryFile"),
                "the dictionary in another file (" + in_quotes(trimmed(f)) + ") is not read; objects are not checked");
    }
    if (const XMLElement* m = d->FirstChildElement("Mailbox")) dev.mailbox = mailbox(m, xml_child_path(path, "Mailbox"));
    position = 0;
    for (const XMLElement* s = d->FirstChildElement("Sm"); s != nullptr; s = s->NextSiblingElement("Sm"))
      dev.sms.push_back(sm(s, xml_child_path(path, "Sm", ++position)));
    for (const bool rx : {true, false}) {
      const char* tag = rx ? "RxPdo" : "TxPdo";
      position = 0;
      for (const XMLElement* p = d->FirstChildElement(tag); p != nullptr; p = p->NextSiblingElement(tag))
        (rx ? dev.rxpdos : dev.txpdos).push_back(pdo(p, xml_child_path(path, tag, ++position)));
    }
    if (const XMLElement* dc = d->FirstChildElement("Dc")) {
      position = 0;
      for (const XMLElement* o = dc->FirstChildElement("OpMode"); o != nullptr; o = o->NextSiblingElement("OpMode"))
        dev.op_modes.push_back(op_mode(o, xml_child_path(xml_child_path(path, "Dc"), "OpMode", ++position)));
    }
    if (dictionary != nullptr) read_dictionary(dictionary, dictionary_path, dev);
    return dev;
  }

  EsiMailbox mailbox(const XMLElement* m, const std::string& path) {
    EsiMailbox mb;
    mb.eoe = m->FirstChildElement("EoE") != nullptr;
    mb.foe = m->FirstChildElement("FoE") != nullptr;
    mb.soe = m->FirstChildElement("SoE") != nullptr;
    mb.aoe = m->FirstChildElement("AoE") != nullptr;
    if (const XMLElement* coe = m->FirstChildElement("CoE")) {
      const std::string p = xml_child_path(path, "CoE");
      mb.coe = true;
      mb.sdo_info = attribute_bool(coe, p, "SdoInfo", false);
      mb.pdo_assign = attribute_bool(coe, p, "PdoAssign", false);
      mb.pdo_config = attribute_bool(coe, p, "PdoConfig", false);
      mb.complete_access = attribute_bool(coe, p, "CompleteAccess", false);
      mb.segmented_sdo = attribute_bool(coe, p, "SegmentedSdo", true);
    }
    return mb;
  }

  EsiSm sm(const XMLElement* s, const std::string& path) {
    EsiSm out;
    out.line = s->GetLineNum();
    out.text = trimmed(s);
    static constexpr std::array<std::pair<std::string_view, EsiSmKind>, 4> kKinds{{
        {"MBoxOut", EsiSmKind::MBoxOut}, {"MBoxIn", EsiSmKind::MBoxIn},
        {"Outputs", EsiSmKind::Outputs}, {"Inputs", EsiSmKind::Inputs}}};
    for (const auto& [word, kind] : kKinds)
      if (same_text(out.text, word)) out.kind = kind;
    if (out.kind == EsiSmKind::Unknown && !out.text.empty())
      warning(s, path, "is " + in_quotes(out.text) + ", none of MBoxOut, MBoxIn, Outputs, Inputs");
    // SyncManager registers: 16-bit start address and length, 8-bit control [ETG.1000.4 Table 59].
    const auto size = [&](const char* name) -> std::optional<std::uint32_t> {
      const auto v = attribute_number(s, path, name, 0xFFFF);
      return v ? std::optional<std::uint32_t>{static_cast<std::uint32_t>(*v)} : std::nullopt;
    };
    out.min_size = size("MinSize");
    out.max_size = size("MaxSize");
    out.default_size = size("DefaultSize");
    if (const auto v = attribute_number(s, path, "StartAddress", 0xFFFF)) out.start_address = static_cast<std::uint16_t>(*v);
    if (const auto v = attribute_number(s, path, "ControlByte", 0xFF)) out.control_byte = static_cast<std::uint8_t>(*v);
    if (const auto v = attribute_number(s, path, "Enable", 0xFF)) out.enable = *v != 0;
    return out;
  }

  EsiPdo pdo(const XMLElement* p, const std::string& path) {
    EsiPdo out;
    out.line = p->GetLineNum();
    out.fixed = attribute_bool(p, path, "Fixed", false);
    out.mandatory = attribute_bool(p, path, "Mandatory", false);
    // An ESC has at most 16 SyncManagers [ETG.1000.4 §6.7].
    if (const auto v = attribute_number(p, path, "Sm", 15)) out.sm = static_cast<int>(*v);
    if (const auto v = required_number(p, path, "Index", 0xFFFF)) out.index = static_cast<std::uint16_t>(*v);
    out.name = name_of(p);
    int position = 0;
    for (const XMLElement* e = p->FirstChildElement("Entry"); e != nullptr; e = e->NextSiblingElement("Entry")) {
      const std::string epath = xml_child_path(path, "Entry", ++position);
      EsiPdoEntry entry;
      entry.line = e->GetLineNum();
      if (const auto v = required_number(e, epath, "Index", 0xFFFF)) entry.object.index = static_cast<std::uint16_t>(*v);
      if (const auto v = optional_number(e, epath, "SubIndex", 0xFF)) entry.object.sub = static_cast<std::uint8_t>(*v);
      // A mapping entry holds the length in one byte [ETG.1000.6 §5.6.7.4.8, CiA 301 §7.5.2.36].
      if (const auto v = required_number(e, epath, "BitLen", 0xFF)) {
        if (*v == 0)
          error(e->FirstChildElement("BitLen"), xml_child_path(epath, "BitLen"), "must be 1..255, got 0");
        else
          entry.bits = static_cast<int>(*v);
      }
      entry.name = name_of(e);
      entry.data_type = trimmed(e->FirstChildElement("DataType"));
      out.entries.push_back(std::move(entry));
    }
    return out;
  }

  EsiOpMode op_mode(const XMLElement* o, const std::string& path) {
    EsiOpMode out;
    out.line = o->GetLineNum();
    out.name = trimmed(o->FirstChildElement("Name"));
    out.desc = trimmed(o->FirstChildElement("Desc"));
    if (out.name.empty()) error(o, path, "has no Name");
    // AssignActivate is written to the 16-bit register 0980h [ETG.1000.4 Table 60].
    if (const auto v = required_number(o, path, "AssignActivate", 0xFFFF)) out.assign_activate = static_cast<std::uint32_t>(*v);
    if (const XMLElement* c = o->FirstChildElement("CycleTimeSync0")) {
      const std::string cpath = xml_child_path(path, "CycleTimeSync0");
      if (const auto v = number(c, cpath, text_of(c), 0xFFFFFFFF)) out.cycle_time_sync0 = static_cast<std::uint32_t>(*v);
      if (const char* f = c->Attribute("Factor"))
        if (const auto v = signed_number(c, cpath + "/@Factor", f, INT32_MIN, INT32_MAX))
          out.cycle_time_sync0_factor = static_cast<std::int32_t>(*v);
    }
    if (const XMLElement* s = o->FirstChildElement("ShiftTimeSync0"))
      out.shift_time_sync0 = signed_number(s, xml_child_path(path, "ShiftTimeSync0"), text_of(s), INT32_MIN, INT32_MAX);
    return out;
  }

  // ---- the dictionary -------------------------------------------------------------------------

  struct Flags {
    EsiAccess access = EsiAccess::ReadOnly;
    bool rx = false;
    bool tx = false;
  };

  Flags flags(const XMLElement* f, const std::string& path, const Flags& otherwise) {
    if (f == nullptr) return otherwise;
    Flags out = otherwise;
    if (const XMLElement* a = f->FirstChildElement("Access")) {
      const std::string v = trimmed(a);
      if (same_text(v, "ro"))
        out.access = EsiAccess::ReadOnly;
      else if (same_text(v, "rw"))
        out.access = EsiAccess::ReadWrite;
      else if (same_text(v, "wo"))
        out.access = EsiAccess::WriteOnly;
      else
        error(a, xml_child_path(path, "Access"), "must be ro, rw or wo, got " + in_quotes(v));
    }
    if (const XMLElement* m = f->FirstChildElement("PdoMapping")) {
      const std::string v = trimmed(m);
      out.rx = out.tx = false;
      for (const char c : v) {
        if (c == 'R' || c == 'r')
          out.rx = true;
        else if (c == 'T' || c == 't')
          out.tx = true;
      }
      if (!v.empty() && !same_text(v, "R") && !same_text(v, "T") && !same_text(v, "RT") && !same_text(v, "TR"))
        warning(m, xml_child_path(path, "PdoMapping"), "must be R, T, RT or TR, got " + in_quotes(v));
    }
    return out;
  }

  // The DataType named `name`, or nullptr.
  const XMLElement* data_type(std::string_view name) const {
    const auto it = data_types_.find(std::string{trim(name)});
    return it == data_types_.end() ? nullptr : it->second;
  }
  static bool is_complex(const XMLElement* dt) {
    return dt != nullptr && (dt->FirstChildElement("SubItem") != nullptr || dt->FirstChildElement("ArrayInfo") != nullptr);
  }

  // `name` down to a base type through DataType aliases (BaseType), enums and the base types a
  // file declares itself (<DataType><Name>UINT</Name><BitSize>16</BitSize>).
  Resolved resolve(std::string_view name) const {
    Resolved r = resolve_from(name, 0);
    if (!r.known) r.name = std::string{trim(name)};  // as written, for messages
    return r;
  }
  Resolved resolve_from(std::string_view name, int depth) const {
    if (auto b = base_type(name)) return *b;
    const XMLElement* dt = data_type(name);
    if (dt == nullptr || is_complex(dt) || depth > 8) return Resolved{std::string{trim(name)}, 0, 0, false};
    int bits = 0;
    if (const auto v = parse_esi_number(text_of(dt->FirstChildElement("BitSize"))); v && *v > 0 && *v <= 0xFFFF)
      bits = static_cast<int>(*v);
    if (const XMLElement* base = dt->FirstChildElement("BaseType")) {
      Resolved r = resolve_from(trimmed(base), depth + 1);
      if (bits > 0) r.bits = bits;
      return r;
    }
    return Resolved{std::string{trim(name)}, 0, bits, false};
  }

  // The entry's BitSize, else its type's; 0 with a warning when neither gives one.
  int bit_size(const XMLElement* e, const std::string& path, const Resolved& type) {
    if (const XMLElement* b = e->FirstChildElement("BitSize")) {
      const auto v = number(b, xml_child_path(path, "BitSize"), text_of(b), 0xFFFF);
      return v ? static_cast<int>(*v) : -1;
    }
    return type.bits;
  }

  // Whether the object being expanded, or the device's dictionary, is full (after one error).
  [[nodiscard]] bool full() const noexcept { return object_full_ || device_full_; }

  void add(EsiObject o, const XMLElement* at, const std::string& path, const Resolved& type) {
    // A record or array has at most 256 sub-indices; more entries can only come from a file that
    // expands a type without end, and must not exhaust memory.
    if (++object_entries_ > 256) {
      object_full_ = true;
      error(at, path, "gives object " + hex_index(o.id.index) + " more than 256 sub-indices");
      return;
    }
    if (out_->objects.size() >= kMaxEsiEntries) {
      device_full_ = true;
      error(object_at_, object_path_, "the dictionary has more than " + std::to_string(kMaxEsiEntries) + " entries");
      return;
    }
    if (!type.known)
      warning(at, path,
              "Type " + in_quotes(o.type) + " is neither an ETG base type nor in DataTypes; its size is taken from BitSize");
    o.data_type = type.code;
    out_->objects.push_back(std::move(o));
  }

  void read_dictionary(const XMLElement* dictionary, const std::string& path, EsiDevice& dev) {
    out_ = &dev;
    device_full_ = false;
    data_types_.clear();
    if (const XMLElement* types = dictionary->FirstChildElement("DataTypes"))
      for (const XMLElement* t = types->FirstChildElement("DataType"); t != nullptr; t = t->NextSiblingElement("DataType")) {
        const std::string name = trimmed(t->FirstChildElement("Name"));
        if (!name.empty()) data_types_.emplace(name, t);  // the first of a name counts
      }
    const XMLElement* objects = dictionary->FirstChildElement("Objects");
    dev.has_dictionary = objects != nullptr;
    int position = 0;
    for (const XMLElement* o = objects ? objects->FirstChildElement("Object") : nullptr; o != nullptr;
         o = o->NextSiblingElement("Object")) {
      object_entries_ = 0;
      object_full_ = false;
      object_at_ = o;
      object_path_ = xml_child_path(xml_child_path(path, "Objects"), "Object", ++position);
      object(o, object_path_);
      if (device_full_) break;
    }
    auto& list = dev.objects;
    std::stable_sort(list.begin(), list.end(), [](const EsiObject& a, const EsiObject& b) { return a.id.key() < b.id.key(); });
    for (std::size_t i = 1; i < list.size(); ++i)
      if (list[i].id == list[i - 1].id)
        report(false, list[i].line, "",
               "object " + id_text(list[i].id) + " is described again (first at line " + std::to_string(list[i - 1].line) +
                   "); the first is kept");
    list.erase(std::unique(list.begin(), list.end(), [](const EsiObject& a, const EsiObject& b) { return a.id == b.id; }),
               list.end());
    out_ = nullptr;
  }

  static std::string id_text(cia402::ObjectId id) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "%04Xh:%u", unsigned{id.index}, unsigned{id.sub});
    return buf;
  }

  void object(const XMLElement* o, const std::string& path) {
    const auto index = required_number(o, path, "Index", 0xFFFF);
    const std::string name = name_of(o);
    const XMLElement* type_element = o->FirstChildElement("Type");
    if (type_element == nullptr) error(o, path, "has no Type");
    if (!index || type_element == nullptr) return;
    const std::string type = trimmed(type_element);
    const Flags object_flags = flags(o->FirstChildElement("Flags"), xml_child_path(path, "Flags"), Flags{});
    const XMLElement* info = o->FirstChildElement("Info");
    EsiObject base;
    base.line = o->GetLineNum();
    base.id.index = static_cast<std::uint16_t>(*index);

    const XMLElement* dt = data_type(type);
    if (!is_complex(dt)) {  // a VAR object
      const Resolved r = resolve(type);
      base.name = name;
      base.type = r.name;
      base.bits = bit_size(o, path, r);
      base.access = object_flags.access;
      base.rx_mappable = object_flags.rx;
      base.tx_mappable = object_flags.tx;
      base.default_data = info ? trimmed(info->FirstChildElement("DefaultData")) : std::string{};
      if (base.bits == 0)
        warning(o, path, "Type " + in_quotes(type) + " has no size and the object no BitSize; it is left out");
      else if (base.bits > 0)
        add(std::move(base), o, path, r);
      return;
    }
    // ARRAY or RECORD: one entry per sub-index, from the type's SubItems [ETG.2000 DataTypeType].
    std::vector<const XMLElement*> info_items;
    for (const XMLElement* s = info ? info->FirstChildElement("SubItem") : nullptr; s != nullptr;
         s = s->NextSiblingElement("SubItem"))
      info_items.push_back(s);
    const auto info_default = [](const XMLElement* item) {
      const XMLElement* i = item ? item->FirstChildElement("Info") : nullptr;
      return i ? trimmed(i->FirstChildElement("DefaultData")) : std::string{};
    };
    base.parent = name;
    std::size_t flat = 0;  // position among the object's sub-indices, for Info/SubItem of arrays
    const std::string tpath = "DataType " + in_quotes(type);
    const auto array = [&](const XMLElement* arr, const std::string& apath, std::optional<std::uint64_t> first,
                           const Flags& f) {
      const XMLElement* ai = arr->FirstChildElement("ArrayInfo");
      const auto lbound = ai ? optional_number(ai, apath + "/ArrayInfo", "LBound", 0xFF) : std::nullopt;
      const auto elements = ai ? required_number(ai, apath + "/ArrayInfo", "Elements", 0xFF) : std::nullopt;
      if (!elements) return;
      const Resolved r = resolve(trimmed(arr->FirstChildElement("BaseType")));
      int bits = r.bits;
      if (bits == 0 && *elements > 0)
        if (const auto total = parse_esi_number(text_of(arr->FirstChildElement("BitSize"))))
          bits = static_cast<int>(*total / *elements);
      const std::uint64_t start = first.value_or(lbound.value_or(1));
      for (std::uint64_t i = 0; i < *elements && !full(); ++i, ++flat) {
        if (start + i > 0xFF) {
          error(arr, apath, "has elements beyond sub-index 255");
          return;
        }
        EsiObject e = base;
        e.id.sub = static_cast<std::uint8_t>(start + i);
        char fallback[16];
        std::snprintf(fallback, sizeof fallback, "SubIndex %03u", static_cast<unsigned>(start + i));
        const XMLElement* item = flat < info_items.size() ? info_items[flat] : nullptr;
        e.name = item ? name_of(item) : std::string{};
        if (e.name.empty()) e.name = fallback;
        e.default_data = info_default(item);
        e.type = r.name;
        e.bits = bits;
        e.access = f.access;
        e.rx_mappable = f.rx;
        e.tx_mappable = f.tx;
        if (bits <= 0) {
          warning(arr, apath, "gives no element size; " + object_name(e) + " is left out");
          continue;
        }
        add(std::move(e), arr, apath, r);
      }
    };
    if (dt->FirstChildElement("SubItem") == nullptr) {  // the object's type is the array itself
      array(dt, tpath, std::nullopt, object_flags);
      return;
    }
    int position = 0;
    for (const XMLElement* s = dt->FirstChildElement("SubItem"); s != nullptr && !full(); s = s->NextSiblingElement("SubItem")) {
      const std::string spath = tpath + "/SubItem[" + std::to_string(++position) + "]";
      const Flags f = flags(s->FirstChildElement("Flags"), xml_child_path(spath, "Flags"), object_flags);
      const std::string stype = trimmed(s->FirstChildElement("Type"));
      const auto subidx = optional_number(s, spath, "SubIdx", 0xFF);
      const XMLElement* sdt = data_type(stype);
      if (sdt != nullptr && sdt->FirstChildElement("ArrayInfo") != nullptr) {
        array(sdt, "DataType " + in_quotes(stype), subidx, f);
        continue;
      }
      if (!subidx) {
        if (s->FirstChildElement("SubIdx") == nullptr) error(s, spath, "has no SubIdx");
        continue;
      }
      EsiObject e = base;
      e.id.sub = static_cast<std::uint8_t>(*subidx);
      e.name = name_of(s);
      const Resolved r = resolve(stype);
      e.type = r.name;
      e.bits = bit_size(s, spath, r);
      e.access = f.access;
      e.rx_mappable = f.rx;
      e.tx_mappable = f.tx;
      // Defaults of a record's sub-items are given under Info by the same name.
      for (const XMLElement* item : info_items)
        if (same_text(name_of(item), e.name)) {
          e.default_data = info_default(item);
          break;
        }
      ++flat;
      if (e.bits == 0)
        warning(s, spath, "Type " + in_quotes(stype) + " has no size and the sub-item no BitSize; " + object_name(e) +
                              " is left out");
      else if (e.bits > 0)
        add(std::move(e), s, spath, r);
    }
  }

  static std::string hex_index(std::uint16_t index) {
    char buf[8];
    std::snprintf(buf, sizeof buf, "%04Xh", unsigned{index});
    return buf;
  }

  static std::string object_name(const EsiObject& o) { return id_text(o.id) + " " + in_quotes(o.name); }

  std::string label_;
  Problems& problems_;
  std::size_t errors_ = 0;
  std::size_t warnings_ = 0;
  std::map<std::string, const XMLElement*> data_types_;
  EsiDevice* out_ = nullptr;
  const XMLElement* object_at_ = nullptr;  // the object being expanded
  std::string object_path_;
  std::size_t object_entries_ = 0;  // its entries
  bool object_full_ = false;
  bool device_full_ = false;
};

}  // namespace

std::string_view to_string(EsiAccess access) noexcept {
  switch (access) {
    case EsiAccess::ReadOnly: return "ro";
    case EsiAccess::ReadWrite: return "rw";
    case EsiAccess::WriteOnly: return "wo";
  }
  return "?";
}

std::optional<std::uint64_t> parse_esi_number(std::string_view text) noexcept {
  text = trim(text);
  int base = 10;
  if (text.size() > 2 && (text.substr(0, 2) == "#x" || text.substr(0, 2) == "#X" || text.substr(0, 2) == "0x" ||
                          text.substr(0, 2) == "0X")) {
    base = 16;
    text.remove_prefix(2);
  }
  if (text.empty() || text.front() == '+' || text.front() == '-') return std::nullopt;
  std::uint64_t v = 0;
  const auto r = std::from_chars(text.data(), text.data() + text.size(), v, base);
  if (r.ec != std::errc{} || r.ptr != text.data() + text.size()) return std::nullopt;
  return v;
}

std::optional<std::int64_t> parse_esi_signed(std::string_view text) noexcept {
  text = trim(text);
  if (!text.empty() && text.front() == '-') {
    const auto rest = text.substr(1);
    if (rest.empty() || std::isdigit(static_cast<unsigned char>(rest.front())) == 0) return std::nullopt;
    std::int64_t v = 0;
    const auto r = std::from_chars(text.data(), text.data() + text.size(), v);
    if (r.ec != std::errc{} || r.ptr != text.data() + text.size()) return std::nullopt;
    return v;
  }
  const auto v = parse_esi_number(text);
  if (!v || *v > static_cast<std::uint64_t>(INT64_MAX)) return std::nullopt;
  return static_cast<std::int64_t>(*v);
}

std::string esi_hex32(std::uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%08X", v);
  return buf;
}

std::string esi_device_text(const EsiDevice& d) {
  std::string s = in_quotes(d.type.empty() ? d.name : d.type) + " (product " + esi_hex32(d.product_code);
  if (d.revision) s += ", revision " + esi_hex32(*d.revision);
  return s + ")";
}

std::optional<EsiFile> load_esi(const std::filesystem::path& file, Problems& problems) {
  const auto text = read_text_file(file.string(), Source{file.string(), &problems}, kMaxEsiBytes);
  if (!text) return std::nullopt;
  return load_esi_text(*text, file.string(), problems);
}

std::optional<EsiFile> load_esi_text(std::string_view text, const std::string& label, Problems& problems) {
  return Parser{label, problems}.run(text);
}

std::vector<const EsiDevice*> find_esi_devices(const EsiFile& file, std::uint32_t product_code,
                                               std::optional<std::uint32_t> revision) {
  std::vector<const EsiDevice*> out;
  for (const auto& d : file.devices)
    if (d.product_code == product_code && (!revision || d.revision == revision)) out.push_back(&d);
  return out;
}

const EsiObject* find_esi_object(std::span<const EsiObject> objects, cia402::ObjectId id) noexcept {
  const auto it = std::lower_bound(objects.begin(), objects.end(), id.key(),
                                   [](const EsiObject& o, std::uint32_t key) { return o.id.key() < key; });
  return it != objects.end() && it->id == id ? &*it : nullptr;
}

std::vector<const EsiObject*> find_esi_objects(std::span<const EsiObject> objects, std::string_view name) {
  std::vector<const EsiObject*> out;
  name = trim(name);
  for (const auto& o : objects)
    if (o.parent.empty() && same_text(o.name, name)) out.push_back(&o);
  if (!out.empty()) return out;
  // "OBJECT:SUB": an object's name may itself hold a colon, so every split is tried.
  for (std::size_t colon = name.find(':'); colon != std::string_view::npos; colon = name.find(':', colon + 1)) {
    const auto parent = trim(name.substr(0, colon));
    const auto sub = trim(name.substr(colon + 1));
    for (const auto& o : objects)
      if (!o.parent.empty() && same_text(o.parent, parent) && same_text(o.name, sub)) out.push_back(&o);
  }
  return out;
}

const EsiObject* find_esi_object(std::span<const EsiObject> objects, std::string_view name) {
  const auto all = find_esi_objects(objects, name);
  return all.size() == 1 ? all.front() : nullptr;
}

}  // namespace drivegate::config
