#include "config/eds.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdio>
#include <map>

#include "config/scalars.hpp"
#include "config/yaml_reader.hpp"

namespace drivegate::config {

namespace {

struct TypeInfo {
  std::uint16_t code;
  const char* name;
  std::uint8_t bits;  // 0: not fixed-size
};

// CiA 301 §7.4.7.1 static data types.
constexpr std::array<TypeInfo, 25> kTypes{{
    {0x0001, "BOOLEAN", 8},        {0x0002, "INTEGER8", 8},        {0x0003, "INTEGER16", 16},
    {0x0004, "INTEGER32", 32},     {0x0005, "UNSIGNED8", 8},       {0x0006, "UNSIGNED16", 16},
    {0x0007, "UNSIGNED32", 32},    {0x0008, "REAL32", 32},         {0x0009, "VISIBLE_STRING", 0},
    {0x000A, "OCTET_STRING", 0},   {0x000B, "UNICODE_STRING", 0},  {0x000C, "TIME_OF_DAY", 48},
    {0x000D, "TIME_DIFFERENCE", 48}, {0x000F, "DOMAIN", 0},        {0x0010, "INTEGER24", 24},
    {0x0011, "REAL64", 64},        {0x0012, "INTEGER40", 40},      {0x0013, "INTEGER48", 48},
    {0x0014, "INTEGER56", 56},     {0x0015, "INTEGER64", 64},      {0x0016, "UNSIGNED24", 24},
    {0x0018, "UNSIGNED40", 40},    {0x0019, "UNSIGNED48", 48},     {0x001A, "UNSIGNED56", 56},
    {0x001B, "UNSIGNED64", 64},
}};

const TypeInfo* type_info(std::uint16_t code) noexcept {
  const auto it = std::find_if(kTypes.begin(), kTypes.end(), [code](const TypeInfo& t) { return t.code == code; });
  return it == kTypes.end() ? nullptr : &*it;
}

std::string lower(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

std::string_view trim(std::string_view s) noexcept {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front())) != 0) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back())) != 0) s.remove_suffix(1);
  return s;
}

std::optional<std::uint32_t> parse_hex(std::string_view s) noexcept {
  if (s.empty() || s.size() > 4) return std::nullopt;
  std::uint32_t v = 0;
  for (const char c : s) {
    const auto u = static_cast<unsigned char>(c);
    if (std::isxdigit(u) == 0) return std::nullopt;
    v = v * 16 + static_cast<std::uint32_t>(std::isdigit(u) != 0 ? u - '0' : std::tolower(u) - 'a' + 10);
  }
  return v;
}

// The object a section names: "6040" -> 6040h, "1018sub1" -> 1018h sub 1. Other sections (FileInfo,
// DeviceInfo, 1018Name, ...) give nullopt and are skipped.
struct SectionId {
  std::uint16_t index = 0;
  std::optional<std::uint8_t> sub;
  bool bad_sub = false;  // "sub" followed by something that is not hex 0..FF
};
std::optional<SectionId> object_section(std::string_view name) {
  if (name.size() < 4) return std::nullopt;
  const auto index = parse_hex(name.substr(0, 4));
  if (!index) return std::nullopt;
  SectionId id{static_cast<std::uint16_t>(*index), std::nullopt, false};
  const std::string_view rest = name.substr(4);
  if (rest.empty()) return id;
  if (rest.size() < 3 || lower(rest.substr(0, 3)) != "sub") return std::nullopt;
  const auto sub = parse_hex(rest.substr(3));
  id.bad_sub = !sub || *sub > 0xFF;
  id.sub = static_cast<std::uint8_t>(sub.value_or(0) & 0xFF);
  return id;
}

// One object section as read, before it becomes an EdsObject.
struct Section {
  std::string name;  // as written, for messages
  SectionId id;
  int line = 0;
  std::map<std::string, std::pair<std::string, int>> keys;  // lower-case key -> (value, line)
};

class Parser {
 public:
  Parser(std::string label, Problems& problems) : label_(std::move(label)), problems_(problems) {}

