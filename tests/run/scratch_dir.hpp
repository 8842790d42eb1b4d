#pragma once
// An empty scratch folder per test, named after the test and the process so
// parallel test processes never share one.
#include <unistd.h>

#include <filesystem>
#include <string>

namespace flocsim::testing {

inline std::filesystem::path fresh_dir(const std::string& name) {
  const std::filesystem::path p = std::filesystem::temp_directory_path() /
                                  ("flocsim_test_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(p);
  return p;
}

}  // namespace flocsim::testing
