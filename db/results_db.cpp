#include "db/results_db.hpp"

#include <fcntl.h>
#include <sqlite3.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <utility>

#include "engine/result_names/result_names.hpp"

namespace flocsim::db {

double unix_now() {
  using namespace std::chrono;
  return duration<double>(system_clock::now().time_since_epoch()).count();
}

namespace {

constexpr int kBusyTimeoutMs = 60000;

// Version 1 of the schema (its tables; the view follows). Later versions
// append migrations below; a database records its version in PRAGMA
// user_version.
constexpr const char* kSchemaV1Tables = R"sql(
CREATE TABLE sweeps (
  id            INTEGER PRIMARY KEY,
  name          TEXT NOT NULL UNIQUE,
  spec_json     TEXT NOT NULL,
  axes_json     TEXT NOT NULL,
  max_attempts  INTEGER NOT NULL CHECK (max_attempts >= 1),
  created_at    REAL NOT NULL,
  updated_at    REAL NOT NULL
);
CREATE TABLE runs (
  id          TEXT PRIMARY KEY,
  case_json   TEXT NOT NULL,
  status      TEXT NOT NULL DEFAULT 'pending' CHECK (status IN
                ('pending','running','completed','failed','refused','interrupted','lost')),
  run_dir     TEXT NOT NULL,
  error       TEXT NOT NULL DEFAULT '',
  created_at  REAL NOT NULL,
  updated_at  REAL NOT NULL
);
CREATE TABLE sweep_runs (
  sweep_id    INTEGER NOT NULL REFERENCES sweeps(id),
  run_id      TEXT NOT NULL REFERENCES runs(id),
  point_json  TEXT NOT NULL,
  PRIMARY KEY (sweep_id, run_id)
);
CREATE INDEX sweep_runs_by_run ON sweep_runs(run_id);
CREATE TABLE attempts (
  id            INTEGER PRIMARY KEY,
  run_id        TEXT NOT NULL REFERENCES runs(id),
  number        INTEGER NOT NULL,
  backend       TEXT NOT NULL,
  host          TEXT NOT NULL,
  pid           INTEGER,
  pid_start     TEXT NOT NULL DEFAULT '',
  owner_pid     INTEGER NOT NULL,
  job_id        TEXT NOT NULL DEFAULT '',
  resumed       INTEGER NOT NULL,
  state         TEXT NOT NULL CHECK (state IN
                  ('running','completed','failed','refused','interrupted','lost')),
  started_at    REAL NOT NULL,
  heartbeat_at  REAL,
  ended_at      REAL,
  exit_code     INTEGER,
  signal        INTEGER,
  fraction      REAL,
  eta_s         REAL,
  mlups         REAL,
  step          INTEGER,
  steps_total   INTEGER,
  log_path      TEXT NOT NULL DEFAULT '',
  error         TEXT NOT NULL DEFAULT '',
  UNIQUE (run_id, number)
);
CREATE INDEX attempts_live ON attempts(state) WHERE state = 'running';
CREATE TABLE results (
  run_id           TEXT PRIMARY KEY REFERENCES runs(id),
  attempt_id       INTEGER NOT NULL REFERENCES attempts(id),
  flocsim_version  TEXT NOT NULL,
  completed_at     TEXT NOT NULL,
  wall_s           REAL,
  mlups            REAL,
  steps            INTEGER,
  window_json      TEXT NOT NULL DEFAULT '',
  result_json      TEXT NOT NULL,
  recorded_at      REAL NOT NULL
);
CREATE TABLE observables (
  run_id  TEXT NOT NULL REFERENCES results(run_id),
  name    TEXT NOT NULL,
  mean    REAL NOT NULL,
  error   REAL,
  PRIMARY KEY (run_id, name)
);
)sql";

// The suspension_results view of schema version 1: one row per result, the
// mean and error of each summary observable as columns, named as result.json
// names them (result_names::kSummaryObservables).
std::string suspension_results_view() {
  std::string sql = "CREATE VIEW suspension_results AS\nSELECT r.run_id,\n";
  for (const std::string_view name : result_names::kSummaryObservables) {
    const std::string n(name);
    sql += "  (SELECT mean  FROM observables o WHERE o.run_id = r.run_id AND o.name = '" + n +
           "') AS " + n + ",\n";
    sql += "  (SELECT error FROM observables o WHERE o.run_id = r.run_id AND o.name = '" + n +
           "') AS " + n + "_error,\n";
  }
  return sql + "  r.window_json, r.wall_s, r.mlups, r.steps\nFROM results r;\n";
}

std::string schema_v1() {
  return kSchemaV1Tables + suspension_results_view();
}

}  // namespace

