#include "config/yaml_reader.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <limits>

#include "config/scalars.hpp"
#include "config/text_util.hpp"

namespace drivegate::config {

namespace {
Diagnostic make(const std::string& file, const YAML::Mark& mark, std::string path, std::string message) {
  Diagnostic d;
  d.file = file;
  if (mark.line >= 0) {
    d.line = mark.line + 1;
    d.column = mark.column + 1;
  }
  d.path = std::move(path);
  d.message = std::move(message);
  return d;
}

// yaml-cpp marks quoted scalars with the non-specific tag "!": they are strings, never numbers.
bool is_quoted(const YAML::Node& n) { return n.Tag() == "!"; }

std::string got(const YAML::Node& n) { return ", got " + describe_value(n); }
}  // namespace

void Source::error(const YAML::Mark& mark, std::string path, std::string message) const {
  problems->error(make(file, mark, std::move(path), std::move(message)));
}

void Source::warning(const YAML::Mark& mark, std::string path, std::string message) const {
  problems->warning(make(file, mark, std::move(path), std::move(message)));
}

std::string describe_value(const YAML::Node& node) {
  switch (node.Type()) {
    case YAML::NodeType::Scalar: return in_quotes(node.Scalar());
    case YAML::NodeType::Map: return "a map";
    case YAML::NodeType::Sequence: return "a list";
    default: return "nothing";
  }
}

NumberRule NumberRule::range(double lo, double hi, std::string what) {
  return {lo, hi, false, what.empty() ? "a number in " + format_number(lo) + ".." + format_number(hi) : std::move(what)};
}

NumberRule NumberRule::positive_up_to(double hi) { return {0, hi, true, "a number > 0 and at most " + format_number(hi)}; }

std::optional<double> read_number(const YAML::Node& n, const std::string& path, const Source& src,
                                  const NumberRule& rule) {
  const auto v = n.IsScalar() && !is_quoted(n) ? parse_number(n.Scalar()) : std::nullopt;
  if (!v) {
    src.error(n.Mark(), path, "must be " + rule.words + got(n));
    return std::nullopt;
  }
  if (!std::isfinite(*v)) {
    src.error(n.Mark(), path, "must be " + rule.words + got(n) + " (not a finite number)");
    return std::nullopt;
  }
  if (!rule.allows(*v)) {
    src.error(n.Mark(), path, "must be " + rule.words + got(n));
    return std::nullopt;
  }
  return v;
}

std::optional<std::int64_t> read_integer(const YAML::Node& n, const std::string& path, const Source& src,
                                         std::int64_t lo, std::int64_t hi, std::string_view words) {
  const auto v = n.IsScalar() && !is_quoted(n) ? parse_integer(n.Scalar()) : std::nullopt;
  if (!v || *v < lo || *v > hi) {
    src.error(n.Mark(), path,
              "must be " + std::string{words} + " in " + std::to_string(lo) + ".." + std::to_string(hi) + got(n));
    return std::nullopt;
  }
  return v;
}

std::optional<std::string> read_string(const YAML::Node& n, const std::string& path, const Source& src) {
  if (!n.IsScalar()) {
    src.error(n.Mark(), path, "must be a string" + got(n));
    return std::nullopt;
  }
  return n.Scalar();
}

std::optional<std::string> read_text_file(const std::string& file, const Source& src, std::uint64_t max_bytes) {
  const auto fail = [&](const std::string& why) {
    src.error(YAML::Mark::null_mark(), "", why);
    return std::nullopt;
  };
  // Opened first and checked on the descriptor, so the file checked is the file read. O_NONBLOCK:
  // opening a FIFO must not hang waiting for a writer.
  const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK | O_NOCTTY);
  if (fd < 0) return fail("cannot open file: " + std::string{std::strerror(errno)});
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  struct stat st{};
  if (::fstat(fd, &st) != 0) return fail("cannot read file: " + std::string{std::strerror(errno)});
  if (S_ISDIR(st.st_mode)) return fail("is a directory, not a file");
  if (!S_ISREG(st.st_mode))
    return fail(std::string{"is not a regular file (it is a "} +
                (S_ISCHR(st.st_mode)    ? "character device"
                 : S_ISBLK(st.st_mode)  ? "block device"
                 : S_ISFIFO(st.st_mode) ? "pipe"
                 : S_ISSOCK(st.st_mode) ? "socket"
                                        : "special file") +
                ")");
  const auto too_big = [&](std::uint64_t size) {
    return fail("is " + std::to_string(size) + " bytes; this kind of file is limited to " +
                std::to_string(max_bytes / (1024 * 1024)) + " MiB");
  };
  if (static_cast<std::uint64_t>(st.st_size) > max_bytes) return too_big(static_cast<std::uint64_t>(st.st_size));
  // Read at most one byte past the limit: a file that grows while it is read is caught too.
  std::string text;
  text.resize(static_cast<std::size_t>(st.st_size) + 1);
  std::size_t have = 0;
  for (;;) {
    if (have == text.size()) {
      if (text.size() > max_bytes) return too_big(have);
      text.resize(std::min<std::size_t>(text.size() * 2, max_bytes + 1));
    }
    const ssize_t n = ::read(fd, text.data() + have, text.size() - have);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return fail("cannot read file: " + std::string{std::strerror(errno)});
    if (n == 0) break;
    have += static_cast<std::size_t>(n);
  }
  if (have > max_bytes) return too_big(have);
  text.resize(have);
  return text;
}

