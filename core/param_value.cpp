#include "core/param_value.hpp"

#include <array>
#include <cfloat>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>

#include "core/bytes.hpp"

namespace drivegate::core {
namespace {

struct TypeInfo {
  ParamType type;
  std::string_view name;
  std::string_view cia;
  std::uint16_t cia_index;  // CiA 301 Table 44
  std::size_t size;         // 0: variable
};

constexpr std::array<TypeInfo, 26> kTypes{{
    {ParamType::Unknown, "", "unknown type", 0, 0},
    {ParamType::Bool, "bool", "BOOLEAN", 0x0001, 1},
    {ParamType::I8, "i8", "INTEGER8", 0x0002, 1},
    {ParamType::I16, "i16", "INTEGER16", 0x0003, 2},
    {ParamType::I24, "i24", "INTEGER24", 0x0010, 3},
    {ParamType::I32, "i32", "INTEGER32", 0x0004, 4},
    {ParamType::I40, "i40", "INTEGER40", 0x0012, 5},
    {ParamType::I48, "i48", "INTEGER48", 0x0013, 6},
    {ParamType::I56, "i56", "INTEGER56", 0x0014, 7},
    {ParamType::I64, "i64", "INTEGER64", 0x0015, 8},
    {ParamType::U8, "u8", "UNSIGNED8", 0x0005, 1},
    {ParamType::U16, "u16", "UNSIGNED16", 0x0006, 2},
    {ParamType::U24, "u24", "UNSIGNED24", 0x0016, 3},
    {ParamType::U32, "u32", "UNSIGNED32", 0x0007, 4},
    {ParamType::U40, "u40", "UNSIGNED40", 0x0018, 5},
    {ParamType::U48, "u48", "UNSIGNED48", 0x0019, 6},
    {ParamType::U56, "u56", "UNSIGNED56", 0x001A, 7},
    {ParamType::U64, "u64", "UNSIGNED64", 0x001B, 8},
    {ParamType::R32, "r32", "REAL32", 0x0008, 4},
    {ParamType::R64, "r64", "REAL64", 0x0011, 8},
    {ParamType::VisibleString, "string", "VISIBLE_STRING", 0x0009, 0},
    {ParamType::OctetString, "octets", "OCTET_STRING", 0x000A, 0},
    {ParamType::UnicodeString, "unicode", "UNICODE_STRING", 0x000B, 0},
    {ParamType::Domain, "domain", "DOMAIN", 0x000F, 0},
    {ParamType::TimeOfDay, "time_of_day", "TIME_OF_DAY", 0x000C, 6},
    {ParamType::TimeDifference, "time_difference", "TIME_DIFFERENCE", 0x000D, 6},
}};

constexpr char kHexDigits[] = "0123456789ABCDEF";

const TypeInfo& info(ParamType t) noexcept {
  for (const auto& i : kTypes)
    if (i.type == t) return i;
  return kTypes[0];
}

char lower(char c) noexcept { return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c; }

bool iequal(std::string_view a, std::string_view b) noexcept {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (lower(a[i]) != lower(b[i])) return false;
  return true;
}

std::string_view trim(std::string_view s) noexcept {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

// Appends `v` as `n` little-endian bytes.
void put_le(std::vector<std::uint8_t>& out, std::uint64_t v, std::size_t n) {
  const std::size_t at = out.size();
  out.resize(at + n);
  core::put_le(std::span(out).subspan(at), v);
}

unsigned bits_of(ParamType t) noexcept { return static_cast<unsigned>(8 * param_type_size(t)); }

std::string range_text(ParamType t) {
  const unsigned bits = bits_of(t);
  if (t == ParamType::Bool) return "0 to 1";
  if (param_type_is_signed(t)) {
    const auto max = bits == 64 ? std::numeric_limits<std::int64_t>::max() : (std::int64_t{1} << (bits - 1)) - 1;
    return std::to_string(-max - 1) + " to " + std::to_string(max);
  }
  const auto max = bits == 64 ? std::numeric_limits<std::uint64_t>::max() : (std::uint64_t{1} << bits) - 1;
  return "0 to " + std::to_string(max);
}

EncodedParam fail(std::string why) { return {{}, std::move(why)}; }

EncodedParam encode_integer(ParamType t, std::string_view text) {
  std::string_view s = trim(text);
  const std::string quoted = "'" + std::string(s) + "'";
  bool negative = false;
  if (!s.empty() && (s.front() == '-' || s.front() == '+')) {
    negative = s.front() == '-';
    s.remove_prefix(1);
  }
  int base = 10;
  if (s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X')) {
    base = 16;
    s.remove_prefix(2);
  }
  std::uint64_t magnitude = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), magnitude, base);
  if (s.empty() || ec == std::errc::invalid_argument || end != s.data() + s.size())
    return fail(quoted + " is not a number (decimal, or hex with 0x) for a " + std::string(param_type_cia_name(t)));
  const std::string out_of_range = "value " + quoted + " is outside the range of " +
                                   std::string(param_type_cia_name(t)) + " (" + range_text(t) + ")";
  if (ec == std::errc::result_out_of_range) return fail(out_of_range);
  const unsigned bits = bits_of(t);
  const std::uint64_t mask = bits == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << bits) - 1;
  std::uint64_t raw = 0;
  if (t == ParamType::Bool) {
    if (negative || magnitude > 1) return fail(out_of_range);
    raw = magnitude;
  } else if (param_type_is_signed(t)) {
    const std::uint64_t max_pos = mask >> 1;  // 2^(bits-1) - 1
    if (base == 16 && !negative) {
      if (magnitude > mask) return fail(out_of_range);  // a bit pattern of the type's width
      raw = magnitude;
    } else if (negative) {
      if (magnitude > max_pos + 1) return fail(out_of_range);
      raw = (~magnitude + 1) & mask;
    } else {
      if (magnitude > max_pos) return fail(out_of_range);
      raw = magnitude;
    }
  } else {
    if (negative && magnitude != 0) return fail(out_of_range);
    if (magnitude > mask) return fail(out_of_range);
    raw = magnitude;
  }
  EncodedParam r;
  put_le(r.bytes, raw, param_type_size(t));
  return r;
}