// A prepared statement with positional binding (1-based) and typed columns.
class ResultsDb::Statement {
 public:
  Statement(sqlite3* db, const char* sql) : db_(db) {
    if (sqlite3_prepare_v2(db, sql, -1, &stmt_, nullptr) != SQLITE_OK)
      throw DbError(std::string("SQL prepare failed: ") + sqlite3_errmsg(db) + " in: " + sql);
  }
  ~Statement() { sqlite3_finalize(stmt_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  Statement& bind(int i, std::int64_t v) {
    check(sqlite3_bind_int64(stmt_, i, v));
    return *this;
  }
  Statement& bind(int i, int v) { return bind(i, static_cast<std::int64_t>(v)); }
  Statement& bind(int i, double v) {
    check(sqlite3_bind_double(stmt_, i, v));
    return *this;
  }
  Statement& bind(int i, const std::string& v) {
    check(sqlite3_bind_text(stmt_, i, v.data(), static_cast<int>(v.size()), SQLITE_TRANSIENT));
    return *this;
  }
  template <class T>
  Statement& bind(int i, const std::optional<T>& v) {
    if (v) return bind(i, *v);
    check(sqlite3_bind_null(stmt_, i));
    return *this;
  }
  // Steps once; true while a row is available.
  bool step() {
    const int rc = sqlite3_step(stmt_);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    throw DbError(std::string("SQL step failed: ") + sqlite3_errmsg(db_) +
                  " in: " + sqlite3_sql(stmt_));
  }
  void run() {
    while (step()) {
    }
  }
  // Makes the statement ready to run again with new bindings.
  void reset() {
    sqlite3_reset(stmt_);
    sqlite3_clear_bindings(stmt_);
  }
  bool null(int c) const { return sqlite3_column_type(stmt_, c) == SQLITE_NULL; }
  std::int64_t i64(int c) const { return sqlite3_column_int64(stmt_, c); }
  double real(int c) const { return sqlite3_column_double(stmt_, c); }
  std::string text(int c) const {
    const unsigned char* t = sqlite3_column_text(stmt_, c);
    return t ? std::string(reinterpret_cast<const char*>(t),
                           static_cast<std::size_t>(sqlite3_column_bytes(stmt_, c)))
             : std::string();
  }
  // A run or attempt state; text the schema does not know is a DbError.
  RunState state(int c) const {
    try {
      return run_state_from_string(text(c));
    } catch (const std::invalid_argument& e) {
      throw DbError(std::string(e.what()) + " in column " + sqlite3_column_name(stmt_, c) +
                    " of: " + sqlite3_sql(stmt_));
    }
  }
  std::optional<double> opt_real(int c) const {
    return null(c) ? std::nullopt : std::optional<double>(real(c));
  }
  std::optional<std::int64_t> opt_i64(int c) const {
    return null(c) ? std::nullopt : std::optional<std::int64_t>(i64(c));
  }

 private:
  void check(int rc) {
    if (rc != SQLITE_OK) throw DbError(std::string("SQL bind failed: ") + sqlite3_errmsg(db_));
  }
  sqlite3* db_;
  sqlite3_stmt* stmt_ = nullptr;
};

namespace {

// An existing file that does not start with SQLite's 16-byte header is not a
// database; say so before SQLite answers with a bare "file is not a database".
void refuse_non_sqlite_file(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::exists(path, ec)) return;
  if (fs::is_directory(path, ec))
    throw NotADatabaseError(path + ": is a directory; --db must name a results database file");
  if (fs::file_size(path, ec) == 0 || ec) return;  // an empty file becomes a new database
  char header[16] = {};
  std::ifstream in(path, std::ios::binary);
  in.read(header, sizeof header);
  if (in.gcount() < 16 || std::memcmp(header, "SQLite format 3", 16) != 0)
    throw NotADatabaseError(path +
                            ": not an SQLite database (it does not start with the SQLite header); "
                            "--db must name a results database written by `flocsim sweep launch`");
}

// Checks the path before SQLite sees it, with the operating system's reason:
// SQLite says only "unable to open database file" (a file in the place of a
// folder, a read-only folder, /proc), blames WAL for an empty path, and on a
// device (/dev/null) says "disk I/O error" after leaving DEVICE-journal beside it.
void check_db_path(const std::string& path, ResultsDb::Mode mode) {
  namespace fs = std::filesystem;
  if (path.empty())
    throw NotADatabaseError(
        "--db \"\": an empty path; give a results database file (e.g. runs/demo.sqlite)");
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0) {
    if (S_ISDIR(st.st_mode))
      throw NotADatabaseError(path + ": is a directory; --db must name a results database file");
    if (!S_ISREG(st.st_mode))
      throw NotADatabaseError(
          path +
          ": not a regular file (a device, a pipe or a socket); --db must name a "
          "results database file");
    return;
  }
  const int err = errno;
  if (err != ENOENT || mode != ResultsDb::Mode::kCreate) {
    if (err == ENOENT) return;  // said below, with what creates it
    throw DbError("cannot open results database " + path + ": " + std::strerror(err));
  }
  // a new database may live in a folder that does not exist yet (runs/x.sqlite)
  const fs::path parent = fs::path(path).parent_path();
  std::error_code ec;
  if (!parent.empty()) fs::create_directories(parent, ec);
  if (ec)
    throw DbError("cannot create results database " + path + ": its folder " + parent.string() +
                  " cannot be made (" + ec.message() + ")");
  const std::string folder = parent.empty() ? "." : parent.string();
  if (::access(folder.c_str(), W_OK | X_OK) != 0)
    throw DbError("cannot create results database " + path + " in " + folder + ": " +
                  std::strerror(errno));
  // made here, where the system says why it cannot be (a /proc folder passes
  // the check above); SQLite takes an empty file as a new database
  const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0 && errno != EEXIST)
    throw DbError("cannot create results database " + path + ": " + std::strerror(errno));
  if (fd >= 0) ::close(fd);
}

