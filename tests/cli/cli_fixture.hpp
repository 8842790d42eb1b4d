#pragma once
// What the command-line tests share: a fresh folder per test (kept when it
// fails) and the built flocsim.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "harness.hpp"
#include "tests/run/scratch_dir.hpp"

namespace flocsim {

namespace t = flocsim::test;

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = flocsim::testing::fresh_dir(
        std::string("cli_") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
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
