#include "config/canopen/eds.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <set>
#include <utility>

#include "config/text_util.hpp"
#include "config/yaml_reader.hpp"

namespace drivegate::config {

namespace {

struct TypeInfo {
  std::uint16_t code;
  const char* name;
  std::uint8_t bits;  // 0: not fixed-size
  EdsTypeKind kind;
};

// CiA 301 §7.4.7.1 static data types and §7.4.7.2 complex data types. 0x000E, 0x0017 and
// 0x001C..0x001F are reserved.
using K = EdsTypeKind;
constexpr std::array<TypeInfo, 29> kTypes{{
    {0x0001, "BOOLEAN", 8, K::Boolean},
    {0x0002, "INTEGER8", 8, K::SignedInteger},
    {0x0003, "INTEGER16", 16, K::SignedInteger},
    {0x0004, "INTEGER32", 32, K::SignedInteger},
    {0x0005, "UNSIGNED8", 8, K::UnsignedInteger},
    {0x0006, "UNSIGNED16", 16, K::UnsignedInteger},
    {0x0007, "UNSIGNED32", 32, K::UnsignedInteger},
    {0x0008, "REAL32", 32, K::Real},
    {0x0009, "VISIBLE_STRING", 0, K::String},
    {0x000A, "OCTET_STRING", 0, K::String},
    {0x000B, "UNICODE_STRING", 0, K::String},
    {0x000C, "TIME_OF_DAY", 48, K::Time},
    {0x000D, "TIME_DIFFERENCE", 48, K::Time},
    {0x000F, "DOMAIN", 0, K::Domain},
    {0x0010, "INTEGER24", 24, K::SignedInteger},
    {0x0011, "REAL64", 64, K::Real},
    {0x0012, "INTEGER40", 40, K::SignedInteger},
    {0x0013, "INTEGER48", 48, K::SignedInteger},
    {0x0014, "INTEGER56", 56, K::SignedInteger},
    {0x0015, "INTEGER64", 64, K::SignedInteger},
    {0x0016, "UNSIGNED24", 24, K::UnsignedInteger},
    {0x0018, "UNSIGNED40", 40, K::UnsignedInteger},
    {0x0019, "UNSIGNED48", 48, K::UnsignedInteger},
    {0x001A, "UNSIGNED56", 56, K::UnsignedInteger},
    {0x001B, "UNSIGNED64", 64, K::UnsignedInteger},
    {0x0020, "PDO_COMMUNICATION_PARAMETER", 0, K::Complex},
    {0x0021, "PDO_MAPPING", 0, K::Complex},
    {0x0022, "SDO_PARAMETER", 0, K::Complex},
    {0x0023, "IDENTITY", 0, K::Complex},
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

bool same_text(std::string_view a, std::string_view b) noexcept {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
         });
}

// Position of `needle` (lower-case) in `s`, ignoring ASCII case.
std::size_t find_ci(std::string_view s, std::string_view needle) noexcept {
  if (needle.size() > s.size()) return std::string_view::npos;
  for (std::size_t i = 0; i + needle.size() <= s.size(); ++i)
    if (same_text(s.substr(i, needle.size()), needle)) return i;
  return std::string_view::npos;
}

// 1..4 hex digits, no prefix (section names).
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

std::string hex4(std::uint16_t v) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "%04X", v);
  return buf;
}

constexpr auto kInt64Max = static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max());

// The one representation of a non-negative integer (EdsNumber::value).
std::variant<std::int64_t, std::uint64_t, double> canonical(std::uint64_t u) noexcept {
  if (u <= kInt64Max) return static_cast<std::int64_t>(u);
  return u;
}

// One number without $NODEID.
struct Term {
  std::variant<std::int64_t, std::uint64_t, double> value{std::int64_t{0}};
  bool radix = false;      // written in hex or octal (two's complement applies)
  bool not_octal = false;  // a leading 0 with digits 8 or 9: read as decimal
};

std::optional<Term> parse_term(std::string_view s) noexcept {
  s = trim(s);
  bool negative = false;
  if (!s.empty() && (s.front() == '+' || s.front() == '-')) {
    negative = s.front() == '-';
    s = trim(s.substr(1));  // "$NODEID + 0x180" leaves "+ 0x180"
  }
  if (s.empty() || s.front() == '+' || s.front() == '-') return std::nullopt;
  Term t;
  int base = 10;
  std::string_view digits = s;
  const auto is_digit = [](char c) { return c >= '0' && c <= '9'; };
  if (s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X')) {
    base = 16;
    digits = s.substr(2);
    t.radix = true;
  } else if (s.size() > 1 && s[0] == '0' && std::all_of(s.begin(), s.end(), is_digit)) {
    // CiA 306 §4.4.1 (like C): a leading 0 means octal.
    if (std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '7'; })) {
      base = 8;
      digits = s.substr(1);
      t.radix = true;
    } else {
      t.not_octal = true;
    }
  }
  std::uint64_t magnitude = 0;
  const char* const end = digits.data() + digits.size();
  const auto [stop, ec] = std::from_chars(digits.data(), end, magnitude, base);
  if (ec == std::errc{} && stop == end) {
    if (!negative) {
      t.value = canonical(magnitude);
    } else if (magnitude <= kInt64Max) {
      t.value = -static_cast<std::int64_t>(magnitude);
    } else if (magnitude == kInt64Max + 1) {
      t.value = std::numeric_limits<std::int64_t>::min();
    } else {
      return std::nullopt;
    }
    return t;
  }
  // Beyond 64 bits, or hex that is not an integer: nothing CiA 306 writes.
  if (base != 10 || ec == std::errc::result_out_of_range) return std::nullopt;
  // A REAL: digits with a point or an exponent ("4.5", "-1e3", ".5"); not "inf" or "nan".
  if (s.find_first_of(".eE") == std::string_view::npos || (!is_digit(s.front()) && s.front() != '.'))
    return std::nullopt;
  double d = 0;
  const auto [rstop, rec] = std::from_chars(s.data(), s.data() + s.size(), d);
  if (rec != std::errc{} || rstop != s.data() + s.size() || !std::isfinite(d)) return std::nullopt;
  t.value = negative ? -d : d;
  t.radix = false;
  t.not_octal = false;
  return t;
}