std::optional<YAML::Node> parse_document(const std::string& text, const Source& src) {
  try {
    // Every document is parsed so that a second one is an error rather than silently ignored.
    std::vector<YAML::Node> docs = YAML::LoadAll(text);
    if (docs.empty()) return YAML::Node{};
    if (docs.size() > 1) {
      src.error(docs[1].Mark(), "",
                "a second YAML document starts here (after \"---\"); a configuration is one document: merge "
                "them or remove the separator");
      return std::nullopt;
    }
    return docs.front();
  } catch (const YAML::ParserException& e) {
    src.error(e.mark, "", "YAML syntax error: " + e.msg);
  } catch (const YAML::Exception& e) {
    src.error(e.mark, "", std::string{"cannot read YAML: "} + e.what());
  }
  return std::nullopt;
}

MapReader::MapReader(const YAML::Node& node, std::string path, const Source& src)
    : node_(node), path_(std::move(path)), src_(src), mark_(node.Mark()), present_(node.IsMap()) {
  if (!present_) {
    src_.error(mark_, path_, "must be a map of fields" + got(node));
    quiet_ = true;
  }
}

MapReader::MapReader(std::string path, const Source& src, YAML::Mark mark, bool quiet)
    : path_(std::move(path)), src_(src), mark_(mark), quiet_(quiet) {}

std::string MapReader::field(std::string_view key) const {
  return path_.empty() ? std::string{key} : path_ + "." + std::string{key};
}

void MapReader::check_keys(std::span<const std::string> allowed) const {
  if (!present_) return;
  std::vector<std::string> seen;
  for (const auto& kv : node_) {
    const YAML::Node& k = kv.first;
    if (!k.IsScalar()) {
      src_.error(k.Mark(), path_, "keys must be plain names" + got(k));
      continue;
    }
    const std::string& key = k.Scalar();
    if (std::find(seen.begin(), seen.end(), key) != seen.end()) {
      src_.error(k.Mark(), field(clipped(key)), "given more than once");
      continue;
    }
    seen.push_back(key);
    if (std::find(allowed.begin(), allowed.end(), key) == allowed.end())
      src_.error(k.Mark(), field(clipped(key)),
                 "unknown field" + did_you_mean(key, allowed) + " (allowed: " + join(allowed) + ")");
  }
}

void MapReader::check_keys(std::initializer_list<std::string_view> allowed) const {
  const std::vector<std::string> keys(allowed.begin(), allowed.end());
  check_keys(std::span<const std::string>{keys});
}

YAML::Node MapReader::find(std::string_view key) const {
  if (!present_) return YAML::Node{YAML::NodeType::Undefined};
  for (const auto& kv : node_)
    if (kv.first.IsScalar() && kv.first.Scalar() == key) return kv.second;
  return YAML::Node{YAML::NodeType::Undefined};
}

YAML::Mark MapReader::mark_of(std::string_view key) const {
  const YAML::Node n = find(key);
  return n.IsDefined() ? n.Mark() : mark_;
}

void MapReader::error(std::string_view key, std::string message) const {
  src_.error(mark_of(key), field(key), std::move(message));
}

YAML::Node MapReader::value(std::string_view key, Need need) const {
  YAML::Node n = find(key);
  if (!n.IsDefined() && need == Need::Required && !quiet_)
    src_.error(mark_, field(key), "missing required field");
  return n;
}