  std::optional<std::vector<EdsObject>> run(std::string_view text) {
    const std::size_t errors_before = problems_.errors().size();
    split_sections(text);
    std::vector<EdsObject> out;
    for (const auto& s : sections_) build(s, out);
    if (problems_.errors().size() != errors_before) return std::nullopt;
    std::sort(out.begin(), out.end(), [](const EdsObject& a, const EdsObject& b) { return a.id.key() < b.id.key(); });
    return out;
  }

 private:
  void error(int line, std::string path, std::string message) {
    Diagnostic d;
    d.file = label_;
    d.line = line;
    d.column = 1;
    d.path = std::move(path);
    d.message = std::move(message);
    problems_.error(std::move(d));
  }

  void split_sections(std::string_view text) {
    Section* current = nullptr;
    bool in_other_section = false;
    int line_no = 0;
    std::map<std::string, int> seen;  // lower-case section name -> line
    while (!text.empty()) {
      const auto nl = text.find('\n');
      const std::string_view raw = text.substr(0, nl);
      text = nl == std::string_view::npos ? std::string_view{} : text.substr(nl + 1);
      ++line_no;
      const std::string_view line = trim(raw);
      if (line.empty() || line.front() == ';') continue;
      if (line.front() == '[') {
        if (line.back() != ']') {
          error(line_no, "", "section header must end with ']', got \"" + std::string{line} + "\"");
          current = nullptr;
          in_other_section = true;
          continue;
        }
        const std::string name{trim(line.substr(1, line.size() - 2))};
        const auto [it, added] = seen.emplace(lower(name), line_no);
        if (!added) {
          error(line_no, "[" + name + "]", "section given twice (first at line " + std::to_string(it->second) + ")");
          current = nullptr;
          in_other_section = true;
          continue;
        }
        const auto id = object_section(name);
        if (!id) {
          current = nullptr;
          in_other_section = true;
          continue;
        }
        if (id->bad_sub) {
          error(line_no, "[" + name + "]", "sub-index must be hex 0..FF (as in [1018sub1])");
          current = nullptr;
          in_other_section = true;
          continue;
        }
        sections_.push_back(Section{name, *id, line_no, {}});
        current = &sections_.back();
        in_other_section = false;
        continue;
      }
      if (!current && !in_other_section) {
        error(line_no, "", "text before the first section: \"" + std::string{line} + "\"");
        continue;
      }
      const auto eq = line.find('=');
      if (eq == std::string_view::npos) {
        error(line_no, current ? "[" + current->name + "]" : "", "expected KEY=VALUE, got \"" + std::string{line} + "\"");
        continue;
      }
      if (!current) continue;  // keys of skipped sections are not checked
      const std::string key = lower(trim(line.substr(0, eq)));
      const auto [it, added] = current->keys.emplace(key, std::make_pair(std::string{trim(line.substr(eq + 1))}, line_no));
      if (!added)
        error(line_no, "[" + current->name + "]." + std::string{trim(line.substr(0, eq))},
              "given twice (first at line " + std::to_string(it->second.second) + ")");
    }
  }

  const Section* find_section(std::uint16_t index) const {
    const auto it = std::find_if(sections_.begin(), sections_.end(),
                                 [index](const Section& s) { return s.id.index == index && !s.id.sub; });
    return it == sections_.end() ? nullptr : &*it;
  }

  // The value of `key` with its line, or nullopt (reported when `required`).
  std::optional<std::pair<std::string, int>> value(const Section& s, const std::string& key, bool required) {
    const auto it = s.keys.find(key);
    if (it != s.keys.end()) return it->second;
    if (required) error(s.line, "[" + s.name + "]", "missing " + key_label(key));
    return std::nullopt;
  }

  static std::string key_label(const std::string& key) {
    static const std::map<std::string, std::string> kLabels{
        {"parametername", "ParameterName"}, {"objecttype", "ObjectType"}, {"datatype", "DataType"},
        {"accesstype", "AccessType"},       {"pdomapping", "PDOMapping"}, {"lowlimit", "LowLimit"},
        {"highlimit", "HighLimit"}};
    const auto it = kLabels.find(key);
    return it == kLabels.end() ? key : it->second;
  }

