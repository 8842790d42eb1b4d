#pragma once
// What the command-line tests share: a fresh folder per test (kept when it
// fails) and the built flocsim.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

#include "harness.hpp"

namespace flocsim {

namespace t = flocsim::test;

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("flocsim_cli_" + std::to_string(getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override {
    if (!HasFailure()) std::filesystem::remove_all(dir_);
  }
  static std::vector<std::string> flocsim(std::vector<std::string> args) {
    args.insert(args.begin(), FLOCSIM_EXE);
    return args;
  }
  std::filesystem::path dir_;
};

}  // namespace flocsim