struct ParsedNumber {
  EdsNumber number;
  bool not_octal = false;
};

std::optional<ParsedNumber> parse_number(std::string_view text, std::uint16_t data_type) noexcept {
  text = trim(text);
  ParsedNumber p;
  std::string_view term = text;
  constexpr std::string_view kNodeId = "$nodeid";
  if (const auto at = find_ci(text, kNodeId); at != std::string_view::npos) {
    if (find_ci(text.substr(at + kNodeId.size()), kNodeId) != std::string_view::npos) return std::nullopt;
    const std::string_view before = trim(text.substr(0, at));
    const std::string_view after = trim(text.substr(at + kNodeId.size()));
    p.number.plus_node_id = true;
    if (before.empty() && after.empty()) return p;  // "$NODEID"
    if (!before.empty() && !after.empty()) return std::nullopt;
    if (!before.empty()) {  // "0x180+$NODEID"
      if (before.back() != '+') return std::nullopt;
      term = before.substr(0, before.size() - 1);
    } else {  // "$NODEID+0x180" (or "-5"): the sign is the term's own
      if (after.front() != '+' && after.front() != '-') return std::nullopt;
      term = after;
    }
  }
  const auto t = parse_term(term);
  if (!t || (p.number.plus_node_id && std::holds_alternative<double>(t->value))) return std::nullopt;
  p.number.value = t->value;
  p.not_octal = t->not_octal;
  // Hex and octal values of signed types are the stored bits: the sign bit makes them negative.
  const TypeInfo* info = type_info(data_type);
  if (t->radix && !p.number.plus_node_id && info && info->kind == EdsTypeKind::SignedInteger) {
    std::optional<std::uint64_t> bits_value;
    if (const auto* i = std::get_if<std::int64_t>(&t->value); i && *i >= 0) bits_value = static_cast<std::uint64_t>(*i);
    if (const auto* u = std::get_if<std::uint64_t>(&t->value)) bits_value = *u;
    if (bits_value) {
      const unsigned bits = info->bits;
      if (bits == 64) {
        if (*bits_value > kInt64Max) p.number.value = static_cast<std::int64_t>(*bits_value);
      } else {
        const std::uint64_t top = std::uint64_t{1} << bits;
        if (*bits_value >= top / 2 && *bits_value < top)
          p.number.value = static_cast<std::int64_t>(*bits_value) - static_cast<std::int64_t>(top);
      }
    }
  }
  return p;
}

// What a section is, from its name.
enum class SectionKind {
  Object,       // [6040]
  Sub,          // [6040sub1]
  Names,        // [1003Name]: CompactSubObj names
  Values,       // [1003Value]: CompactSubObj defaults
  Denotations,  // [1003Denotation] (DCF)
  ObjectLinks,  // [6040ObjectLinks]
  DummyUsage,   // [DummyUsage]
  Other,        // another CiA 306 section: read past
  Unknown,      // not CiA 306: read past, with a warning
  Broken,       // [6045subZZ]: its lines are ignored
};

SectionKind classify(std::string_view name, std::uint16_t& index, std::uint8_t& sub) {
  const std::string l = lower(name);
  if (l.size() >= 4) {
    if (const auto ix = parse_hex(std::string_view{l}.substr(0, 4))) {
      index = static_cast<std::uint16_t>(*ix);
      const std::string_view rest = std::string_view{l}.substr(4);
      if (rest.empty()) return SectionKind::Object;
      if (rest.starts_with("sub")) {
        const auto s = parse_hex(trim(rest.substr(3)));
        if (!s || *s > 0xFF) return SectionKind::Broken;
        sub = static_cast<std::uint8_t>(*s);
        return SectionKind::Sub;
      }
      if (rest == "name") return SectionKind::Names;
      if (rest == "value") return SectionKind::Values;
      if (rest == "denotation") return SectionKind::Denotations;
      if (rest == "objectlinks") return SectionKind::ObjectLinks;
      return SectionKind::Unknown;
    }
  }
  if (l == "dummyusage") return SectionKind::DummyUsage;
  static const std::set<std::string, std::less<>> kOther{
      "fileinfo",           "deviceinfo",          "comments",   "mandatoryobjects", "optionalobjects",
      "manufacturerobjects", "devicecomissioning", "devicecommissioning", "tools", "supportedmodules",
      "dynamicchannels"};
  if (kOther.contains(l)) return SectionKind::Other;
  const auto digits_after = [&l](std::size_t from) {
    return l.size() > from && std::isdigit(static_cast<unsigned char>(l[from])) != 0;
  };
  // [Tool1], [DynamicChannels1], and the modular-device sections [M1ModuleInfo], [M1FixedObjects], ...
  if ((l.starts_with("tool") && digits_after(4)) || (l.starts_with("dynamicchannels") && digits_after(15)) ||
      (l.starts_with("m") && digits_after(1)))
    return SectionKind::Other;
  return SectionKind::Unknown;
}