// Whether the file system holding `path` has (next to) no room left for an
// unprivileged writer.
bool file_system_full(const std::string& path) {
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  struct statvfs fs {};
  if (::statvfs(parent.empty() ? "." : parent.c_str(), &fs) != 0) return false;
  return static_cast<double>(fs.f_bavail) * static_cast<double>(fs.f_frsize) < 64.0 * 1024;
}

}  // namespace

ResultsDb::ResultsDb(const std::string& path, Mode mode) : path_(path), owner_pid_(getpid()) {
  check_db_path(path, mode);
  refuse_non_sqlite_file(path);
  if (mode == Mode::kReadOnly) {
    open_read_only();
    return;
  }
  const int flags = SQLITE_OPEN_READWRITE | SQLITE_OPEN_NOMUTEX |
                    (mode == Mode::kCreate ? SQLITE_OPEN_CREATE : 0);
  const int rc = sqlite3_open_v2(path.c_str(), &db_, flags, nullptr);
  if (rc != SQLITE_OK) {
    const std::string why = db_ ? sqlite3_errmsg(db_) : sqlite3_errstr(rc);
    sqlite3_close(db_);
    db_ = nullptr;
    throw DbError(
        "cannot open results database " + path + ": " + why +
        (mode == Mode::kExisting ? " (does it exist? `flocsim sweep launch` creates it)" : ""));
  }
  const std::string read_only_message =
      "results database " + path +
      " is read-only (file permissions or a read-only file system), and this command writes to "
      "it; `flocsim query` and `flocsim sweep status` can still read it";
  if (sqlite3_db_readonly(db_, "main") == 1) {
    sqlite3_close(db_);
    db_ = nullptr;
    throw ReadOnlyDbError(read_only_message);
  }
  sqlite3_busy_timeout(db_, kBusyTimeoutMs);
  try {
    exec("PRAGMA foreign_keys = ON");
    // Switching to WAL is persistent; once the file is in WAL this is a read.
    {
      Statement wal(db_, "PRAGMA journal_mode = WAL");
      wal.step();
      if (wal.text(0) != "wal")
        throw DbError("results database " + path + " cannot use WAL journaling (got " +
                      wal.text(0) + "); is it on a network file system?");
    }
    exec("PRAGMA synchronous = NORMAL");
    create_or_migrate();
  } catch (const DbError& e) {
    const int code = sqlite3_errcode(db_);
    sqlite3_close(db_);
    db_ = nullptr;
    // a writable file in a read-only folder: WAL cannot make its -wal file
    if (code == SQLITE_READONLY || code == SQLITE_CANTOPEN)
      throw ReadOnlyDbError(read_only_message);
    // a full file system: WAL cannot make its -shm index, and SQLite says
    // "disk I/O error"; said as what it is, and readable as a read-only one
    if ((code == SQLITE_FULL || (code & 0xff) == SQLITE_IOERR) && file_system_full(path))
      throw DiskFullDbError("the file system under results database " + path +
                            " is full, and this command writes to it: free some space; "
                            "`flocsim query` and `flocsim sweep status` can still read it");
    throw DbError(std::string(e.what()).find(path) == std::string::npos
                      ? "results database " + path + ": " + e.what()
                      : std::string(e.what()));
  }
}

