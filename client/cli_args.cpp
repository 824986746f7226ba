#include "client/cli_args.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>

namespace drivegate::client {

Args::Args(int argc, const char* const* argv, const std::set<std::string, std::less<>>& flags) {
  for (int i = 1; i < argc; ++i) {
    const std::string_view a = argv[i];
    if (a == "-h") {
      flags_.insert("help");
      continue;
    }
    if (a.size() < 3 || a.substr(0, 2) != "--") {
      positional_.emplace_back(a);  // includes negative numbers such as "-5"
      continue;
    }
    std::string name(a.substr(2));
    const auto eq = name.find('=');
    if (eq != std::string::npos) {
      options_[name.substr(0, eq)] = name.substr(eq + 1);
    } else if (flags.count(name) != 0) {
      flags_.insert(name);
    } else {
      if (i + 1 >= argc) throw UsageError("option --" + name + " needs a value");
      options_[name] = argv[++i];
    }
  }
}

bool Args::flag(std::string_view name) const { return flags_.find(name) != flags_.end(); }

std::optional<std::string> Args::option(std::string_view name) const {
  const auto it = options_.find(name);
  if (it == options_.end()) return std::nullopt;
  return it->second;
}

std::string Args::option_or(std::string_view name, std::string fallback) const {
  auto v = option(name);
  return v ? *v : std::move(fallback);
}

std::optional<double> Args::number(std::string_view name) const {
  const auto v = option(name);
  if (!v) return std::nullopt;
  return parse_number("--" + std::string(name), *v);
}

void Args::reject_unknown(const std::set<std::string, std::less<>>& known) const {
  for (const auto& [name, value] : options_)
    if (known.count(name) == 0) throw UsageError("unknown option --" + name);
  for (const auto& name : flags_)
    if (known.count(name) == 0) throw UsageError("option --" + name + " does not apply here");
}

double parse_number(std::string_view what, std::string_view text) {
  const std::string s(text);
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || end != s.c_str() + s.size() || errno == ERANGE || !std::isfinite(v))
    throw UsageError(std::string(what) + ": '" + s + "' is not a finite number");
  return v;
}

std::int64_t parse_integer(std::string_view what, std::string_view text, std::int64_t min, std::int64_t max) {
  const std::string s(text);
  char* end = nullptr;
  errno = 0;
  const long long v = std::strtoll(s.c_str(), &end, 0);  // base 0: accepts 0x.. hex
  if (s.empty() || end != s.c_str() + s.size() || errno == ERANGE || v < min || v > max)
    throw UsageError(std::string(what) + ": '" + s + "' is not an integer in " + std::to_string(min) + ".." +
                     std::to_string(max));
  return v;
}

}  // namespace drivegate::client
