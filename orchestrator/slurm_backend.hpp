#pragma once
// The Slurm backend: the runs to do are packed into a job array (several runs
// per array task when the sweep asks for it); each array task is
// `flocsim sweep slurm-task`, which claims its runs in the results database
// and runs them one after the other with the same worker code as the local
// pool (heartbeats, result recording, graceful stop on scancel). The launcher
// follows the job with squeue; the database, not the scheduler, says what
// finished. Runs still marked running when their job has left the queue are lost.
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "db/results_db.hpp"

namespace flocsim::orchestrator {

struct SlurmLaunch {
  std::string worker;   // program run as `WORKER run CASE --out DIR` inside the tasks
  std::string flocsim;  // this flocsim, run as `flocsim sweep slurm-task` by each task
  std::string device;   // "cpu", "cuda" or empty (each case's own): --device of the workers
  std::vector<db::RunState> states{db::RunState::kPending, db::RunState::kInterrupted,
                                   db::RunState::kLost};
  double lease_s = 60;
  bool wait = true;  // follow the job until it leaves the queue
  double poll_s = 1.0;
  std::ostream* out = nullptr;
};

struct SlurmSummary {
  std::string job_id;  // empty when nothing was submitted
  int tasks = 0, runs = 0;
  int lost = 0;  // runs left running by a job that ended
  bool stopped = false;
  // Tasks that Slurm says did not complete: "task N STATE (exit C), output F; ..."
  std::string failed_tasks;
};

// True when sbatch and squeue can be run and answer.
bool slurm_available(std::string* why = nullptr);

SlurmSummary run_slurm(db::ResultsDb& db, const db::SweepRecord& sweep, const SlurmLaunch& launch);

// The body of one array task: runs the run ids listed in `task_file`.
int run_slurm_task(db::ResultsDb& db, const db::SweepRecord& sweep, const std::string& task_file,
                   const std::string& worker, double lease_s, std::ostream& out);

// Asks every live orchestrator on this host (SIGTERM) and every Slurm job with
// live attempts (scancel) to stop; returns how many were asked.
int cancel_all(db::ResultsDb& db, std::ostream& out);

}  // namespace flocsim::orchestrator
