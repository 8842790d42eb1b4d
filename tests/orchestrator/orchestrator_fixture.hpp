#pragma once
// The fixture of the orchestrator's end-to-end tests (orchestrator_test.cpp:
// runs, faults and resume; orchestrator_input_test.cpp: bad input, hostile
// names, databases and plans; orchestrator_devices_test.cpp: workers on GPUs):
// a scratch folder and database per test, `flocsim sweep ...` and `flocsim
// query` as processes against the scriptable fake worker, and the database
// read back directly. One named class, so that every file's TEST_F shares it.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "db/results_db.hpp"
#include "harness.hpp"

namespace flocsim::test::orchestrator_fixture {

namespace fs = std::filesystem;
using flocsim::db::ResultsDb;
using flocsim::db::RunState;
using nlohmann::json;
namespace t = flocsim::test;

class Orchestrator : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("flocsim_orch_test_" + std::to_string(getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    db_ = (dir_ / "results.db").string();
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }

  // A sweep of fake-worker runs over x, each `steps` steps of `step_ms`.
  std::string fake_sweep(const std::vector<double>& xs, int steps, int step_ms,
                         const json& fake_extra = json::object(), int max_attempts = 2) {
    json fake{{"steps", steps}, {"step_ms", step_ms}};
    fake.update(fake_extra);
    json s{{"name", "fake"},
           {"base", {{"x", 0}, {"fake", fake}}},
           {"axes", {{"x", xs}}},
           {"max_attempts", max_attempts}};
    const std::string file = (dir_ / "sweep.json").string();
    t::write_text(file, s.dump(2));
    return file;
  }
  // A stand-in Slurm in dir/fake-slurm: squeue answers nothing, sbatch runs
  // `sbatch_body` (a shell script's lines). Returns the PATH entry that puts
  // it first, for t::run's environment.
  std::string stand_in_slurm(const std::string& sbatch_body) {
    const fs::path bin = dir_ / "fake-slurm";
    fs::create_directories(bin);
    t::write_text(bin / "squeue", "#!/bin/sh\nexit 0\n");
    t::write_text(bin / "sbatch", "#!/bin/sh\n" + sbatch_body);
    fs::permissions(bin / "squeue", fs::perms::owner_all);
    fs::permissions(bin / "sbatch", fs::perms::owner_all);
    return "PATH=" + bin.string() + ":" + std::getenv("PATH");
  }
  std::vector<std::string> flocsim(std::vector<std::string> args) {
    args.insert(args.begin(), FLOCSIM_EXE);
    return args;
  }
  std::vector<std::string> launch(const std::string& sweep, int jobs = 2,
                                  std::vector<std::string> extra = {}) {
    std::vector<std::string> a = flocsim({"sweep", "launch", sweep, "--db", db_, "--jobs",
                                          std::to_string(jobs), "--worker", FAKE_WORKER_EXE});
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  }
  std::vector<std::string> resume(int jobs = 2) {
    return flocsim({"sweep", "resume", "--db", db_, "--jobs", std::to_string(jobs), "--worker",
                    FAKE_WORKER_EXE});
  }
  json query() {
    const t::Output o = t::run(flocsim({"query", "--db", db_, "--format", "json"}));
    EXPECT_EQ(o.code, 0) << o.out;
    return json::parse(o.out, nullptr, false);
  }
  // Run directory of the run whose case has x.
  fs::path run_dir(double x) {
    ResultsDb db(db_, ResultsDb::Mode::kExisting);
    for (const auto& r : db.runs())
      if (json::parse(r.case_json).value("x", -1.0) == x) return r.run_dir;
    ADD_FAILURE() << "no run with x = " << x;
    return {};
  }
  std::map<double, std::string> statuses() {
    ResultsDb db(db_, ResultsDb::Mode::kExisting);
    std::map<double, std::string> out;
    for (const auto& r : db.runs())
      out[json::parse(r.case_json).value("x", -1.0)] = to_string(r.status);
    return out;
  }
  int progress_step(double x) {
    const json p = t::read_json(run_dir(x) / "progress.json");
    return p.is_object() ? p.value("step", 0) : 0;
  }
  void expect_one_result_per_completed_run() {
    ResultsDb db(db_, ResultsDb::Mode::kExisting);
    EXPECT_EQ(db.integrity_check(), "ok");
    for (const auto& r : db.runs())
      EXPECT_EQ(db.count_results(r.id), r.status == RunState::kCompleted ? 1 : 0) << r.case_json;
  }

  // `ro` shows `rw` read-only (a bind mount); false where that cannot be
  // done (not root), with nothing left mounted.
  static bool mount_read_only(const fs::path& rw, const fs::path& ro) {
    if (::geteuid() == 0 &&
        std::system(("mount --bind " + rw.string() + " " + ro.string() +
                     " && mount -o remount,ro,bind " + ro.string() + " 2>/dev/null")
                        .c_str()) == 0)
      return true;
    std::system(("umount " + ro.string() + " 2>/dev/null").c_str());
    return false;
  }

  fs::path dir_;
  std::string db_;
};

}  // namespace flocsim::test::orchestrator_fixture
