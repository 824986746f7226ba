#pragma once
// A string with a fixed capacity stored inline, so that replies, events and snapshots can cross
// the cycle-thread boundary without touching the heap. Text longer than the capacity is cut at a
// character boundary and ends in "..." so that a truncation is visible, never silent.
#include <algorithm>
#include <array>
#include <cstdarg>
#include <cstddef>
#include <cstdio>
#include <string>
#include <string_view>

namespace drivegate::core {

template <std::size_t N>
class FixedString {
  static_assert(N >= 4, "FixedString needs room for at least a few characters");

 public:
  constexpr FixedString() noexcept = default;
  FixedString(std::string_view s) noexcept { assign(s); }  // NOLINT(google-explicit-constructor)

  void assign(std::string_view s) noexcept {
    if (s.size() <= N) {
      std::copy(s.begin(), s.end(), data_.begin());
      size_ = s.size();
    } else {
      std::size_t keep = N - 3;
      // Do not cut a UTF-8 sequence in half.
      while (keep > 0 && (static_cast<unsigned char>(s[keep]) & 0xC0U) == 0x80U) --keep;
      std::copy(s.begin(), s.begin() + static_cast<std::ptrdiff_t>(keep), data_.begin());
      std::copy_n("...", 3, data_.begin() + static_cast<std::ptrdiff_t>(keep));
      size_ = keep + 3;
    }
    data_[size_] = '\0';
  }

  // printf-style formatting into the inline buffer (no heap). Truncates like assign(). The
  // format attribute lets the compiler check arguments against the format at every call site.
  __attribute__((format(printf, 2, 3))) void format(const char* fmt, ...) noexcept {
    va_list args;
    va_start(args, fmt);
    vformat(fmt, args);
    va_end(args);
  }

  __attribute__((format(printf, 2, 0))) void vformat(const char* fmt, va_list args) noexcept {
    // One character more than fits, so that assign() sees the overflow and truncates visibly and
    // on a UTF-8 boundary.
    std::array<char, N + 2> tmp{};
    const int n = std::vsnprintf(tmp.data(), tmp.size(), fmt, args);
    if (n < 0) {
      clear();
      return;
    }
    assign(std::string_view(tmp.data(), std::min(static_cast<std::size_t>(n), N + 1)));
  }

  void clear() noexcept {
    size_ = 0;
    data_[0] = '\0';
  }
  [[nodiscard]] std::string_view view() const noexcept { return {data_.data(), size_}; }
  [[nodiscard]] std::string str() const { return std::string(view()); }
  [[nodiscard]] const char* c_str() const noexcept { return data_.data(); }
  [[nodiscard]] std::size_t size() const noexcept { return size_; }
  [[nodiscard]] bool empty() const noexcept { return size_ == 0; }
  static constexpr std::size_t capacity() noexcept { return N; }

  friend bool operator==(const FixedString& a, std::string_view b) noexcept { return a.view() == b; }

 private:
  std::array<char, N + 1> data_{};
  std::size_t size_ = 0;
};

}  // namespace drivegate::core