EncodedParam encode_real(ParamType t, std::string_view text) {
  const std::string_view s = trim(text);
  double v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  const std::string quoted = "'" + std::string(s) + "'";
  if (s.empty() || ec == std::errc::invalid_argument || end != s.data() + s.size())
    return fail(quoted + " is not a number for a " + std::string(param_type_cia_name(t)));
  if (ec == std::errc::result_out_of_range || !std::isfinite(v))
    return fail("value " + quoted + " is not a finite number a " + std::string(param_type_cia_name(t)) + " holds");
  EncodedParam r;
  if (t == ParamType::R32) {
    if (std::fabs(v) > static_cast<double>(FLT_MAX))
      return fail("value " + quoted + " is outside the range of REAL32 (+/-3.4e38)");
    const auto f = static_cast<float>(v);
    std::uint32_t raw = 0;
    std::memcpy(&raw, &f, sizeof raw);
    put_le(r.bytes, raw, 4);
  } else {
    std::uint64_t raw = 0;
    std::memcpy(&raw, &v, sizeof raw);
    put_le(r.bytes, raw, 8);
  }
  return r;
}

int hex_digit(char c) noexcept {
  if (c >= '0' && c <= '9') return c - '0';
  c = lower(c);
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

EncodedParam encode_hex_bytes(ParamType t, std::string_view text) {
  EncodedParam r;
  std::size_t i = 0;
  const auto separator = [](char c) { return c == ' ' || c == '\t' || c == ':' || c == '-' || c == ','; };
  while (i < text.size()) {
    if (separator(text[i])) {
      ++i;
      continue;
    }
    std::size_t j = i;
    while (j < text.size() && !separator(text[j])) ++j;
    std::string_view token = text.substr(i, j - i);
    if (token.size() > 2 && token[0] == '0' && (token[1] == 'x' || token[1] == 'X')) token.remove_prefix(2);
    if (token.size() % 2 != 0)
      return fail("'" + std::string(text.substr(i, j - i)) + "' is not whole bytes: give two hex digits per byte");
    for (std::size_t k = 0; k < token.size(); k += 2) {
      const int hi = hex_digit(token[k]);
      const int lo = hex_digit(token[k + 1]);
      if (hi < 0 || lo < 0)
        return fail("'" + std::string(text.substr(i, j - i)) + "' is not hex bytes (e.g. \"01 02 0a\" or 0x01020a)");
      r.bytes.push_back(static_cast<std::uint8_t>(hi * 16 + lo));
    }
    i = j;
  }
  const std::size_t fixed = param_type_size(t);
  if (fixed != 0 && r.bytes.size() != fixed)
    return fail(std::string(param_type_cia_name(t)) + " takes " + std::to_string(fixed) + " bytes, got " +
                std::to_string(r.bytes.size()));
  return r;
}

EncodedParam encode_visible(std::string_view text) {
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c < 0x20 || c > 0x7E)
      return fail("VISIBLE_STRING takes printable ASCII only; character " + std::to_string(i + 1) + " is byte 0x" +
                  hex_bytes(std::span<const std::uint8_t>(&c, 1)) + " (use type unicode or octets)");
  }
  return {{text.begin(), text.end()}, {}};
}

