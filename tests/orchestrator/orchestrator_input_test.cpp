// The orchestrator's answers to what it is given: bad sweep files and command
// lines, hostile names and bytes from a database or the command line (escaped
// on every output), databases that are not SQLite, read-only or on a full
// disk, and plans that refuse what launch refuses. Fixture:
// orchestrator_fixture.hpp.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sqlite3.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>
#include <tuple>

#include "db/results_db.hpp"
#include "engine/lattice_gpu/gpu_runtime.hpp"
#include "harness.hpp"
#include "orchestrator/local_pool.hpp"
#include "orchestrator/plan.hpp"
#include "orchestrator/sweep.hpp"
#include "orchestrator_fixture.hpp"
#include "tests/run/folder_holder.hpp"

// the fixture and its names: Orchestrator, fs, json, t (flocsim::test), ResultsDb, RunState
using namespace flocsim::test::orchestrator_fixture;

namespace {

// Issue 41, item 6: the printed "restart what did not finish with: flocsim
// sweep resume ... --sweep NAME" left the name unquoted, and a sweep named
// $(touch${IFS}X) ran touch when the line was pasted into a shell.
TEST_F(Orchestrator, SuggestedCommandsAreShellQuoted) {
  const std::string name = "$(touch${IFS}PWNED)";
  json s{{"name", name},
         {"base", {{"x", 0}, {"fake", {{"steps", 1}, {"step_ms", 1}, {"exit", 1}}}}},
         {"axes", {{"x", {1}}}}};
  t::write_text(dir_ / "evil.json", s.dump());
  const t::Output o = t::run(launch((dir_ / "evil.json").string()));
  EXPECT_EQ(o.code, 1) << o.out;
  const t::Output st = t::run(flocsim({"sweep", "status", "--db", db_}));
  for (const std::string& text : {o.out, st.out}) {
    const auto at = text.find("flocsim sweep resume ");
    ASSERT_NE(at, std::string::npos) << text;
    const std::string line = text.substr(at, text.find('\n', at) - at);
    // the line as a shell reads it, with echo in the place of flocsim
    const t::Output echoed =
        t::run({"/bin/sh", "-c", "cd " + dir_.string() + " && echo " + line.substr(8)});
    EXPECT_EQ(echoed.out, "sweep resume --db " + db_ + " --sweep " + name + "\n") << line;
    EXPECT_FALSE(fs::exists(dir_ / "PWNED")) << line;
  }
}

// Issue 41, item 13: a missing --worker failed every run with exit 127,
// naming no path, and each failure used up an attempt.
TEST_F(Orchestrator, AWorkerThatCannotStartIsRefusedBeforeAnyAttempt) {
  const std::string sweep = fake_sweep({1}, 1, 1, {{"exit", 1}}, 3);
  const std::string missing = (dir_ / "no-such-worker").string();
  const t::Output l = t::run(flocsim({"sweep", "launch", sweep, "--db", db_, "--worker", missing}));
  EXPECT_EQ(l.code, 2) << l.out;
  EXPECT_NE(l.out.find("--worker " + missing + ": no such file"), std::string::npos) << l.out;
  EXPECT_FALSE(fs::exists(db_)) << "registered before the refusal";
  EXPECT_EQ(t::run(launch(sweep)).code, 1);  // one real, failed attempt
  t::write_text(dir_ / "not-executable", "#!/bin/sh\n");
  for (const std::string& worker :
       {missing, (dir_ / "not-executable").string(), std::string("no-such-program-on-path")}) {
    const t::Output r = t::run(flocsim({"sweep", "resume", "--db", db_, "--worker", worker}));
    EXPECT_EQ(r.code, 2) << r.out;
    EXPECT_NE(r.out.find("--worker " + worker + ": "), std::string::npos) << r.out;
  }
  ResultsDb db(db_, ResultsDb::Mode::kExisting);
  EXPECT_EQ(db.runs().front().attempts, 1);
}

// Issue 41, item 8: `sweep resume --backend slurm` trusted the Slurm settings
// stored in the database: runs_per_task 0 wrote empty task files without end
// (and ignored SIGTERM), a string for cpus_per_task gave a raw type_error.
// They are checked as `sweep launch` checks them, before Slurm is asked.
TEST_F(Orchestrator, StoredSlurmSettingsAreCheckedAsLaunchChecksThem) {
  const std::string sweep = fake_sweep({1}, 1, 1, {{"exit", 1}}, 3);
  EXPECT_EQ(t::run(launch(sweep)).code, 1);
  const json file = t::read_json(sweep);
  for (const auto& [field, value, expect] :
       {std::tuple<std::string, json, std::string>{"runs_per_task", 0, "slurm.runs_per_task = 0"},
        {"cpus_per_task", "eight", "slurm.cpus_per_task"},
        {"time_limit", "abc", "slurm.time_limit = \"abc\""}}) {
    json stored = file;
    stored["slurm"] = {{field, value}};
    {
      ResultsDb db(db_, ResultsDb::Mode::kExisting);
      db.upsert_sweep("fake", stored.dump(), "[\"x\"]", 3);
    }
    const t::Output r = t::run({"/usr/bin/timeout", "20", FLOCSIM_EXE, "sweep", "resume", "--db",
                                db_, "--backend", "slurm", "--worker", FAKE_WORKER_EXE});
    EXPECT_EQ(r.code, 2) << field << ": " << r.out;
    EXPECT_NE(r.out.find(expect), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("as stored"), std::string::npos) << r.out;
  }
  EXPECT_FALSE(fs::exists(dir_ / "results.runs" / "slurm")) << "task files written";
}

// Issue 41, item 7: ESC sequences and U+202E in names and axis values reached
// the terminal raw through launch, status and query.
TEST_F(Orchestrator, ControlAndBidiCharactersAreShownEscaped) {
  const std::string esc = "\x1b[2J", rlo = "\xe2\x80\xae";
  json s{{"name", "n" + esc + "a" + rlo + "me"},
         {"base", {{"x", 0}, {"fake", {{"steps", 1}, {"step_ms", 1}}}}},
         {"axes", {{"label", {"red" + esc, "evil" + rlo + "gpj.exe"}}}}};
  t::write_text(dir_ / "odd.json", s.dump());
  const t::Output l = t::run(launch((dir_ / "odd.json").string()));
  EXPECT_EQ(l.code, 0) << l.out;
  const t::Output st = t::run(flocsim({"sweep", "status", "--db", db_}));
  const t::Output q = t::run(flocsim({"query", "--db", db_}));
  for (const t::Output* o : {&l, &st, &q}) {
    EXPECT_EQ(o->out.find('\x1b'), std::string::npos) << o->out;
    EXPECT_EQ(o->out.find(rlo), std::string::npos) << o->out;
  }
  EXPECT_NE(l.out.find("label=red\\x1b[2J"), std::string::npos) << l.out;
  EXPECT_NE(l.out.find("evil\\u202egpj.exe"), std::string::npos) << l.out;
  EXPECT_NE(st.out.find("sweep n\\x1b[2Ja\\u202eme"), std::string::npos) << st.out;
  EXPECT_NE(q.out.find("\\u202e"), std::string::npos) << q.out;
}

// Bytes a terminal obeys, or that are not UTF-8, among those the test below
// puts into names, values, paths and messages: none may reach the output raw.
// Newlines are the output's own, so a name's newline is checked by finding
// the name whole, escaped, in one line.
std::string raw_bytes_in(const std::string& out) {
  std::string found;
  for (std::size_t i = 0; i < out.size(); ++i) {
    const auto b = static_cast<unsigned char>(out[i]);
    if ((b < 0x20 && b != '\n') || b == 0x7f || b == 0xff || b == 0xfe ||
        out.compare(i, 2, "\xc2\x9b") == 0 || out.compare(i, 3, "\xe2\x80\xae") == 0)
      found += "byte " + std::to_string(b) + " at " + std::to_string(i) + "; ";
  }
  return found;
}

// Issue 41, item 7, the rest: a hostile database (names, points, messages,
// bytes that are not UTF-8, a newline in a name) and hostile command-line
// words reached the terminal raw through status, query, resume's progress
// lines, the suggested commands and the error messages on stderr.
TEST_F(Orchestrator, HostileNamesFromADatabaseAreEscapedOnEveryOutput) {
  const std::string sweep = fake_sweep({1, 2}, 1, 1, {{"by_x", {{"2", {{"exit", 1}}}}}}, 5);
  ASSERT_EQ(t::run(launch(sweep)).code, 1);
  // U+001B [31m, U+202E, a newline, the byte 0xFF, U+009B (C1 CSI)
  const std::string hostile = "n\x1b[31m\xe2\x80\xae\nx\xff\xc2\x9b";
  const std::string shown = "n\\x1b[31m\\u202e\\x0ax\\xff\\u009b";
  {
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open(db_.c_str(), &db), SQLITE_OK);
    const auto exec = [&](const char* sql, const std::string& a) {
      sqlite3_stmt* st = nullptr;
      ASSERT_EQ(sqlite3_prepare_v2(db, sql, -1, &st, nullptr), SQLITE_OK) << sqlite3_errmsg(db);
      sqlite3_bind_text(st, 1, a.data(), static_cast<int>(a.size()), SQLITE_TRANSIENT);
      EXPECT_EQ(sqlite3_step(st), SQLITE_DONE) << sqlite3_errmsg(db);
      sqlite3_finalize(st);
    };
    exec("UPDATE sweeps SET name = ?1", hostile);
    // a point that is JSON (its value holds ESC and U+202E as JSON escapes)
    // for the failed run, one that is not for the completed run
    exec(
        "UPDATE sweep_runs SET point_json = ?1 WHERE run_id IN "
        "(SELECT id FROM runs WHERE status = 'failed')",
        R"({"x":"v\u001b[31m\u202e"})");
    exec(
        "UPDATE sweep_runs SET point_json = ?1 WHERE run_id IN "
        "(SELECT id FROM runs WHERE status = 'completed')",
        "{\"x\":\"\xff\"}");
    exec("UPDATE runs SET error = ?1 WHERE status = 'failed'", "boom\x1b]0;title\x07 \xe2\x80\xae");
    sqlite3_close(db);
  }
  const t::Output st = t::run(flocsim({"sweep", "status", "--db", db_}));
  EXPECT_EQ(st.code, 0) << st.out;
  EXPECT_EQ(raw_bytes_in(st.out), "") << st.out;
  EXPECT_NE(st.out.find("sweep " + shown + ": 2 runs:"), std::string::npos) << st.out;
  EXPECT_NE(st.out.find("x=v\\x1b[31m\\u202e"), std::string::npos) << st.out;
  EXPECT_NE(st.out.find("boom\\x1b]0;title\\x07 \\u202e"), std::string::npos) << st.out;
  // the suggested command: bash's $'...', the name's bytes as \xNN
  const std::string quoted = "$'n\\x1b[31m\\xe2\\x80\\xae\\x0ax\\xff\\xc2\\x9b'";
  EXPECT_NE(st.out.find("--sweep " + quoted), std::string::npos) << st.out;

  for (const std::string format : {"table", "csv", "json"}) {
    const t::Output q =
        t::run(flocsim({"query", "--db", db_, "--sweep", hostile, "--format", format, "--all"}));
    EXPECT_EQ(q.code, 0) << format << ": " << q.out;
    EXPECT_EQ(raw_bytes_in(q.out), "") << format << ": " << q.out;
  }
  const t::Output j = t::run(flocsim({"query", "--db", db_, "--format", "json"}));
  // JSON keeps the message (ESC and U+202E as JSON's escapes)
  EXPECT_NE(j.out.find(R"("error": "boom\u001b]0;title\u0007 \u202e")"), std::string::npos)
      << j.out;

