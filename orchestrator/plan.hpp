#pragma once
// `flocsim sweep plan`: what a sweep will cost before it starts. Every point of
// the grid is read and checked by the parser `flocsim run` uses (so a point
// refused here is refused by the run, with the same message naming what would
// work), sized (box, N, steps from the run's own protocol, lattice updates),
// and timed: each distinct configuration (the case less what does not change
// the cost of a step) builds its real coupled step and runs a few steps, or,
// given a database, takes the measured cost of its completed runs of the same
// configuration. `flocsim sweep launch` prints the same summary and goes on.
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "engine/run/case_cost.hpp"
#include "orchestrator/gpu_rates.hpp"
#include "orchestrator/sweep.hpp"

namespace flocsim::db {
class ResultsDb;
}

namespace flocsim::orchestrator {

struct PlanOptions {
  int jobs = 1;                   // local backend: runs at once
  std::string backend = "local";  // local | slurm
  int measure_steps = 3;          // steps timed per configuration at least; 0: none
  double measure_seconds = 1.0;   // ... and at least this long
  db::ResultsDb* db = nullptr;    // completed runs give the rate; complete runs are skipped
  // A GPU's benchmark figures (--gpu-rate): every configuration the GPU can
  // run is estimated on it, one GPU per worker, instead of measured here.
  const GpuRates* gpu = nullptr;
  std::ostream* progress = nullptr;  // "measuring ..." lines while it works
};

// What one step of one configuration costs, and where that figure comes from.
struct StepCost {
  nlohmann::json key;       // run::CaseSize::cost_key
  std::string description;  // "suspension, 64 x 32 x 32 cells, 49 spheres, float, ..."
  int runs = 0;             // planned runs of this configuration
  std::optional<run::StepMeasurement> measured;  // one copy alone (its memory is one run's)
  // as many copies at once as the sweep runs workers (local backend, --jobs > 1)
  std::optional<run::StepMeasurement> measured_together;
  int copies_together = 0;
  int db_runs = 0;       // completed runs of this configuration in the database
  double db_step_s = 0;  // their median wall seconds per step (setup and output included)
  int db_threads = 0;
  std::optional<double> gpu_step_s;  // from --gpu-rate, where it has a figure
  std::string gpu_name, gpu_why;     // the GPU; why it has no figure
  // seconds per step and threads of the estimate: the GPU's with --gpu-rate,
  // else the database's when it has runs, else the measurement's; empty when
  // none exists
  std::optional<double> step_s() const;
  int threads() const;
  std::string basis() const;  // where the figure comes from, in words
};

struct PlannedRun {
  RunPoint point;
  std::string refused;    // the run's own refusal message; empty when it runs
  bool complete = false;  // already completed in the database: nothing to do
  run::CaseSize size;
  int cost = -1;  // index into SweepPlan::costs
  // --gpu-rate: this run's seconds per step on the GPU (its own marker count:
  // the input radius, which a configuration leaves out, sets it)
  std::optional<double> gpu_step_s;
  // estimated wall seconds of the run, shortest and longest protocol, on
  // this machine at the planned concurrency; empty without a rate
  std::optional<double> wall_min_s, wall_max_s;
};

struct SweepPlan {
  std::string sweep, backend;
  int jobs = 1;
  int cores = 1;        // this machine's
  double slowdown = 1;  // runs sharing cores: jobs x threads / cores when above 1
  std::vector<PlannedRun> runs;
  std::vector<StepCost> costs;
  int to_run = 0, refused = 0, complete = 0;
  double lattice_updates_min = 0, lattice_updates_max = 0;  // of the runs to run
  std::optional<double> wall_min_s, wall_max_s;             // the whole sweep
  std::optional<double> core_hours_min, core_hours_max;     // of the runs on CPU cores
  double gpu_hours_min = 0, gpu_hours_max = 0;              // of the runs estimated on a GPU
  double memory_per_run_max = 0;   // bytes, the largest configuration measured
  std::vector<std::string> notes;  // warnings: memory, Slurm time limits
};

SweepPlan plan_sweep(const SweepSpec& spec, const PlanOptions& options);

// The plan as text: `every_run` lists each run (flocsim sweep plan); without
// it, one screen of totals, configurations and refusals (flocsim sweep launch).
void write_plan(const SweepPlan& plan, std::ostream& out, bool every_run);

// A Slurm time limit ("MM", "MM:SS", "HH:MM:SS", "D-HH", "D-HH:MM",
// "D-HH:MM:SS") in seconds; empty when it is none of those.
std::optional<double> slurm_time_limit_s(const std::string& limit);

}  // namespace flocsim::orchestrator
