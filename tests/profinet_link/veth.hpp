#pragma once
// A veth pair between two network namespaces the test creates (and always removes): end A is the
// controller's port, end B the device's. Skips without root / ip.
#include <poll.h>

#include <gtest/gtest.h>

#include <chrono>
#include <memory>

#include "tests/support/netns.hpp"

namespace drivegate::profinet::test {

class VethTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (const std::string& why = drivegate::test::netns_unavailable(); !why.empty()) GTEST_SKIP() << why;
    ns_a_ = std::make_unique<drivegate::test::NetNamespace>();
    ns_b_ = std::make_unique<drivegate::test::NetNamespace>();
    veth_ = std::make_unique<drivegate::test::VethPair>(ns_a_.get(), ns_b_.get());
  }

  std::unique_ptr<drivegate::test::NetNamespace> ns_a_;
  std::unique_ptr<drivegate::test::NetNamespace> ns_b_;
  std::unique_ptr<drivegate::test::VethPair> veth_;
};

// Waits until `fd` is readable, at most `timeout`.
inline bool wait_readable(int fd, std::chrono::milliseconds timeout) {
  pollfd p{fd, POLLIN, 0};
  return ::poll(&p, 1, static_cast<int>(timeout.count())) > 0;
}

}  // namespace drivegate::profinet::test
