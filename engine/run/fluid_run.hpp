#pragma once
// The time loop of the fluid-only scene: set up the lattice from a case, step
// it with progress, periodic checkpoints, blow-up detection and a clean stop
// on SIGTERM/SIGINT, and write result.json (atomically) at the end.
//
// Output directory layout (the contract the orchestrator relies on):
//   run.log         the log
//   progress.json   heartbeat, rewritten atomically at least every 5 s
//   checkpoint.h5   latest complete checkpoint (written atomically)
//   fields.h5/.xdmf field snapshots, when requested
//   result.json     written last, atomically, only when the run completed
#include <filesystem>
#include <nlohmann/json.hpp>

#include "engine/case/fluid_case.hpp"

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

RunReport run_fluid_case(const cases::FluidCase& c, const RunOptions& options);

}  // namespace flocsim::run
