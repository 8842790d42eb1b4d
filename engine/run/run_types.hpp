#pragma once
// What every scene's time loop takes and gives back.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

namespace flocsim::run {

struct RunOptions {
  std::filesystem::path out_dir;
  bool resume = false;  // continue from out_dir/checkpoint.h5 when present
  bool quiet = false;   // nothing on stderr (the log file is still written)
  // Stop after this many steps of this invocation as if SIGTERM had arrived
  // (checkpoint, exit code 3). For restart tests; 0 = never.
  long stop_after_steps = 0;
  // Also checkpoint every this many steps (0 = by wall time only): makes
  // checkpoint placement deterministic for tests.
  long checkpoint_every_steps = 0;
};

enum class RunOutcome { completed, interrupted, failed };

struct RunReport {
  RunOutcome outcome = RunOutcome::failed;
  nlohmann::json result;  // result.json content when completed
  std::string message;    // diagnosis when failed
};

}  // namespace flocsim::run
