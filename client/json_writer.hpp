#pragma once
// A tiny streaming JSON writer for drivegatectl's --json output: objects, arrays, strings with
// proper escaping (RFC 8259 §7), numbers (NaN/inf become null, JSON has no spelling for them).
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace drivegate::client {

class JsonWriter {
 public:
  JsonWriter& begin_object();
  JsonWriter& end_object();
  JsonWriter& begin_array();
  JsonWriter& end_array();
  JsonWriter& key(std::string_view k);
  JsonWriter& value(std::string_view v);
  JsonWriter& value(const char* v) { return value(std::string_view(v)); }
  JsonWriter& value(double v);
  JsonWriter& value(std::int64_t v);
  JsonWriter& value(std::uint64_t v);
  JsonWriter& value(bool v);
  JsonWriter& null();
  // Shorthand for key(k).value(v).
  template <typename T>
  JsonWriter& field(std::string_view k, T v) {
    return key(k).value(v);
  }

  [[nodiscard]] const std::string& str() const noexcept { return out_; }

  // `s` as a quoted JSON string.
  static std::string quote(std::string_view s);

 private:
  void separate();
  std::string out_;
  std::vector<bool> first_;  // per open container: no element written yet
  bool after_key_ = false;
};

}  // namespace drivegate::client
