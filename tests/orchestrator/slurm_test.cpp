// The Slurm backend against a real single-node Slurm that this test starts
// (slurm_cluster.sh) and stops. Skipped, saying why, where Slurm cannot start.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <sstream>

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

// Issue 41, item 5: the #SBATCH lines were written unquoted: a space in the
// runs folder ("Invalid directive"), a % in the sweep name (the task's output
// file could not be opened; the job failed before it ran, yet flocsim said
// "finished"), a " ("Unmatched quote"), a 300-character name ("File name too
// long"). The real sbatch must take them all and the runs complete.
TEST_F(Slurm, OddNamesAndFoldersReachSlurmIntact) {
  const fs::path folder = dir_ / "my runs %j \"q\"";
  fs::create_directories(folder);
  fs::permissions(folder, fs::perms::all);
  int k = 0;
  for (const std::string& name : {std::string("50%x\"done#1"), std::string(300, 'n')}) {
    SCOPED_TRACE(name.substr(0, 20));
    json s{{"name", name},
           {"base", {{"x", 0}, {"fake", {{"steps", 2}, {"step_ms", 10}}}}},
           {"axes", {{"x", {1, 2}}}}};
    const fs::path file = dir_ / ("odd" + std::to_string(k) + ".json");
    t::write_text(file, s.dump());
    const std::string db = (folder / ("results" + std::to_string(k++) + ".db")).string();
    const t::Output o = t::run(flocsim({"sweep", "launch", file.string(), "--db", db, "--backend",
                                        "slurm", "--worker", FAKE_WORKER_EXE}));
    EXPECT_EQ(o.code, 0) << o.out;
    EXPECT_NE(o.out.find(" finished"), std::string::npos) << o.out;
    ResultsDb rdb(db, ResultsDb::Mode::kExisting);
    for (const auto& r : rdb.runs()) EXPECT_EQ(r.status, RunState::kCompleted) << r.error;
  }
}

// Issue 41, item 5: a job whose tasks fail before they run recorded nothing,
// and flocsim said "job N finished", leaving the runs pending with no reason.
// Slurm's own state of each task is reported.
TEST_F(Slurm, ATaskThatFailsBeforeItRunsIsReportedWithSlurmsState) {
  json s{{"name", "broken"},
         {"base", {{"x", 0}, {"fake", {{"steps", 2}, {"step_ms", 10}}}}},
         {"axes", {{"x", {1}}}}};
  t::write_text(dir_ / "broken.json", s.dump());
  const t::Output o = t::run(flocsim({"sweep", "launch", (dir_ / "broken.json").string(), "--db",
                                      db_, "--backend", "slurm", "--worker", FAKE_WORKER_EXE}),
                             {"FLOCSIM_SWEEP_EXE=" + (dir_ / "no-such-flocsim").string()});
  EXPECT_EQ(o.code, 1) << o.out;
  EXPECT_NE(o.out.find("ended with Slurm's failure: task 0 FAILED"), std::string::npos) << o.out;
  EXPECT_NE(o.out.find("task_0.out"), std::string::npos) << o.out;
  std::istringstream lines(o.out);
  for (std::string line; std::getline(lines, line);)
    EXPECT_FALSE(line.rfind("slurm: job ", 0) == 0 && line.size() > 9 &&
                 line.compare(line.size() - 9, 9, " finished") == 0)
        << line;
}

// Issue 41, item 10: with squeue on PATH but no sbatch, launch said
// "sbatch failed (exit -1):" and no reason.
TEST_F(Slurm, AMissingSbatchIsNamed) {
  const fs::path bin = dir_ / "bin";
  fs::create_directories(bin);
  for (const char* program : {"squeue", "scontrol"}) {
    const fs::path real = fs::exists("/usr/bin/" + std::string(program))
                              ? fs::path("/usr/bin/" + std::string(program))
                              : fs::path("/usr/sbin/" + std::string(program));
    fs::create_symlink(real, bin / program);
  }
  json s{{"name", "nosbatch"},
         {"base", {{"x", 0}, {"fake", {{"steps", 2}, {"step_ms", 10}}}}},
         {"axes", {{"x", {1}}}}};
  t::write_text(dir_ / "nosbatch.json", s.dump());
  const t::Output o = t::run(flocsim({"sweep", "launch", (dir_ / "nosbatch.json").string(), "--db",
                                      db_, "--backend", "slurm", "--worker", FAKE_WORKER_EXE}),
                             {"PATH=" + bin.string()});
  EXPECT_NE(o.code, 0) << o.out;
  EXPECT_NE(o.out.find("sbatch is not on PATH (" + bin.string() + ")"), std::string::npos) << o.out;
}

}  // namespace