struct KeyValue {
  std::string key;  // as written
  std::string value;
  int line = 0;
};

struct RawSection {
  std::string name;  // as written, for messages
  int line = 0;
  SectionKind kind = SectionKind::Unknown;
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  std::map<std::string, KeyValue> keys;  // lower-case key
  bool used = false;                     // a [XXXXName]/[XXXXValue] an ARRAY read
};

// Keys of an object or sub-index section [CiA 306 §4.6.3, §4.6.6, §4.6.7; DCF and CiA 304 keys].
const std::map<std::string, std::string, std::less<>>& known_keys() {
  static const std::map<std::string, std::string, std::less<>> kKeys{
      {"parametername", "ParameterName"}, {"objecttype", "ObjectType"},   {"datatype", "DataType"},
      {"accesstype", "AccessType"},       {"defaultvalue", "DefaultValue"}, {"pdomapping", "PDOMapping"},
      {"subnumber", "SubNumber"},         {"compactsubobj", "CompactSubObj"}, {"lowlimit", "LowLimit"},
      {"highlimit", "HighLimit"},         {"objflags", "ObjFlags"},       {"parametervalue", "ParameterValue"},
      {"denotation", "Denotation"},       {"uploadfile", "UploadFile"},   {"downloadfile", "DownloadFile"},
      {"srdomapping", "SRDOMapping"},     {"invertedsrad", "InvertedSRAD"}};
  return kKeys;
}

// A numeric field may carry a trailing "; comment" in files of some tools.
std::string_view numeric_text(std::string_view value) noexcept {
  return trim(value.substr(0, value.find(';')));
}

constexpr const char* kNumberForms = "decimal, 0x hex or octal";

class Parser {
 public:
  Parser(std::string label, Problems& problems) : label_(std::move(label)), problems_(problems) {}

  std::optional<EdsDictionary> run(std::string_view text) {
    split_sections(text);
    index_sections();
    for (std::size_t i = 0; i < sections_.size(); ++i) {
      switch (sections_[i].kind) {
        case SectionKind::Object: build_object(sections_[i]); break;
        case SectionKind::Sub: build_sub(sections_[i]); break;
        case SectionKind::DummyUsage: check_dummy_usage(sections_[i]); break;
        default: break;
      }
    }
    for (const auto& [section, entries] : compact_) build_compact(sections_[section], entries);
    for (const auto& s : sections_)
      if ((s.kind == SectionKind::Names || s.kind == SectionKind::Values) && !s.used)
        warn(s.line, "[" + s.name + "]",
             "ignored: object " + hex4(s.index) + "h is not an ARRAY with CompactSubObj (CiA 306 §4.6.7)");
    return finish();
  }

 private:
  Diagnostic diagnostic(int line, std::string path, std::string message) const {
    Diagnostic d;
    d.file = label_;
    d.line = line;
    d.column = 1;
    d.path = std::move(path);
    d.message = std::move(message);
    return d;
  }

  void warn(int line, std::string path, std::string message) {
    warnings_.push_back(diagnostic(line, std::move(path), std::move(message)));
  }

  void skip(cia402::ObjectId id, bool whole_index, int line, std::string reason) {
    skipped_.push_back(EdsSkipped{id, whole_index, line, std::move(reason)});
  }

  std::optional<EdsDictionary> finish() {
    for (const auto& [key, seen] : unknown_keys_)
      if (seen.more > 0)
        warnings_[seen.warning].message += " (also in " + std::to_string(seen.more) + " more section" +
                                           (seen.more == 1 ? "" : "s") + ")";
    std::stable_sort(warnings_.begin(), warnings_.end(),
                     [](const Diagnostic& a, const Diagnostic& b) { return a.line < b.line; });
    if (objects_.empty()) {
      // Nothing to go on: the file is not an EDS (or every object in it is unusable). Its warnings
      // say why, so they become errors: a refused load shows errors only.
      for (auto& w : warnings_) problems_.error(std::move(w));
      problems_.error(diagnostic(0, "", "lists no usable object" +
                                            (skipped_.empty() ? std::string{}
                                                              : " (" + std::to_string(skipped_.size()) +
                                                                    " skipped, see above)") +
                                            "; is it a CiA 306 EDS file?"));
      return std::nullopt;
    }
    for (std::size_t i = 0; i < warnings_.size() && i < kMaxEdsWarnings; ++i) problems_.warning(std::move(warnings_[i]));
    if (warnings_.size() > kMaxEdsWarnings)
      problems_.warning(diagnostic(0, "", std::to_string(warnings_.size() - kMaxEdsWarnings) +
                                              " more warnings about this file not shown"));
    EdsDictionary out;
    out.objects = std::move(objects_);
    std::sort(out.objects.begin(), out.objects.end(),
              [](const EdsObject& a, const EdsObject& b) { return a.id.key() < b.id.key(); });
    out.skipped = std::move(skipped_);
    return out;
  }

