#pragma once
// Single-writer seqlock for snapshots (DESIGN.md §3): the cycle thread writes an axis or bus
// snapshot (every cycle, or once per BusRunner publish period) without waiting; readers on the control plane retry until they get a
// consistent copy. T must be trivially copyable; the payload is copied word by word through
// relaxed atomics so that the concurrent copy is not a data race in the C++ memory model.
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>

namespace drivegate::core {

template <typename T>
class Seqlock {
  static_assert(std::is_trivially_copyable_v<T>, "Seqlock payload must be trivially copyable");
  static constexpr std::size_t kWords = (sizeof(T) + sizeof(std::uint64_t) - 1) / sizeof(std::uint64_t);
  static constexpr std::size_t kFullWords = sizeof(T) / sizeof(std::uint64_t);
  static constexpr std::size_t kTail = sizeof(T) % sizeof(std::uint64_t);

 public:
  Seqlock() noexcept { store(T{}); }

  // Writer (one thread only). Never blocks.
  // The words are read straight from `value` (no staging copy: with a snapshot of several hundred
  // bytes per axis, the extra copy was most of the cost of publishing it every cycle).
  void store(const T& value) noexcept {
    const auto* bytes = reinterpret_cast<const unsigned char*>(&value);
    const std::uint64_t s = seq_.load(std::memory_order_relaxed);
    seq_.store(s + 1, std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_release);
    for (std::size_t i = 0; i < kFullWords; ++i) {
      std::uint64_t word;
      std::memcpy(&word, bytes + i * sizeof(word), sizeof(word));
      data_[i].store(word, std::memory_order_relaxed);
    }
    if constexpr (kTail != 0) {
      std::uint64_t word = 0;
      std::memcpy(&word, bytes + kFullWords * sizeof(word), kTail);
      data_[kFullWords].store(word, std::memory_order_relaxed);
    }
    seq_.store(s + 2, std::memory_order_release);
  }

  // Reader (any thread). Retries while a write is in progress.
  [[nodiscard]] T load() const noexcept {
    std::array<std::uint64_t, kWords> words{};
    for (;;) {
      const std::uint64_t s1 = seq_.load(std::memory_order_acquire);
      if (s1 & 1U) continue;
      for (std::size_t i = 0; i < kWords; ++i) words[i] = data_[i].load(std::memory_order_relaxed);
      std::atomic_thread_fence(std::memory_order_acquire);
      if (seq_.load(std::memory_order_relaxed) == s1) break;
    }
    T out;
    std::memcpy(static_cast<void*>(&out), words.data(), sizeof(T));
    return out;
  }

  // Number of completed writes; lets a reader see whether anything new arrived.
  [[nodiscard]] std::uint64_t version() const noexcept { return seq_.load(std::memory_order_acquire) / 2; }

 private:
  std::atomic<std::uint64_t> seq_{0};
  std::array<std::atomic<std::uint64_t>, kWords> data_{};
};

}  // namespace drivegate::core