  const t::Output r = t::run(
      flocsim({"sweep", "resume", "--db", db_, "--sweep", hostile, "--worker", FAKE_WORKER_EXE}));
  EXPECT_EQ(r.code, 1) << r.out;  // x = 2 fails again
  EXPECT_EQ(raw_bytes_in(r.out), "") << r.out;
  EXPECT_NE(r.out.find("x=v\\x1b[31m\\u202e"), std::string::npos) << r.out;  // started ...
  EXPECT_NE(r.out.find("--sweep " + quoted), std::string::npos) << r.out;

  // stderr: the words given, as messages quote them
  const std::string word = "zz\x1b[31m\n\xe2\x80\xae\xff";
  const t::Output e1 = t::run(flocsim({"sweep", "status", "--db", db_, "--sweep", word}));
  EXPECT_EQ(e1.code, 2) << e1.out;
  EXPECT_EQ(raw_bytes_in(e1.out), "") << e1.out;
  EXPECT_NE(e1.out.find("--sweep zz\\x1b[31m\\x0a\\u202e\\xff: no such sweep in "),
            std::string::npos)
      << e1.out;
  const std::string missing_db = (dir_ / ("d" + word + ".db")).string();
  for (const auto& args :
       {std::vector<std::string>{"sweep", "status", "--db", missing_db},
        std::vector<std::string>{"query", "--db", missing_db},
        std::vector<std::string>{"run", missing_db, "--out", missing_db},
        std::vector<std::string>{"sweep", "launch", missing_db, "--db", missing_db},
        std::vector<std::string>{"sweep", "status", "--db", db_, "--lease", word},
        std::vector<std::string>{word}}) {
    const t::Output e = t::run(flocsim(args));
    EXPECT_NE(e.code, 0) << args.front() << ": " << e.out;
    EXPECT_EQ(raw_bytes_in(e.out), "") << args.front() << ": " << e.out;
    EXPECT_NE(e.out.find("zz\\x1b[31m\\x0a\\u202e\\xff"), std::string::npos) << e.out;
  }
  EXPECT_FALSE(fs::exists(missing_db));