// Read-only: no WAL switch, no migration. A WAL database in a folder where
// the -shm index cannot be made is read as immutable when it has no -wal
// content (nothing to miss); otherwise the reader must be able to make it.
void ResultsDb::open_read_only() {
  auto open = [&](const std::string& name, int extra) {
    sqlite3_close(db_);
    db_ = nullptr;
    const int rc = sqlite3_open_v2(name.c_str(), &db_,
                                   SQLITE_OPEN_READONLY | SQLITE_OPEN_NOMUTEX | extra, nullptr);
    if (rc != SQLITE_OK) return false;
    sqlite3_busy_timeout(db_, kBusyTimeoutMs);
    return sqlite3_exec(db_, "SELECT count(*) FROM sqlite_master", nullptr, nullptr, nullptr) ==
           SQLITE_OK;
  };
  if (!std::filesystem::exists(path_)) {
    throw DbError("cannot open results database " + path_ +
                  ": no such file (does it exist? `flocsim sweep launch` creates it)");
  }
  bool ok = open(path_, 0);
  if (!ok) {
    std::error_code ec;
    const auto wal = std::filesystem::file_size(path_ + "-wal", ec);
    if (ec || wal == 0) ok = open("file:" + path_ + "?immutable=1", SQLITE_OPEN_URI);
  }
  if (!ok) {
    const std::string why = db_ ? sqlite3_errmsg(db_) : "cannot open";
    sqlite3_close(db_);
    db_ = nullptr;
    throw DbError("cannot read results database " + path_ + ": " + why);
  }
  const int found = schema_version();
  if (found != kSchemaVersion) {
    sqlite3_close(db_);
    db_ = nullptr;
    // a database `sweep launch` has only just created holds no schema yet
    throw DbError(found == 0
                      ? path_ +
                            ": holds no flocsim results (does it exist? `flocsim sweep "
                            "launch` creates it)"
                      : path_ + " has schema version " + std::to_string(found) +
                            ", this flocsim reads version " + std::to_string(kSchemaVersion));
  }
}

ResultsDb::~ResultsDb() {
  // A forked child must not close (and so checkpoint) its parent's connection.
  if (db_ && getpid() == owner_pid_) sqlite3_close(db_);
}

void ResultsDb::check_owner() const {
  if (getpid() != owner_pid_)
    throw DbError("results database connection used in a forked child; open a new one after fork");
}

void ResultsDb::exec(const char* sql) {
  check_owner();
  char* err = nullptr;
  if (sqlite3_exec(db_, sql, nullptr, nullptr, &err) != SQLITE_OK) {
    std::string why = err ? err : "unknown error";
    sqlite3_free(err);
    throw DbError("SQL failed on " + path_ + ": " + why);
  }
}

// Runs `body` inside one BEGIN IMMEDIATE transaction; rolls back on throw.
template <class F>
auto ResultsDb::write(F&& body) {
  exec("BEGIN IMMEDIATE");
  try {
    if constexpr (std::is_void_v<decltype(body())>) {
      body();
      exec("COMMIT");
    } else {
      auto out = body();
      exec("COMMIT");
      return out;
    }
  } catch (...) {
    sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
    throw;
  }
}

int ResultsDb::schema_version() {
  check_owner();
  Statement s(db_, "PRAGMA user_version");
  s.step();
  return static_cast<int>(s.i64(0));
}

std::string ResultsDb::journal_mode() {
  check_owner();
  Statement s(db_, "PRAGMA journal_mode");
  s.step();
  return s.text(0);
}

std::string ResultsDb::integrity_check() {
  check_owner();
  Statement s(db_, "PRAGMA integrity_check");
  std::string out;
  while (s.step()) out += (out.empty() ? "" : "\n") + s.text(0);
  return out;
}

void ResultsDb::create_or_migrate() {
  const int found = schema_version();
  if (found == kSchemaVersion) return;
  if (found > kSchemaVersion)
    throw DbError("results database " + path_ + " has schema version " + std::to_string(found) +
                  ", newer than this flocsim understands (" + std::to_string(kSchemaVersion) +
                  "); use a newer flocsim");
  write([&] {
    // Re-read inside the write lock: another process may have created it.
    const int now = schema_version();
    if (now == kSchemaVersion) return;
    if (now == 0) {
      Statement any(db_, "SELECT count(*) FROM sqlite_master");
      any.step();
      if (any.i64(0) != 0)
        throw NotADatabaseError(path_ + " is an SQLite file but not a flocsim results database");
      exec(schema_v1().c_str());
    }
    exec(("PRAGMA user_version = " + std::to_string(kSchemaVersion)).c_str());
  });
}

