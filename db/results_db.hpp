#pragma once
// The results database of the orchestrator: a versioned SQLite schema with
// sweeps, runs, the attempts made at each run and the results of the runs
// that completed. This file and results_db.cpp are the only code of the
// project that speaks SQL.
//
// Concurrency rules (SQLite in WAL mode, several processes on one file):
//  - every connection sets journal_mode=WAL, a busy timeout and foreign keys;
//  - every write is one short BEGIN IMMEDIATE transaction (no read-then-upgrade
//    deadlocks, writers queue on the busy timeout instead of failing);
//  - a connection belongs to the process that opened it: a ResultsDb used in a
//    forked child throws instead of corrupting the parent's connection. Open a
//    new one after fork.
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "db/run_state.hpp"

struct sqlite3;

namespace flocsim::db {

class DbError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The --db path names something that cannot be a results database (an empty
// path, a folder, a device, a file that is not SQLite, or another program's
// SQLite file): bad input, where the other errors are failures of the place.
class NotADatabaseError : public DbError {
 public:
  using DbError::DbError;
};

// A writer opened a database it may not write (a read-only file, folder or
// file system). Readers open such a database with Mode::kReadOnly.
class ReadOnlyDbError : public DbError {
 public:
  using DbError::DbError;
};

// A writer could not open a database because the file system under it is
// full (SQLite says only "disk I/O error"). Like a read-only one, it can
// still be read.
class DiskFullDbError : public ReadOnlyDbError {
 public:
  using ReadOnlyDbError::ReadOnlyDbError;
};

inline constexpr int kSchemaVersion = 1;

// Run and attempt states (RunState, with their stored text) are in
// db/run_state.hpp.

struct SweepRecord {
  std::int64_t id = 0;
  std::string name;
  std::string spec_json;  // the sweep file as last launched
  std::string axes_json;  // JSON array of the axis paths, in file order
  int max_attempts = 3;
  double created_at = 0, updated_at = 0;
};

struct RunRecord {
  std::string id;         // SHA-256 of the canonical case, hex
  std::string case_json;  // canonical case
  RunState status = RunState::kPending;
  std::string run_dir;
  std::string error;       // text of the last failure, empty when none
  int attempts = 0;        // attempts made
  int failures = 0;        // attempts that ended `failed` (what the retry limit counts)
  std::string point_json;  // axis values of this run in the sweep (when listed per sweep)
};

struct AttemptStart {
  std::string backend = "local";  // local | slurm
  std::string host;
  std::int64_t owner_pid = 0;  // the orchestrator process that watches the worker
  std::string job_id;          // backend job id (Slurm: JOBID_TASK), empty locally
};

struct AttemptRecord {
  std::int64_t id = 0;
  std::string run_id;
  int number = 0;  // 1, 2, ... within the run
  std::string backend, host, job_id;
  RunState state = RunState::kRunning;  // never kPending
  std::string log_path, error;
  std::int64_t pid = 0, owner_pid = 0;
  std::string pid_start;  // process start time (from /proc), guards against pid reuse
  bool resumed = false;
  double started_at = 0;
  std::optional<double> heartbeat_at, ended_at, fraction, eta_s, mlups;
  std::optional<std::int64_t> step, steps_total;
  std::optional<int> exit_code, signal;
};

struct Heartbeat {
  std::int64_t attempt_id = 0;
  double at = 0;  // unix seconds
  std::optional<double> fraction, eta_s, mlups;
  std::optional<std::int64_t> step, steps_total;
};

struct Observable {
  std::string name;
  double mean = 0;
  std::optional<double> error;  // absent for plain numbers
};

struct ResultRecord {
  std::string run_id;
  std::string flocsim_version, completed_at;
  std::optional<double> wall_s, mlups;
  std::optional<std::int64_t> steps;
  std::string window_json;  // averaging window, JSON text ("" when none)
  std::string result_json;  // the whole result.json as recorded
  std::vector<Observable> observables;
  double recorded_at = 0;
};

// How claim_run picks: runs of `sweep_id` in one of `states`, in grid order,
// skipping runs whose failures reached `max_attempts` and runs in `exclude`.
struct ClaimRequest {
  std::int64_t sweep_id = 0;
  std::vector<RunState> states;
  int max_attempts = 3;
  std::optional<std::string> run_id;  // only this run
  std::vector<std::string> exclude;   // never these runs (already tried by the caller)
};

struct Claim {
  RunRecord run;  // as it was before the claim
  std::int64_t attempt_id = 0;
};

struct StateCount {
  RunState status = RunState::kPending;
  int runs = 0;
};

class ResultsDb {
 public:
  // kCreate and kExisting open for writing (kCreate makes a missing file);
  // kReadOnly only reads, also from a read-only file or file system, and
  // never changes the file (no WAL switch, no migration).
  enum class Mode { kCreate, kExisting, kReadOnly };
  // Opens (and creates or migrates, when writable) the database at `path`.
  // A file that is not an SQLite database, or a writer's read-only file, is
  // refused with a DbError (ReadOnlyDbError) naming the path.
  ResultsDb(const std::string& path, Mode mode);
  ~ResultsDb();
  ResultsDb(const ResultsDb&) = delete;
  ResultsDb& operator=(const ResultsDb&) = delete;

  const std::string& path() const { return path_; }
  int schema_version();
  std::string journal_mode();
  std::string integrity_check();  // "ok" when sound

  // --- sweeps ---
  // Inserts the sweep or updates its spec (a grown grid); returns its id.
  std::int64_t upsert_sweep(const std::string& name, const std::string& spec_json,
                            const std::string& axes_json, int max_attempts);
  std::optional<SweepRecord> find_sweep(const std::string& name);
  std::vector<SweepRecord> sweeps();

  // --- runs ---
  struct NewRun {
    std::string id, case_json, run_dir, point_json;
  };
  struct AddedRuns {
    int added = 0;   // runs new to the database
    int reused = 0;  // runs already known (from this or another sweep)
  };
  // Adds the runs (insert-or-ignore by id) and links them to the sweep.
  AddedRuns add_runs(std::int64_t sweep_id, const std::vector<NewRun>& runs);
  std::vector<RunRecord> runs(std::optional<std::int64_t> sweep_id = std::nullopt);
  std::optional<RunRecord> find_run(const std::string& id);
  std::vector<StateCount> count_states(std::optional<std::int64_t> sweep_id = std::nullopt);

  // --- attempts ---
  // Atomically picks a run, opens an attempt (state running, no pid yet) and
  // marks the run running. Empty when nothing is claimable. An attempt at a
  // run that was started before (not pending) is marked `resumed`: the worker
  // continues from the run's checkpoint.
  std::optional<Claim> claim_run(const ClaimRequest& request, const AttemptStart& start);
  // The worker of an attempt started: its pid, start time and log file.
  void set_attempt_pid(std::int64_t attempt_id, std::int64_t pid, const std::string& pid_start,
                       const std::string& log_path);
  // Makes `owner_pid` the watcher of a live attempt whose watcher died.
  bool adopt_attempt(std::int64_t attempt_id, std::int64_t owner_pid);
  void record_heartbeats(const std::vector<Heartbeat>& beats);
  // Closes a live attempt in `state` (failed, refused, interrupted, lost) and
  // sets its run to the same state with `error`. A no-op when the attempt is
  // no longer running (someone else closed it first); returns whether it acted.
  bool end_attempt(std::int64_t attempt_id, RunState state, std::optional<int> exit_code,
                   std::optional<int> signal, const std::string& error);
  // Records a completed run in one transaction: the result and its
  // observables, the attempt closed with exit code 0, the run completed.
  // A run holds at most one result: a second one is refused (returns false)
  // and the attempt is still closed.
  bool record_result(std::int64_t attempt_id, const ResultRecord& result);
  std::vector<AttemptRecord> live_attempts();
  std::vector<AttemptRecord> attempts(const std::string& run_id);
  std::optional<AttemptRecord> find_attempt(std::int64_t attempt_id);

  // --- results ---
  struct ResultRow {
    RunRecord run;
    std::optional<std::int64_t> sweep_id;
    bool has_result = false;
    std::optional<double> wall_s, mlups;
    std::optional<std::int64_t> steps;
    std::string window_json, completed_at, flocsim_version;
    std::string result_json;  // the whole result.json as recorded ("" without a result)
    std::vector<Observable> observables;
  };
  // Every run (of one sweep when given) with its result and observables.
  std::vector<ResultRow> result_rows(std::optional<std::int64_t> sweep_id = std::nullopt);
  int count_results(const std::string& run_id);

 private:
  class Statement;
  void check_owner() const;
  void exec(const char* sql);
  template <class F>
  auto write(F&& body);
  void create_or_migrate();
  void open_read_only();

  std::string path_;
  sqlite3* db_ = nullptr;
  long owner_pid_ = 0;
};

// Seconds since the epoch, with sub-second resolution.
double unix_now();

}  // namespace flocsim::db