  // launch: a sweep name from a file (ESC and U+202E as JSON escapes), a
  // database and a runs folder whose paths hold them too
  json s = t::read_json(sweep);
  s["name"] = "l\x1b[31m\xe2\x80\xae";
  t::write_text(dir_ / "l.json", s.dump());
  const std::string odd = (dir_ / "o\x1b[31m\xe2\x80\xae").string();
  fs::create_directories(odd);
  const t::Output l =
      t::run(flocsim({"sweep", "launch", (dir_ / "l.json").string(), "--db", odd + "/r.db",
                      "--runs-dir", odd + "/runs", "--worker", FAKE_WORKER_EXE}));
  EXPECT_EQ(l.code, 1) << l.out;
  EXPECT_EQ(raw_bytes_in(l.out), "") << l.out;
  EXPECT_NE(l.out.find("sweep l\\x1b[31m\\u202e: 2 runs (2 new, 0 already in " + dir_.string() +
                       "/o\\x1b[31m\\u202e/r.db); run folders under " + dir_.string() +
                       "/o\\x1b[31m\\u202e/runs"),
            std::string::npos)
      << l.out;
}

// Found by scripts/probe-cli.sh, beside issue 41's items 10 and 13: an sbatch
// whose answer is not a job id was reported as "submitted job not a job id"
// (exit 0); an sbatch that never answers held the launch through SIGTERM; and
// a missing $FLOCSIM_WORKER, unlike --worker, was only found by failing runs.
TEST_F(Orchestrator, SbatchWithoutAJobIdOrAnswerAndAMissingEnvWorkerAreSaid) {
  const std::string path = stand_in_slurm("echo 'sbatch: queued somewhere'\n");
  const fs::path bin = dir_ / "fake-slurm";
  const std::string sweep = fake_sweep({1}, 1, 1);
  const t::Output o = t::run(flocsim({"sweep", "launch", sweep, "--db", db_, "--backend", "slurm",
                                      "--no-wait", "--worker", FAKE_WORKER_EXE}),
                             {path});
  EXPECT_EQ(o.code, 1) << o.out;
  EXPECT_NE(o.out.find("answered \"sbatch: queued somewhere"), std::string::npos) << o.out;
  EXPECT_NE(o.out.find("where --parsable gives the job id"), std::string::npos) << o.out;
  EXPECT_EQ(o.out.find("submitted job"), std::string::npos) << o.out;

  t::write_text(bin / "sbatch", "#!/bin/sh\ntouch \"$(dirname \"$0\")/asked\"\nexec sleep 60\n");
  // env execs flocsim: the pid is flocsim's
  t::Background b = t::start({"/usr/bin/env", path, FLOCSIM_EXE, "sweep", "resume", "--db", db_,
                              "--backend", "slurm", "--no-wait", "--worker", FAKE_WORKER_EXE},
                             (dir_ / "hung.log").string());
  ASSERT_TRUE(t::wait_for([&] { return fs::exists(bin / "asked"); }, 20));  // sbatch runs
  kill(b.pid, SIGTERM);
  const auto begin = std::chrono::steady_clock::now();
  EXPECT_EQ(b.wait(20), 1) << t::read_text(dir_ / "hung.log");
  EXPECT_LT(std::chrono::steady_clock::now() - begin, std::chrono::seconds(10));
  EXPECT_NE(t::read_text(dir_ / "hung.log").find("stopped: flocsim was asked to stop"),
            std::string::npos)
      << t::read_text(dir_ / "hung.log");

  const std::string missing = (dir_ / "no-such-worker").string();
  const t::Output e =
      t::run(flocsim({"sweep", "resume", "--db", db_}), {"FLOCSIM_WORKER=" + missing});
  EXPECT_EQ(e.code, 2) << e.out;
  EXPECT_NE(e.out.find("FLOCSIM_WORKER=" + missing + ": no such file"), std::string::npos) << e.out;
  ResultsDb db(db_, ResultsDb::Mode::kExisting);
  EXPECT_EQ(db.runs().front().attempts, 0);
}

