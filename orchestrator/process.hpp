#pragma once
// Worker processes: start them, tell whether one still lives, read what it
// left on disk (progress.json heartbeat, result.json).
#include <sys/types.h>

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "db/results_db.hpp"

namespace flocsim::orchestrator {

std::string host_name();
// Start time of a process (field 22 of /proc/PID/stat, clock ticks since boot),
// empty when it cannot be read. Together with the pid it names one process:
// a recycled pid has another start time.
std::string process_start_time(pid_t pid);
// True while the process exists and is not a zombie; when `start_time` is not
// empty the process must also have that start time.
bool process_alive(pid_t pid, const std::string& start_time = "");

// fork + exec of `argv` with stdout and stderr appended to `log_file`, in its
// own process group (a Ctrl-C at the terminal reaches the orchestrator, which
// stops workers itself). On Linux the worker gets SIGTERM when the process
// that started it dies, so it checkpoints instead of running on unwatched.
// Only async-signal-safe calls happen between fork and exec: no database
// connection is touched in the child. `environment` adds to or replaces
// variables of the worker's environment (a GPU: CUDA_VISIBLE_DEVICES).
pid_t spawn(const std::vector<std::string>& argv, const std::string& log_file,
            const std::vector<std::pair<std::string, std::string>>& environment = {});

// What progress.json says (the heartbeat); empty when absent or unreadable.
std::optional<db::Heartbeat> read_progress(const std::string& run_dir);
// Where a run stands in its own terms, from its progress.json: its stage and
// simulated time (written by sphere scenes; empty fields otherwise).
struct RunStage {
  std::string stage;                       // "stage 1", "stage 2", "statistics"
  std::optional<double> time, time_total;  // simulated time now and at the end
  std::string time_unit;                   // "a/U_inf"
};
RunStage read_run_stage(const std::string& run_dir);

// Parses DIR/result.json into a record for `run_id`. Returns the reason when
// the file is missing, truncated, not JSON or not a completed result.
struct ResultRead {
  std::optional<db::ResultRecord> record;
  std::string problem;
  bool foreign = false;  // complete, but the result of another case
};
ResultRead read_result(const std::string& run_dir, const std::string& run_id);

// The last `max_chars` characters of a text file (whole lines), for error text.
std::string tail_of_file(const std::string& filename, std::size_t max_chars = 1500);

std::string signal_name(int sig);

}  // namespace flocsim::orchestrator
