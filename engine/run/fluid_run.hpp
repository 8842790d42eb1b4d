#pragma once
// The time loop of the fluid-only scene: set up the lattice from a case, step
// it with progress, periodic checkpoints, blow-up detection and a clean stop
// on SIGTERM/SIGINT, and write result.json (atomically) at the end.
//
// Output directory layout (the contract the orchestrator relies on):
//   run.log         the log
//   progress.json   heartbeat, rewritten atomically at least every 5 s
//   checkpoint.h5   latest complete checkpoint (written atomically)
//   fields/step_NNNNNNNNNN.h5, fields.xdmf  field snapshots, when requested
//   result.json     written last, atomically, only when the run completed
#include <filesystem>
#include <nlohmann/json.hpp>

#include "engine/case/fluid_case.hpp"
#include "engine/run/run_types.hpp"

namespace flocsim::run {

RunReport run_fluid_case(const cases::FluidCase& c, const RunOptions& options);

}  // namespace flocsim::run
