// The fluid time loop: a run stopped and resumed gives bit-identical results
// to one that never stopped; a blow-up stops the run with a diagnosis and the
// last good checkpoint kept; result.json holds the exact body-force momentum
// and the analytic decay of the initial wave.
#include "engine/run/fluid_run.hpp"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "engine/case/case_file.hpp"
#include "engine/case/fluid_case.hpp"
#include "engine/coupling_gpu/gpu_partially_saturated.hpp"
#include "engine/input/input_reader.hpp"
#include "engine/lattice_gpu/gpu_runtime.hpp"
#include "engine/output/field_snapshots.hpp"
#include "engine/output/hdf5_file.hpp"
#include "engine/process/stop_signal.hpp"
#include "engine/run/coupled_step.hpp"
#include "engine/run/output_directory.hpp"
#include "tests/run/folder_holder.hpp"
#include "tests/run/scratch_dir.hpp"

namespace flocsim::run {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

using flocsim::testing::fresh_dir;

cases::FluidCase shear_wave_case(const std::string& precision) {
  return cases::parse_fluid_case(json::parse(R"({
    "scene": "fluid", "precision": ")" + precision +
                                             R"(",
    "fluid": {"size": [24, 6, 5], "viscosity": 0.02, "body_force": [1e-6, 0, -2e-6],
              "initial": {"type": "shear_wave", "amplitude": 0.02, "velocity": [0.01, 0, 0],
                          "noise": 0.001}},
    "run": {"steps": 301, "write_fields": true}
  })"));
}

template <class T>
std::vector<T> final_field(const fs::path& dir, const std::string& name, long step) {
  return output::Hdf5File(output::snapshot_file(dir / "fields", step), output::Hdf5File::Mode::read)
      .read<T>("/" + name);
}

class RestartIdentity : public ::testing::TestWithParam<std::string> {};

TEST_P(RestartIdentity, StopAndResumeGivesBitIdenticalFields) {
  // N steps in one go against N/2 + stop (checkpoint) + resume + the rest.
  // 301 steps and a stop after 151 put the checkpoint in the odd (shifted)
  // layout of the AA pattern, the harder case.
  const cases::FluidCase c = shear_wave_case(GetParam());
  const fs::path straight = fresh_dir("straight_" + GetParam()),
                 split = fresh_dir("split_" + GetParam());
  RunReport a = run_fluid_case(c, {straight, false, true, 0});
  ASSERT_EQ(a.outcome, RunOutcome::completed);

  RunReport first = run_fluid_case(c, {split, false, true, 151});
  ASSERT_EQ(first.outcome, RunOutcome::interrupted);
  ASSERT_TRUE(fs::exists(split / "checkpoint.h5"));
  EXPECT_FALSE(fs::exists(split / "result.json"));  // never recorded before completion
  RunReport second = run_fluid_case(c, {split, true, true, 0});
  ASSERT_EQ(second.outcome, RunOutcome::completed);
  EXPECT_FALSE(fs::exists(split / "checkpoint.h5"));  // removed once the result is on disk

  for (const char* name : {"density", "velocity_x", "velocity_y", "velocity_z"}) {
    const auto u = final_field<double>(straight, name, 301),
               v = final_field<double>(split, name, 301);
    ASSERT_EQ(u.size(), v.size());
    for (std::size_t i = 0; i < u.size(); ++i) ASSERT_EQ(u[i], v[i]) << name << " cell " << i;
  }
  EXPECT_EQ(a.result["observables"], second.result["observables"]);
  fs::remove_all(straight);
  fs::remove_all(split);
}

INSTANTIATE_TEST_SUITE_P(BothPrecisions, RestartIdentity, ::testing::Values("double", "float"));

TEST(FluidRun, ResultHoldsExactMomentumAndAnalyticDecay) {
  const cases::FluidCase c = shear_wave_case("double");
  const fs::path dir = fresh_dir("result");
  const RunReport r = run_fluid_case(c, {dir, false, true, 0});
  ASSERT_EQ(r.outcome, RunOutcome::completed);
  const json on_disk = json::parse(std::ifstream(dir / "result.json"));
  EXPECT_EQ(on_disk, r.result);
  EXPECT_EQ(on_disk["status"], "completed");
  const auto& obs = on_disk["observables"];
  // momentum grows by exactly f per cell per step (docs/model.md section 5)
  for (int d = 0; d < 3; ++d)
    EXPECT_NEAR(obs["momentum_final"][d].get<double>(), obs["momentum_expected"][d].get<double>(),
                1e-11);
  EXPECT_NEAR(obs["mass_relative_change"].get<double>(), 0.0, 1e-14);
  // shear wave decay nu k^2 over the whole run, including the start-up
  // transient of an equilibrium initial state: within 2 %
  EXPECT_NEAR(obs["viscosity_measured"].get<double>() / 0.02, 1.0, 0.02);
  fs::remove_all(dir);
}

TEST(FluidRun, BlowUpStopsWithDiagnosisAndKeepsLastGoodCheckpoint) {
  // nu = 1e-4 (tau = 0.5003) at u = 0.1 with grid-scale noise on a 16^3
  // grid is far outside the stable range: the run must stop, not write NaNs.
  json d = json::parse(R"({"scene": "fluid",
    "fluid": {"size": [16, 16, 16], "viscosity": 0.0001,
              "initial": {"type": "taylor_green", "amplitude": 0.1, "noise": 0.005}},
    "run": {"steps": 3000}})");
  const cases::FluidCase c = cases::parse_fluid_case(d);
  const fs::path dir = fresh_dir("blowup");
  RunOptions options{dir, false, true, 0};
  options.checkpoint_every_steps = 20;  // deterministic: checkpoints well before the blow-up
  const RunReport r = run_fluid_case(c, options);
  ASSERT_EQ(r.outcome, RunOutcome::failed);
  EXPECT_NE(r.message.find("blow-up"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("last good checkpoint"), std::string::npos) << r.message;
  EXPECT_FALSE(fs::exists(dir / "result.json"));
  ASSERT_TRUE(fs::exists(dir / "checkpoint.h5"));
  // the kept checkpoint is finite everywhere
  output::Hdf5File f(dir / "checkpoint.h5", output::Hdf5File::Mode::read);
  for (int i = 0; i < 19; ++i)
    for (double v : f.read<double>("/fluid/population_deviation_" + std::to_string(i)))
      ASSERT_TRUE(std::isfinite(v));
  fs::remove_all(dir);
}

TEST(FluidRun, SignalStopsTheRunWithACheckpoint) {
  const cases::FluidCase c = shear_wave_case("double");
  const fs::path dir = fresh_dir("signal");
  process::request_stop(SIGTERM);
  const RunReport r = run_fluid_case(c, {dir, false, true, 0});
  process::clear_stop_request();
  EXPECT_EQ(r.outcome, RunOutcome::interrupted);
  EXPECT_TRUE(fs::exists(dir / "checkpoint.h5"));
  EXPECT_FALSE(fs::exists(dir / "result.json"));
  fs::remove_all(dir);
}

TEST(FluidRun, ResumeRefusesACheckpointOfAnotherCase) {
  cases::FluidCase c = shear_wave_case("double");
  const fs::path dir = fresh_dir("othercase");
  ASSERT_EQ(run_fluid_case(c, {dir, false, true, 10}).outcome, RunOutcome::interrupted);
  c.relaxation.viscosity = 0.03;
  EXPECT_THROW(run_fluid_case(c, {dir, true, true, 0}), input::InputError);
  fs::remove_all(dir);
}

TEST(FluidRun, ResumeAcceptsOtherRunControlAndExtendsARun) {
  // threads, cadences and (fluid) the step count are not physics: a run may
  // be continued with other values; the result equals an uninterrupted run.
  const cases::FluidCase c = shear_wave_case("double");
  const fs::path straight = fresh_dir("extend_straight"), split = fresh_dir("extend_split");
  ASSERT_EQ(run_fluid_case(c, {straight, false, true, 0}).outcome, RunOutcome::completed);
  cases::FluidCase shorter = c;
  shorter.run.steps = 200;
  shorter.run.threads = 1;
  ASSERT_EQ(run_fluid_case(shorter, {split, false, true, 100}).outcome, RunOutcome::interrupted);
  const RunReport b = run_fluid_case(c, {split, true, true, 0});
  ASSERT_EQ(b.outcome, RunOutcome::completed);
  const auto u = final_field<double>(straight, "velocity_y", 301),
             v = final_field<double>(split, "velocity_y", 301);
  EXPECT_EQ(u, v);
  fs::remove_all(straight);
  fs::remove_all(split);
}

TEST(FluidRun, AFreshStartNeverDiscardsACheckpointOrAResult) {
  const cases::FluidCase c = shear_wave_case("double");
  const fs::path dir = fresh_dir("fresh");
  ASSERT_EQ(run_fluid_case(c, {dir, false, true, 10}).outcome, RunOutcome::interrupted);
  EXPECT_THROW(run_fluid_case(c, {dir, false, true, 0}), input::InputError);  // checkpoint there
  const RunReport done = run_fluid_case(c, {dir, true, true, 0});
  ASSERT_EQ(done.outcome, RunOutcome::completed);
  EXPECT_THROW(run_fluid_case(c, {dir, false, true, 0}), input::InputError);  // result there
  // --resume of a completed run changes nothing and reports the stored result
  const auto before = fs::last_write_time(dir / "result.json");
  const RunReport again = run_fluid_case(c, {dir, true, true, 0});
  EXPECT_EQ(again.outcome, RunOutcome::completed);
  EXPECT_EQ(again.result, done.result);
  EXPECT_EQ(fs::last_write_time(dir / "result.json"), before);
  fs::remove_all(dir);
}

// Two runs given one --out would overwrite each other's output: while another
// process holds the directory, a fresh start and a --resume are both refused,
// naming that process, before anything in the directory is read or written;
// once the holder is killed (no destructor runs, its lock file stays) the
// next run takes the directory over, and a run that ends leaves no lock file.
TEST(OutputDirectory, ASecondRunInTheSameDirectoryIsRefusedWhileTheFirstHoldsIt) {
  const cases::FluidCase c = shear_wave_case("double");
  const fs::path dir = fresh_dir("held");
  fs::create_directories(dir);
  flocsim::testing::FolderHolder other(dir);  // the other flocsim
  const pid_t holder = other.pid();
  for (const bool resume : {false, true}) {
    try {
      run_fluid_case(c, {dir, resume, true, 0});
      ADD_FAILURE() << "a run into a held directory was not refused (resume " << resume << ")";
    } catch (const OutputDirectoryBusy& e) {  // exit 4 in `flocsim run`, not a case error
      EXPECT_NE(std::string(e.what()).find("another flocsim (process " + std::to_string(holder) +
                                           ") is writing to this directory"),
                std::string::npos)
          << e.what();
    }
  }
  EXPECT_FALSE(fs::exists(dir / "run.log"));  // refused before the directory was touched
  EXPECT_FALSE(fs::exists(dir / kRunRecord));
  other.kill();
  EXPECT_TRUE(fs::exists(dir / ".flocsim-run.lock"));  // a killed holder leaves its file
  EXPECT_EQ(run_fluid_case(c, {dir, false, true, 0}).outcome, RunOutcome::completed);
  EXPECT_FALSE(fs::exists(dir / ".flocsim-run.lock"));
  fs::remove_all(dir);
}

TEST(FluidRun, TaylorGreenCarriedByAMeanFlowDecaysAtTheAnalyticRate) {
  // The vortex is advected by a uniform flow; the amplitude measured by
  // projection on all four phase combinations must still decay as
  // exp(-nu (k1^2 + k2^2) t): within 2 % over the whole run (start-up
  // transient of the equilibrium initial state, Galilean error 3U^2 ~ 0.1 %).
  const cases::FluidCase c = cases::parse_fluid_case(json::parse(R"({
    "scene": "fluid", "fluid": {"size": [32, 24, 2], "viscosity": 0.02,
      "initial": {"type": "taylor_green", "amplitude": 0.01, "velocity": [0.02, 0.01, 0]}},
    "run": {"steps": 1500}})"));
  const fs::path dir = fresh_dir("tg_advected");
  const RunReport r = run_fluid_case(c, {dir, false, true, 0});
  ASSERT_EQ(r.outcome, RunOutcome::completed);
  EXPECT_NEAR(r.result["observables"]["viscosity_measured"].get<double>() / 0.02, 1.0, 0.02);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace flocsim::run

namespace flocsim::run {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
using flocsim::testing::fresh_dir;

cases::FluidCase small_case(double viscosity) {
  return cases::parse_fluid_case(
      json{{"scene", "fluid"},
           {"fluid", {{"size", {8, 4, 4}}, {"viscosity", viscosity}}},
           {"run", {{"steps", 20}, {"write_fields", true}, {"fields_every", 5}}}});
}

std::string text_of(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// A checkpoint from before numerics.immersed_boundary existed was run with the
// paper's method: it resumes under a case that names that method, and not
// under one that asks for another.
TEST(OutputDirectory, CheckpointsWithoutAnImmersedBoundaryFieldWereThePaperMethod) {
  const json old_case = {
      {"scene", "suspension"}, {"phi", 0.2}, {"numerics", {{"a_over_dx", 4}, {"viscosity", 0.02}}}};
  json paper = old_case;
  paper["numerics"]["immersed_boundary"] = {
      {"marker_spacing", 0.7}, {"sweeps", 2}, {"kernel", "roma3"}};
  json one_sweep = old_case;
  one_sweep["numerics"]["immersed_boundary"] = {
      {"marker_spacing", 1.0}, {"sweeps", 1}, {"kernel", "roma3"}};
  EXPECT_TRUE(resumable_under(old_case, paper));
  EXPECT_FALSE(resumable_under(old_case, one_sweep));
  EXPECT_FALSE(resumable_under(paper, one_sweep));
}

// A checkpoint from before lubrication_model existed used Nguyen-Ladd's
// correction: it resumes under a case that says so, and the refusal under the
// calibrated model names the field and both values.
TEST(OutputDirectory, CheckpointsWithoutALubricationModelWereNguyenLadd) {
  const json old_case = {
      {"scene", "suspension"},
      {"phi", 0.2},
      {"numerics",
       {{"a_over_dx", 4},
        {"immersed_boundary", {{"marker_spacing", 0.7}, {"sweeps", 2}, {"kernel", "roma3"}}}}}};
  json nguyen_ladd = old_case;
  nguyen_ladd["lubrication_model"] = "nguyen-ladd";
  json calibrated = old_case;
  calibrated["lubrication_model"] = "calibrated";
  EXPECT_TRUE(resumable_under(old_case, nguyen_ladd));
  EXPECT_FALSE(resumable_under(old_case, calibrated));
  EXPECT_EQ(case_differences(old_case, calibrated),
            "lubrication_model = \"nguyen-ladd\" in the checkpoint, \"calibrated\" now");
  json other = nguyen_ladd;
  other["numerics"]["a_over_dx"] = 6;
  EXPECT_EQ(case_differences(nguyen_ladd, other),
            "numerics.a_over_dx = 4 in the checkpoint, 6 now");
  // a scene without lubrication resumes whatever default its version wrote
  json fixed_old = nguyen_ladd, fixed_now = calibrated;
  fixed_old["scene"] = fixed_now["scene"] = "fixed-array";
  EXPECT_TRUE(resumable_under(fixed_old, fixed_now));
}

TEST(OutputDirectory, ResumingACompletedRunOfAnotherCaseIsRefusedNamingTheField) {
  // The reproducer of the report: a completed run, the case edited, `--resume`
  // exited 0 with "already completed" and the old result.
  const fs::path o = fresh_dir("completed_other_case");
  ASSERT_EQ(run_fluid_case(small_case(0.05), {o, false, true, 0}).outcome, RunOutcome::completed);
  const std::string result = text_of(o / "result.json");
  try {
    run_fluid_case(small_case(0.06), {o, true, true, 0});
    ADD_FAILURE() << "a completed run of viscosity 0.05 was reported as the run of 0.06";
  } catch (const input::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("fluid.viscosity = 0.05 in the result, 0.06 now"),
              std::string::npos)
        << e.what();
  }
  // a completed run is not extended: more steps are another case too
  cases::FluidCase longer = small_case(0.05);
  longer.run.steps = 40;
  EXPECT_THROW(run_fluid_case(longer, {o, true, true, 0}), input::InputError);
  EXPECT_EQ(text_of(o / "result.json"), result);
  // the same case, with other run control, is the completed run
  cases::FluidCase same = small_case(0.05);
  same.run.threads = 1;
  EXPECT_EQ(run_fluid_case(same, {o, true, true, 0}).outcome, RunOutcome::completed);
  fs::remove_all(o);
}

// Issue 41, item 3: a result.json cut short made a run unresumable: --resume
// said "already completed", then failed on a raw JSON parse error naming no
// file, at every resume until the file was removed by hand.
TEST(OutputDirectory, AnUnreadableResultIsSetAsideAndTheRunGoesOn) {
  const fs::path o = fresh_dir("unreadable_result");
  // with a checkpoint: the run continues from it
  ASSERT_EQ(run_fluid_case(small_case(0.05), {o, false, true, 12}).outcome,
            RunOutcome::interrupted);
  std::ofstream(o / "result.json") << "{\"status\": \"comp";
  // without --resume: refused, naming the file and the way out
  try {
    run_fluid_case(small_case(0.05), {o, false, true, 0});
    ADD_FAILURE() << "a fresh start went ahead over an unreadable result.json";
  } catch (const input::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("result.json: cannot be read"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("--resume"), std::string::npos) << e.what();
  }
  const RunReport r = run_fluid_case(small_case(0.05), {o, true, true, 0});
  ASSERT_EQ(r.outcome, RunOutcome::completed) << r.message;
  EXPECT_EQ(text_of(o / "result.json.unreadable"), "{\"status\": \"comp");  // kept, not removed
  EXPECT_EQ(json::parse(text_of(o / "result.json")).value("status", ""), "completed");
  EXPECT_NE(text_of(o / "run.log").find("continues from its checkpoint"), std::string::npos);
  // completed, no checkpoint left: the run record says it is this case, so it starts again
  std::ofstream(o / "result.json") << "[1, 2";
  const RunReport again = run_fluid_case(small_case(0.05), {o, true, true, 0});
  ASSERT_EQ(again.outcome, RunOutcome::completed) << again.message;
  EXPECT_EQ(text_of(o / "result.json.unreadable.1"), "[1, 2");
  // a damaged result.json that nothing says this case wrote is the user's: refused
  const fs::path foreign = fresh_dir("unreadable_foreign_result");
  fs::create_directories(foreign);
  std::ofstream(foreign / "result.json") << "{";
  EXPECT_THROW(run_fluid_case(small_case(0.05), {foreign, true, true, 0}), input::InputError);
  EXPECT_EQ(text_of(foreign / "result.json"), "{");
  // and a fresh start there is not told to use --resume, which would be refused as above
  try {
    run_fluid_case(small_case(0.05), {foreign, false, true, 0});
    ADD_FAILURE() << "a fresh start went ahead over a user's unreadable result.json";
  } catch (const input::InputError& e) {
    EXPECT_EQ(std::string(e.what()).find("--resume"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("move it away"), std::string::npos) << e.what();
  }
  EXPECT_EQ(text_of(foreign / "result.json"), "{");
  fs::remove_all(o);
  fs::remove_all(foreign);
}

// Issue 41, item 3: a damaged checkpoint.h5 failed with HDF5's words only;
// the failure now names the file and what to do with it.
TEST(OutputDirectory, ADamagedCheckpointSaysWhatToDoWithIt) {
  const fs::path o = fresh_dir("damaged_checkpoint");
  ASSERT_EQ(run_fluid_case(small_case(0.05), {o, false, true, 12}).outcome,
            RunOutcome::interrupted);
  std::ofstream(o / "checkpoint.h5", std::ios::trunc) << "not hdf5";
  const RunReport r = run_fluid_case(small_case(0.05), {o, true, true, 0});
  EXPECT_EQ(r.outcome, RunOutcome::failed);
  EXPECT_NE(r.message.find((o / "checkpoint.h5").string() + " cannot be read"), std::string::npos)
      << r.message;
  EXPECT_NE(r.message.find("Move it away"), std::string::npos) << r.message;
  EXPECT_EQ(text_of(o / "checkpoint.h5"), "not hdf5");
  // moved away, --resume starts the case over
  fs::rename(o / "checkpoint.h5", o / "checkpoint.h5.bad");
  EXPECT_EQ(run_fluid_case(small_case(0.05), {o, true, true, 0}).outcome, RunOutcome::completed);
  fs::remove_all(o);
}

TEST(OutputDirectory, AFreshRunNeverRemovesAUsersFiles) {
  // The reproducer of the report: a folder holding the user's spheres/mine.txt
  // and a file called `fields`; the fresh run removed both and exited 0.
  const fs::path o = fresh_dir("users_files");
  fs::create_directories(o / "spheres");
  std::ofstream(o / "spheres" / "mine.txt") << "mine\n";
  std::ofstream(o / "fields") << "notes\n";
  std::ofstream(o / "case.json") << "{}\n";  // unrelated files are no obstacle
  try {
    run_fluid_case(small_case(0.05), {o, false, true, 0});
    ADD_FAILURE() << "a run started over the user's files";
  } catch (const input::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("flocsim removes only what it wrote"), std::string::npos)
        << e.what();
  }
  EXPECT_EQ(text_of(o / "spheres" / "mine.txt"), "mine\n");
  EXPECT_EQ(text_of(o / "fields"), "notes\n");
  EXPECT_EQ(text_of(o / "case.json"), "{}\n");
  // without the colliding names the run goes ahead and leaves case.json alone
  fs::remove(o / "fields");
  fs::remove_all(o / "spheres");
  EXPECT_EQ(run_fluid_case(small_case(0.05), {o, false, true, 0}).outcome, RunOutcome::completed);
  EXPECT_EQ(text_of(o / "case.json"), "{}\n");
  fs::remove_all(o);
}

// Found by scripts/probe-cli.sh: a run.log in --out that is a symbolic link
// had the run's log appended to the file it points to (a user's file). Every
// place a run writes is checked for a link before any work.
TEST(OutputDirectory, ALinkWhereTheRunWritesIsRefusedAndItsTargetKept) {
  const fs::path o = fresh_dir("linked_outputs");
  const fs::path mine = o.parent_path() / "linked_outputs_mine.txt";
  std::ofstream(mine) << "mine\n";
  for (const std::string name : {"run.log", "progress.json", "flocsim-run.json", "series.h5"}) {
    fs::remove_all(o);
    fs::create_directories(o);
    fs::create_symlink(mine, o / name);
    try {
      run_fluid_case(small_case(0.05), {o, false, true, 0});
      ADD_FAILURE() << name << ": a run wrote through a link";
    } catch (const input::InputError& e) {
      EXPECT_NE(std::string(e.what()).find((o / name).string() + ": a symbolic link"),
                std::string::npos)
          << e.what();
    }
    EXPECT_EQ(text_of(mine), "mine\n") << name;
    EXPECT_TRUE(fs::is_symlink(o / name)) << name;
  }
  fs::remove_all(o);
  fs::remove(mine);
}

TEST(OutputDirectory, AFreshStartOfTheSameCaseReplacesOnlyItsOwnSnapshots) {
  // An attempt that died before its first checkpoint left snapshots; the next
  // attempt of the same case (the orchestrator's retry) removes those by name
  // and keeps whatever else is in the folders.
  const fs::path o = fresh_dir("same_case");
  ASSERT_EQ(run_fluid_case(small_case(0.05), {o, false, true, 12}).outcome,
            RunOutcome::interrupted);
  ASSERT_EQ(output::snapshot_steps(o / "fields"), (std::vector<long>{5, 10}));
  fs::remove(o / "checkpoint.h5");  // as if it had died before the checkpoint
  std::ofstream(o / "fields" / "notes.txt") << "keep\n";
  std::ofstream(o / "fields" / ".step_0000000015.h5.tmp.4242") << "half";  // a killed writer's
  ASSERT_EQ(run_fluid_case(small_case(0.05), {o, false, true, 7}).outcome, RunOutcome::interrupted);
  EXPECT_EQ(output::snapshot_steps(o / "fields"), (std::vector<long>{5}));
  EXPECT_EQ(text_of(o / "fields" / "notes.txt"), "keep\n");
  EXPECT_FALSE(fs::exists(o / "fields" / ".step_0000000015.h5.tmp.4242"));
  // another case in the same folder is refused, and nothing is touched
  fs::remove(o / "checkpoint.h5");
  try {
    run_fluid_case(small_case(0.06), {o, false, true, 0});
    ADD_FAILURE() << "another case ran over this one's output";
  } catch (const input::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("holds the output of a different case"), std::string::npos)
        << e.what();
  }
  EXPECT_EQ(output::snapshot_steps(o / "fields"), (std::vector<long>{5}));
  fs::remove_all(o);
}

TEST(DiskFull, TheMessageSaysNoSpaceLeftOnDevice) {
  // /dev/full accepts the open and fails every write with ENOSPC, as a full
  // disk does; HDF5's own text ("cannot write dataset ...") lacked the reason.
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full on this system";
  try {
    output::Hdf5File f("/dev/full", output::Hdf5File::Mode::create);
    const std::vector<double> x(1 << 16, 1.0);
    f.write("/x", {x.size()}, x.data());
    f.close();
    ADD_FAILURE() << "wrote to /dev/full";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("No space left on device"), std::string::npos) << e.what();
  }
}

TEST(DiskFull, AFluidRunSaysSoInItsLog) {
  // A fluid run on a 1 MiB file system: the failure and its reason reach
  // run.log, not only stderr. Needs root to mount the file system.
  const fs::path o = fresh_dir("disk_full");
  fs::create_directories(o);
  if (::geteuid() != 0 ||
      std::system(("mount -t tmpfs -o size=1m tmpfs " + o.string() + " 2>/dev/null").c_str()) != 0)
    GTEST_SKIP() << "cannot mount a small tmpfs here (needs root)";
  cases::FluidCase c = cases::parse_fluid_case(
      json{{"scene", "fluid"},
           {"fluid", {{"size", {32, 32, 32}}, {"viscosity", 0.05}}},
           {"run", {{"steps", 20}, {"write_fields", true}, {"fields_every", 5}}}});
  const RunReport r = run_fluid_case(c, {o / "run", false, true, 0});
  const std::string log = text_of(o / "run" / "run.log");
  std::system(("umount " + o.string()).c_str());
  EXPECT_EQ(r.outcome, RunOutcome::failed);
  EXPECT_NE(r.message.find("No space left on device"), std::string::npos) << r.message;
  EXPECT_NE(log.find("No space left on device"), std::string::npos) << log;
  fs::remove_all(o);
}

// ---- device (engine/case/device.hpp) ------------------------------------------

TEST(Device, CaseFieldDefaultsToTheCpuAndIsWrittenOnlyOffTheDefault) {
  const auto with = [](const std::string& device) {
    json j = json::parse(R"({"scene": "fluid", "fluid": {"size": [8, 4, 4], "viscosity": 0.02}})");
    if (!device.empty()) j["device"] = device;
    return cases::parse_fluid_case(j);
  };
  EXPECT_EQ(with("").device, cases::Device::cpu);
  // cases written before the field existed keep their canonical form (run ids)
  EXPECT_FALSE(with("").to_json().contains("device"));
  EXPECT_FALSE(with("cpu").to_json().contains("device"));
  EXPECT_EQ(with("cuda").device, cases::Device::cuda);
  EXPECT_EQ(with("cuda").to_json()["device"], "cuda");
  try {
    with("gpu");
    FAIL() << "device \"gpu\" accepted";
  } catch (const input::InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("device"), std::string::npos) << what;
    EXPECT_NE(what.find("gpu"), std::string::npos) << what;
    EXPECT_NE(what.find("cuda"), std::string::npos) << what;
  }
}

