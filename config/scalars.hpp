#pragma once
// Parsing of scalar text as YAML writes it: numbers (with YAML's .inf/.nan spellings, so they can
// be refused by name), integers (decimal or 0x hex) and durations ("250us", "1ms", "0.5s", "2s",
// or a bare number of seconds).
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "core/clock.hpp"

namespace drivegate::config {

// Any real number, including non-finite ones (".inf", "-.inf", ".nan"); nullopt if not a number.
std::optional<double> parse_number(std::string_view text) noexcept;
// A whole number, decimal or 0x-prefixed hex, with optional sign; nullopt otherwise.
std::optional<std::int64_t> parse_integer(std::string_view text) noexcept;
// A duration with unit ns, us, ms, s or min, or a bare number of seconds. Negative values parse
// (range checks belong to the caller); non-finite or overflowing values do not.
std::optional<core::Duration> parse_duration(std::string_view text) noexcept;
// "250us", "1ms", "0.5s", "30s": the shortest exact form with the largest fitting unit.
std::string format_duration(core::Duration d);

}  // namespace drivegate::config
