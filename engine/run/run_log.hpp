#pragma once
// What a run tells its user: a log file in the output directory (always), the
// same lines on stderr (unless quiet), and a progress line that updates in
// place on a terminal and prints plain lines otherwise. progress.json, the
// heartbeat the orchestrator watches, is rewritten atomically with it.
#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>

namespace flocsim::run {

class RunLog {
 public:
  RunLog(const std::filesystem::path& file, bool quiet);
  void info(const std::string& line);
  void warning(const std::string& line) { info("warning: " + line); }
  void error(const std::string& line) { info("error: " + line); }
  bool quiet() const { return quiet_; }
  // Ends an in-place progress line before other output.
  void break_progress_line();
  void progress_line(const std::string& line);

 private:
  std::ofstream file_;
  bool quiet_;
  bool terminal_;
  bool progress_open_ = false;
};

struct ProgressSnapshot {
  long step = 0;
  long steps_total = 0;
  double mlups = 0;
  double eta_s = 0;
};

// Reports progress at most every `every_s` seconds on the log and rewrites
// progress.json at most every min(every_s, 5) seconds. `cells` is the number
// of lattice cells updated per step (0 for runs without a liquid: no MLUPS).
class ProgressReporter {
 public:
  ProgressReporter(RunLog& log, std::filesystem::path progress_json, long first_step,
                   long steps_total, long cells, double every_s);
  // Call after each step; cheap when nothing is due.
  void update(long step, const std::string& extra = "");
  // Forces a final report.
  void finish(long step);
  // Runs whose length is decided on the way (stationarity) revise their total.
  void set_steps_total(long steps_total);
  // Where the run stands in its own terms (its stage, its simulated time),
  // written into progress.json with the next report for `flocsim sweep status`.
  void set_state(nlohmann::json state) { state_ = std::move(state); }
  double mlups(long step) const;

 private:
  // last: the final report, printed whatever the cadence
  void report(long step, const std::string& extra, bool last = false);
  RunLog& log_;
  std::filesystem::path progress_json_;
  long first_step_, steps_total_, cells_;
  double every_s_;
  nlohmann::json state_ = nlohmann::json::object();
  std::chrono::steady_clock::time_point start_, last_print_, last_json_;
};

std::string format_duration(double seconds);

}  // namespace flocsim::run
