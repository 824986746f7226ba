#pragma once
// Counts calls to the global operator new on the calling thread while a scope is armed. Linking
// drivegate_test_support replaces the global allocation functions for the whole test binary.
#include <cstddef>

namespace drivegate::test {

// Number of allocations made by this thread since the process started.
std::size_t thread_allocations() noexcept;

class AllocationScope {
 public:
  AllocationScope() noexcept : start_(thread_allocations()) {}
  [[nodiscard]] std::size_t count() const noexcept { return thread_allocations() - start_; }

 private:
  std::size_t start_;
};

}  // namespace drivegate::test
