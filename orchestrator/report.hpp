#pragma once
// What `flocsim query` and `flocsim sweep status` print. The runs a query
// lists and its filters are run_selection.hpp's, shared with `flocsim post`.
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "db/results_db.hpp"
#include "orchestrator/run_selection.hpp"

namespace flocsim::orchestrator {

// A mean shown to the precision its standard error supports: the error
// rounded to one significant digit and the mean to the same decimal place,
// "0.304 ± 0.002" (not "0.303742 ± 0.00189871"). Without an error (or a zero
// one) the mean is shown to 4 significant digits.
std::string format_with_error(double mean, std::optional<double> error,
                              const std::string& plus_minus = " ± ");

// A duration as a user reads it: "45 s", "12.5 min", "3.2 h", "6.1 days".
std::string duration_text(double seconds);

struct QueryOptions {
  std::optional<std::string> sweep;  // restrict to one sweep
  std::vector<Filter> where;
  std::string format = "table";  // table | csv | json
  // Only these columns (an observable brings its error along), in this order;
  // empty: every column some row fills (the table: the first-read ones first).
  std::vector<std::string> columns;
  // table: fit this many characters, leaving out the last columns (0: no limit)
  std::size_t width = 0;
  // Where the rows left out as unreadable are listed (run, field, what is
  // wrong); the table's last line counts them.
  std::ostream* left_out = nullptr;
};

// Runs the query and writes it to `out`; returns the number of rows written.
int write_query(db::ResultsDb& db, const QueryOptions& options, std::ostream& out);

// When a sweep will be done, from what its runs report. The time a whole run
// takes is the mean wall time of the completed runs; before any run has
// completed, each running attempt's rate extrapolated to a whole run
// (eta / (1 - fraction): the runs of a sweep share their step count and
// lattice more often than not, so this is an estimate, said as such).
struct RunningProgress {
  double fraction = 0;          // of the run's steps done
  std::optional<double> eta_s;  // the worker's own estimate for what is left (< 0: none yet)
};
struct SweepEta {
  double remaining_s = 0;          // the slowest running run, then the waiting ones
  double per_run_s = 0;            // 0 when nothing waits
  int lanes = 1;                   // runs that go at once (the running ones, at least 1)
  bool from_running_rate = false;  // per_run_s extrapolated, no run completed yet
};
// Empty when nothing runs or waits, when a running run has no estimate yet,
// or when runs wait and neither a completed run nor a running one with
// progress gives their length.
std::optional<SweepEta> estimate_sweep_eta(const std::vector<double>& completed_wall_s,
                                           const std::vector<RunningProgress>& running,
                                           int waiting);

// Counts by state (lost and recovered runs too); each running run's stage,
// simulated time, share done and ETA (from its progress.json); the runs that
// did not finish with the first line of why and the command that retries
// them; the sweep's ETA. True while a run of the sweep(s) is running.
bool write_status(db::ResultsDb& db, const std::optional<std::string>& sweep, std::ostream& out);

}  // namespace flocsim::orchestrator