EncodedParam encode_unicode(std::string_view text) {
  EncodedParam r;
  const auto put16 = [&](std::uint32_t u) { put_le(r.bytes, u, 2); };
  for (std::size_t i = 0; i < text.size();) {
    const auto c = static_cast<unsigned char>(text[i]);
    std::uint32_t cp = 0;
    std::size_t n = 0;
    if (c < 0x80) {
      cp = c;
      n = 1;
    } else if ((c & 0xE0) == 0xC0) {
      cp = c & 0x1F;
      n = 2;
    } else if ((c & 0xF0) == 0xE0) {
      cp = c & 0x0F;
      n = 3;
    } else if ((c & 0xF8) == 0xF0) {
      cp = c & 0x07;
      n = 4;
    } else {
      return fail("text is not UTF-8 (byte " + std::to_string(i + 1) + ")");
    }
    if (i + n > text.size()) return fail("text is not UTF-8 (truncated character at byte " + std::to_string(i + 1) + ")");
    for (std::size_t k = 1; k < n; ++k) {
      const auto cc = static_cast<unsigned char>(text[i + k]);
      if ((cc & 0xC0) != 0x80) return fail("text is not UTF-8 (byte " + std::to_string(i + k + 1) + ")");
      cp = (cp << 6) | (cc & 0x3F);
    }
    const bool overlong = (n == 2 && cp < 0x80) || (n == 3 && cp < 0x800) || (n == 4 && cp < 0x10000);
    if (overlong || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF))
      return fail("text is not UTF-8 (byte " + std::to_string(i + 1) + ")");
    if (cp >= 0x10000) {
      cp -= 0x10000;
      put16(0xD800 + (cp >> 10));
      put16(0xDC00 + (cp & 0x3FF));
    } else {
      put16(cp);
    }
    i += n;
  }
  return r;
}

void append_utf8(std::string& out, std::uint32_t cp) {
  if (cp < 0x80) {
    out.push_back(static_cast<char>(cp));
  } else if (cp < 0x800) {
    out.push_back(static_cast<char>(0xC0 | (cp >> 6)));
    out.push_back(static_cast<char>(0x80 | (cp & 0x3F)));
  } else if (cp < 0x10000) {
    out.push_back(static_cast<char>(0xE0 | (cp >> 12)));
    out.push_back(static_cast<char>(0x80 | ((cp >> 6) & 0x3F)));
    out.push_back(static_cast<char>(0x80 | (cp & 0x3F)));
  } else {
    out.push_back(static_cast<char>(0xF0 | (cp >> 18)));
    out.push_back(static_cast<char>(0x80 | ((cp >> 12) & 0x3F)));
    out.push_back(static_cast<char>(0x80 | ((cp >> 6) & 0x3F)));
    out.push_back(static_cast<char>(0x80 | (cp & 0x3F)));
  }
}

std::optional<std::string> decode_unicode(std::span<const std::uint8_t> b) {
  if (b.size() % 2 != 0) return std::nullopt;
  std::string out;
  for (std::size_t i = 0; i < b.size(); i += 2) {
    std::uint32_t u = get_u16(b, i);
    if (u >= 0xD800 && u <= 0xDBFF) {
      if (i + 3 >= b.size()) return std::nullopt;
      const std::uint32_t lo = get_u16(b, i + 2);
      if (lo < 0xDC00 || lo > 0xDFFF) return std::nullopt;
      u = 0x10000 + ((u - 0xD800) << 10) + (lo - 0xDC00);
      i += 2;
    } else if (u >= 0xDC00 && u <= 0xDFFF) {
      return std::nullopt;
    }
    if (u == 0) break;  // a NUL ends the text
    append_utf8(out, u);
  }
  return out;
}

// Printable ASCII as it is, anything else as \xNN; trailing NULs (padding of fixed-length
// strings, dunker-ethercat-coe.md §4: VisStr 16) are not shown.
std::string visible_text(std::span<const std::uint8_t> b) {
  std::size_t n = b.size();
  while (n > 0 && b[n - 1] == 0) --n;
  std::string out;
  for (std::size_t i = 0; i < n; ++i) {
    if (b[i] >= 0x20 && b[i] <= 0x7E && b[i] != '\\') {
      out.push_back(static_cast<char>(b[i]));
    } else if (b[i] == '\\') {
      out += "\\\\";
    } else {
      out += "\\x";
      out.push_back(kHexDigits[b[i] >> 4]);
      out.push_back(kHexDigits[b[i] & 0xF]);
    }
  }
  return out;
}