TEST_F(Orchestrator, BadInputGetsClearErrorsAndExitCode2) {
  t::write_text(dir_ / "bad.json", R"({"name": "b", "base": {}, "axes": {"fluid.viscosity": []}})");
  t::Output o = t::run(launch((dir_ / "bad.json").string()));
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.out.find("bad.json: axes.fluid.viscosity = []: must be a non-empty array"),
            std::string::npos)
      << o.out;
  t::write_text(dir_ / "broken.json", R"({"name": "b", "base": {)");
  o = t::run(launch((dir_ / "broken.json").string()));
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.out.find("broken.json: not valid JSON"), std::string::npos) << o.out;
  o = t::run(flocsim({"query", "--db", (dir_ / "missing.db").string()}));
  EXPECT_EQ(o.code, 1);
  EXPECT_NE(o.out.find("cannot open results database"), std::string::npos) << o.out;
  EXPECT_FALSE(fs::exists(dir_ / "missing.db"));
  ASSERT_EQ(t::run(launch(fake_sweep({1}, 1, 1))).code, 0);
  o = t::run(flocsim({"query", "--db", db_, "--where", "x~1"}));
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.out.find("expected FIELD OP VALUE"), std::string::npos) << o.out;
  o = t::run(flocsim({"query", "--db", db_, "--where", "nosuch=1"}));
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.out.find("no column or case field \"nosuch\""), std::string::npos) << o.out;
}

TEST_F(Orchestrator, CommandLineMistakesAreNamed) {
  t::Output o = t::run(flocsim({"frobnicate"}));
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.out.find("frobnicate: no such subcommand (subcommands: "), std::string::npos)
      << o.out;
  t::write_text(dir_ / "fluid.json",
                R"({"scene": "fluid", "fluid": {"size": [8, 8, 8], "viscosity": 0.05},
                    "run": {"steps": 5}})");
  o = t::run(flocsim({"run", (dir_ / "fluid.json").string(), "--out", (dir_ / "o").string(),
                      "--stop-after", "-1"}));
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.out.find("--stop-after: must be a whole number of steps >= 1, got -1"),
            std::string::npos)
      << o.out;
  // 0 ran the whole case (the engine's "no stop"); refused like any other non-step
  o = t::run(flocsim({"run", (dir_ / "fluid.json").string(), "--out", (dir_ / "o").string(),
                      "--stop-after", "00"}));
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.out.find("--stop-after: must be a whole number of steps >= 1, got 00"),
            std::string::npos)
      << o.out;
  EXPECT_FALSE(fs::exists(dir_ / "o"));
  EXPECT_LT(o.out.size(), 300u);  // not the 309-digit range of double
  const std::string long_name = (dir_ / std::string(5000, 'x')).string();
  o = t::run(flocsim({"run", (dir_ / "fluid.json").string(), "--out", long_name}));
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.out.find("cannot prepare the output directory (File name too long)"),
            std::string::npos)
      << o.out.substr(0, 400);
  EXPECT_LT(o.out.size(), 400u);
}

TEST_F(Orchestrator, RefusedSweepFilesLeaveNoDatabaseBehind) {
  // a directory given as the sweep file
  fs::create_directories(dir_ / "adir");
  t::Output o = t::run(launch((dir_ / "adir").string()));
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.out.find("adir: is a directory, not a JSON file"), std::string::npos) << o.out;
  // a grid refused at expansion (two points give one case)
  // nested 50,000 deep (it crashed `sweep launch`), and a key given twice
  t::write_text(dir_ / "deep.json", "{\"name\": \"d\", \"base\": " + std::string(50000, '[') +
                                        std::string(50000, ']') + "}");
  o = t::run(launch((dir_ / "deep.json").string()));
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.out.find("base[0][0]"), std::string::npos) << o.out.substr(0, 500);
  EXPECT_NE(o.out.find("nested deeper than 64 levels"), std::string::npos) << o.out.substr(0, 500);
  t::write_text(dir_ / "dup.json",
                R"({"name": "d", "base": {"x": 1}, "axes": {"x": [1]}, "name": "e"})");
  o = t::run(launch((dir_ / "dup.json").string()));
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.out.find("dup.json: name: key given twice"), std::string::npos) << o.out;
  // a grid refused only when it is expanded: an axis through a number
  t::write_text(dir_ / "through.json",
                R"({"name": "t", "base": {"y": 1}, "axes": {"x": [1], "y.z": [2]}})");
  o = t::run(launch((dir_ / "through.json").string()));
  EXPECT_EQ(o.code, 2) << o.out;
  EXPECT_NE(o.out.find("goes through base.y = 1, which is not an object"), std::string::npos)
      << o.out;
  EXPECT_FALSE(fs::exists(db_)) << "a refused sweep left " << db_;
}

