#pragma once
// Typed, position-aware reading of YAML maps. Every getter checks type and range and, on a
// problem, records "FILE:LINE:COL: PATH: must be ..., got ..." and returns nullopt, so a loader
// keeps going and reports everything in one run.
#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <initializer_list>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "config/config_error.hpp"
#include "core/clock.hpp"

namespace drivegate::config {

enum class Need : std::uint8_t { Optional, Required };

// Where problems go: the file being read and the collector.
struct Source {
  std::string file;
  Problems* problems = nullptr;
  void error(const YAML::Mark& mark, std::string path, std::string message) const;
  void warning(const YAML::Mark& mark, std::string path, std::string message) const;
};

// Allowed range of a number, with the words used in messages ("a number > 0").
struct NumberRule {
  double min = -1e300;
  double max = 1e300;
  bool min_exclusive = false;
  std::string words = "a finite number";
  static NumberRule any() { return {}; }
  static NumberRule positive() { return {0, 1e300, true, "a number > 0"}; }
  static NumberRule non_negative() { return {0, 1e300, false, "a number >= 0"}; }
  // min..max inclusive; `words` defaults to "a number in MIN..MAX".
  static NumberRule range(double lo, double hi, std::string what = {});
  // > 0 and at most `hi`.
  static NumberRule positive_up_to(double hi);
  [[nodiscard]] bool allows(double v) const noexcept {
    return (min_exclusive ? v > min : v >= min) && v <= max;
  }
};

// How a value is shown after "got": "\"fast\"", "a map", "a list", "nothing".
std::string describe_value(const YAML::Node& node);

// Readers for single values (also used for list elements). `path` names the value.
std::optional<double> read_number(const YAML::Node& n, const std::string& path, const Source& src,
                                  const NumberRule& rule);
// `words` names what the integer is in messages: "must be a CANopen node-ID in 1..127, got ...".
std::optional<std::int64_t> read_integer(const YAML::Node& n, const std::string& path, const Source& src,
                                         std::int64_t lo, std::int64_t hi, std::string_view words = "an integer");
std::optional<std::string> read_string(const YAML::Node& n, const std::string& path, const Source& src);
// A duration in min..max; a zero `min` means strictly positive, a negative one zero or more.
std::optional<core::Duration> read_duration(const YAML::Node& n, const std::string& path, const Source& src,
                                            core::Duration min, core::Duration max);

// Configuration and device profile files are refused above this size: the YAML parser needs about
// a hundred times a file's size in memory, and a real deployment is a few kilobytes.
inline constexpr std::uint64_t kMaxYamlBytes = 1024 * 1024;

// The whole content of a regular file of at most `max_bytes`; a directory, device, pipe, socket,
// an unreadable or a too large file is reported (without position) and gives nullopt.
std::optional<std::string> read_text_file(const std::string& file, const Source& src,
                                          std::uint64_t max_bytes = kMaxYamlBytes);

// Parses a YAML text that must hold one document; a syntax error is reported at its position, a
// second document is an error, and both give nullopt.
std::optional<YAML::Node> parse_document(const std::string& text, const Source& src);

class MapReader {
 public:
  // A present map (type-checked here: anything else is reported as "must be a map").
  MapReader(const YAML::Node& node, std::string path, const Source& src);

  [[nodiscard]] bool present() const noexcept { return present_; }
  [[nodiscard]] const YAML::Node& node() const noexcept { return node_; }
  [[nodiscard]] const std::string& path() const noexcept { return path_; }
  [[nodiscard]] const Source& source() const noexcept { return src_; }
  [[nodiscard]] YAML::Mark mark() const noexcept { return mark_; }
  [[nodiscard]] std::string field(std::string_view key) const;

  // Reports keys outside `allowed` (with a "did you mean") and keys given twice.
  void check_keys(std::span<const std::string> allowed) const;
  void check_keys(std::initializer_list<std::string_view> allowed) const;

  // The value under `key`, or an undefined node.
  [[nodiscard]] YAML::Node find(std::string_view key) const;
  [[nodiscard]] bool has(std::string_view key) const { return find(key).IsDefined(); }
  // Mark of the value under `key`, or of this map when the key is absent.
  [[nodiscard]] YAML::Mark mark_of(std::string_view key) const;
  // Reports a problem about `key` (at its value, or at this map when absent).
  void error(std::string_view key, std::string message) const;

  // A nested map. When absent (or not a map) the result is an absent reader whose getters return
  // nullopt; its required fields are still reported at this map's position, unless the absence
  // was already reported.
  [[nodiscard]] MapReader map(std::string_view key, Need need) const;
  // A nested list (sequence).
  [[nodiscard]] std::optional<YAML::Node> list(std::string_view key, Need need) const;

  std::optional<std::string> string(std::string_view key, Need need) const;
  // [A-Za-z0-9_.-]{1,63}, or [A-Za-z0-9_]{1,63} without punctuation.
  std::optional<std::string> name(std::string_view key, Need need, bool allow_punct = true) const;
  std::optional<std::string> choice(std::string_view key, Need need, std::span<const std::string> options) const;
  std::optional<double> number(std::string_view key, Need need, const NumberRule& rule) const;
  std::optional<std::int64_t> integer(std::string_view key, Need need, std::int64_t lo, std::int64_t hi,
                                      std::string_view words = "an integer") const;
  // Durations in min..max; a zero `min` means strictly positive.
  std::optional<core::Duration> duration(std::string_view key, Need need, core::Duration min,
                                         core::Duration max) const;
  std::optional<bool> boolean(std::string_view key, Need need) const;

 private:
  MapReader(std::string path, const Source& src, YAML::Mark mark, bool quiet);
  [[nodiscard]] YAML::Node value(std::string_view key, Need need) const;

  YAML::Node node_;
  std::string path_;
  Source src_;
  YAML::Mark mark_;
  bool present_ = false;
  bool quiet_ = false;  // absent and already reported: do not report missing fields again
};

}  // namespace drivegate::config
