// `flocsim sweep status`: when a sweep will be done, worked by hand from what
// its runs report, and the report on a database with a run under way.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <sstream>

#include "db/results_db.hpp"
#include "orchestrator/report.hpp"

namespace fs = std::filesystem;
namespace orc = flocsim::orchestrator;
using flocsim::db::ClaimRequest;
using flocsim::db::ResultsDb;
using flocsim::db::RunState;

namespace {

TEST(SweepEta, WaitingRunsTakeTheMeanWallTimeOfTheCompletedOnes) {
  // Completed 1.0 h and 1.5 h: 1.25 h each. One run at 50 % with 20 min left,
  // two waiting on that one worker: 20 min + 2 x 75 min = 170 min.
  const auto eta = orc::estimate_sweep_eta({3600, 5400}, {{0.5, 1200.0}}, 2);
  ASSERT_TRUE(eta);
  EXPECT_DOUBLE_EQ(eta->per_run_s, 4500);
  EXPECT_DOUBLE_EQ(eta->remaining_s, 1200 + 2 * 4500);
  EXPECT_EQ(eta->lanes, 1);
  EXPECT_FALSE(eta->from_running_rate);
}

TEST(SweepEta, BeforeAnyRunCompletesTheRunningRateGivesTheLength) {
  // A quarter done with 3 h left: a whole run takes 4 h at that rate, and the
  // three waiting runs follow one another: 3 h + 3 x 4 h = 15 h.
  const auto eta = orc::estimate_sweep_eta({}, {{0.25, 10800.0}}, 3);
  ASSERT_TRUE(eta);
  EXPECT_DOUBLE_EQ(eta->per_run_s, 14400);
  EXPECT_DOUBLE_EQ(eta->remaining_s, 10800 + 3 * 14400);
  EXPECT_TRUE(eta->from_running_rate);
}

TEST(SweepEta, SeveralWorkersShareTheWaitingRuns) {
  // Whole runs of 200 s (half done, 100 s left) and 500 s (a fifth done, 400 s
  // left): 350 s each on average; four waiting runs over two workers after
  // the slower of the two: 400 + 4 x 350 / 2 = 1100 s.
  const auto eta = orc::estimate_sweep_eta({}, {{0.5, 100.0}, {0.2, 400.0}}, 4);
  ASSERT_TRUE(eta);
  EXPECT_DOUBLE_EQ(eta->per_run_s, 350);
  EXPECT_EQ(eta->lanes, 2);
  EXPECT_DOUBLE_EQ(eta->remaining_s, 1100);
}

TEST(SweepEta, NothingIsClaimedWithoutAnEstimate) {
  EXPECT_FALSE(orc::estimate_sweep_eta({}, {}, 0));  // nothing to do
  EXPECT_FALSE(orc::estimate_sweep_eta({}, {}, 2));  // waiting, no length known
  // a worker that has not reported yet
  EXPECT_FALSE(orc::estimate_sweep_eta({3600}, {{0.0, std::nullopt}}, 1));
  // the -1 a worker writes before it has a rate
  EXPECT_FALSE(orc::estimate_sweep_eta({3600}, {{0.5, -1.0}}, 1));
  // an estimate but no progress: no rate for a whole run
  EXPECT_FALSE(orc::estimate_sweep_eta({}, {{0.0, 500.0}}, 1));
  // the last run: its own estimate, whatever the others took
  const auto last = orc::estimate_sweep_eta({}, {{0.9, 60.0}}, 0);
  ASSERT_TRUE(last);
  EXPECT_DOUBLE_EQ(last->remaining_s, 60);
  // waiting only (no worker now): one after another at the completed length
  const auto idle = orc::estimate_sweep_eta({100}, {}, 2);
  ASSERT_TRUE(idle);
  EXPECT_DOUBLE_EQ(idle->remaining_s, 200);
}

TEST(SweepStatus, ReportsTheSweepEtaWhileTheFirstRunIsUnderWay) {
  const fs::path dir = fs::temp_directory_path() / ("flocsim_status_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  {
    ResultsDb db((dir / "r.sqlite").string(), ResultsDb::Mode::kCreate);
    const std::int64_t id = db.upsert_sweep("s", "{}", "[\"x\"]", 2);
    std::vector<ResultsDb::NewRun> runs;
    for (int i = 0; i < 3; ++i)
      runs.push_back({"run" + std::to_string(i) + "aaaaaaaaaaaa", "{}",
                      (dir / std::to_string(i)).string(), "{\"x\":" + std::to_string(i) + "}"});
    db.add_runs(id, runs);
    flocsim::db::AttemptStart start;
    start.host = "h";
    start.owner_pid = getpid();
    const auto claim = db.claim_run(ClaimRequest{id, {RunState::kPending}, 2, {}, {}}, start);
    ASSERT_TRUE(claim);
    db.set_attempt_pid(claim->attempt_id, getpid(), "", (dir / "log").string());
    flocsim::db::Heartbeat beat;
    beat.attempt_id = claim->attempt_id;
    beat.at = flocsim::db::unix_now();
    beat.fraction = 0.25;
    beat.eta_s = 3 * 3600;
    beat.step = 250;
    beat.steps_total = 1000;
    db.record_heartbeats({beat});
    std::ostringstream out;
    orc::write_status(db, std::string("s"), out);
    // 3 h left, then two runs of 4 h each (a quarter took 1 h): 11 h.
    EXPECT_NE(out.str().find("ETA: about 11.0 h (2 waiting at 4.0 h each at the running rate"),
              std::string::npos)
        << out.str();
  }
  fs::remove_all(dir);
}

}  // namespace
