#pragma once
// Command-line parsing shared by drivegatectl and drivegate-demo: positional words plus
// "--name value", "--name=value" and boolean "--flag" options anywhere on the line.
#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace drivegate::client {

// Wrong usage: the caller prints it with a pointer to --help and exits with status 2.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class Args {
 public:
  // `flags` names the options that take no value ("json", "watch", ...); every other option takes one.
  Args(int argc, const char* const* argv, const std::set<std::string, std::less<>>& flags);

  [[nodiscard]] const std::vector<std::string>& positional() const noexcept { return positional_; }
  [[nodiscard]] bool flag(std::string_view name) const;
  [[nodiscard]] std::optional<std::string> option(std::string_view name) const;
  [[nodiscard]] std::string option_or(std::string_view name, std::string fallback) const;
  [[nodiscard]] std::optional<double> number(std::string_view name) const;  // option as a finite number
  // Options seen but not in `known` (flags and value options): a typo gets an error, not silence.
  void reject_unknown(const std::set<std::string, std::less<>>& known) const;

 private:
  std::vector<std::string> positional_;
  std::map<std::string, std::string, std::less<>> options_;
  std::set<std::string, std::less<>> flags_;
};

// Parsers that name what they parse in their error.
double parse_number(std::string_view what, std::string_view text);
std::int64_t parse_integer(std::string_view what, std::string_view text, std::int64_t min, std::int64_t max);

}  // namespace drivegate::client