// --- sweeps ---

std::int64_t ResultsDb::upsert_sweep(const std::string& name, const std::string& spec_json,
                                     const std::string& axes_json, int max_attempts) {
  check_owner();
  return write([&] {
    const double now = unix_now();
    Statement s(db_,
                "INSERT INTO sweeps (name, spec_json, axes_json, max_attempts, created_at, "
                "updated_at) VALUES (?1, ?2, ?3, ?4, ?5, ?5) ON CONFLICT (name) DO UPDATE SET "
                "spec_json = excluded.spec_json, axes_json = excluded.axes_json, "
                "max_attempts = excluded.max_attempts, updated_at = excluded.updated_at");
    s.bind(1, name).bind(2, spec_json).bind(3, axes_json).bind(4, max_attempts).bind(5, now).run();
    Statement id(db_, "SELECT id FROM sweeps WHERE name = ?1");
    id.bind(1, name);
    id.step();
    return id.i64(0);
  });
}

namespace {
constexpr const char* kSweepColumns =
    "SELECT id, name, spec_json, axes_json, max_attempts, created_at, updated_at FROM sweeps ";
}

std::optional<SweepRecord> ResultsDb::find_sweep(const std::string& name) {
  for (SweepRecord& s : sweeps())
    if (s.name == name) return s;
  return std::nullopt;
}

std::vector<SweepRecord> ResultsDb::sweeps() {
  check_owner();
  Statement s(db_, (std::string(kSweepColumns) + "ORDER BY id").c_str());
  std::vector<SweepRecord> out;
  while (s.step())
    out.push_back({s.i64(0), s.text(1), s.text(2), s.text(3), static_cast<int>(s.i64(4)), s.real(5),
                   s.real(6)});
  return out;
}

// --- runs ---

ResultsDb::AddedRuns ResultsDb::add_runs(std::int64_t sweep_id, const std::vector<NewRun>& runs) {
  check_owner();
  return write([&] {
    AddedRuns out;
    const double now = unix_now();
    Statement ins(db_,
                  "INSERT OR IGNORE INTO runs (id, case_json, run_dir, created_at, updated_at) "
                  "VALUES (?1, ?2, ?3, ?4, ?4)");
    Statement link(db_,
                   "INSERT INTO sweep_runs (sweep_id, run_id, point_json) VALUES (?1, ?2, ?3) "
                   "ON CONFLICT (sweep_id, run_id) DO UPDATE SET point_json = excluded.point_json");
    for (const NewRun& r : runs) {
      ins.reset();
      ins.bind(1, r.id).bind(2, r.case_json).bind(3, r.run_dir).bind(4, now).run();
      if (sqlite3_changes(db_) > 0)
        ++out.added;
      else
        ++out.reused;
      link.reset();
      link.bind(1, sweep_id).bind(2, r.id).bind(3, r.point_json).run();
    }
    return out;
  });
}

namespace {
// Columns of a run with its attempt and failure counts; `?1` filters by sweep
// when not NULL.
constexpr const char* kRunSelect =
    "SELECT r.id, r.case_json, r.status, r.run_dir, r.error, "
    "(SELECT count(*) FROM attempts a WHERE a.run_id = r.id), "
    "(SELECT count(*) FROM attempts a WHERE a.run_id = r.id AND a.state = 'failed'), ";
}  // namespace

std::vector<RunRecord> ResultsDb::runs(std::optional<std::int64_t> sweep_id) {
  check_owner();
  const std::string sql =
      sweep_id ? std::string(kRunSelect) +
                     "sr.point_json FROM sweep_runs sr JOIN runs r ON r.id = sr.run_id "
                     "WHERE sr.sweep_id = ?1 ORDER BY sr.rowid"
               : std::string(kRunSelect) + "'' FROM runs r ORDER BY r.rowid";
  Statement s(db_, sql.c_str());
  if (sweep_id) s.bind(1, *sweep_id);
  std::vector<RunRecord> out;
  while (s.step())
    out.push_back({s.text(0), s.text(1), s.state(2), s.text(3), s.text(4),
                   static_cast<int>(s.i64(5)), static_cast<int>(s.i64(6)), s.text(7)});
  return out;
}