  // Lines end in LF, CRLF or CR; a UTF-8 byte order mark is dropped.
  void split_sections(std::string_view text) {
    if (text.starts_with("\xEF\xBB\xBF")) text.remove_prefix(3);
    constexpr std::size_t kNone = static_cast<std::size_t>(-1);
    std::size_t current = kNone;
    bool after_broken_header = false;  // its lines are ignored without a warning each
    std::map<std::string, std::size_t> by_name;  // lower-case section name -> sections_ position
    int line_no = 0;
    while (!text.empty()) {
      const auto end = text.find_first_of("\r\n");
      const std::string_view raw = text.substr(0, end);
      if (end == std::string_view::npos) {
        text = {};
      } else {
        text.remove_prefix(end + (text[end] == '\r' && end + 1 < text.size() && text[end + 1] == '\n' ? 2 : 1));
      }
      ++line_no;
      const std::string_view line = trim(raw);
      if (line.empty() || line.front() == ';' || line.front() == '#') continue;
      if (line.front() == '[') {
        current = kNone;
        after_broken_header = true;
        const auto close = line.find(']');
        if (close == std::string_view::npos) {
          warn(line_no, "", "section header without ']': " + in_quotes(line) + "; its lines are ignored");
          continue;
        }
        const std::string name{trim(line.substr(1, close - 1))};
        if (const auto rest = trim(line.substr(close + 1)); !rest.empty() && rest.front() != ';')
          warn(line_no, "[" + name + "]", "text after ']' ignored: " + in_quotes(rest));
        if (name.empty()) {
          warn(line_no, "", "section header without a name; its lines are ignored");
          continue;
        }
        const auto [it, added] = by_name.emplace(lower(name), sections_.size());
        if (!added) {
          RawSection& first = sections_[it->second];
          if (first.kind == SectionKind::Broken) continue;
          warn(line_no, "[" + name + "]",
               "section given twice (first at line " + std::to_string(first.line) +
                   "); its keys are merged into the first, later values win");
          current = it->second;
          after_broken_header = false;
          continue;
        }
        RawSection s;
        s.name = name;
        s.line = line_no;
        s.kind = classify(name, s.index, s.sub);
        if (s.kind == SectionKind::Broken) {
          warn(line_no, "[" + name + "]", "sub-index must be hex 0..FF (as in [1018sub1]); the section is ignored");
          skip({s.index, 0}, true, line_no, "its sub-index is not hex 0..FF");
        } else if (s.kind == SectionKind::Unknown) {
          warn(line_no, "[" + name + "]", "unknown section, ignored");
        }
        sections_.push_back(std::move(s));
        if (sections_.back().kind != SectionKind::Broken) {
          current = sections_.size() - 1;
          after_broken_header = false;
        }
        continue;
      }
      if (current == kNone) {
        if (!after_broken_header) warn(line_no, "", "text before the first section, ignored: " + in_quotes(line));
        continue;
      }
      RawSection& s = sections_[current];
      const auto eq = line.find('=');
      if (eq == std::string_view::npos) {
        warn(line_no, "[" + s.name + "]", "expected KEY=VALUE, got " + in_quotes(line) + "; ignored");
        continue;
      }
      const std::string key{trim(line.substr(0, eq))};
      const std::string value{trim(line.substr(eq + 1))};
      if (key.empty()) {
        warn(line_no, "[" + s.name + "]", "a line without a key before '=', ignored: " + in_quotes(line));
        continue;
      }
      const auto [kit, kadded] = s.keys.try_emplace(lower(key), KeyValue{key, value, line_no});
      if (!kadded) {
        warn(line_no, "[" + s.name + "]." + key_label(kit->first, key),
             "given twice (first at line " + std::to_string(kit->second.line) + "); the later value " +
                 in_quotes(value) + " wins");
        kit->second = KeyValue{key, value, line_no};
      }
    }
  }

  void index_sections() {
    for (std::size_t i = 0; i < sections_.size(); ++i) {
      const RawSection& s = sections_[i];
      switch (s.kind) {
        case SectionKind::Object: mains_.emplace(s.index, i); break;
        case SectionKind::Sub: ++sub_count_[s.index]; break;
        case SectionKind::Names: names_.emplace(s.index, i); break;
        case SectionKind::Values: values_.emplace(s.index, i); break;
        default: break;
      }
    }
  }

  static std::string key_label(const std::string& lower_key, const std::string& written) {
    const auto& known = known_keys();
    const auto it = known.find(lower_key);
    return it == known.end() ? written : it->second;
  }

  static std::string where(const RawSection& s) { return "[" + s.name + "]"; }
  static std::string where(const RawSection& s, const KeyValue& kv) {
    return "[" + s.name + "]." + key_label(lower(kv.key), kv.key);
  }

  // The key's line when it is given with a non-empty value; an empty value counts as left out.
  static const KeyValue* field(const RawSection& s, const std::string& key) {
    const auto it = s.keys.find(key);
    return it == s.keys.end() || it->second.value.empty() ? nullptr : &it->second;
  }

  // A number as any numeric field is written; a note when a leading 0 was read as decimal.
  std::optional<EdsNumber> number(const RawSection& s, const KeyValue& kv, std::uint16_t data_type = 0) {
    const auto p = parse_number(numeric_text(kv.value), data_type);
    if (p && p->not_octal)
      warn(kv.line, where(s, kv),
           in_quotes(numeric_text(kv.value)) + " starts with 0, which CiA 306 reads as octal, but is not octal; "
                                               "read as decimal");
    if (!p) return std::nullopt;
    return p->number;
  }