  std::optional<std::int64_t> integer(const Section& s, const std::string& key, bool required) {
    const auto v = value(s, key, required);
    if (!v) return std::nullopt;
    const auto i = parse_integer(v->first);
    if (!i) error(v->second, "[" + s.name + "]." + key_label(key), "must be an integer (decimal or 0x hex), got \"" + v->first + "\"");
    return i;
  }

  void build(const Section& s, std::vector<EdsObject>& out) {
    const std::string where = "[" + s.name + "]";
    // ObjectType [CiA 306 §4.6.3]: 0x7 VAR (the default), 0x8 ARRAY, 0x9 RECORD, 0x2 DOMAIN; the
    // type definitions 0x5/0x6 describe no accessible object.
    std::int64_t object_type = 0x7;
    if (const auto t = value(s, "objecttype", false)) {
      const auto v = parse_integer(t->first);
      if (!v || (*v != 0x2 && *v != 0x5 && *v != 0x6 && *v != 0x7 && *v != 0x8 && *v != 0x9)) {
        error(t->second, where + ".ObjectType",
              "must be 0x7 (VAR), 0x8 (ARRAY), 0x9 (RECORD), 0x2 (DOMAIN), 0x5 or 0x6, got \"" + t->first + "\"");
        return;
      }
      object_type = *v;
    }
    const auto name = value(s, "parametername", true);
    if (s.id.sub && object_type != 0x7 && object_type != 0x2) {
      error(s.line, where + ".ObjectType", "a sub-index must be a VAR (0x7)");
      return;
    }
    std::string parent;
    if (s.id.sub) {
      const Section* p = find_section(s.id.index);
      if (!p) {
        char buf[8];
        std::snprintf(buf, sizeof buf, "%04X", s.id.index);
        error(s.line, where, std::string{"sub-index without its object: there is no ["} + buf + "] section");
        return;
      }
      if (const auto pn = p->keys.find("parametername"); pn != p->keys.end()) parent = pn->second.first;
    } else if (object_type == 0x8 || object_type == 0x9 || object_type == 0x5 || object_type == 0x6) {
      return;  // the accessible entries are its sub-index sections
    }

    EdsObject o;
    o.id = {s.id.index, s.id.sub.value_or(0)};
    o.name = name ? name->first : std::string{};
    o.parent = parent;
    o.line = s.line;
    if (const auto dt = value(s, "datatype", true)) {
      const auto v = parse_integer(dt->first);
      if (!v || *v < 0 || *v > 0xFFFF || !type_info(static_cast<std::uint16_t>(*v)))
        error(dt->second, where + ".DataType",
              "must be a CiA 301 data type such as 0x0007 (UNSIGNED32) or 0x0009 (VISIBLE_STRING), got \"" +
                  dt->first + "\"");
      else
        o.data_type = static_cast<std::uint16_t>(*v);
    }
    if (const auto at = value(s, "accesstype", true)) {
      static const std::map<std::string, EdsAccess> kAccess{
          {"ro", EdsAccess::ReadOnly},        {"wo", EdsAccess::WriteOnly},       {"rw", EdsAccess::ReadWrite},
          {"rwr", EdsAccess::ReadWriteRead},  {"rww", EdsAccess::ReadWriteWrite}, {"const", EdsAccess::Const}};
      const auto it = kAccess.find(lower(at->first));
      if (it == kAccess.end())
        error(at->second, where + ".AccessType", "must be one of ro, wo, rw, rwr, rww, const, got \"" + at->first + "\"");
      else
        o.access = it->second;
    }
    if (const auto pm = value(s, "pdomapping", false)) {
      if (pm->first != "0" && pm->first != "1")
        error(pm->second, where + ".PDOMapping", "must be 0 or 1, got \"" + pm->first + "\"");
      o.pdo_mapping = pm->first == "1";
    }
    if (const auto dv = value(s, "defaultvalue", false)) o.default_value = dv->first;
    // Limits may be written relative to the node-ID ("$NODEID+0x80"); those are not checked here.
    const auto limit = [&](const std::string& key) -> std::optional<std::int64_t> {
      const auto v = value(s, key, false);
      if (!v || v->first.empty() || v->first.front() == '$') return std::nullopt;
      return integer(s, key, false);
    };
    o.low_limit = limit("lowlimit");
    o.high_limit = limit("highlimit");
    if (o.low_limit && o.high_limit && *o.low_limit > *o.high_limit)
      error(value(s, "lowlimit", false)->second, where + ".LowLimit",
            "must not exceed HighLimit (" + std::to_string(*o.high_limit) + "), got " + std::to_string(*o.low_limit));
    out.push_back(std::move(o));
  }