std::optional<RunRecord> ResultsDb::find_run(const std::string& id) {
  check_owner();
  Statement s(db_, (std::string(kRunSelect) + "'' FROM runs r WHERE r.id = ?1").c_str());
  s.bind(1, id);
  if (!s.step()) return std::nullopt;
  return RunRecord{s.text(0),
                   s.text(1),
                   s.state(2),
                   s.text(3),
                   s.text(4),
                   static_cast<int>(s.i64(5)),
                   static_cast<int>(s.i64(6)),
                   ""};
}

std::vector<StateCount> ResultsDb::count_states(std::optional<std::int64_t> sweep_id) {
  check_owner();
  std::map<RunState, int> counts;
  for (RunState st : kAllRunStates) counts[st] = 0;
  Statement s(db_, sweep_id ? "SELECT r.status, count(*) FROM sweep_runs sr JOIN runs r ON r.id "
                              "= sr.run_id WHERE sr.sweep_id = ?1 GROUP BY r.status"
                            : "SELECT status, count(*) FROM runs GROUP BY status");
  if (sweep_id) s.bind(1, *sweep_id);
  while (s.step()) counts[s.state(0)] = static_cast<int>(s.i64(1));
  std::vector<StateCount> out;
  for (RunState st : kAllRunStates) out.push_back({st, counts[st]});
  return out;
}

// --- attempts ---

std::optional<Claim> ResultsDb::claim_run(const ClaimRequest& request, const AttemptStart& start) {
  check_owner();
  if (request.states.empty()) return std::nullopt;
  std::string in;
  for (std::size_t i = 0; i < request.states.size(); ++i)
    in += (i ? ", ?" : "?") + std::to_string(i + 5);
  const std::string sql = std::string(kRunSelect) +
                          "sr.point_json FROM sweep_runs sr JOIN runs r ON r.id = sr.run_id "
                          "WHERE sr.sweep_id = ?1 AND (?3 IS NULL OR r.id = ?3) AND r.id NOT IN "
                          "(SELECT value FROM json_each(?4)) AND r.status IN (" +
                          in +
                          ") AND (SELECT count(*) FROM attempts a WHERE a.run_id = r.id AND "
                          "a.state = 'failed') < ?2 ORDER BY sr.rowid LIMIT 1";
  return write([&]() -> std::optional<Claim> {
    Statement pick(db_, sql.c_str());
    std::string exclude = "[";
    for (std::size_t i = 0; i < request.exclude.size(); ++i)
      exclude += (i ? ",\"" : "\"") + request.exclude[i] + "\"";
    exclude += "]";
    pick.bind(1, request.sweep_id).bind(2, request.max_attempts).bind(3, request.run_id);
    pick.bind(4, exclude);
    for (std::size_t i = 0; i < request.states.size(); ++i)
      pick.bind(static_cast<int>(i + 5), to_string(request.states[i]));
    if (!pick.step()) return std::nullopt;
    Claim c;
    c.run = {pick.text(0),
             pick.text(1),
             pick.state(2),
             pick.text(3),
             pick.text(4),
             static_cast<int>(pick.i64(5)),
             static_cast<int>(pick.i64(6)),
             pick.text(7)};
    const double now = unix_now();
    Statement ins(db_,
                  "INSERT INTO attempts (run_id, number, backend, host, owner_pid, job_id, "
                  "resumed, state, started_at, heartbeat_at) VALUES (?1, ?2, ?3, ?4, "
                  "?5, ?6, ?7, 'running', ?8, ?8)");
    ins.bind(1, c.run.id)
        .bind(2, c.run.attempts + 1)
        .bind(3, start.backend)
        .bind(4, start.host)
        .bind(5, start.owner_pid)
        .bind(6, start.job_id)
        .bind(7, c.run.status != RunState::kPending ? 1 : 0)
        .bind(8, now)
        .run();
    c.attempt_id = sqlite3_last_insert_rowid(db_);
    Statement upd(db_, "UPDATE runs SET status = 'running', updated_at = ?2 WHERE id = ?1");
    upd.bind(1, c.run.id).bind(2, now).run();
    return c;
  });
}

void ResultsDb::set_attempt_pid(std::int64_t attempt_id, std::int64_t pid,
                                const std::string& pid_start, const std::string& log_path) {
  check_owner();
  write([&] {
    Statement s(db_, "UPDATE attempts SET pid = ?2, pid_start = ?3, log_path = ?4 WHERE id = ?1");
    s.bind(1, attempt_id).bind(2, pid).bind(3, pid_start).bind(4, log_path).run();
  });
}

bool ResultsDb::adopt_attempt(std::int64_t attempt_id, std::int64_t owner_pid) {
  check_owner();
  return write([&] {
    Statement s(db_, "UPDATE attempts SET owner_pid = ?2 WHERE id = ?1 AND state = 'running'");
    s.bind(1, attempt_id).bind(2, owner_pid).run();
    return sqlite3_changes(db_) > 0;
  });
}