  // A plain integer field (ObjectType, DataType, SubNumber, ...): nullopt, without a warning, when
  // it is not one; the caller says what follows.
  std::optional<std::int64_t> integer(const RawSection& s, const KeyValue& kv) {
    const auto n = number(s, kv);
    if (!n || n->plus_node_id) return std::nullopt;
    return n->as_int64();
  }

  void check_keys(const RawSection& s) {
    const auto& known = known_keys();
    for (const auto& [key, kv] : s.keys) {
      if (known.contains(key)) continue;
      const auto [it, added] = unknown_keys_.try_emplace(key, UnknownKey{warnings_.size(), 0});
      if (added)
        warn(kv.line, "[" + s.name + "]." + kv.key, "unknown key, ignored");
      else
        ++it->second.more;
    }
  }

  void check_numeric(const RawSection& s, const std::string& key) {
    if (const KeyValue* kv = field(s, key); kv && !integer(s, *kv))
      warn(kv->line, where(s, *kv), std::string{"must be a number ("} + kNumberForms + "), got " + in_quotes(kv->value) +
                                        "; ignored");
  }

  // ObjectType [CiA 301 §7.4.3]: 0x0 NULL, 0x2 DOMAIN, 0x5 DEFTYPE, 0x6 DEFSTRUCT, 0x7 VAR (the
  // default), 0x8 ARRAY, 0x9 RECORD; nullopt (with a warning) for anything else.
  std::optional<std::int64_t> object_type(const RawSection& s, const char* consequence) {
    const KeyValue* kv = field(s, "objecttype");
    if (!kv) return 0x7;
    const auto v = integer(s, *kv);
    if (v && (*v == 0x0 || *v == 0x2 || *v == 0x5 || *v == 0x6 || *v == 0x7 || *v == 0x8 || *v == 0x9)) return v;
    warn(kv->line, where(s, *kv),
         "must be 0x7 (VAR), 0x8 (ARRAY), 0x9 (RECORD), 0x2 (DOMAIN), 0x0, 0x5 or 0x6, got " + in_quotes(kv->value) +
             "; " + consequence);
    return std::nullopt;
  }

  void build_object(const RawSection& s) {
    check_keys(s);
    check_numeric(s, "objflags");
    const auto type = object_type(s, "the object is skipped");
    if (!type) {
      skip({s.index, 0}, false, s.line, "ObjectType " + in_quotes(field(s, "objecttype")->value) + " is unknown");
      return;
    }
    std::optional<std::int64_t> sub_number;
    if (const KeyValue* kv = field(s, "subnumber")) {
      sub_number = integer(s, *kv);
      if (!sub_number)
        warn(kv->line, where(s, *kv), std::string{"must be a number ("} + kNumberForms + "), got " +
                                          in_quotes(kv->value) + "; ignored");
    }
    std::int64_t compact = 0;
    const KeyValue* compact_kv = field(s, "compactsubobj");
    if (compact_kv) {
      if (const auto v = integer(s, *compact_kv)) {
        compact = *v;
      } else {
        warn(compact_kv->line, where(s, *compact_kv), std::string{"must be a number ("} + kNumberForms + "), got " +
                                                          in_quotes(compact_kv->value) + "; ignored");
      }
    }
    if (*type == 0x0 || *type == 0x5 || *type == 0x6) return;  // type definitions: no accessible object
    if (*type == 0x8 || *type == 0x9) {
      if (compact != 0) {
        if (*type == 0x9) {
          warn(compact_kv->line, where(s, *compact_kv), "is for ARRAYs (0x8) only, ignored on a RECORD");
        } else if (compact < 1 || compact > 0xFE) {
          // Sub-indices 1..N next to sub-index 0: N = 0xFF would need sub-index 0 to hold 255 and
          // leave no room for CiA 301's 0xFF; more is impossible.
          warn(compact_kv->line, where(s, *compact_kv),
               "must be 1..254 entries, got " + in_quotes(compact_kv->value) + "; the sub-indices are not created");
          skip({s.index, 0}, true, s.line, "CompactSubObj " + in_quotes(compact_kv->value) + " is out of range");
        } else {
          compact_.emplace_back(static_cast<std::size_t>(&s - sections_.data()), static_cast<int>(compact));
          return;
        }
      }
      const auto it = sub_count_.find(s.index);
      const int subs = it == sub_count_.end() ? 0 : it->second;
      if (sub_number && *sub_number != subs)
        warn(field(s, "subnumber")->line, where(s, *field(s, "subnumber")),
             "is " + std::to_string(*sub_number) + " but the file has " + std::to_string(subs) + " [" + hex4(s.index) +
                 "subN] sections");
      return;  // the accessible entries are its sub-index sections
    }
    if (auto o = entry(s, {s.index, 0}, "", *type == 0x2, false, "the object is skipped")) add(std::move(*o), s);
  }

  void build_sub(const RawSection& s) {
    check_keys(s);
    check_numeric(s, "objflags");
    std::string parent;
    const auto main = mains_.find(s.index);
    if (main == mains_.end()) {
      warn(s.line, where(s),
           "sub-index without its object: there is no [" + hex4(s.index) + "] section; kept without a parent");
    } else if (const KeyValue* pn = field(sections_[main->second], "parametername")) {
      parent = pn->value;
    }
    bool domain = false;
    if (const KeyValue* kv = field(s, "objecttype")) {
      const auto v = integer(s, *kv);
      domain = v == 0x2;
      if (!v || (*v != 0x7 && *v != 0x2))
        warn(kv->line, where(s, *kv), "a sub-index is a VAR (0x7), got " + in_quotes(kv->value) + "; read as one");
    }
    if (auto o = entry(s, {s.index, s.sub}, parent, domain, false, "the sub-index is skipped")) add(std::move(*o), s);
  }

