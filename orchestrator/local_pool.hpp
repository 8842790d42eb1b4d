#pragma once
// The local backend: a pool of worker processes (`flocsim run CASE --out DIR`)
// fed from the results database, and the bookkeeping every backend shares:
// registering a sweep, finding lost workers.
#include <functional>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "db/results_db.hpp"
#include "orchestrator/sweep.hpp"

namespace flocsim::orchestrator {

struct Registered {
  db::SweepRecord sweep;
  int runs = 0;
  db::ResultsDb::AddedRuns added;
};
// Throws input::InputError, naming the field, where `db` holds a sweep of this
// name with another base or other axes (a sweep may only add axis values):
// what register_sweep refuses, asked before any work.
void refuse_changed_grid(db::ResultsDb& db, const SweepSpec& spec);
// Records the sweep and its runs (one run directory per case id under
// `runs_dir`); runs already known are reused, whatever their state.
Registered register_sweep(db::ResultsDb& db, const SweepSpec& spec, const std::string& runs_dir);
// Default run folder for a database file: "results.db" -> "results.runs".
std::string default_runs_dir(const std::string& db_path);

struct PoolOptions {
  std::string worker;  // the flocsim executable to run as `WORKER run CASE --out DIR`
  int jobs = 1;
  // what to (re)start
  std::vector<db::RunState> states{db::RunState::kPending, db::RunState::kInterrupted,
                                   db::RunState::kLost};
  std::optional<std::vector<std::string>> only_runs;  // restrict to these run ids

  double lease_s = 60;   // a worker silent for longer is lost
  double poll_s = 0.2;   // how often children are checked
  double grace_s = 120;  // how long a stopping worker may take to checkpoint
  std::string backend = "local";
  std::string job_id;  // backend job id recorded in attempts
  // "cpu" or "cuda": passed to every worker as --device; empty: each case's
  // own "device". With cuda and `gpus` > 1, each worker gets the GPU that
  // runs the fewest workers (CUDA_VISIBLE_DEVICES), so jobs > gpus shares them.
  std::string device;
  int gpus = 1;
  // The CUDA_VISIBLE_DEVICES value that names each of the `gpus` GPUs
  // (visible_gpu_ids); empty: their CUDA indices 0 .. gpus - 1.
  std::vector<std::string> gpu_ids;
  std::ostream* out = nullptr;  // progress lines; nothing when null
};

// What a worker's CUDA_VISIBLE_DEVICES must say to give it the GPU that this
// process sees at CUDA index i, for each i of `cuda_indices`: where this
// process was itself given a list (`inherited`, e.g. "2,3" or GPU UUIDs),
// index i is that list's i-th entry, not the machine's GPU i; without one,
// the index itself.
std::vector<std::string> visible_gpu_ids(const char* inherited,
                                         const std::vector<int>& cuda_indices);

struct PoolSummary {
  int started = 0, completed = 0, failed = 0, refused = 0, interrupted = 0, lost = 0;
  int recovered = 0;     // results found complete on disk and recorded without a rerun
  bool stopped = false;  // a stop signal ended the pool early
};

// Runs the sweep's claimable runs until none is left (or a stop signal).
PoolSummary run_pool(db::ResultsDb& db, const db::SweepRecord& sweep, const PoolOptions& options);

// Closes attempts whose worker is gone: on this host, a dead worker pid whose
// watcher (owner) is dead too; elsewhere, a heartbeat older than `lease_s`.
// A worker that finished (valid result.json) while nobody watched is recorded
// as completed. Returns the number of attempts closed.
int reconcile_lost_workers(db::ResultsDb& db, double lease_s, std::ostream* out = nullptr);

}  // namespace flocsim::orchestrator
