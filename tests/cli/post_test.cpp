// flocsim post as a process: gnuplot runs without a shell whatever the output
// folder is called, and a missing gnuplot leaves the tables and a report.
#include <gmock/gmock.h>

#include "cli_fixture.hpp"
#include "db/results_db.hpp"

namespace flocsim {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
using ::testing::AllOf;
using ::testing::HasSubstr;

class Post : public Cli {
 protected:
  // A database with one completed du = 0 suspension (F and Re: the drag figure
  // has a point).
  std::string demo_db() {
    const std::string path = (dir_ / "demo.sqlite").string();
    db::ResultsDb db(path, db::ResultsDb::Mode::kCreate);
    const auto sweep = db.upsert_sweep("demo", "{}", "[\"du_over_Uinf\"]", 3);
    const json c = {{"scene", "suspension"}, {"phi", 0.2}, {"Re_inf", 12}, {"du_over_Uinf", 0}};
    db.add_runs(sweep, {{"r0", c.dump(), (dir_ / "r0").string(), "{}"}});
    db::ClaimRequest req;
    req.sweep_id = sweep;
    req.states = {db::RunState::kPending};
    db::AttemptStart start;
    start.owner_pid = getpid();
    const auto claim = db.claim_run(req, start);
    db::ResultRecord rec;
    rec.run_id = "r0";
    rec.flocsim_version = "test";
    rec.completed_at = "now";
    rec.result_json = json{{"case", c}, {"observables", json::object()}}.dump();
    rec.observables = {{"F", 4.2, 0.1}, {"Re", 4.0, 0.1}, {"n_a_mean", 2.0, 0.1}};
    db.record_result(claim->attempt_id, rec);
    return path;
  }
};

// `--out "x';touch PWNED;'"` ran touch through std::system; `--out "bob's
// post"` failed. gnuplot now runs without a shell, in the figures folder.
TEST_F(Post, RunsGnuplotWithoutAShell) {
  const std::string db = demo_db();
  const fs::path pwned = dir_ / "PWNED";
  for (const std::string& out :
       {(dir_ / ("x';touch " + pwned.string() + ";'")).string(), (dir_ / "bob's post").string()}) {
    SCOPED_TRACE(out);
    const t::Output o = t::run(flocsim({"post", "figures", "--db", db, "--out", out}));
    EXPECT_EQ(o.code, 0) << o.out;
    EXPECT_TRUE(fs::exists(fs::path(out) / "figures" / "drag_vs_Re.png")) << o.out;
    EXPECT_TRUE(fs::exists(fs::path(out) / "figures" / "drag_vs_Re.pdf")) << o.out;
  }
  EXPECT_FALSE(fs::exists(pwned)) << "the output folder's name ran as a shell command";
}

// Without gnuplot `post report` exited 1 after writing nothing ("gnuplot failed
// on figure drag_vs_Re"; only a log said "gnuplot: not found").
TEST_F(Post, WithoutGnuplotSaysSoAndStillWritesTablesAndAReport) {
  const std::string db = demo_db();
  const fs::path empty = dir_ / "no-programs";
  fs::create_directories(empty);
  const std::vector<std::string> no_gnuplot = {"PATH=" + empty.string()};
  const fs::path out = dir_ / "post";
  const t::Output r =
      t::run(flocsim({"post", "report", "--db", db, "--out", out.string()}), no_gnuplot);
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_THAT(r.out, AllOf(HasSubstr("gnuplot"), HasSubstr("not on PATH")));
  EXPECT_LT(r.out.find("not on PATH"), r.out.find("Aggregation")) << "said after the work";
  EXPECT_TRUE(fs::exists(out / "aggregation.csv"));
  EXPECT_TRUE(fs::exists(out / "non_aggregating.md"));
  EXPECT_THAT(t::read_text(out / "report.html"),
              AllOf(HasSubstr("Not drawn: every figure: gnuplot"), HasSubstr("not on PATH")));
  const t::Output f =
      t::run(flocsim({"post", "figures", "--db", db, "--out", (dir_ / "f").string()}), no_gnuplot);
  EXPECT_EQ(f.code, 1) << f.out;
  EXPECT_THAT(f.out, AllOf(HasSubstr("no figures can be drawn"), HasSubstr("not on PATH")));
}

// Issue 41, item 4: post wrote through symbolic links inside --out and
// overwrote their targets (aggregation.csv, the gnuplot scripts). It now
// refuses before any work, naming the links, and leaves targets and links be.
TEST_F(Post, SymbolicLinksWhereOutputGoesAreRefusedAndTheirTargetsKept) {
  const std::string db = demo_db();
  const fs::path out = dir_ / "post", target = dir_ / "precious.txt";
  t::write_text(target, "precious\n");
  fs::create_directories(out / "figures" / "scripts");
  fs::create_symlink(target, out / "aggregation.csv");
  fs::create_symlink(target, out / "figures" / "scripts" / "drag_vs_Re.gp");
  const t::Output r = t::run(flocsim({"post", "report", "--db", db, "--out", out.string()}));
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_THAT(r.out, AllOf(HasSubstr((out / "aggregation.csv").string()),
                           HasSubstr((out / "figures" / "scripts" / "drag_vs_Re.gp").string()),
                           HasSubstr("symbolic link")));
  EXPECT_EQ(t::read_text(target), "precious\n");
  EXPECT_TRUE(fs::is_symlink(out / "aggregation.csv"));
  EXPECT_FALSE(fs::exists(out / "figures" / "drag_vs_Re.png")) << "work done before the refusal";
  // a link of the user's that post does not write is no obstacle
  fs::remove(out / "aggregation.csv");
  fs::remove(out / "figures" / "scripts" / "drag_vs_Re.gp");
  fs::create_symlink(target, out / "notes.txt");
  const t::Output ok = t::run(flocsim({"post", "tables", "--db", db, "--out", out.string()}));
  EXPECT_EQ(ok.code, 0) << ok.out;
  EXPECT_EQ(t::read_text(target), "precious\n");
}

// Audit of 2026-11-28: post replaced a user's own aggregation.csv and
// report.html in --out without a word, and an --out that is a file ended in a
// raw filesystem error (exit 1). Files where post writes, in a folder no
// earlier post wrote, are now refused before any work and kept; post's own
// folder (its .flocsim-post record) is refreshed as before; an --out that is
// a file is an input error.
TEST_F(Post, AUsersFilesWherePostWritesAreRefusedAndKept) {
  const std::string db = demo_db();
  const fs::path out = dir_ / "mine";
  fs::create_directories(out);
  t::write_text(out / "aggregation.csv", "my own table\n");
  t::write_text(out / "notes.txt", "notes\n");
  const t::Output r = t::run(flocsim({"post", "tables", "--db", db, "--out", out.string()}));
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_THAT(r.out, AllOf(HasSubstr((out / "aggregation.csv").string()),
                           HasSubstr("record of an earlier flocsim post")));
  EXPECT_EQ(t::read_text(out / "aggregation.csv"), "my own table\n");
  EXPECT_FALSE(fs::exists(out / "aggregation.md")) << "work done before the refusal";
  // a folder of post's own, with other files of the user's beside: written, then refreshed
  const fs::path own = dir_ / "own";
  fs::create_directories(own);
  t::write_text(own / "notes.txt", "notes\n");
  ASSERT_EQ(t::run(flocsim({"post", "tables", "--db", db, "--out", own.string()})).code, 0);
  EXPECT_TRUE(fs::exists(own / ".flocsim-post"));
  const t::Output again = t::run(flocsim({"post", "tables", "--db", db, "--out", own.string()}));
  EXPECT_EQ(again.code, 0) << again.out;
  EXPECT_EQ(t::read_text(own / "notes.txt"), "notes\n");
  // --out naming a file
  const t::Output file =
      t::run(flocsim({"post", "tables", "--db", db, "--out", (own / "notes.txt").string()}));
  EXPECT_EQ(file.code, 2) << file.out;
  EXPECT_THAT(file.out, HasSubstr("exists and is not a folder"));
}

// Issue 41, item 16: `post report --columns bogus` was refused only after
// every figure and table was written (and no report.html beside them).
TEST_F(Post, AnUnknownColumnIsRefusedBeforeAnyWork) {
  const std::string db = demo_db();
  const fs::path out = dir_ / "post";
  const t::Output r = t::run(
      flocsim({"post", "report", "--db", db, "--out", out.string(), "--columns", "phi,bogus"}));
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_THAT(r.out, AllOf(HasSubstr("--columns bogus: no such column"), HasSubstr("F_over_F0")));
  EXPECT_FALSE(fs::exists(out / "figures")) << r.out;
  EXPECT_FALSE(fs::exists(out / "aggregation.csv")) << r.out;
}

}  // namespace
}  // namespace flocsim
