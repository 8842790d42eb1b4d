// The time loop of sphere scenes, on the granular scene (spheres with direct
// interactions and no liquid): a run stopped and resumed gives bit-identical
// results; elastic hard spheres with square wells conserve kinetic energy
// minus the well depth of attached pairs; the protocol's stages and windows
// are reported; scenes this build cannot run are refused as input errors.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "engine/case/suspension_case.hpp"
#include "engine/input/input_reader.hpp"
#include "engine/output/hdf5_file.hpp"
#include "engine/run/sphere_run.hpp"

namespace flocsim::run {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

fs::path fresh_dir(const std::string& name) {
  const fs::path p = fs::temp_directory_path() / ("flocsim_sphere_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(p);
  return p;
}

cases::SuspensionCase granular(double du_over_uinf) {
  return cases::parse_suspension_case(json::parse(R"({
    "scene": "granular", "fidelity": "draft", "phi": 0.25, "Re_inf": 12,
    "du_over_Uinf": )" + std::to_string(du_over_uinf) + R"(,
    "protocol": {"stage1_min": 2, "stage1_max": 4, "stage2_settle": 2, "statistics": 10,
                 "stationarity_window": 1, "snapshot_every": 3, "sample_every": 0.25}
  })"));
}

TEST(SphereRun, GranularStopAndResumeIsBitIdentical) {
  const cases::SuspensionCase c = granular(0.5);
  const fs::path straight = fresh_dir("straight"), split = fresh_dir("split");
  const RunReport a = run_sphere_case(c, {straight, false, true, 0});
  ASSERT_EQ(a.outcome, RunOutcome::completed);
  // stop inside stage 2 (after wells switched on: attached pairs are state)
  const long stop = static_cast<long>(5.3 * c.convective_time);
  ASSERT_EQ(run_sphere_case(c, {split, false, true, stop}).outcome, RunOutcome::interrupted);
  EXPECT_FALSE(fs::exists(split / "result.json"));
  const RunReport b = run_sphere_case(c, {split, true, true, 0});
  ASSERT_EQ(b.outcome, RunOutcome::completed);
  EXPECT_EQ(a.result["observables"], b.result["observables"]);
  const long last = a.result["cost"]["steps"].get<long>();
  char g[48];
  std::snprintf(g, sizeof g, "/step_%010ld/position", last);
  const auto pa = output::Hdf5File(straight / "spheres.h5", output::Hdf5File::Mode::read).read<double>(g);
  const auto pb = output::Hdf5File(split / "spheres.h5", output::Hdf5File::Mode::read).read<double>(g);
  ASSERT_EQ(pa.size(), static_cast<std::size_t>(3 * c.sphere_count));
  EXPECT_EQ(pa, pb);
  fs::remove_all(straight);
  fs::remove_all(split);
}

TEST(SphereRun, ElasticGasConservesKineticMinusWellEnergy) {
  // e = 1, no friction, no liquid: kinetic energy minus m_p du^2 per attached
  // pair is conserved to round-off (VALIDATION.md) over the statistics window,
  // with many collisions, captures and escapes, and no overlap.
  const cases::SuspensionCase c = granular(0.5);
  const fs::path dir = fresh_dir("energy");
  const RunReport r = run_sphere_case(c, {dir, false, true, 0});
  ASSERT_EQ(r.outcome, RunOutcome::completed);
  const auto& obs = r.result["observables"];
  EXPECT_LT(std::abs(obs["energy_relative_change"].get<double>()), 1e-12);
  EXPECT_GT(obs["events"]["collisions"].get<long>(), 1000);
  EXPECT_GT(obs["events"]["well_entries"].get<long>(), 100);
  EXPECT_GT(obs["events"]["escapes"].get<long>(), 100);
  EXPECT_LE(obs["events"]["worst_overlap"].get<double>(), 1e-9);
  // the window is the one asked for: statistics = 10 a/U_inf after settle
  EXPECT_NEAR(obs["window"]["end"].get<double>() - obs["window"]["start"].get<double>(), 10.0, 0.01);
  // the mass-weighted size distribution sums to 1 and gives <n_a>
  double total = 0, mean = 0;
  const auto p = obs["size_distribution"].get<std::vector<double>>();
  for (std::size_t n = 0; n < p.size(); ++n) total += p[n], mean += n * p[n];
  EXPECT_NEAR(total, 1.0, 1e-12);
  EXPECT_NEAR(mean, obs["n_a_mean"]["mean"].get<double>(), 0.05);
  ASSERT_TRUE(fs::exists(dir / "series.h5"));
  ASSERT_TRUE(fs::exists(dir / "spheres.xdmf"));
  fs::remove_all(dir);
}

TEST(SphereRun, ScenesThisBuildCannotRunAreInputErrors) {
  cases::SuspensionCase c = granular(0.0);
  c.scene = "suspension";
  if (std::find(runnable_sphere_scenes().begin(), runnable_sphere_scenes().end(), "suspension") !=
      runnable_sphere_scenes().end())
    GTEST_SKIP() << "this build runs the suspension scene";
  EXPECT_THROW(run_sphere_case(c, {fresh_dir("refused"), false, true, 0}), input::InputError);
}

}  // namespace
}  // namespace flocsim::run