  // The entry a VAR section (or an ARRAY's CompactSubObj template) describes; nullopt, with a
  // warning naming the key, when its DataType or AccessType is missing or unusable: the checks
  // depend on both, and guessing could pass a PDO map the drive refuses at boot.
  std::optional<EdsObject> entry(const RawSection& s, cia402::ObjectId id, const std::string& parent, bool domain,
                                 bool whole_index, const char* consequence) {
    EdsObject o;
    o.id = id;
    o.parent = parent;
    o.line = s.line;
    if (const KeyValue* n = field(s, "parametername"))
      o.name = n->value;
    else
      warn(s.line, where(s) + ".ParameterName", "missing; the object cannot be found by name");

    // Both are checked before giving up, so that one run names every missing key.
    std::optional<std::string> unusable;
    if (const KeyValue* dt = field(s, "datatype")) {
      const auto v = integer(s, *dt);
      if (!v || *v < 0 || *v > 0xFFFF) {
        warn(dt->line, where(s, *dt),
             "must be a CiA 301 data type code such as 0x0007 (UNSIGNED32) or a vendor type 0x0040..0x005F, got " +
                 in_quotes(dt->value) + "; " + consequence);
        unusable = "DataType " + in_quotes(dt->value) + " is not a data type code";
      } else {
        o.data_type = static_cast<std::uint16_t>(*v);
      }
    } else if (domain) {
      o.data_type = 0x000F;  // a DOMAIN object's type goes without saying
    } else {
      warn(s.line, where(s) + ".DataType", std::string{"missing; "} + consequence);
      unusable = "DataType is missing";
    }

    static const std::map<std::string, EdsAccess, std::less<>> kAccess{
        {"ro", EdsAccess::ReadOnly},       {"wo", EdsAccess::WriteOnly},       {"rw", EdsAccess::ReadWrite},
        {"rwr", EdsAccess::ReadWriteRead}, {"rww", EdsAccess::ReadWriteWrite}, {"const", EdsAccess::Const}};
    if (const KeyValue* at = field(s, "accesstype")) {
      if (const auto access = kAccess.find(lower(at->value)); access != kAccess.end()) {
        o.access = access->second;
      } else {
        warn(at->line, where(s, *at),
             "must be one of ro, wo, rw, rwr, rww, const, got " + in_quotes(at->value) + "; " + consequence);
        if (!unusable) unusable = "AccessType " + in_quotes(at->value) + " is unknown";
      }
    } else {
      warn(s.line, where(s) + ".AccessType", std::string{"missing; "} + consequence);
      if (!unusable) unusable = "AccessType is missing";
    }
    if (unusable) {
      skip(id, whole_index, s.line, std::move(*unusable));
      return std::nullopt;
    }

    if (const KeyValue* pm = field(s, "pdomapping")) o.pdo_mapping = pdo_mapping(s, *pm);

    if (const auto it = s.keys.find("defaultvalue"); it != s.keys.end()) {
      o.default_value = it->second.value;
      const auto kind = eds_type_kind(o.data_type);
      const bool numeric = kind == EdsTypeKind::Boolean || kind == EdsTypeKind::SignedInteger ||
                           kind == EdsTypeKind::UnsignedInteger || kind == EdsTypeKind::Real;
      if (numeric && !o.default_value.empty() && !number(s, it->second, o.data_type))
        warn(it->second.line, where(s, it->second),
             "is not a number, which a " + eds_type_name(o.data_type) + " object needs: " +
                 in_quotes(o.default_value) + "; kept as written");
    }

    o.low_limit = limit(s, "lowlimit", o.data_type);
    o.high_limit = limit(s, "highlimit", o.data_type);
    if (o.low_limit && o.high_limit && compare(o.low_limit->value, o.high_limit->value) == std::partial_ordering::greater)
      warn(field(s, "lowlimit")->line, where(s) + ".LowLimit",
           "is above HighLimit (" + o.high_limit->text + "): " + o.low_limit->text + "; both are kept as written");
    return o;
  }

  // PDOMapping is 0 or 1 [CiA 306 §4.6.3]; other values are read as what they most likely mean.
  bool pdo_mapping(const RawSection& s, const KeyValue& kv) {
    if (const auto v = integer(s, kv)) {
      if (*v == 0 || *v == 1) return *v == 1;
      warn(kv.line, where(s, kv), "should be 0 or 1, got " + in_quotes(kv.value) + "; read as 1 (mappable)");
      return true;
    }
    const std::string l = lower(kv.value);
    if (l == "yes" || l == "true" || l == "on") {
      warn(kv.line, where(s, kv), "should be 0 or 1, got " + in_quotes(kv.value) + "; read as 1 (mappable)");
      return true;
    }
    // Not mappable is the safe reading: a device mapping the object is then refused at load
    // rather than by the drive at boot.
    warn(kv.line, where(s, kv), "should be 0 or 1, got " + in_quotes(kv.value) + "; read as 0 (not mappable)");
    return false;
  }