template <typename T>
std::string shortest(T v) {
  std::array<char, 64> buf{};
  const auto [end, ec] = std::to_chars(buf.data(), buf.data() + buf.size(), v);
  if (ec != std::errc{}) return "?";
  return {buf.data(), end};
}

}  // namespace

std::string_view param_type_name(ParamType t) noexcept { return info(t).name; }
std::string_view param_type_cia_name(ParamType t) noexcept { return info(t).cia; }
std::size_t param_type_size(ParamType t) noexcept { return info(t).size; }

std::optional<ParamType> param_type_from_name(std::string_view name) noexcept {
  name = trim(name);
  if (name.empty()) return std::nullopt;
  for (const auto& i : kTypes) {
    if (i.type == ParamType::Unknown) continue;
    if (iequal(name, i.name) || iequal(name, i.cia)) return i.type;
  }
  struct Alias {
    std::string_view alias;
    ParamType type;
  };
  static constexpr std::array<Alias, 22> kAliases{{
      {"boolean", ParamType::Bool},   {"int8", ParamType::I8},       {"int16", ParamType::I16},
      {"int32", ParamType::I32},      {"int64", ParamType::I64},     {"uint8", ParamType::U8},
      {"uint16", ParamType::U16},     {"uint32", ParamType::U32},    {"uint64", ParamType::U64},
      {"f32", ParamType::R32},        {"float", ParamType::R32},     {"real32", ParamType::R32},
      {"f64", ParamType::R64},        {"double", ParamType::R64},    {"real64", ParamType::R64},
      {"vs", ParamType::VisibleString}, {"str", ParamType::VisibleString},
      {"visible_string", ParamType::VisibleString}, {"os", ParamType::OctetString},
      {"bytes", ParamType::OctetString}, {"octet_string", ParamType::OctetString},
      {"unicode_string", ParamType::UnicodeString},
  }};
  for (const auto& a : kAliases)
    if (iequal(name, a.alias)) return a.type;
  return std::nullopt;
}

ParamType param_type_from_cia(std::uint16_t data_type) noexcept {
  for (const auto& i : kTypes)
    if (i.cia_index != 0 && i.cia_index == data_type) return i.type;
  return ParamType::Unknown;
}

bool param_type_is_integer(ParamType t) noexcept {
  return t == ParamType::Bool || (t >= ParamType::I8 && t <= ParamType::U64);
}
bool param_type_is_signed(ParamType t) noexcept { return t >= ParamType::I8 && t <= ParamType::I64; }
bool param_type_is_real(ParamType t) noexcept { return t == ParamType::R32 || t == ParamType::R64; }

std::optional<ParamType> integer_param_type(std::size_t size, bool is_signed) noexcept {
  switch (size) {
    case 1: return is_signed ? ParamType::I8 : ParamType::U8;
    case 2: return is_signed ? ParamType::I16 : ParamType::U16;
    case 4: return is_signed ? ParamType::I32 : ParamType::U32;
    case 8: return is_signed ? ParamType::I64 : ParamType::U64;
    default: return std::nullopt;
  }
}

EncodedParam encode_param(ParamType t, std::string_view text) {
  EncodedParam r;
  if (t == ParamType::Unknown) return fail("the object's type is not known: name it (--type u16, string, domain, ...)");
  if (param_type_is_integer(t)) {
    if (t == ParamType::Bool) {
      const std::string_view s = trim(text);
      if (iequal(s, "true")) return {{1}, {}};
      if (iequal(s, "false")) return {{0}, {}};
    }
    r = encode_integer(t, text);
  } else if (param_type_is_real(t)) {
    r = encode_real(t, text);
  } else if (t == ParamType::VisibleString) {
    r = encode_visible(text);
  } else if (t == ParamType::UnicodeString) {
    r = encode_unicode(text);
  } else {
    r = encode_hex_bytes(t, text);
  }
  if (r.error.empty() && r.bytes.empty()) return fail("an empty value cannot be written (SDO transfers carry at least one byte)");
  if (r.error.empty() && r.bytes.size() > kMaxParamBytes)
    return fail("value is " + std::to_string(r.bytes.size()) + " bytes; parameters carry at most " +
                std::to_string(kMaxParamBytes));
  return r;
}

std::string param_size_error(ParamType t, std::size_t size) {
  const std::size_t fixed = param_type_size(t);
  if (fixed == 0 || fixed == size) return {};
  return std::to_string(size) + (size == 1 ? " byte" : " bytes") + " do not fit a " + std::string(param_type_cia_name(t)) +
         ", which has " + std::to_string(fixed);
}

