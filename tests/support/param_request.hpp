#pragma once
// Parameter requests and replies in tests, as the daemon builds them: the value encoded for its
// type (core/param_value.hpp), the reply's bytes decoded the same way.
#include <cstdint>
#include <stdexcept>
#include <string_view>

#include "core/command.hpp"
#include "core/param_value.hpp"

namespace drivegate::test {

inline core::ParamRequest param_read(core::CommandId id, std::uint16_t index, std::uint8_t sub,
                                     core::ParamType type = core::ParamType::Unknown) {
  core::ParamRequest r;
  r.id = id;
  r.index = index;
  r.sub = sub;
  r.type = type;
  return r;
}

inline core::ParamRequest param_write(core::CommandId id, std::uint16_t index, std::uint8_t sub, core::ParamType type,
                                      std::string_view value) {
  core::ParamRequest r = param_read(id, index, sub, type);
  r.write = true;
  const core::EncodedParam e = core::encode_param(type, value);
  if (!e.error.empty()) throw std::invalid_argument("param_write: " + e.error);
  r.size = static_cast<std::uint16_t>(e.bytes.size());
  for (std::size_t i = 0; i < e.bytes.size(); ++i) r.data[i] = e.bytes[i];
  return r;
}

// The integer a reply carries; a sentinel that no test expects when it carries none.
inline std::int64_t reply_integer(const core::ParamReply& r) {
  return core::param_as_signed(r.type, r.bytes()).value_or(INT64_MIN);
}

}  // namespace drivegate::test