  std::optional<EdsLimit> limit(const RawSection& s, const std::string& key, std::uint16_t data_type) {
    const KeyValue* kv = field(s, key);
    if (!kv) return std::nullopt;
    const auto n = number(s, *kv, data_type);
    if (!n) {
      warn(kv->line, where(s, *kv),
           std::string{"must be a number ("} + kNumberForms + ", a REAL such as 4.5, or $NODEID+X), got " +
               in_quotes(kv->value) + "; ignored");
      return std::nullopt;
    }
    return EdsLimit{std::string{numeric_text(kv->value)}, *n};
  }

  // Each index and sub-index once: the first section wins.
  void add(EdsObject o, const RawSection& s) {
    const auto [it, added] = taken_.emplace(o.id.key(), s.line);
    if (!added) {
      warn(s.line, where(s),
           "describes " + hex4(o.id.index) + "h sub-index " + std::to_string(o.id.sub) + " again (first at line " +
               std::to_string(it->second) + "); ignored");
      return;
    }
    objects_.push_back(std::move(o));
  }

  // CompactSubObj=N [CiA 306 §4.6.7]: sub-index 0 "NrOfEntries" (UNSIGNED8, ro, default N) and
  // sub-indices 1..N with the ARRAY's DataType, AccessType, PDOMapping, limits and DefaultValue,
  // named "<ParameterName><i>" unless [XXXXName] names them, their defaults from [XXXXValue].
  void build_compact(const RawSection& s, int entries) {
    const auto tmpl = entry(s, {s.index, 1}, "", false, true, "the CompactSubObj sub-indices are not created");
    const auto names = compact_list(names_, s.index, entries);
    const auto values = compact_list(values_, s.index, entries);
    if (!tmpl) return;
    const KeyValue* compact_kv = field(s, "compactsubobj");
    const auto place = [&](EdsObject o) {
      const auto [it, added] = taken_.emplace(o.id.key(), s.line);
      if (!added) {
        warn(compact_kv->line, where(s, *compact_kv),
             "sub-index " + std::to_string(o.id.sub) + " is also given by a section at line " +
                 std::to_string(it->second) + ", which is used");
        return;
      }
      objects_.push_back(std::move(o));
    };
    EdsObject count;
    count.id = {s.index, 0};
    count.name = "NrOfEntries";
    count.parent = tmpl->name;
    count.data_type = 0x0005;
    count.access = EdsAccess::ReadOnly;
    count.default_value = std::to_string(entries);
    count.line = s.line;
    place(std::move(count));
    for (int i = 1; i <= entries; ++i) {
      EdsObject o = *tmpl;
      o.id.sub = static_cast<std::uint8_t>(i);
      o.parent = tmpl->name;
      const auto n = names.find(i);
      o.name = n != names.end() ? n->second : tmpl->name + std::to_string(i);
      if (const auto v = values.find(i); v != values.end()) o.default_value = v->second;
      place(std::move(o));
    }
  }

  // The "i=TEXT" lines of [XXXXName] / [XXXXValue] for sub-indices 1..entries.
  std::map<int, std::string> compact_list(const std::map<std::uint16_t, std::size_t>& sections, std::uint16_t index,
                                          int entries) {
    std::map<int, std::string> out;
    const auto found = sections.find(index);
    if (found == sections.end()) return out;
    RawSection& s = sections_[found->second];
    s.used = true;
    std::vector<const KeyValue*> lines;  // in file order, so that "the first" is the first written
    for (const auto& [key, kv] : s.keys)
      if (key != "nrofentries") lines.push_back(&kv);
    std::sort(lines.begin(), lines.end(), [](const KeyValue* a, const KeyValue* b) { return a->line < b->line; });
    std::map<int, int> first_line;
    for (const KeyValue* line : lines) {
      const KeyValue& kv = *line;
      const auto v = parse_number(kv.key, 0);
      const auto sub = v && !v->number.plus_node_id ? v->number.as_int64() : std::nullopt;
      if (!sub) {
        warn(kv.line, "[" + s.name + "]." + kv.key, "unknown key, ignored (expected NrOfEntries or a sub-index 1.." +
                                                        std::to_string(entries) + ")");
      } else if (*sub < 1 || *sub > entries) {
        warn(kv.line, "[" + s.name + "]." + kv.key,
             "CompactSubObj=" + std::to_string(entries) + " has no sub-index " + std::to_string(*sub) + "; ignored");
      } else if (const auto [it, added] = first_line.emplace(static_cast<int>(*sub), kv.line); !added) {
        warn(kv.line, "[" + s.name + "]." + kv.key,
             "sub-index " + std::to_string(*sub) + " given twice (first at line " + std::to_string(it->second) +
                 "); the first wins");
      } else {
        out.emplace(static_cast<int>(*sub), kv.value);
      }
    }
    if (const KeyValue* n = field(s, "nrofentries")) {
      const auto v = integer(s, *n);
      if (!v)
        warn(n->line, "[" + s.name + "].NrOfEntries", std::string{"must be a number ("} + kNumberForms + "), got " +
                                                          in_quotes(n->value) + "; ignored");
      else if (*v != static_cast<std::int64_t>(out.size()))
        warn(n->line, "[" + s.name + "].NrOfEntries",
             "is " + std::to_string(*v) + " but " + std::to_string(out.size()) + " entries follow");
    }
    return out;
  }

