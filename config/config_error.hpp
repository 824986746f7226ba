#pragma once
// Problems found while loading a configuration. Loading goes on after a problem so that one run
// reports all of them; each names FILE:LINE:COL and the field path, and says what is allowed.
#include <stdexcept>
#include <string>
#include <vector>

namespace drivegate::config {

struct Diagnostic {
  std::string file;
  int line = 0;    // 1-based; 0 when the problem has no position (e.g. unreadable file)
  int column = 0;  // 1-based
  std::string path;  // field path, e.g. "axes[2].limits.max_velocity"
  std::string message;
  // "FILE:LINE:COL: PATH: message" (position and path left out when unknown).
  [[nodiscard]] std::string to_string() const;
};

class ConfigError : public std::runtime_error {
 public:
  explicit ConfigError(std::vector<Diagnostic> problems);
  [[nodiscard]] const std::vector<Diagnostic>& problems() const noexcept { return problems_; }

 private:
  std::vector<Diagnostic> problems_;
};

// Collects errors and warnings during one load.
class Problems {
 public:
  void error(Diagnostic d) { errors_.push_back(std::move(d)); }
  void warning(Diagnostic d) { warnings_.push_back(std::move(d)); }
  [[nodiscard]] bool has_errors() const noexcept { return !errors_.empty(); }
  [[nodiscard]] const std::vector<Diagnostic>& errors() const noexcept { return errors_; }
  [[nodiscard]] const std::vector<Diagnostic>& warnings() const noexcept { return warnings_; }
  // Throws ConfigError with every error, ordered by file and position, when there is any.
  void throw_if_errors() const;

 private:
  std::vector<Diagnostic> errors_;
  std::vector<Diagnostic> warnings_;
};

}  // namespace drivegate::config