TEST_F(Orchestrator, RelaunchingASweepNameWithAnotherBaseIsRefused) {
  // Same name, changed base: the two grids would be merged into one sweep and
  // `query` would show rows with the same axis values.
  ASSERT_EQ(t::run(launch(fake_sweep({1, 2}, 1, 1))).code, 0);
  json changed{{"name", "fake"},
               {"base", {{"x", 0}, {"fake", {{"steps", 2}, {"step_ms", 1}}}}},
               {"axes", {{"x", {1, 2}}}}};
  t::write_text(dir_ / "changed.json", changed.dump());
  t::Output o = t::run(launch((dir_ / "changed.json").string()));
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.out.find("was launched with base.fake.steps = 1; this file has 2"), std::string::npos)
      << o.out;
  EXPECT_NE(o.out.find("another \"name\""), std::string::npos) << o.out;
  // other axes are refused too; more values on the same axes grow the grid
  changed["base"]["fake"]["steps"] = 1;
  changed["axes"] = {{"fake.step_ms", {1, 2}}};
  t::write_text(dir_ / "axes.json", changed.dump());
  o = t::run(launch((dir_ / "axes.json").string()));
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.out.find("was launched with the axes x; this file has fake.step_ms"),
            std::string::npos)
      << o.out;
  EXPECT_EQ(t::run(launch(fake_sweep({1, 2, 3}, 1, 1))).code, 0);
  EXPECT_EQ(statuses().size(), 3u);
}

// Audit of 2026-11-28: a grid whose every point `flocsim run` refuses (a
// misspelt axis), a --runs-dir that cannot be made, a --db that cannot be a
// database and a base asking for a GPU this machine lacks were recorded and
// then failed, refused or got stuck (and kept the sweep's name for the bad
// grid); a changed base was refused only after the plan had timed the case.
// All are refused now (exit 2) before anything is recorded or timed.
TEST_F(Orchestrator, LaunchRefusesWhatCannotRunBeforeRecordingOrTimingAnything) {
  const std::string base = R"("base": {"scene": "fluid", "fluid": {"size": [8, 8, 8],
                              "viscosity": 0.05}, "run": {"steps": 10}})";
  const auto sweep_file = [&](const std::string& name, const std::string& text) {
    t::write_text(dir_ / name, text);
    return (dir_ / name).string();
  };
  const auto launch_flocsim = [&](const std::string& file, std::vector<std::string> more = {}) {
    std::vector<std::string> cmd{"sweep", "launch", file, "--db", db_};
    cmd.insert(cmd.end(), more.begin(), more.end());
    return t::run(flocsim(cmd));
  };
  const std::string typo = sweep_file(
      "typo.json", R"({"name": "a", )" + base + R"(, "axes": {"fluid.viscositty": [0.1]}})");
  t::Output o = launch_flocsim(typo);
  EXPECT_EQ(o.code, 2) << o.out;
  EXPECT_NE(o.out.find("every point of the grid is refused"), std::string::npos) << o.out;
  EXPECT_NE(o.out.find("did you mean fluid.viscosity?"), std::string::npos) << o.out;
  EXPECT_FALSE(fs::exists(db_));

  const std::string ok = sweep_file(
      "ok.json", R"({"name": "ok", )" + base + R"(, "axes": {"fluid.viscosity": [0.1]}})");
  o = launch_flocsim(ok, {"--runs-dir", typo});
  EXPECT_EQ(o.code, 2) << o.out;
  EXPECT_NE(o.out.find("--runs-dir " + typo + ": exists and is not a folder"), std::string::npos)
      << o.out;
  o = launch_flocsim(ok, {"--runs-dir", "/proc/flocsim-no-such/runs"});
  EXPECT_EQ(o.code, 2) << o.out;
  EXPECT_NE(o.out.find("cannot make or write a folder there"), std::string::npos) << o.out;
  EXPECT_FALSE(fs::exists(db_));
  // a --db that is a folder: refused, and the run folders made for it taken back
  o = t::run(flocsim({"sweep", "launch", ok, "--db", dir_.string(), "--runs-dir",
                      (dir_ / "new" / "runs").string()}));
  EXPECT_EQ(o.code, 2) << o.out;
  EXPECT_NE(o.out.find("is a directory"), std::string::npos) << o.out;
  EXPECT_FALSE(fs::exists(dir_ / "new"));

  ASSERT_EQ(launch_flocsim(ok).code, 0);
  const std::string changed = sweep_file(
      "changed.json", R"({"name": "ok", "base": {"scene": "fluid", "fluid": {"size": [8, 8, 8],
                          "viscosity": 0.05}, "run": {"steps": 20}}, "axes": {"fluid.viscosity": [0.1]}})");
  o = launch_flocsim(changed);
  EXPECT_EQ(o.code, 2) << o.out;
  EXPECT_NE(o.out.find("was launched with base.run.steps = 10; this file has 20"),
            std::string::npos)
      << o.out;
  EXPECT_EQ(o.out.find("per step"), std::string::npos) << "timed before refusing:\n" << o.out;

  if (flocsim::gpu::query_gpus().devices.empty()) {
    const std::string cuda = sweep_file(
        "cuda.json", R"({"name": "cu", "base": {"scene": "fluid", "device": "cuda", "fluid":
                         {"size": [8, 8, 8], "viscosity": 0.05}, "run": {"steps": 10}},
                         "axes": {"fluid.viscosity": [0.1]}})");
    const std::string other_db = (dir_ / "cuda.sqlite").string();
    o = t::run(flocsim({"sweep", "launch", cuda, "--db", other_db}));
    EXPECT_EQ(o.code, 2) << o.out;
    EXPECT_NE(o.out.find("the grid's cases ask for device = \"cuda\""), std::string::npos) << o.out;
    EXPECT_FALSE(fs::exists(other_db));
    // and `case check` says that `run` would refuse such a case here (it is
    // not refused: a GPU case is checked on a login node, run on a GPU node)
    t::write_text(dir_ / "cuda-case.json",
                  json::parse(t::read_text(dir_ / "cuda.json"))["base"].dump());
    o = t::run(flocsim({"case", "check", (dir_ / "cuda-case.json").string()}));
    EXPECT_EQ(o.code, 0) << o.out;
    EXPECT_NE(o.out.find("warning: `flocsim run` on this machine would refuse this case: "
                         "device = \"cuda\""),
              std::string::npos)
        << o.out;
  }
}

