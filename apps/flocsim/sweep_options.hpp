#pragma once
// The options of `flocsim sweep`'s subcommands, as the command line gives them.
#include <string>
#include <vector>

namespace flocsim::app {

struct SweepOptions {
  std::string sweep_file, db_path, runs_dir, backend = "local", worker, sweep_name;
  std::string device;  // --device: every worker's, overriding the cases' own
  int jobs = 1;
  double lease_s = 60;
  double grace_s = 120;
  bool no_wait = false;
  bool jobs_given = false;  // --jobs on the command line (the local pool's; Slurm has its own)
  int measure_steps = 3;
  double watch_s = 0;
  std::string plan_db;
  std::vector<std::string> gpu_rate_files;  // plan --gpu-rate
  // slurm-task (internal)
  std::string task_file;
};

}  // namespace flocsim::app
