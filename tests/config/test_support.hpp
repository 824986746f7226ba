#pragma once
// Helpers shared by the configuration tests: load options that see the in-tree and test device
// profiles, error capture, and a private temporary directory per test (tests run in parallel).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

#include "config/loader.hpp"

namespace drivegate::config::test {

inline LoadOptions test_options() {
  LoadOptions o;
  o.device_dirs = {DRIVEGATE_DEVICE_DIR_SOURCE, DRIVEGATE_TEST_DEVICE_DIR};
  return o;
}

// Every problem of loading `yaml` (labelled t.yaml), or "(loaded without error)".
inline std::string errors_of(const std::string& yaml, const LoadOptions& options = test_options(),
                             const std::string& label = "t.yaml") {
  try {
    load_plan_from_string(yaml, label, options);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "(loaded without error)";
}

#define EXPECT_REPORTED(errors, text) EXPECT_NE((errors).find(text), std::string::npos) << (errors)

class TempDir : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("drivegate-cfgtest-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path write(const std::string& file, const std::string& text) const {
    const std::filesystem::path p = dir_ / file;
    std::ofstream(p) << text;
    return p;
  }
  std::filesystem::path dir_;
};

}  // namespace drivegate::config::test