// --no-wait with the local pool and --jobs with Slurm were accepted and
// silently ignored; both are refused now, and --help gives the defaults.
TEST_F(Orchestrator, AnOptionTheBackendWouldIgnoreIsRefused) {
  const std::string sweep = fake_sweep({1}, 1, 1);
  t::Output o = t::run(
      flocsim({"sweep", "launch", sweep, "--db", db_, "--no-wait", "--worker", FAKE_WORKER_EXE}));
  EXPECT_EQ(o.code, 2) << o.out;
  EXPECT_NE(o.out.find("--no-wait: only with --backend slurm"), std::string::npos) << o.out;
  o = t::run(flocsim({"sweep", "launch", sweep, "--db", db_, "--backend", "slurm", "--jobs", "4",
                      "--worker", FAKE_WORKER_EXE}));
  EXPECT_EQ(o.code, 2) << o.out;
  EXPECT_NE(o.out.find("--jobs 4: only for the local backend"), std::string::npos) << o.out;
  EXPECT_FALSE(fs::exists(db_));
  o = t::run(flocsim({"sweep", "launch", "--help"}));
  const auto default_of = [&](const std::string& option) {
    const auto at = o.out.find(option + " ");
    return at == std::string::npos ? std::string() : o.out.substr(at, o.out.find('\n', at) - at);
  };
  EXPECT_THAT(default_of("--grace"), testing::EndsWith("=120")) << o.out;
  EXPECT_THAT(default_of("--lease"), testing::EndsWith("=60")) << o.out;
  EXPECT_THAT(default_of("--jobs"), testing::EndsWith("=1")) << o.out;
}

// `flocsim run` into a folder another live process holds exits 4 (busy), not
// 2: a sweep's pool takes 2 for a case at fault and never retries it.
TEST_F(Orchestrator, ARunIntoAHeldFolderExitsFourNamingTheHolder) {
  t::write_text(dir_ / "fluid.json",
                R"({"scene": "fluid", "fluid": {"size": [8, 8, 8], "viscosity": 0.05},
                    "run": {"steps": 5}})");
  const fs::path out = dir_ / "held";
  fs::create_directories(out);
  flocsim::testing::FolderHolder other(out);
  const pid_t holder = other.pid();
  const t::Output o =
      t::run(flocsim({"run", (dir_ / "fluid.json").string(), "--out", out.string()}));
  other.kill();
  EXPECT_EQ(o.code, 4) << o.out;
  EXPECT_NE(o.out.find("another flocsim (process " + std::to_string(holder) + ")"),
            std::string::npos)
      << o.out;
  EXPECT_EQ(t::run(flocsim({"run", (dir_ / "fluid.json").string(), "--out", out.string()})).code,
            0);
}

TEST_F(Orchestrator, WhereRefusesTextAgainstANumber) {
  // 'x<abc' compared as text and returned every row
  ASSERT_EQ(t::run(launch(fake_sweep({1, 2}, 1, 1))).code, 0);
  t::Output o = t::run(flocsim({"query", "--db", db_, "--where", "x<abc"}));
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.out.find("x is a number, \"abc\" is not"), std::string::npos) << o.out;
  o = t::run(flocsim({"query", "--db", db_, "--where", "x<1.5", "--format", "csv"}));
  EXPECT_EQ(o.code, 0) << o.out;
  EXPECT_EQ(std::count(o.out.begin(), o.out.end(), '\n'), 2) << o.out;  // header + one run
  o = t::run(flocsim({"query", "--db", db_, "--where", "status=completed"}));
  EXPECT_EQ(o.code, 0) << o.out;  // text against a text column stays allowed
  // F<inf matched nothing and F!=nan everything: non-finite bounds are refused
  for (const std::string bound : {"x<inf", "x>-inf", "x<1e999", "x=nan", "x!=NaN"}) {
    o = t::run(flocsim({"query", "--db", db_, "--where", bound}));
    EXPECT_EQ(o.code, 2) << bound << ": " << o.out;
    EXPECT_NE(o.out.find("is not a finite number"), std::string::npos) << o.out;
  }
}

