// The Slurm backend against a real single-node Slurm that this test starts
// (slurm_cluster.sh) and stops. Skipped, saying why, where Slurm cannot start.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>

#include "db/results_db.hpp"
#include "harness.hpp"

namespace fs = std::filesystem;
using flocsim::db::ResultsDb;
using flocsim::db::RunState;
using nlohmann::json;
namespace t = flocsim::test;

namespace {

const std::string kCluster = FLOCSIM_SOURCE_DIR "/tests/orchestrator/slurm_cluster.sh";

class Slurm : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    prefix_ = fs::temp_directory_path() / ("flocsim_slurm_" + std::to_string(getpid()));
    fs::remove_all(prefix_);
    fs::create_directories(prefix_);
    const t::Output o = t::run({"/bin/sh", kCluster, "start", prefix_.string()});
    started_ = o.code == 0;
    why_ = o.out;
    if (started_) setenv("SLURM_CONF", (prefix_ / "slurm.conf").c_str(), 1);
  }
  static void TearDownTestSuite() {
    t::run({"/bin/sh", kCluster, "stop", prefix_.string()});
    unsetenv("SLURM_CONF");
    fs::remove_all(prefix_);
  }
  void SetUp() override {
    if (!started_) GTEST_SKIP() << "Slurm could not start here: " << why_;
    dir_ = prefix_ / ::testing::UnitTest::GetInstance()->current_test_info()->name();
    fs::create_directories(dir_);
    // Jobs run in the submitting environment; the run folders must be readable by them.
    fs::permissions(prefix_, fs::perms::all);
    db_ = (dir_ / "results.db").string();
  }
  std::vector<std::string> flocsim(std::vector<std::string> args) {
    args.insert(args.begin(), FLOCSIM_EXE);
    return args;
  }

  static inline fs::path prefix_;
  static inline bool started_ = false;
  static inline std::string why_;
  fs::path dir_;
  std::string db_;
};

TEST_F(Slurm, CiSweepRunsAsAJobArrayWithTwoRunsPerTask) {
  const t::Output o = t::run(flocsim({"sweep", "launch", FLOCSIM_SOURCE_DIR "/sweeps/ci.json",
                                      "--db", db_, "--backend", "slurm"}));
  ASSERT_EQ(o.code, 0) << o.out;
  EXPECT_NE(o.out.find("4 runs in 2 array tasks"), std::string::npos) << o.out;
  ResultsDb db(db_, ResultsDb::Mode::kExisting);
  std::map<std::string, int> per_task;
  for (const auto& r : db.runs()) {
    EXPECT_EQ(r.status, RunState::kCompleted);
    EXPECT_EQ(db.count_results(r.id), 1);
    const auto a = db.attempts(r.id);
    ASSERT_EQ(a.size(), 1u);
    EXPECT_EQ(a[0].backend, "slurm");
    ++per_task[a[0].job_id];
  }
  ASSERT_EQ(per_task.size(), 2u);
  for (const auto& [job, n] : per_task) {
    EXPECT_EQ(n, 2) << job;
    EXPECT_NE(job.find('_'), std::string::npos) << job;  // JOBID_TASK of an array
  }
  EXPECT_EQ(db.integrity_check(), "ok");
}

TEST_F(Slurm, CancelledJobIsResumedFromCheckpointsByANewArray) {
  json s{{"name", "slow"},
         {"base", {{"x", 0}, {"fake", {{"steps", 200}, {"step_ms", 50}}}}},
         {"axes", {{"x", {1, 2}}}},
         {"slurm", {{"runs_per_task", 1}}}};
  t::write_text(dir_ / "slow.json", s.dump());
  t::Background launch = t::start(flocsim({"sweep", "launch", (dir_ / "slow.json").string(), "--db",
                                           db_, "--backend", "slurm", "--worker", FAKE_WORKER_EXE}),
                                  (dir_ / "launch.log").string());
  // Wait until both runs make progress inside their array tasks.
  auto stepped = [&](int min_step) {
    if (!fs::exists(db_)) return false;
    ResultsDb db(db_, ResultsDb::Mode::kExisting);
    int ready = 0;
    for (const auto& r : db.runs()) {
      const json p = t::read_json(fs::path(r.run_dir) / "progress.json");
      ready += p.is_object() && p.value("step", 0) >= min_step;
    }
    return ready == 2;
  };
  ASSERT_TRUE(t::wait_for([&] { return stepped(5); }, 60)) << t::read_text(dir_ / "launch.log");
  // status follows Slurm jobs as it does local workers, from their progress files:
  // each run's stage, simulated time of its total (fake worker: 0.5 a/U_inf per
  // step, 200 steps) and its array job
  const t::Output st = t::run(flocsim({"sweep", "status", "--db", db_}));
  EXPECT_NE(st.out.find("running (2)"), std::string::npos) << st.out;
  EXPECT_NE(st.out.find("/100 a/U_inf"), std::string::npos) << st.out;
  EXPECT_NE(st.out.find("stage 1"), std::string::npos) << st.out;
  EXPECT_NE(st.out.find(" job "), std::string::npos) << st.out;
  const t::Output c = t::run(flocsim({"sweep", "cancel", "--db", db_}));
  EXPECT_EQ(c.code, 0) << c.out;
  EXPECT_NE(c.out.find("scancel"), std::string::npos) << c.out;
  EXPECT_EQ(launch.wait(60), 1) << t::read_text(dir_ / "launch.log");
  {
    ResultsDb db(db_, ResultsDb::Mode::kExisting);
    for (const auto& r : db.runs())
      EXPECT_TRUE(r.status == RunState::kInterrupted || r.status == RunState::kLost)
          << r.status << " " << r.error;
  }
  const t::Output r = t::run(
      flocsim({"sweep", "resume", "--db", db_, "--backend", "slurm", "--worker", FAKE_WORKER_EXE}));
  ASSERT_EQ(r.code, 0) << r.out;
  ResultsDb db(db_, ResultsDb::Mode::kExisting);
  for (const auto& run : db.runs()) {
    EXPECT_EQ(run.status, RunState::kCompleted);
    EXPECT_EQ(db.count_results(run.id), 1);
    const json result = t::read_json(fs::path(run.run_dir) / "result.json");
    EXPECT_GE(result["observables"]["first_step"].get<int>(), 5);  // continued, not restarted
    const auto attempts = db.attempts(run.id);
    ASSERT_EQ(attempts.size(), 2u);
    EXPECT_NE(attempts[0].job_id.substr(0, attempts[0].job_id.find('_')),
              attempts[1].job_id.substr(0, attempts[1].job_id.find('_')));
  }
  EXPECT_EQ(db.integrity_check(), "ok");
}

}  // namespace
