#pragma once
// Helpers for the orchestrator's end-to-end tests: run the flocsim binary,
// start it in the background, wait for files, read JSON.
#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace flocsim::test {

struct Output {
  int code = -1;    // exit code, or 128 + signal
  std::string out;  // stdout and stderr together
};

// Runs `argv` to completion (with the environment plus `env`, "NAME=VALUE").
Output run(const std::vector<std::string>& argv, const std::vector<std::string>& env = {});

// A process started in the background; its output goes to `log`.
struct Background {
  pid_t pid = -1;
  std::string log;
  // Waits for it to end; returns the exit code (128 + signal when killed).
  int wait(double timeout_s = 120);
  Background() = default;
  Background(const Background&) = delete;
  Background& operator=(const Background&) = delete;
  Background(Background&& other) noexcept : pid(other.pid), log(std::move(other.log)) {
    other.pid = -1;
  }
  ~Background();  // kills the process if it still runs
};
Background start(const std::vector<std::string>& argv, const std::string& log);

// Polls `ready` every 50 ms; false on timeout.
bool wait_for(const std::function<bool()>& ready, double timeout_s);

std::string read_text(const std::filesystem::path& file);
void write_text(const std::filesystem::path& file, const std::string& text);
nlohmann::json read_json(const std::filesystem::path& file);
int count_lines(const std::filesystem::path& file);

}  // namespace flocsim::test