MapReader MapReader::map(std::string_view key, Need need) const {
  const YAML::Node n = value(key, need);
  if (!n.IsDefined()) return MapReader{field(key), src_, mark_, quiet_ || need == Need::Required};
  return MapReader{n, field(key), src_};
}

std::optional<YAML::Node> MapReader::list(std::string_view key, Need need) const {
  const YAML::Node n = value(key, need);
  if (!n.IsDefined()) return std::nullopt;
  if (!n.IsSequence()) {
    src_.error(n.Mark(), field(key), "must be a list" + got(n));
    return std::nullopt;
  }
  return n;
}

std::optional<std::string> MapReader::string(std::string_view key, Need need) const {
  const YAML::Node n = value(key, need);
  if (!n.IsDefined()) return std::nullopt;
  return read_string(n, field(key), src_);
}

std::optional<std::string> MapReader::name(std::string_view key, Need need, bool allow_punct) const {
  const YAML::Node n = value(key, need);
  if (!n.IsDefined()) return std::nullopt;
  if (!n.IsScalar() || !is_valid_name(n.Scalar(), allow_punct)) {
    src_.error(n.Mark(), field(key),
               std::string{"must be a name of 1 to 63 characters from "} +
                   (allow_punct ? "A-Z a-z 0-9 _ . -" : "A-Z a-z 0-9 _") + got(n));
    return std::nullopt;
  }
  return n.Scalar();
}

std::optional<std::string> MapReader::choice(std::string_view key, Need need,
                                             std::span<const std::string> options) const {
  const YAML::Node n = value(key, need);
  if (!n.IsDefined()) return std::nullopt;
  if (!n.IsScalar() || std::find(options.begin(), options.end(), n.Scalar()) == options.end()) {
    src_.error(n.Mark(), field(key),
               "must be one of " + join(options) + got(n) +
                   (n.IsScalar() ? did_you_mean(n.Scalar(), options) : std::string{}));
    return std::nullopt;
  }
  return n.Scalar();
}

std::optional<double> MapReader::number(std::string_view key, Need need, const NumberRule& rule) const {
  const YAML::Node n = value(key, need);
  if (!n.IsDefined()) return std::nullopt;
  return read_number(n, field(key), src_, rule);
}

std::optional<std::int64_t> MapReader::integer(std::string_view key, Need need, std::int64_t lo, std::int64_t hi,
                                               std::string_view words) const {
  const YAML::Node n = value(key, need);
  if (!n.IsDefined()) return std::nullopt;
  return read_integer(n, field(key), src_, lo, hi, words);
}

std::optional<core::Duration> read_duration(const YAML::Node& n, const std::string& path, const Source& src,
                                            core::Duration min, core::Duration max) {
  const auto d = n.IsScalar() && !is_quoted(n) ? parse_duration(n.Scalar()) : std::nullopt;
  const bool zero_allowed = min.count() < 0;
  // A zero minimum means "strictly positive", a negative one "zero or more"; any other minimum is
  // inclusive.
  if (min.count() < 0) min = core::Duration::zero();
  const bool strict = min.count() == 0 && !zero_allowed;
  const bool ok = d && (strict ? *d > min : *d >= min) && *d <= max;
  if (!ok) {
    const std::string range = strict ? "> 0 (at most " + format_duration(max) + ")"
                            : zero_allowed ? "in 0.." + format_duration(max)
                                           : "in " + format_duration(min) + ".." + format_duration(max);
    src.error(n.Mark(), path,
              "must be a duration " + range + " such as 250us, 1ms, 0.5s or 2s (a bare number is seconds)" + got(n));
    return std::nullopt;
  }
  return d;
}

std::optional<core::Duration> MapReader::duration(std::string_view key, Need need, core::Duration min,
                                                  core::Duration max) const {
  const YAML::Node n = value(key, need);
  if (!n.IsDefined()) return std::nullopt;
  return read_duration(n, field(key), src_, min, max);
}

std::optional<bool> MapReader::boolean(std::string_view key, Need need) const {
  const YAML::Node n = value(key, need);
  if (!n.IsDefined()) return std::nullopt;
  if (n.IsScalar() && !is_quoted(n)) {
    const std::string& s = n.Scalar();
    if (s == "true" || s == "True" || s == "TRUE") return true;
    if (s == "false" || s == "False" || s == "FALSE") return false;
  }
  src_.error(n.Mark(), field(key), "must be true or false" + got(n));
  return std::nullopt;
}

}  // namespace drivegate::config
