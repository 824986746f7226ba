#include "config/config_error.hpp"

#include <algorithm>

namespace drivegate::config {

std::string Diagnostic::to_string() const {
  std::string s = file;
  if (line > 0) s += ":" + std::to_string(line) + ":" + std::to_string(column);
  s += ": ";
  if (!path.empty()) s += path + ": ";
  s += message;
  return s;
}

namespace {
// A file of garbage could produce an error per line: the first ones say enough.
constexpr std::size_t kShownProblems = 50;

std::string render(const std::vector<Diagnostic>& problems) {
  std::string s;
  for (std::size_t i = 0; i < problems.size() && i < kShownProblems; ++i) {
    if (!s.empty()) s += '\n';
    s += problems[i].to_string();
  }
  if (problems.size() > kShownProblems)
    s += "\n... and " + std::to_string(problems.size() - kShownProblems) + " more problems";
  return s;
}
}  // namespace

ConfigError::ConfigError(std::vector<Diagnostic> problems)
    : std::runtime_error(render(problems)), problems_(std::move(problems)) {}

void Problems::throw_if_errors() const {
  if (errors_.empty()) return;
  // Grouped by file in the order files were first seen, then in reading order within a file.
  std::vector<std::string> files;
  for (const auto& d : errors_)
    if (std::find(files.begin(), files.end(), d.file) == files.end()) files.push_back(d.file);
  const auto rank = [&files](const Diagnostic& d) {
    return std::find(files.begin(), files.end(), d.file) - files.begin();
  };
  std::vector<Diagnostic> sorted = errors_;
  std::stable_sort(sorted.begin(), sorted.end(), [&rank](const Diagnostic& a, const Diagnostic& b) {
    const auto ra = rank(a);
    const auto rb = rank(b);
    if (ra != rb) return ra < rb;
    return a.line != b.line ? a.line < b.line : a.column < b.column;
  });
  throw ConfigError(std::move(sorted));
}

}  // namespace drivegate::config