  // [DummyUsage] Dummy0001..Dummy0007 = 0 or 1 [CiA 306 §4.5.3]: checked, not kept (no check here
  // needs the dummy objects).
  void check_dummy_usage(const RawSection& s) {
    for (const auto& [key, kv] : s.keys) {
      if (key.size() == 9 && key.starts_with("dummy") && parse_hex(std::string_view{key}.substr(5))) {
        const auto v = integer(s, kv);
        if (!v || (*v != 0 && *v != 1))
          warn(kv.line, "[" + s.name + "]." + kv.key, "should be 0 or 1, got " + in_quotes(kv.value) + "; ignored");
      } else {
        warn(kv.line, "[" + s.name + "]." + kv.key, "unknown key, ignored (expected Dummy0001..Dummy0007)");
      }
    }
  }

  struct UnknownKey {
    std::size_t warning;  // position in warnings_ of the first one's warning
    int more;
  };

  std::string label_;
  Problems& problems_;
  std::vector<RawSection> sections_;
  std::map<std::uint16_t, std::size_t> mains_;
  std::map<std::uint16_t, int> sub_count_;
  std::map<std::uint16_t, std::size_t> names_;
  std::map<std::uint16_t, std::size_t> values_;
  std::vector<std::pair<std::size_t, int>> compact_;  // ARRAY section, entries
  std::map<std::uint32_t, int> taken_;                // ObjectId::key() -> line of its section
  std::map<std::string, UnknownKey> unknown_keys_;
  std::vector<Diagnostic> warnings_;
  std::vector<EdsObject> objects_;
  std::vector<EdsSkipped> skipped_;
};

}  // namespace

std::optional<std::int64_t> EdsNumber::as_int64() const noexcept {
  if (const auto* i = std::get_if<std::int64_t>(&value)) return *i;
  return std::nullopt;
}

std::optional<std::uint64_t> EdsNumber::as_uint64() const noexcept {
  if (const auto* i = std::get_if<std::int64_t>(&value); i && *i >= 0) return static_cast<std::uint64_t>(*i);
  if (const auto* u = std::get_if<std::uint64_t>(&value)) return *u;
  return std::nullopt;
}

double EdsNumber::as_double() const noexcept {
  return std::visit([](auto v) { return static_cast<double>(v); }, value);
}

EdsNumber EdsNumber::for_node(std::uint8_t node_id) const noexcept {
  if (!plus_node_id) return *this;
  EdsNumber out;
  if (const auto* i = std::get_if<std::int64_t>(&value)) {
    if (*i >= 0)
      out.value = canonical(static_cast<std::uint64_t>(*i) + node_id);
    else
      out.value = *i + node_id;
  } else if (const auto* u = std::get_if<std::uint64_t>(&value)) {
    out.value = *u + node_id;  // above INT64_MAX already; wraps like the drive's arithmetic would
  } else {
    out.value = std::get<double>(value) + node_id;
  }
  return out;
}

std::partial_ordering compare(const EdsNumber& a, const EdsNumber& b) noexcept {
  if (a.plus_node_id != b.plus_node_id) return std::partial_ordering::unordered;
  if (a.is_real() || b.is_real()) return a.as_double() <=> b.as_double();
  return std::visit(
      [](auto x, auto y) -> std::partial_ordering {
        if constexpr (std::is_same_v<decltype(x), double> || std::is_same_v<decltype(y), double>) {
          return std::partial_ordering::unordered;  // handled above
        } else {
          if (std::cmp_less(x, y)) return std::partial_ordering::less;
          if (std::cmp_equal(x, y)) return std::partial_ordering::equivalent;
          return std::partial_ordering::greater;
        }
      },
      a.value, b.value);
}

std::optional<EdsNumber> parse_eds_number(std::string_view text, std::uint16_t data_type) noexcept {
  const auto p = parse_number(text, data_type);
  if (!p) return std::nullopt;
  return p->number;
}

std::optional<EdsDictionary> load_eds(const std::filesystem::path& file, Problems& problems) {
  const auto text = read_text_file(file.string(), Source{file.string(), &problems}, kMaxEdsBytes);
  if (!text) return std::nullopt;
  return load_eds_text(*text, file.string(), problems);
}

std::optional<EdsDictionary> load_eds_text(std::string_view text, const std::string& label, Problems& problems) {
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

const EdsSkipped* find_eds_skipped(std::span<const EdsSkipped> skipped, cia402::ObjectId id) noexcept {
  const auto it = std::find_if(skipped.begin(), skipped.end(), [id](const EdsSkipped& s) {
    return s.id == id || (s.whole_index && s.id.index == id.index);
  });
  return it == skipped.end() ? nullptr : &*it;
}

EdsTypeKind eds_type_kind(std::uint16_t data_type) noexcept {
  if (const TypeInfo* t = type_info(data_type)) return t->kind;
  if (data_type >= 0x0040 && data_type <= 0x005F) return EdsTypeKind::VendorDefined;
  if (data_type >= 0x0060 && data_type <= 0x025F) return EdsTypeKind::ProfileDefined;
  return EdsTypeKind::Unknown;
}

std::string eds_type_name(std::uint16_t data_type) {
  if (const TypeInfo* t = type_info(data_type)) return t->name;
  char buf[40];
  const auto kind = eds_type_kind(data_type);
  std::snprintf(buf, sizeof buf, "0x%04X (%s)", data_type,
                kind == EdsTypeKind::VendorDefined    ? "vendor-defined"
                : kind == EdsTypeKind::ProfileDefined ? "device-profile-defined"
                                                      : "unknown");
  return buf;
}

std::optional<std::uint8_t> eds_type_bits(std::uint16_t data_type) noexcept {
  const TypeInfo* t = type_info(data_type);
  if (!t || t->bits == 0) return std::nullopt;
  return t->bits;
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
