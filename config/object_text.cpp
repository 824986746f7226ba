#include "config/object_text.hpp"

#include <algorithm>
#include <array>
#include <cstdio>

#include "config/scalars.hpp"
#include "config/text_util.hpp"

namespace drivegate::config {

std::optional<cia402::ObjectId> parse_object_id(std::string_view text) {
  const auto colon = text.find(':');
  const std::string_view index_text = text.substr(0, colon);
  if (!index_text.starts_with("0x") && !index_text.starts_with("0X")) return std::nullopt;
  const auto index = parse_integer(index_text);
  if (!index || *index < 0 || *index > 0xFFFF) return std::nullopt;
  std::int64_t sub = 0;
  if (colon != std::string_view::npos) {
    const auto s = parse_integer(text.substr(colon + 1));
    if (!s || *s < 0 || *s > 0xFF) return std::nullopt;
    sub = *s;
  }
  return cia402::ObjectId{static_cast<std::uint16_t>(*index), static_cast<std::uint8_t>(sub)};
}

namespace {
constexpr std::array<std::pair<std::string_view, cia402::DataType>, 6> kTypes{{
    {"i8", cia402::DataType::I8},
    {"u8", cia402::DataType::U8},
    {"i16", cia402::DataType::I16},
    {"u16", cia402::DataType::U16},
    {"i32", cia402::DataType::I32},
    {"u32", cia402::DataType::U32},
}};

}  // namespace

std::optional<cia402::DataType> parse_data_type(std::string_view text) {
  for (const auto& [name, type] : kTypes)
    if (name == text) return type;
  return std::nullopt;
}

const std::vector<std::string>& data_type_names() {
  static const std::vector<std::string> kNames = [] {
    std::vector<std::string> names;
    for (const auto& [name, type] : kTypes) names.emplace_back(name);
    return names;
  }();
  return kNames;
}

std::string_view to_string(cia402::DataType type) noexcept {
  for (const auto& [name, t] : kTypes)
    if (t == type) return name;
  return "?";
}

std::string object_hex(cia402::ObjectId id) {
  char buf[16];
  if (id.sub == 0)
    std::snprintf(buf, sizeof buf, "0x%04X", id.index);
  else
    std::snprintf(buf, sizeof buf, "0x%04X:%u", id.index, static_cast<unsigned>(id.sub));
  return buf;
}

std::string cyclic_image_difference(const std::vector<cia402::ObjectId>& mapped,
                                    const std::vector<cia402::ObjectId>& cyclic, std::string_view cyclic_word) {
  const auto contains = [](const std::vector<cia402::ObjectId>& v, cia402::ObjectId id) {
    return std::find(v.begin(), v.end(), id) != v.end();
  };
  std::vector<std::string> unmapped;
  std::vector<std::string> unlisted;
  for (const auto& id : cyclic)
    if (!contains(mapped, id)) unmapped.push_back(object_hex(id));
  for (const auto& id : mapped)
    if (!contains(cyclic, id)) unlisted.push_back(object_hex(id));
  std::string out;
  if (!unmapped.empty()) out += " not mapped: " + join(unmapped, " ") + (unlisted.empty() ? "" : ";");
  if (!unlisted.empty()) out += " mapped but not " + std::string{cyclic_word} + ": " + join(unlisted, " ");
  return out;
}

std::string object_text(cia402::ObjectId id) {
  char buf[16];
  if (id.sub == 0)
    std::snprintf(buf, sizeof buf, "%04Xh", id.index);
  else
    std::snprintf(buf, sizeof buf, "%04Xh:%u", id.index, static_cast<unsigned>(id.sub));
  return buf;
}

std::int64_t type_min(cia402::DataType type) noexcept {
  return cia402::is_signed(type) ? -type_max(type) - 1 : 0;
}

std::int64_t type_max(cia402::DataType type) noexcept {
  const unsigned bits = 8U * cia402::size_of(type);
  return (std::int64_t{1} << (cia402::is_signed(type) ? bits - 1U : bits)) - 1;
}

}  // namespace drivegate::config