void ResultsDb::record_heartbeats(const std::vector<Heartbeat>& beats) {
  check_owner();
  if (beats.empty()) return;
  write([&] {
    for (const Heartbeat& b : beats) {
      Statement s(db_,
                  "UPDATE attempts SET heartbeat_at = max(coalesce(heartbeat_at, 0), ?2), "
                  "fraction = coalesce(?3, fraction), eta_s = coalesce(?4, eta_s), "
                  "mlups = coalesce(?5, mlups), step = coalesce(?6, step), "
                  "steps_total = coalesce(?7, steps_total) WHERE id = ?1 AND state = 'running'");
      s.bind(1, b.attempt_id)
          .bind(2, b.at)
          .bind(3, b.fraction)
          .bind(4, b.eta_s)
          .bind(5, b.mlups)
          .bind(6, b.step)
          .bind(7, b.steps_total)
          .run();
    }
  });
}

bool ResultsDb::end_attempt(std::int64_t attempt_id, RunState state, std::optional<int> exit_code,
                            std::optional<int> signal, const std::string& error) {
  check_owner();
  if (state == RunState::kPending || state == RunState::kRunning || state == RunState::kCompleted)
    throw DbError("end_attempt: state '" + to_string(state) +
                  "' is not an ending state (record_result completes runs)");
  return write([&] {
    const double now = unix_now();
    Statement s(db_,
                "UPDATE attempts SET state = ?2, exit_code = ?3, signal = ?4, error = ?5, "
                "ended_at = ?6 WHERE id = ?1 AND state = 'running'");
    s.bind(1, attempt_id)
        .bind(2, to_string(state))
        .bind(3, exit_code)
        .bind(4, signal)
        .bind(5, error)
        .bind(6, now);
    s.run();
    if (sqlite3_changes(db_) == 0) return false;
    Statement r(db_,
                "UPDATE runs SET status = ?2, error = ?3, updated_at = ?4 WHERE id = (SELECT "
                "run_id FROM attempts WHERE id = ?1) AND status = 'running'");
    r.bind(1, attempt_id).bind(2, to_string(state)).bind(3, error).bind(4, now).run();
    return true;
  });
}

bool ResultsDb::record_result(std::int64_t attempt_id, const ResultRecord& result) {
  check_owner();
  return write([&] {
    const double now = unix_now();
    Statement close(db_,
                    "UPDATE attempts SET state = 'completed', exit_code = 0, ended_at = ?2, "
                    "fraction = 1 WHERE id = ?1 AND state = 'running'");
    close.bind(1, attempt_id).bind(2, now).run();
    Statement exists(db_, "SELECT count(*) FROM results WHERE run_id = ?1");
    exists.bind(1, result.run_id);
    exists.step();
    const bool duplicate = exists.i64(0) > 0;
    if (!duplicate) {
      Statement ins(db_,
                    "INSERT INTO results (run_id, attempt_id, flocsim_version, completed_at, "
                    "wall_s, mlups, steps, window_json, result_json, recorded_at) VALUES (?1, "
                    "?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10)");
      ins.bind(1, result.run_id)
          .bind(2, attempt_id)
          .bind(3, result.flocsim_version)
          .bind(4, result.completed_at)
          .bind(5, result.wall_s)
          .bind(6, result.mlups)
          .bind(7, result.steps)
          .bind(8, result.window_json)
          .bind(9, result.result_json)
          .bind(10, now)
          .run();
      for (const Observable& o : result.observables) {
        Statement ob(db_,
                     "INSERT INTO observables (run_id, name, mean, error) VALUES (?1, ?2, ?3, ?4)");
        ob.bind(1, result.run_id).bind(2, o.name).bind(3, o.mean).bind(4, o.error).run();
      }
    }
    Statement run(
        db_, "UPDATE runs SET status = 'completed', error = '', updated_at = ?2 WHERE id = ?1");
    run.bind(1, result.run_id).bind(2, now).run();
    return !duplicate;
  });
}

namespace {
constexpr const char* kAttemptSelect =
    "SELECT id, run_id, number, backend, host, job_id, state, log_path, error, pid, owner_pid, "
    "pid_start, resumed, started_at, heartbeat_at, ended_at, fraction, eta_s, mlups, step, "
    "steps_total, exit_code, signal FROM attempts ";
}