TEST_F(Orchestrator, AFileThatIsNotSqliteIsNamed) {
  t::write_text(dir_ / "notes.db", "these are my notes, not a database\n");
  for (const std::vector<std::string>& cmd :
       {std::vector<std::string>{"query", "--db", (dir_ / "notes.db").string()},
        std::vector<std::string>{"sweep", "status", "--db", (dir_ / "notes.db").string()}}) {
    const t::Output o = t::run(flocsim(cmd));
    EXPECT_EQ(o.code, 1);
    EXPECT_NE(o.out.find((dir_ / "notes.db").string() + ": not an SQLite database"),
              std::string::npos)
        << o.out;
  }
  const t::Output o = t::run(flocsim({"sweep", "launch", fake_sweep({1}, 1, 1), "--db",
                                      (dir_ / "notes.db").string(), "--worker", FAKE_WORKER_EXE}));
  EXPECT_NE(o.code, 0);
  EXPECT_EQ(t::read_text(dir_ / "notes.db"), "these are my notes, not a database\n");
}

TEST_F(Orchestrator, AReadOnlyDatabaseIsReadAndWritersSaySo) {
  // On a read-only file system `query` and `status`, which only read, failed
  // with "unable to open database file". Root ignores file permissions, so
  // the test mounts the folder read-only (and skips where it cannot).
  const fs::path rw = dir_ / "rw", ro = dir_ / "ro";
  fs::create_directories(rw);
  fs::create_directories(ro);
  const std::string db = (rw / "results.db").string();
  ASSERT_EQ(t::run(flocsim({"sweep", "launch", fake_sweep({1, 2}, 1, 1), "--db", db, "--worker",
                            FAKE_WORKER_EXE}))
                .code,
            0);
  if (!mount_read_only(rw, ro)) GTEST_SKIP() << "cannot mount a read-only folder here (needs root)";
  const std::string ro_db = (ro / "results.db").string();
  const t::Output q = t::run(flocsim({"query", "--db", ro_db, "--format", "csv"}));
  const t::Output st = t::run(flocsim({"sweep", "status", "--db", ro_db}));
  const t::Output w = t::run(flocsim({"sweep", "resume", "--db", ro_db}));
  std::system(("umount " + ro.string()).c_str());
  EXPECT_EQ(q.code, 0) << q.out;
  EXPECT_EQ(std::count(q.out.begin(), q.out.end(), '\n'), 3) << q.out;  // header + 2 runs
  EXPECT_EQ(st.code, 0) << st.out;
  EXPECT_NE(st.out.find("is read-only"), std::string::npos) << st.out;
  EXPECT_EQ(w.code, 1) << w.out;
  EXPECT_NE(w.out.find(ro_db + " is read-only"), std::string::npos) << w.out;
}

// Issue 41, item 20: `sweep cancel` refused a read-only database, though it
// only reads the live attempts and signals their owners.
TEST_F(Orchestrator, CancelReadsAReadOnlyDatabase) {
  const fs::path rw = dir_ / "rw", ro = dir_ / "ro";
  fs::create_directories(rw);
  fs::create_directories(ro);
  const std::string db = (rw / "results.db").string();
  ASSERT_EQ(t::run(flocsim({"sweep", "launch", fake_sweep({1}, 1, 1), "--db", db, "--worker",
                            FAKE_WORKER_EXE}))
                .code,
            0);
  if (!mount_read_only(rw, ro)) GTEST_SKIP() << "cannot mount a read-only folder here (needs root)";
  const t::Output c = t::run(flocsim({"sweep", "cancel", "--db", (ro / "results.db").string()}));
  std::system(("umount " + ro.string()).c_str());
  EXPECT_EQ(c.code, 0) << c.out;
  EXPECT_NE(c.out.find("nothing is running"), std::string::npos) << c.out;
}

// Issue 41, item 12: `sweep plan --jobs 4096` built 4096 copies of the demo's
// case to time them together (29 GB) before any memory check, and died of
// std::bad_alloc under a memory limit. It now times as many as fit.
TEST_F(Orchestrator, PlanWithMoreJobsThanMemoryHoldsTimesOneCopy) {
  // the demo's case (about 7 MB) over 600 seeds, under a 2 GB address-space
  // limit: 600 copies timed together would need about 4 GB
  json s = t::read_json(FLOCSIM_SOURCE_DIR "/sweeps/demo.json");
  json seeds = json::array();
  for (int k = 1; k <= 600; ++k) seeds.push_back(k);
  s["axes"] = {{"seed", seeds}};
  t::write_text(dir_ / "many.json", s.dump());
  const t::Output o =
      t::run({"/usr/bin/prlimit", "--as=2000000000", FLOCSIM_EXE, "sweep", "plan",
              (dir_ / "many.json").string(), "--jobs", "4096", "--measure-steps", "1"});
  EXPECT_EQ(o.code, 0) << o.out.substr(0, 3000);
  EXPECT_NE(o.out.find("600 runs"), std::string::npos) << o.out.substr(0, 3000);
}

