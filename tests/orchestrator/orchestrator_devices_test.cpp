// Sweeps on GPUs: the local pool gives each worker its own GPU where there are
// several (CUDA_VISIBLE_DEVICES) and shares them beyond; CPU sweeps ask for
// none; Slurm tasks of a cuda sweep ask for one (--gres). Fixture:
// orchestrator_fixture.hpp.
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
#include <vector>

#include "db/results_db.hpp"
#include "engine/lattice_gpu/gpu_runtime.hpp"
#include "harness.hpp"
#include "orchestrator/local_pool.hpp"
#include "orchestrator/plan.hpp"
#include "orchestrator/sweep.hpp"
#include "orchestrator_fixture.hpp"

// the fixture and its names: Orchestrator, fs, json, t (flocsim::test), ResultsDb, RunState
using namespace flocsim::test::orchestrator_fixture;

namespace {

// The sweep file recorded in `db`, its run folders under dir/runs.
flocsim::db::SweepRecord registered(ResultsDb& db, const std::string& sweep_file,
                                    const fs::path& dir) {
  return flocsim::orchestrator::register_sweep(
             db, flocsim::orchestrator::read_sweep_file(sweep_file), (dir / "runs").string())
      .sweep;
}

// A pool of `jobs` fake workers.
flocsim::orchestrator::PoolOptions fake_pool(int jobs) {
  flocsim::orchestrator::PoolOptions p;
  p.worker = FAKE_WORKER_EXE;
  p.jobs = jobs;
  return p;
}

TEST_F(Orchestrator, WorkersOnCudaGetTheirOwnGpuThenShare) {
  // The pool on two GPUs with three workers at once (six runs, each long
  // enough that the three overlap): every worker is told --device cuda, the
  // first two get GPUs 0 and 1, and the third shares one. The command line
  // refuses --device cuda where no GPU is usable, so this drives the pool
  // itself, as `sweep launch` does once the GPUs are counted.
  ResultsDb db(db_, ResultsDb::Mode::kCreate);
  const flocsim::db::SweepRecord sweep =
      registered(db, fake_sweep({1, 2, 3, 4, 5, 6}, 6, 50), dir_);
  flocsim::orchestrator::PoolOptions p = fake_pool(3);
  p.device = "cuda";
  p.gpus = 2;
  const flocsim::orchestrator::PoolSummary s = flocsim::orchestrator::run_pool(db, sweep, p);
  EXPECT_EQ(s.completed, 6);
  std::map<double, std::string> gpu_of;
  for (double x : {1, 2, 3, 4, 5, 6}) {
    const std::string line = t::read_text(run_dir(x) / "devices.log");
    EXPECT_EQ(line.rfind("device cuda gpu ", 0), 0u) << line;
    gpu_of[x] = line.substr(16, line.size() - 17);
    EXPECT_TRUE(gpu_of[x] == "0" || gpu_of[x] == "1") << line;  // only the two GPUs
  }
  // the first three start together, in grid order: one GPU each, then the
  // least busy (the lower index among equals) takes the third
  EXPECT_EQ(gpu_of[1], "0");
  EXPECT_EQ(gpu_of[2], "1");
  EXPECT_EQ(gpu_of[3], "0");
}

TEST_F(Orchestrator, WorkersGetTheGpusTheOrchestratorWasGivenNotTheMachinesFirst) {
  // An orchestrator started with CUDA_VISIBLE_DEVICES=5,7 sees those two GPUs
  // as CUDA indices 0 and 1; a worker given "0" would run on the machine's
  // GPU 0, which is not its to use. Its workers must be given "5" and "7".
  ResultsDb db(db_, ResultsDb::Mode::kCreate);
  const flocsim::db::SweepRecord sweep = registered(db, fake_sweep({1, 2}, 2, 50), dir_);
  flocsim::orchestrator::PoolOptions p = fake_pool(2);
  p.device = "cuda";
  p.gpus = 2;
  p.gpu_ids = flocsim::orchestrator::visible_gpu_ids("5,7", {0, 1});
  ASSERT_EQ(flocsim::orchestrator::run_pool(db, sweep, p).completed, 2);
  EXPECT_EQ(t::read_text(run_dir(1) / "devices.log"), "device cuda gpu 5\n");
  EXPECT_EQ(t::read_text(run_dir(2) / "devices.log"), "device cuda gpu 7\n");
}

TEST(VisibleGpuIds, MapCudaIndicesThroughTheInheritedList) {
  using flocsim::orchestrator::visible_gpu_ids;
  using V = std::vector<std::string>;
  // no list of its own: the CUDA index is the machine's
  EXPECT_EQ(visible_gpu_ids(nullptr, {0, 1, 2}), (V{"0", "1", "2"}));
  // a list: index i is its i-th entry, spaces trimmed; UUIDs pass as given
  EXPECT_EQ(visible_gpu_ids("2, 3", {0, 1}), (V{"2", "3"}));
  EXPECT_EQ(visible_gpu_ids("GPU-8f1c,GPU-02ab", {1}), (V{"GPU-02ab"}));
  // a GPU the query left out (too old, busy) leaves its entry unused
  EXPECT_EQ(visible_gpu_ids("4,6,9", {0, 2}), (V{"4", "9"}));
}

TEST_F(Orchestrator, WorkersOnTheCpuGetNoGpuAndNoDeviceFlagByDefault) {
  ResultsDb db(db_, ResultsDb::Mode::kCreate);
  const flocsim::db::SweepRecord sweep = registered(db, fake_sweep({1, 2}, 2, 10), dir_);
  flocsim::orchestrator::PoolOptions p = fake_pool(2);
  ASSERT_EQ(flocsim::orchestrator::run_pool(db, sweep, p).completed, 2);
  for (double x : {1, 2}) {
    const std::string line = t::read_text(run_dir(x) / "devices.log");
    // the orchestrator's own CUDA_VISIBLE_DEVICES, if any, passes through untouched
    const char* inherited = std::getenv("CUDA_VISIBLE_DEVICES");
    EXPECT_EQ(line, std::string("device - gpu ") + (inherited ? inherited : "-") + "\n");
  }
}

TEST_F(Orchestrator, SlurmTasksOnCudaAskForAGpuAndPassTheDevice) {
  // What a sweep launched on cuda hands sbatch, against a stand-in Slurm
  // (squeue answers, sbatch writes down its arguments and gives a job id):
  // each array task asks for one GPU unless the sweep names its gres, and its
  // task file tells the task's pool --device cuda. Needs a build with the
  // CUDA back-end (one without refuses --device cuda, tested in test_cli).
  if (!flocsim::gpu::built_with_cuda()) GTEST_SKIP() << "this build has no CUDA back-end";
  const std::string path = stand_in_slurm(
      "for a in \"$@\"; do echo \"$a\"; done > \"$(dirname \"$0\")/args\"\necho 4242\n");
  const fs::path bin = dir_ / "fake-slurm";
  for (const std::string gres : {"", "gpu:h100:2"}) {
    json sweep = json::parse(t::read_text(fs::path(FLOCSIM_SOURCE_DIR) / "sweeps/ci.json"));
    sweep["name"] = gres.empty() ? "gpu-default" : "gpu-named";
    if (!gres.empty()) sweep["slurm"]["gres"] = gres;
    t::write_text(dir_ / "sweep.json", sweep.dump());
    const t::Output o =
        t::run(flocsim({"sweep", "launch", (dir_ / "sweep.json").string(), "--db", db_, "--backend",
                        "slurm", "--no-wait", "--device", "cuda"}),
               {path});
    ASSERT_EQ(o.code, 0) << o.out;
    std::vector<std::string> args;
    std::istringstream lines(t::read_text(bin / "args"));
    for (std::string line; std::getline(lines, line);) args.push_back(line);
    ASSERT_FALSE(args.empty());
    EXPECT_NE(std::find(args.begin(), args.end(), "--gres=" + (gres.empty() ? "gpu:1" : gres)),
              args.end())
        << t::read_text(bin / "args");
    // the task files beside the job script carry the device to the tasks' pools
    const fs::path job_dir = fs::path(args.back()).parent_path();
    EXPECT_EQ(t::read_json(job_dir / "task_0.json").value("device", ""), "cuda");
  }
}

TEST_F(Orchestrator, CudaSweepsStopOnlyForWhatCudaAloneCannotRun) {
  // A grid point refused on every device (here Re_inf 72 at the draft
  // preset: nu 0.0033 below a = 4's stability floor) is recorded as refused
  // by its worker, as without --device, and the rest of the sweep runs on the
  // GPU; a point only cuda refuses (a scene without a liquid) stops the launch
  // before anything is recorded. Against the stand-in Slurm of the test above.
  if (!flocsim::gpu::built_with_cuda()) GTEST_SKIP() << "this build has no CUDA back-end";
  const std::string path = stand_in_slurm("echo 4242\n");
  const auto launch = [&](const json& sweep) {
    t::write_text(dir_ / "sweep.json", sweep.dump());
    return t::run(flocsim({"sweep", "launch", (dir_ / "sweep.json").string(), "--db", db_,
                           "--backend", "slurm", "--no-wait", "--device", "cuda"}),
                  {path});
  };
  json suspension = json::parse(t::read_text(fs::path(FLOCSIM_SOURCE_DIR) / "sweeps/demo.json"));
  suspension["axes"] = {{"Re_inf", {6, 72}}};
  const t::Output accepted = launch(suspension);
  EXPECT_EQ(accepted.code, 0) << accepted.out;
  EXPECT_EQ(accepted.out.find("grid point"), std::string::npos) << accepted.out;

  const json granular = {{"name", "granular-on-cuda"},
                         {"base", json::parse(t::read_text(fs::path(FLOCSIM_SOURCE_DIR) /
                                                           "examples/granular_gas.json"))},
                         {"axes", {{"seed", {1, 2}}}}};
  const t::Output refused = launch(granular);
  EXPECT_EQ(refused.code, 2) << refused.out;
  EXPECT_NE(refused.out.find("--device cuda: grid point"), std::string::npos) << refused.out;
  EXPECT_NE(refused.out.find("granular"), std::string::npos) << refused.out;
}

}  // namespace