#define FLOCSIM_READ_ATTEMPTS(stmt, out)                              \
  while (stmt.step()) {                                               \
    AttemptRecord a;                                                  \
    a.id = stmt.i64(0);                                               \
    a.run_id = stmt.text(1);                                          \
    a.number = static_cast<int>(stmt.i64(2));                         \
    a.backend = stmt.text(3);                                         \
    a.host = stmt.text(4);                                            \
    a.job_id = stmt.text(5);                                          \
    a.state = stmt.state(6);                                          \
    a.log_path = stmt.text(7);                                        \
    a.error = stmt.text(8);                                           \
    a.pid = stmt.null(9) ? 0 : stmt.i64(9);                           \
    a.owner_pid = stmt.i64(10);                                       \
    a.pid_start = stmt.text(11);                                      \
    a.resumed = stmt.i64(12) != 0;                                    \
    a.started_at = stmt.real(13);                                     \
    a.heartbeat_at = stmt.opt_real(14);                               \
    a.ended_at = stmt.opt_real(15);                                   \
    a.fraction = stmt.opt_real(16);                                   \
    a.eta_s = stmt.opt_real(17);                                      \
    a.mlups = stmt.opt_real(18);                                      \
    a.step = stmt.opt_i64(19);                                        \
    a.steps_total = stmt.opt_i64(20);                                 \
    if (!stmt.null(21)) a.exit_code = static_cast<int>(stmt.i64(21)); \
    if (!stmt.null(22)) a.signal = static_cast<int>(stmt.i64(22));    \
    out.push_back(std::move(a));                                      \
  }

std::vector<AttemptRecord> ResultsDb::live_attempts() {
  check_owner();
  Statement s(db_, (std::string(kAttemptSelect) + "WHERE state = 'running' ORDER BY id").c_str());
  std::vector<AttemptRecord> out;
  FLOCSIM_READ_ATTEMPTS(s, out)
  return out;
}

std::vector<AttemptRecord> ResultsDb::attempts(const std::string& run_id) {
  check_owner();
  Statement s(db_, (std::string(kAttemptSelect) + "WHERE run_id = ?1 ORDER BY number").c_str());
  s.bind(1, run_id);
  std::vector<AttemptRecord> out;
  FLOCSIM_READ_ATTEMPTS(s, out)
  return out;
}

std::optional<AttemptRecord> ResultsDb::find_attempt(std::int64_t attempt_id) {
  check_owner();
  Statement s(db_, (std::string(kAttemptSelect) + "WHERE id = ?1").c_str());
  s.bind(1, attempt_id);
  std::vector<AttemptRecord> out;
  FLOCSIM_READ_ATTEMPTS(s, out)
  if (out.empty()) return std::nullopt;
  return out.front();
}

#undef FLOCSIM_READ_ATTEMPTS

// --- results ---

std::vector<ResultsDb::ResultRow> ResultsDb::result_rows(std::optional<std::int64_t> sweep_id) {
  check_owner();
  // One read transaction, so runs, results and observables are one snapshot.
  exec("BEGIN");
  try {
    std::vector<ResultRow> rows;
    for (RunRecord& r : runs(sweep_id)) {
      ResultRow row;
      row.run = std::move(r);
      row.sweep_id = sweep_id;
      rows.push_back(std::move(row));
    }
    std::map<std::string, ResultRow*> by_id;
    for (ResultRow& row : rows) by_id[row.run.id] = &row;
    Statement res(db_,
                  "SELECT run_id, wall_s, mlups, steps, window_json, completed_at, "
                  "flocsim_version, result_json FROM results");
    while (res.step()) {
      auto it = by_id.find(res.text(0));
      if (it == by_id.end()) continue;
      ResultRow& row = *it->second;
      row.has_result = true;
      row.wall_s = res.opt_real(1);
      row.mlups = res.opt_real(2);
      row.steps = res.opt_i64(3);
      row.window_json = res.text(4);
      row.completed_at = res.text(5);
      row.flocsim_version = res.text(6);
      row.result_json = res.text(7);
    }
    Statement obs(db_, "SELECT run_id, name, mean, error FROM observables ORDER BY rowid");
    while (obs.step()) {
      auto it = by_id.find(obs.text(0));
      if (it == by_id.end()) continue;
      it->second->observables.push_back({obs.text(1), obs.real(2), obs.opt_real(3)});
    }
    exec("COMMIT");
    return rows;
  } catch (...) {
    sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
    throw;
  }
}

int ResultsDb::count_results(const std::string& run_id) {
  check_owner();
  Statement s(db_, "SELECT count(*) FROM results WHERE run_id = ?1");
  s.bind(1, run_id);
  s.step();
  return static_cast<int>(s.i64(0));
}

}  // namespace flocsim::db