std::optional<std::uint64_t> param_as_unsigned(ParamType t, std::span<const std::uint8_t> bytes) noexcept {
  if (!param_type_is_integer(t) || bytes.size() != param_type_size(t)) return std::nullopt;
  return get_le(bytes);
}

std::optional<std::int64_t> param_as_signed(ParamType t, std::span<const std::uint8_t> bytes) noexcept {
  const auto u = param_as_unsigned(t, bytes);
  if (!u) return std::nullopt;
  const unsigned bits = bits_of(t);
  if (param_type_is_signed(t) && bits < 64 && ((*u >> (bits - 1)) & 1U) != 0)
    return static_cast<std::int64_t>(*u | ~((std::uint64_t{1} << bits) - 1));
  return static_cast<std::int64_t>(*u);
}

std::optional<double> param_as_real(ParamType t, std::span<const std::uint8_t> bytes) noexcept {
  if (!param_type_is_real(t) || bytes.size() != param_type_size(t)) return std::nullopt;
  if (t == ParamType::R32) {
    const auto raw = static_cast<std::uint32_t>(get_le(bytes));
    float f = 0;
    std::memcpy(&f, &raw, sizeof f);
    return f;
  }
  const std::uint64_t raw = get_le(bytes);
  double d = 0;
  std::memcpy(&d, &raw, sizeof d);
  return d;
}

std::string hex_bytes(std::span<const std::uint8_t> bytes) {
  std::string out;
  out.reserve(bytes.size() * 3);
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    if (i != 0) out.push_back(' ');
    out.push_back(kHexDigits[bytes[i] >> 4]);
    out.push_back(kHexDigits[bytes[i] & 0xF]);
  }
  return out;
}

std::string format_param(ParamType t, std::span<const std::uint8_t> bytes) {
  if (!param_size_error(t, bytes.size()).empty()) return hex_bytes(bytes);
  if (t == ParamType::Bool && bytes[0] <= 1) return bytes[0] != 0 ? "true" : "false";
  if (param_type_is_signed(t)) return std::to_string(*param_as_signed(t, bytes));
  if (param_type_is_integer(t) && t != ParamType::Bool) return std::to_string(*param_as_unsigned(t, bytes));
  if (t == ParamType::R32) return shortest(static_cast<float>(*param_as_real(t, bytes)));
  if (t == ParamType::R64) return shortest(*param_as_real(t, bytes));
  if (t == ParamType::VisibleString) return visible_text(bytes);
  if (t == ParamType::UnicodeString) {
    if (auto s = decode_unicode(bytes)) return *s;
  }
  return hex_bytes(bytes);
}

std::optional<std::string> format_param_hex(ParamType t, std::span<const std::uint8_t> bytes) {
  const auto u = param_as_unsigned(t, bytes);
  if (!u || t == ParamType::Bool) return std::nullopt;
  std::string out = "0x";
  for (std::size_t i = bytes.size() * 2; i-- > 0;) out.push_back(kHexDigits[(*u >> (4 * i)) & 0xF]);
  return out;
}

bool param_reads_as_hex(std::uint16_t index, std::uint8_t sub) noexcept {
  const auto in = [&](unsigned lo, unsigned hi) { return index >= lo && index <= hi; };
  switch (index) {
    case 0x1000:  // device type
    case 0x1001:  // error register
    case 0x1002:  // manufacturer status register
    case 0x1005:  // COB-ID SYNC
    case 0x1012:  // COB-ID TIME
    case 0x1014:  // COB-ID EMCY
    case 0x1F80:  // NMT start-up
    case 0x603F:  // error code
    case 0x6040:  // controlword
    case 0x6041:  // statusword
    case 0x6502:  // supported drive modes
      return true;
    case 0x1003:  // pre-defined error field
    case 0x1010:  // store parameters (signature)
    case 0x1011:  // restore default parameters (signature)
    case 0x1016:  // consumer heartbeat (node and time)
    case 0x1018:  // identity
      return sub != 0;
    default: break;
  }
  if (in(0x1200, 0x12FF)) return sub == 1 || sub == 2;                      // SDO COB-IDs
  if (in(0x1400, 0x15FF) || in(0x1800, 0x19FF)) return sub == 1;            // PDO COB-ID
  if (in(0x1600, 0x17FF) || in(0x1A00, 0x1BFF)) return sub != 0;            // PDO mapping entries
  return false;
}

}  // namespace drivegate::core