TEST(Device, ACheckpointOrResultMovesBetweenDevices) {
  // the device is how a run is computed, like its threads: a checkpoint
  // written on the GPU continues on the CPU, a result counts on either
  const json cpu = shear_wave_case("double").to_json();
  json cuda = cpu;
  cuda["device"] = "cuda";
  EXPECT_TRUE(resumable_under(cuda, cpu));
  EXPECT_TRUE(resumable_under(cpu, cuda));
  EXPECT_TRUE(completed_under(cuda, cpu));
  json other = cuda;
  other["precision"] = "float";  // what is computed still has to match
  EXPECT_FALSE(resumable_under(other, cpu));
}

// A scene with a liquid, coupled by the immersed boundary or by partially
// saturated cells, may ask for the GPU (its lattice and coupling run there,
// docs/gpu.md), recorded in the case as the fluid scene's is; a scene without
// a liquid is refused with the reason.
TEST(Device, SphereScenesTakeCudaWhereTheirCouplingRunsOnTheGpu) {
  for (const char* scene : {"suspension", "fixed-array", "single-sphere"}) {
    json j = {{"scene", scene}, {"device", "cuda"}, {"fidelity", "draft"}};
    if (std::string(scene) != "single-sphere") j["phi"] = 0.1;
    const cases::ParsedCase c = cases::parse_case(j);
    EXPECT_EQ(c.spheres.device, cases::Device::cuda) << scene;
    EXPECT_EQ(c.spheres.to_json()["device"], "cuda") << scene;
    j.erase("device");
    EXPECT_FALSE(cases::parse_case(j).spheres.to_json().contains("device")) << scene;
  }
  try {
    cases::parse_case(json{{"scene", "granular"}, {"device", "cuda"}, {"phi", 0.1}});
    ADD_FAILURE() << "granular accepted device cuda";
  } catch (const input::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("has no liquid, and the GPU runs the lattice"),
              std::string::npos)
        << e.what();
  }
  // Partially saturated cells run on the GPU too (engine/coupling_gpu): the
  // case is accepted as it is; its run needs a usable GPU, and where there is
  // none the GPU lattice is refused with the reason, before any work.
  const json psm = {{"scene", "suspension"},
                    {"device", "cuda"},
                    {"phi", 0.1},
                    {"fidelity", "draft"},
                    {"numerics", {{"coupling", "partially-saturated"}}}};
  const cases::ParsedCase c = cases::parse_case(psm);
  EXPECT_EQ(c.spheres.device, cases::Device::cuda);
  EXPECT_EQ(c.spheres.to_json()["device"], "cuda");
  ASSERT_FALSE(c.spheres.numerics.coupling.immersed_boundary());
  const gpu::GpuQuery gpus = gpu::query_gpus();
  const lattice::Relaxation relaxation{c.spheres.numerics.viscosity, c.spheres.numerics.trt_magic};
  if (gpus.devices.empty()) {
    ASSERT_FALSE(gpus.why_none.empty());
    try {
      gpu::GpuFluidLattice<double> device(c.spheres.derived.box, relaxation);
      ADD_FAILURE() << "a GPU lattice without a usable GPU";
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(std::string(e.what()), gpus.why_none);
    }
  } else {
    Liquid<double> liquid(c.spheres, std::make_unique<gpu::GpuFluidLattice<double>>(
                                         c.spheres.derived.box, relaxation));
    EXPECT_NE(dynamic_cast<gpu::GpuPartiallySaturatedCells<double>*>(liquid.coupling.get()),
              nullptr);
    EXPECT_EQ(liquid.coupling->stage_name(), "partially_saturated");
  }
}

}  // namespace
}  // namespace flocsim::run
