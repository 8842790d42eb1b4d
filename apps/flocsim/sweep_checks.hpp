#pragma once
// What `flocsim sweep launch` and `resume` check before anything is recorded,
// claimed or started, so that a sweep never holds runs that can only fail:
// the worker program, the device (a GPU where the grid asks for one), a grid
// none of whose points runs, the folder for the run folders, the database
// file, and options the chosen backend would ignore. Each refusal is an
// input::InputError (exit 2) naming the option or the point and what would
// work; a place that fails (a read-only or full file system) is a failure
// (exit 1). cmd_sweep.cpp wires them into the subcommands.
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "apps/flocsim/sweep_options.hpp"
#include "db/results_db.hpp"
#include "orchestrator/sweep.hpp"

namespace flocsim::app {

// This flocsim, as the default worker program.
std::string default_worker();
// Refuses a --worker (or $FLOCSIM_WORKER) that cannot be started.
void check_worker(const std::string& given);
// Whether the workers read flocsim's cases (no other --worker given).
bool reads_flocsim_cases(const SweepOptions& o);
// The GPU where --device cuda or the grid's cases ask for one (may set
// o.device to cuda where every case asks); what CUDA_VISIBLE_DEVICES names
// each GPU the local pool spreads its workers over by.
std::vector<std::string> check_device(SweepOptions& o,
                                      const std::vector<orchestrator::RunPoint>& points,
                                      bool flocsim_cases);
// Refuses a grid every point of which `flocsim run` would refuse.
void refuse_an_unrunnable_grid(const std::vector<orchestrator::RunPoint>& points,
                               const std::string& device);
// Makes the folder the run folders go under, or refuses it; returns the
// folders it made, deepest first, for unmake_runs_dir.
std::vector<std::filesystem::path> make_runs_dir(const std::string& dir, bool given);
// Takes back what make_runs_dir made, each folder only while still empty.
void unmake_runs_dir(const std::vector<std::filesystem::path>& made);
// Opens --db, refusing a path that cannot be a results database.
std::unique_ptr<db::ResultsDb> open_db(const std::string& path, db::ResultsDb::Mode mode);
// Refuses --no-wait without Slurm and --jobs with it.
void refuse_options_of_the_other_backend(const SweepOptions& o);

}  // namespace flocsim::app