  std::string label_;
  Problems& problems_;
  std::vector<Section> sections_;
};

bool same_text(std::string_view a, std::string_view b) noexcept {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
         });
}

}  // namespace

std::optional<std::vector<EdsObject>> parse_eds(const std::filesystem::path& file, Problems& problems) {
  const auto text = read_text_file(file.string(), Source{file.string(), &problems}, kMaxEdsBytes);
  if (!text) return std::nullopt;
  return parse_eds_text(*text, file.string(), problems);
}

std::optional<std::vector<EdsObject>> parse_eds_text(std::string_view text, const std::string& label,
                                                     Problems& problems) {
  return Parser{label, problems}.run(text);
}

const EdsObject* find_eds_object(std::span<const EdsObject> objects, cia402::ObjectId id) noexcept {
  const auto it = std::find_if(objects.begin(), objects.end(), [id](const EdsObject& o) { return o.id == id; });
  return it == objects.end() ? nullptr : &*it;
}

const EdsObject* find_eds_object(std::span<const EdsObject> objects, std::string_view name) noexcept {
  const EdsObject* found = nullptr;
  int matches = 0;
  for (const auto& o : objects)
    if (same_text(o.name, name)) {
      found = &o;
      ++matches;
    }
  if (matches == 1) return found;
  if (matches > 1) return nullptr;
  // "PARENT.NAME": the parent's name may itself contain dots, so try every split.
  for (std::size_t dot = name.find('.'); dot != std::string_view::npos; dot = name.find('.', dot + 1)) {
    for (const auto& o : objects)
      if (!o.parent.empty() && same_text(o.parent, name.substr(0, dot)) && same_text(o.name, name.substr(dot + 1))) {
        found = &o;
        ++matches;
      }
  }
  return matches == 1 ? found : nullptr;
}

std::string eds_type_name(std::uint16_t data_type) {
  if (const TypeInfo* t = type_info(data_type)) return t->name;
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%04X", data_type);
  return buf;
}

std::optional<std::uint8_t> eds_type_bits(std::uint16_t data_type) noexcept {
  const TypeInfo* t = type_info(data_type);
  if (!t || t->bits == 0) return std::nullopt;
  return t->bits;
}

std::optional<cia402::DataType> eds_integer_type(std::uint16_t data_type) noexcept {
  switch (data_type) {  // CiA 301 §7.4.7.1
    case 0x0001: return cia402::DataType::U8;  // BOOLEAN
    case 0x0002: return cia402::DataType::I8;
    case 0x0003: return cia402::DataType::I16;
    case 0x0004: return cia402::DataType::I32;
    case 0x0005: return cia402::DataType::U8;
    case 0x0006: return cia402::DataType::U16;
    case 0x0007: return cia402::DataType::U32;
    default: return std::nullopt;
  }
}

std::string_view to_string(EdsAccess access) noexcept {
  switch (access) {
    case EdsAccess::ReadOnly: return "ro";
    case EdsAccess::WriteOnly: return "wo";
    case EdsAccess::ReadWrite: return "rw";
    case EdsAccess::ReadWriteRead: return "rwr";
    case EdsAccess::ReadWriteWrite: return "rww";
    case EdsAccess::Const: return "const";
  }
  return "?";
}

}  // namespace drivegate::config
