// The results database: schema, claims, attempts, results, and its behaviour
// under several processes (one connection each, opened after fork).
#include "db/results_db.hpp"

#include <gtest/gtest.h>
#include <sqlite3.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <set>

namespace fs = std::filesystem;
using flocsim::db::AttemptStart;
using flocsim::db::ClaimRequest;
using flocsim::db::DbError;
using flocsim::db::ResultRecord;
using flocsim::db::ResultsDb;
using flocsim::db::RunState;

namespace {

class DbTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("flocsim_db_test_" + std::to_string(getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    path_ = (dir_ / "results.db").string();
  }
  void TearDown() override { fs::remove_all(dir_); }

  // A sweep "s" with runs r0..r(n-1), in that order.
  std::int64_t add_sweep(ResultsDb& db, int n) {
    const std::int64_t id = db.upsert_sweep("s", "{}", "[\"x\"]", 2);
    std::vector<ResultsDb::NewRun> runs;
    for (int i = 0; i < n; ++i)
      runs.push_back({"r" + std::to_string(i), "{\"x\":" + std::to_string(i) + "}",
                      (dir_ / ("r" + std::to_string(i))).string(),
                      "{\"x\":" + std::to_string(i) + "}"});
    db.add_runs(id, runs);
    return id;
  }
  static AttemptStart start() {
    AttemptStart s;
    s.host = "testhost";
    s.owner_pid = getpid();
    return s;
  }
  static ResultRecord result(const std::string& run, double f) {
    ResultRecord r;
    r.run_id = run;
    r.flocsim_version = "t";
    r.completed_at = "now";
    r.wall_s = 1.5;
    r.result_json = "{}";
    r.window_json = "[1,2]";
    r.observables = {{"F", f, 0.25}, {"mass", 1.0, std::nullopt}};
    return r;
  }

  fs::path dir_;
  std::string path_;
};

TEST_F(DbTest, NewDatabaseHasCurrentSchemaInWalMode) {
  {
    ResultsDb db(path_, ResultsDb::Mode::kCreate);
    EXPECT_EQ(db.schema_version(), flocsim::db::kSchemaVersion);
    EXPECT_EQ(db.journal_mode(), "wal");
    EXPECT_EQ(db.integrity_check(), "ok");
    add_sweep(db, 2);
  }
  // Reopening keeps the data and the version.
  ResultsDb db(path_, ResultsDb::Mode::kExisting);
  EXPECT_EQ(db.schema_version(), flocsim::db::kSchemaVersion);
  EXPECT_EQ(db.runs().size(), 2u);
}

TEST_F(DbTest, CreatesTheFolderOfANewDatabase) {
  // `flocsim sweep launch --db runs/demo.sqlite` on a fresh checkout: the
  // folder does not exist yet and is made; an existing database is never
  // created silently.
  const std::string nested = (dir_ / "runs" / "deeper" / "demo.sqlite").string();
  { ResultsDb db(nested, ResultsDb::Mode::kCreate); }
  EXPECT_TRUE(fs::exists(nested));
  EXPECT_THROW(ResultsDb((dir_ / "absent" / "x.sqlite").string(), ResultsDb::Mode::kExisting),
               DbError);
  EXPECT_FALSE(fs::exists(dir_ / "absent"));
}

// Issue 41, item 14: paths SQLite cannot open got "unable to open database
// file" with no reason; --db "" blamed WAL on a network file system; --db
// /dev/null said "disk I/O error" and left /dev/null-journal behind.
TEST_F(DbTest, PathsThatCannotHoldADatabaseAreNamedWithTheReason) {
  auto error_of = [](const std::string& path, ResultsDb::Mode mode) {
    try {
      ResultsDb db(path, mode);
    } catch (const DbError& e) {
      return std::string(e.what());
    }
    return std::string("(opened)");
  };
  EXPECT_NE(error_of("", ResultsDb::Mode::kCreate).find("--db \"\": an empty path"),
            std::string::npos);
  std::error_code ec;
  const bool journal_before = fs::exists("/dev/null-journal", ec);
  for (auto mode :
       {ResultsDb::Mode::kCreate, ResultsDb::Mode::kExisting, ResultsDb::Mode::kReadOnly})
    EXPECT_NE(error_of("/dev/null", mode).find("/dev/null: not a regular file"), std::string::npos)
        << error_of("/dev/null", mode);
  if (!journal_before) EXPECT_FALSE(fs::exists("/dev/null-journal", ec));
  std::ofstream(dir_ / "afile") << "x";
  const std::string under_file = (dir_ / "afile" / "x.db").string();
  EXPECT_NE(error_of(under_file, ResultsDb::Mode::kCreate).find("Not a directory"),
            std::string::npos)
      << error_of(under_file, ResultsDb::Mode::kCreate);
  EXPECT_NE(error_of(under_file, ResultsDb::Mode::kExisting).find("Not a directory"),
            std::string::npos)
      << error_of(under_file, ResultsDb::Mode::kExisting);
  EXPECT_NE(error_of(dir_.string(), ResultsDb::Mode::kCreate).find("is a directory"),
            std::string::npos);
  // a folder that takes no files though it looks writable: the system's reason
  const std::string in_proc = error_of("/proc/flocsim_test.sqlite", ResultsDb::Mode::kCreate);
  EXPECT_EQ(in_proc.find("unable to open database file"), std::string::npos) << in_proc;
  EXPECT_NE(in_proc.find("cannot create results database /proc/flocsim_test.sqlite: "),
            std::string::npos)
      << in_proc;
}

TEST_F(DbTest, RefusesMissingForeignAndNewerFiles) {
  EXPECT_THROW(ResultsDb(path_, ResultsDb::Mode::kExisting), DbError);
  EXPECT_FALSE(fs::exists(path_));

  sqlite3* raw = nullptr;
  ASSERT_EQ(sqlite3_open(path_.c_str(), &raw), SQLITE_OK);
  sqlite3_exec(raw, "CREATE TABLE other(x)", nullptr, nullptr, nullptr);
  sqlite3_close(raw);
  try {
    ResultsDb db(path_, ResultsDb::Mode::kCreate);
    FAIL() << "a foreign SQLite file was accepted";
  } catch (const DbError& e) {
    EXPECT_NE(std::string(e.what()).find("not a flocsim results database"), std::string::npos);
  }

  fs::remove(path_);
  { ResultsDb db(path_, ResultsDb::Mode::kCreate); }
  ASSERT_EQ(sqlite3_open(path_.c_str(), &raw), SQLITE_OK);
  sqlite3_exec(raw, "PRAGMA user_version = 99", nullptr, nullptr, nullptr);
  sqlite3_close(raw);
  try {
    ResultsDb db(path_, ResultsDb::Mode::kExisting);
    FAIL() << "a newer schema was accepted";
  } catch (const DbError& e) {
    EXPECT_NE(std::string(e.what()).find("schema version 99"), std::string::npos) << e.what();
  }
}

TEST_F(DbTest, AddingRunsAgainReusesThemAndKeepsGridOrder) {
  ResultsDb db(path_, ResultsDb::Mode::kCreate);
  const std::int64_t id = add_sweep(db, 3);
  const auto again = db.add_runs(id, {{"r1", "{}", "d", "{}"}, {"r9", "{}", "d9", "{}"}});
  EXPECT_EQ(again.added, 1);
  EXPECT_EQ(again.reused, 1);
  const auto runs = db.runs(id);
  ASSERT_EQ(runs.size(), 4u);
  EXPECT_EQ(runs[0].id, "r0");
  EXPECT_EQ(runs[1].id, "r1");
  EXPECT_EQ(runs[1].case_json, "{\"x\":1}");  // the first record of a run is kept
  EXPECT_EQ(runs[3].id, "r9");
  // Updating the sweep keeps its id.
  EXPECT_EQ(db.upsert_sweep("s", "{\"grown\":true}", "[\"x\"]", 2), id);
  EXPECT_EQ(db.find_sweep("s")->spec_json, "{\"grown\":true}");
}

TEST_F(DbTest, ClaimsPendingRunsInGridOrderOnce) {
  ResultsDb db(path_, ResultsDb::Mode::kCreate);
  const std::int64_t id = add_sweep(db, 3);
  ClaimRequest req{id, {RunState::kPending}, 2, std::nullopt, {}};
  auto a = db.claim_run(req, start());
  auto b = db.claim_run(req, start());
  ASSERT_TRUE(a && b);
  EXPECT_EQ(a->run.id, "r0");
  EXPECT_EQ(b->run.id, "r1");
  EXPECT_EQ(db.find_run("r0")->status, RunState::kRunning);
  const auto live = db.live_attempts();
  ASSERT_EQ(live.size(), 2u);
  EXPECT_EQ(live[0].number, 1);
  EXPECT_EQ(live[0].host, "testhost");
  EXPECT_FALSE(live[0].resumed);
  // Excluded runs are skipped; nothing else is pending afterwards.
  req.exclude = {"r2"};
  EXPECT_FALSE(db.claim_run(req, start()));
  req.exclude.clear();
  EXPECT_EQ(db.claim_run(req, start())->run.id, "r2");
  EXPECT_FALSE(db.claim_run(req, start()));
}

TEST_F(DbTest, FailuresCountAgainstTheRetryLimitAndKeepTheError) {
  ResultsDb db(path_, ResultsDb::Mode::kCreate);
  const std::int64_t id = add_sweep(db, 1);
  ClaimRequest req{id, {RunState::kPending, RunState::kFailed}, 2, std::nullopt, {}};
  for (int attempt = 1; attempt <= 2; ++attempt) {
    auto c = db.claim_run(req, start());
    ASSERT_TRUE(c) << "attempt " << attempt;
    EXPECT_EQ(c->run.failures, attempt - 1);
    EXPECT_TRUE(db.end_attempt(c->attempt_id, RunState::kFailed, 1, std::nullopt,
                               "blow-up " + std::to_string(attempt)));
    // A second close of the same attempt changes nothing.
    EXPECT_FALSE(db.end_attempt(c->attempt_id, RunState::kLost, std::nullopt, 9, "late"));
  }
  EXPECT_FALSE(db.claim_run(req, start())) << "retry limit of 2 failures not applied";
  const auto run = db.find_run("r0");
  EXPECT_EQ(run->status, RunState::kFailed);
  EXPECT_EQ(run->error, "blow-up 2");
  EXPECT_EQ(run->attempts, 2);
  EXPECT_EQ(run->failures, 2);
  const auto attempts = db.attempts("r0");
  ASSERT_EQ(attempts.size(), 2u);
  EXPECT_EQ(attempts[1].number, 2);
  EXPECT_TRUE(attempts[1].resumed);  // a run that ran before continues from its checkpoint
  EXPECT_EQ(attempts[0].exit_code, 1);
  EXPECT_TRUE(attempts[0].ended_at.has_value());
}

TEST_F(DbTest, LostAndInterruptedRunsDoNotCountAsFailures) {
  ResultsDb db(path_, ResultsDb::Mode::kCreate);
  const std::int64_t id = add_sweep(db, 1);
  ClaimRequest req{
      id, {RunState::kPending, RunState::kLost, RunState::kInterrupted}, 1, std::nullopt, {}};
  auto c1 = db.claim_run(req, start());
  db.end_attempt(c1->attempt_id, RunState::kLost, std::nullopt, 9, "killed");
  auto c2 = db.claim_run(req, start());
  ASSERT_TRUE(c2);
  db.end_attempt(c2->attempt_id, RunState::kInterrupted, 3, std::nullopt, "stopped");
  auto c3 = db.claim_run(req, start());
  ASSERT_TRUE(c3);
  EXPECT_EQ(c3->run.status, RunState::kInterrupted);
  EXPECT_EQ(db.find_attempt(c1->attempt_id)->signal, 9);
}

// Existing databases hold the states as text: every state's text is one the
// schema accepts, reads back as that state and is counted in status order; a
// text no state has is refused by name, not read as some state.
TEST_F(DbTest, StoredStateTextsReadBackAsRunStates) {
  const std::size_t n = std::size(flocsim::db::kAllRunStates);
  std::int64_t id = 0;
  {
    ResultsDb db(path_, ResultsDb::Mode::kCreate);
    id = add_sweep(db, static_cast<int>(n));
  }
  sqlite3* raw = nullptr;
  ASSERT_EQ(sqlite3_open(path_.c_str(), &raw), SQLITE_OK);
  for (std::size_t i = 0; i < n; ++i) {
    const std::string sql = "UPDATE runs SET status = '" +
                            to_string(flocsim::db::kAllRunStates[i]) + "' WHERE id = 'r" +
                            std::to_string(i) + "'";
    EXPECT_EQ(sqlite3_exec(raw, sql.c_str(), nullptr, nullptr, nullptr), SQLITE_OK) << sql;
  }
  {
    ResultsDb db(path_, ResultsDb::Mode::kExisting);
    const auto runs = db.runs(id);
    ASSERT_EQ(runs.size(), n);
    for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(runs[i].status, flocsim::db::kAllRunStates[i]);
    const auto counts = db.count_states(id);
    ASSERT_EQ(counts.size(), n);
    for (std::size_t i = 0; i < n; ++i) {
      EXPECT_EQ(counts[i].status, flocsim::db::kAllRunStates[i]);
      EXPECT_EQ(counts[i].runs, 1) << counts[i].status;
    }
  }
  // the schema's CHECK keeps unknown text out; switched off, it gets in
  EXPECT_NE(sqlite3_exec(raw, "UPDATE runs SET status = 'cancelled' WHERE id = 'r0'", nullptr,
                         nullptr, nullptr),
            SQLITE_OK);
  sqlite3_exec(raw, "PRAGMA ignore_check_constraints = ON", nullptr, nullptr, nullptr);
  ASSERT_EQ(sqlite3_exec(raw, "UPDATE runs SET status = 'cancelled' WHERE id = 'r0'", nullptr,
                         nullptr, nullptr),
            SQLITE_OK);
  sqlite3_close(raw);
  ResultsDb db(path_, ResultsDb::Mode::kExisting);
  try {
    db.runs(id);
    FAIL() << "an unknown state was read";
  } catch (const DbError& e) {
    EXPECT_NE(std::string(e.what()).find("unknown run state \"cancelled\""), std::string::npos)
        << e.what();
  }
}

TEST_F(DbTest, ResultIsRecordedOnceWithItsObservables) {
  ResultsDb db(path_, ResultsDb::Mode::kCreate);
  const std::int64_t id = add_sweep(db, 2);
  ClaimRequest req{id, {RunState::kPending}, 2, std::nullopt, {}};
  auto c = db.claim_run(req, start());
  db.record_heartbeats({{c->attempt_id, 123.0, 0.5, 10.0, 2.0, 50, 100}});
  auto live = db.find_attempt(c->attempt_id);
  EXPECT_DOUBLE_EQ(*live->heartbeat_at, std::max(123.0, live->started_at));
  EXPECT_DOUBLE_EQ(*live->fraction, 0.5);
  EXPECT_EQ(*live->steps_total, 100);

  EXPECT_TRUE(db.record_result(c->attempt_id, result(c->run.id, 12.5)));
  EXPECT_FALSE(db.record_result(c->attempt_id, result(c->run.id, 99.0)));
  EXPECT_EQ(db.count_results("r0"), 1);
  EXPECT_EQ(db.find_run("r0")->status, RunState::kCompleted);
  EXPECT_EQ(db.find_attempt(c->attempt_id)->state, RunState::kCompleted);
  EXPECT_EQ(db.find_attempt(c->attempt_id)->exit_code, 0);
  const auto rows = db.result_rows(id);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_TRUE(rows[0].has_result);
  EXPECT_FALSE(rows[1].has_result);
  ASSERT_EQ(rows[0].observables.size(), 2u);
  EXPECT_EQ(rows[0].observables[0].name, "F");
  EXPECT_DOUBLE_EQ(rows[0].observables[0].mean, 12.5);  // the first result stands
  EXPECT_DOUBLE_EQ(*rows[0].observables[0].error, 0.25);
  EXPECT_FALSE(rows[0].observables[1].error.has_value());
  EXPECT_DOUBLE_EQ(*rows[0].wall_s, 1.5);
  EXPECT_EQ(rows[0].window_json, "[1,2]");
  // Completed runs are never claimed again, whatever states are asked for.
  ClaimRequest all{id,
                   {RunState::kPending, RunState::kFailed, RunState::kLost, RunState::kInterrupted,
                    RunState::kRefused},
                   5,
                   "r0",
                   {}};
  EXPECT_FALSE(db.claim_run(all, start()));
  const auto counts = db.count_states(id);
  for (const auto& s : counts) {
    if (s.status == RunState::kCompleted || s.status == RunState::kPending) {
      EXPECT_EQ(s.runs, 1);
    }
  }
}

TEST_F(DbTest, ConnectionRefusesUseInForkedChild) {
  ResultsDb db(path_, ResultsDb::Mode::kCreate);
  add_sweep(db, 1);
  const pid_t pid = fork();
  if (pid == 0) {
    int code = 0;
    try {
      db.runs();
      code = 1;  // used the parent's connection: wrong
    } catch (const DbError&) {
      code = 0;
    }
    // A fresh connection in the child works.
    try {
      ResultsDb mine(path_, ResultsDb::Mode::kExisting);
      if (mine.runs().size() != 1) code = 2;
    } catch (...) {
      code = 3;
    }
    _exit(code);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
  EXPECT_EQ(db.runs().size(), 1u);  // the parent's connection is untouched
}

// Eight processes claim from the same 200 runs at once, each through its own
// connection: every run is claimed exactly once and nobody sees "locked".
TEST_F(DbTest, ConcurrentClaimsFromManyProcessesNeverCollide) {
  constexpr int kRuns = 200, kProcs = 8;
  {
    ResultsDb db(path_, ResultsDb::Mode::kCreate);
    add_sweep(db, kRuns);
  }
  std::vector<pid_t> kids;
  for (int p = 0; p < kProcs; ++p) {
    const pid_t pid = fork();
    if (pid == 0) {
      try {
        ResultsDb db(path_, ResultsDb::Mode::kExisting);
        const auto sweep = db.find_sweep("s");
        ClaimRequest req{sweep->id, {RunState::kPending}, 2, std::nullopt, {}};
        std::ofstream out(dir_ / ("claims_" + std::to_string(p)));
        while (auto c = db.claim_run(req, start())) {
          out << c->run.id << "\n";
          db.record_heartbeats({{c->attempt_id, 1.0, 0.5, 1.0, 1.0, 1, 2}});
          db.record_result(c->attempt_id, result(c->run.id, 1.0));
        }
      } catch (const std::exception& e) {
        std::ofstream(dir_ / ("error_" + std::to_string(p))) << e.what();
        _exit(1);
      }
      _exit(0);
    }
    kids.push_back(pid);
  }
  for (pid_t k : kids) {
    int status = 0;
    waitpid(k, &status, 0);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  }
  std::multiset<std::string> claimed;
  for (int p = 0; p < kProcs; ++p) {
    EXPECT_FALSE(fs::exists(dir_ / ("error_" + std::to_string(p))));
    std::ifstream in(dir_ / ("claims_" + std::to_string(p)));
    std::string id;
    while (in >> id) claimed.insert(id);
  }
  EXPECT_EQ(claimed.size(), static_cast<std::size_t>(kRuns));
  EXPECT_EQ(std::set<std::string>(claimed.begin(), claimed.end()).size(),
            static_cast<std::size_t>(kRuns));
  ResultsDb db(path_, ResultsDb::Mode::kExisting);
  EXPECT_EQ(db.integrity_check(), "ok");
  for (const auto& s : db.count_states())
    EXPECT_EQ(s.runs, s.status == RunState::kCompleted ? kRuns : 0) << s.status;
}

}  // namespace