// Issue 41, item 15: on a full file system `sweep status` and `resume` failed
// with SQLite's "disk I/O error" and never mentioned space. Status reads the
// database as it does a read-only one and says the disk is full.
TEST_F(Orchestrator, AFullDiskIsNamedAndStatusStillReads) {
  const fs::path full = dir_ / "full";
  fs::create_directories(full);
  if (::geteuid() != 0 ||
      std::system(("mount -t tmpfs -o size=2m tmpfs " + full.string() + " 2>/dev/null").c_str()) !=
          0)
    GTEST_SKIP() << "cannot mount a small file system here (needs root)";
  const std::string db = (full / "results.db").string();
  const t::Output l = t::run(flocsim({"sweep", "launch", fake_sweep({1}, 1, 1, {{"exit", 1}}, 3),
                                      "--db", db, "--worker", FAKE_WORKER_EXE}));
  std::system(("dd if=/dev/zero of=" + (full / "fill").string() + " bs=4k 2>/dev/null").c_str());
  const t::Output st = t::run(flocsim({"sweep", "status", "--db", db}));
  const t::Output r = t::run(flocsim({"sweep", "resume", "--db", db, "--worker", FAKE_WORKER_EXE}));
  std::system(("umount " + full.string()).c_str());
  EXPECT_EQ(l.code, 1) << l.out;
  EXPECT_EQ(st.code, 0) << st.out;
  EXPECT_NE(st.out.find("the file system under it is full"), std::string::npos) << st.out;
  EXPECT_NE(st.out.find("sweep fake"), std::string::npos) << st.out;
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("is full"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("disk I/O error"), std::string::npos) << r.out;
}

// The real worker: the CI sweep with `flocsim run`, then a real run killed with
// SIGKILL and resumed from its HDF5 checkpoint.
TEST_F(Orchestrator, PlanRefusesWhatLaunchRefusesAndCountsTheRunsLatticeUpdates) {
  // Three points at the draft preset (a = 4, 64 x 32 x 32 cells, 49 spheres)
  // and U_inf 0.03: Re_inf 24 runs (nu = 2 a U_inf / Re_inf = 0.01), 48 and 72
  // are refused (nu 0.005 and 0.0033, below the floor 0.01 at a = 4). Stage 1
  // has a fixed length (stage1_min = stage1_max), so the run's length is known
  // exactly: the plan's lattice updates must be the run's own steps x cells.
  json s{{"name", "plancheck"},
         {"base",
          {{"scene", "suspension"},
           {"fidelity", "draft"},
           {"phi", 0.2},
           {"precision", "float"},
           {"du_over_Uinf", 0.03},
           {"numerics", {{"U_inf", 0.03}}},
           {"protocol",
            {{"stage1_min", 3},
             {"stage1_max", 3},
             {"stage2_settle", 1},
             {"statistics", 10},
             {"snapshot_every", 0},
             {"threads", 1}}}}},
         {"axes", {{"Re_inf", {24, 48, 72}}}}};
  const std::string sweep = (dir_ / "plancheck.json").string();
  t::write_text(sweep, s.dump(2));
  const t::Output plan = t::run(flocsim({"sweep", "plan", sweep, "--measure-steps", "2"}));
  ASSERT_EQ(plan.code, 0) << plan.out;
  EXPECT_NE(plan.out.find("3 points, 1 to run, 2 refused"), std::string::npos) << plan.out;
  const t::Output o = t::run(flocsim({"sweep", "launch", sweep, "--db", db_, "--jobs", "1"}));
  EXPECT_EQ(o.code, 1) << o.out;  // two runs refused
  // launch printed the same plan first
  EXPECT_NE(o.out.find("plan of sweep plancheck: 3 points, 1 to run, 2 refused"), std::string::npos)
      << o.out;
  ResultsDb db(db_, ResultsDb::Mode::kExisting);
  int refused = 0;
  for (const auto& row : db.result_rows()) {
    const double re = json::parse(row.run.case_json)["Re_inf"];
    if (row.run.status == RunState::kRefused) {
      ++refused;
      EXPECT_NE(re, 24);
      // the run's message, first line, is the one the plan printed for it
      const std::string first = row.run.error.substr(row.run.error.find("input error"));
      const std::string reason = first.substr(first.find(": ") + 2, 60);
      EXPECT_NE(plan.out.find(reason), std::string::npos) << reason << "\n" << plan.out;
      continue;
    }
    ASSERT_EQ(row.run.status, RunState::kCompleted) << row.run.error;
    const json result = json::parse(row.result_json);
    const json box = result["derived"]["box_cells"];
    const long updates = result["cost"]["steps"].get<long>() * box[0].get<long>() *
                         box[1].get<long>() * box[2].get<long>();
    // the plan's row for it shows these steps, and its count is exactly theirs
    std::istringstream lines(plan.out);
    std::string line, planned;
    while (std::getline(lines, line))
      if (line.find("Re_inf=24") != std::string::npos) planned = line;
    EXPECT_NE(planned.find("  " + std::to_string(result["cost"]["steps"].get<long>()) + "  "),
              std::string::npos)
        << planned;
    flocsim::orchestrator::PlanOptions options;
    options.measure_steps = 0;
    const auto exact =
        flocsim::orchestrator::plan_sweep(flocsim::orchestrator::read_sweep_file(sweep), options);
    EXPECT_EQ(exact.lattice_updates_min, static_cast<double>(updates));
    EXPECT_EQ(exact.lattice_updates_max, static_cast<double>(updates));
  }
  EXPECT_EQ(refused, 2);
}

}  // namespace
