#pragma once
// Small text helpers for configuration messages: "did you mean", lists, name patterns, numbers.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace drivegate::config {

// The candidate closest to `word` by edit distance, if it is close enough to be a likely typo
// (at most a third of the word's length, at least one edit); empty otherwise.
std::string closest_match(std::string_view word, std::span<const std::string> candidates);

// `, did you mean "x"?` or nothing, ready to append to a message.
std::string did_you_mean(std::string_view word, std::span<const std::string> candidates);

// "a, b, c" (or "(none)" for an empty list).
std::string join(std::span<const std::string> items, std::string_view sep = ", ");

// "buses[2]": the path of a list element in messages.
std::string indexed(std::string_view list, std::size_t i);

// Names of gateways, buses and axes: [A-Za-z0-9_.-]{1,63}. With allow_punct false: [A-Za-z0-9_]{1,63}.
bool is_valid_name(std::string_view s, bool allow_punct = true) noexcept;

// `"value"` for messages, cut after 60 characters ("…(4096 characters)") so that a hostile or
// mistaken value cannot flood the terminal or the journal.
std::string in_quotes(std::string_view value);
// The same without quotes, for field paths built from keys.
std::string clipped(std::string_view value);

// Linux interface names: 1..15 bytes (IFNAMSIZ 16 with the terminator), no '/', ':' or blanks.
bool is_interface_name(std::string_view s) noexcept;

// "192.168.0.1": four decimal octets 0..255; nullopt for anything else.
std::optional<std::array<int, 4>> parse_ipv4(std::string_view s) noexcept;
// The same as one number in host order (192.168.0.1 is C0A80001h).
std::optional<std::uint32_t> parse_ipv4_host(std::string_view s) noexcept;

// Shortest readable form of a number: "5", "0.5", "26214.4", "1e-06".
std::string format_number(double v);

}  // namespace drivegate::config
