// The liquid averages on the GPU (engine/observables_gpu, Liquid::averages in
// engine/run/coupled_step.hpp) against the CPU's observables::liquid_averages:
//   - after coupled steps of the demo's suspension on the GPU, at both
//     parities of the AA pattern, in float and double: the device's averages
//     against the CPU's on the same state (the mirror brought up to date for
//     the comparison only: the device's averages themselves download none);
//   - a 200-step suspension run (sphere_run.cpp) on "cuda" and on "cpu": the
//     samples' liquid columns and the largest speeds agree, i.e. the samples,
//     which no longer download the lattice, read the right state.
// tests/observables/liquid_average_body_test.cpp holds the launch's kernel
// bodies and order to the CPU here; this suite checks them on a GPU.
//
// Round-off: on one state the two sum the same per-cell numbers (each float
// population is read into double on both) in different orders, and the GPU
// may fuse a multiply-add the CPU rounds twice, so a sum of n terms of size
// at most M differs by ~sqrt(n) eps M: compared to 1e-12 of M (M: the
// largest speed for the mean velocities, it times the cell count for the
// momentum; 1e-12 relative for the mass and the largest speeds). Two runs
// differ by the trajectories' round-off grown over the steps (the GPU
// coupling's atomic additions): 1e-6 of a column's largest value, in double.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "engine/case/case_file.hpp"
#include "engine/lattice_gpu/gpu_fluid_lattice.hpp"
#include "engine/observables/liquid_averages.hpp"
#include "engine/output/hdf5_file.hpp"
#include "engine/run/coupled_step.hpp"
#include "engine/run/sphere_run.hpp"
#include "tests/run/scratch_dir.hpp"

namespace flocsim::gpu {
namespace {

namespace fs = std::filesystem;

void expect_same_averages(const observables::LiquidAverages& gpu,
                          const observables::LiquidAverages& cpu, long cells) {
  constexpr double r = 1e-12;
  ASSERT_GT(cpu.max_speed, 0) << "a liquid at rest: the comparison would prove little";
  EXPECT_EQ(gpu.liquid_cells, cpu.liquid_cells);
  EXPECT_NEAR(gpu.mean_velocity_x, cpu.mean_velocity_x, r * cpu.max_speed);
  EXPECT_NEAR(gpu.mean_velocity_x_all_cells, cpu.mean_velocity_x_all_cells, r * cpu.max_speed);
  EXPECT_NEAR(gpu.lattice_momentum_x, cpu.lattice_momentum_x,
              r * cpu.max_speed * static_cast<double>(cells));
  EXPECT_NEAR(gpu.mass, cpu.mass, r * cpu.mass);
  EXPECT_NEAR(gpu.max_speed, cpu.max_speed, r * cpu.max_speed);
  EXPECT_NEAR(gpu.max_speed_outside_spheres, cpu.max_speed_outside_spheres,
              r * cpu.max_speed_outside_spheres);
}

// The demo's suspension (draft: a = 4, 64 x 32 x 32, 49 spheres).
cases::SuspensionCase demo(const char* precision) {
  const nlohmann::json doc = {{"scene", "suspension"},
                              {"fidelity", "draft"},
                              {"phi", 0.2},
                              {"Re_inf", 24},
                              {"du_over_Uinf", 0.03},
                              {"precision", precision},
                              {"numerics", {{"U_inf", 0.03}}}};
  return cases::parse_case(doc).spheres;
}

template <class Real>
void averages_after_coupled_steps(const char* precision) {
  const cases::SuspensionCase c = demo(precision);
  run::TimedStages stages;
  run::CoupledStep<Real> step(
      c, 0.03 * c.derived.settling_velocity, stages,
      std::make_unique<GpuFluidLattice<Real>>(
          c.derived.box, lattice::Relaxation{c.numerics.viscosity, c.numerics.trt_magic}));
  spheres::SphereSet s;
  s.radius = c.numerics.radius_cells;
  s.density_ratio = c.physics.density_ratio;
  run::place_spheres(c, cases::modules_of(c.scene), step.box(), s);
  run::Liquid<Real>& liquid = *step.liquid();
  liquid.to_device();
  for (int n = 1; n <= 40; ++n) {
    ASSERT_EQ(step.advance(s), "") << "step " << n;
    if (n != 39 && n != 40) continue;  // an odd and an even number of steps
    SCOPED_TRACE("after " + std::to_string(n) + " steps");
    const long mirror_step = liquid.fluid.time_step();
    const observables::LiquidAverages on_gpu = liquid.averages(s);
    EXPECT_EQ(liquid.fluid.time_step(), mirror_step) << "the averages downloaded the lattice";
    liquid.to_host();  // for the CPU's averages only
    std::vector<std::uint8_t> scratch;
    const observables::LiquidAverages on_cpu =
        observables::liquid_averages(liquid.fluid, s, scratch);
    expect_same_averages(on_gpu, on_cpu, c.derived.box.cells());
  }
}

TEST(GpuLiquidAverages, MatchTheCpusAfterCoupledStepsDouble) {
  averages_after_coupled_steps<double>("double");
}
TEST(GpuLiquidAverages, MatchTheCpusAfterCoupledStepsFloat) {
  averages_after_coupled_steps<float>("float");
}

// A suspension run of 200 steps (a = 4, 56 x 28 x 28, 33 spheres, stages of
// fixed length so that no stationarity test can end one differently on the
// two devices), sampled every 4 steps and checkpointed every 100 (the
// checkpoints download the lattice; the samples between them do not).
TEST(GpuLiquidAverages, ASuspensionRunSamplesAsOnTheCpu) {
  nlohmann::json doc = {{"scene", "suspension"},
                        {"fidelity", "draft"},
                        {"phi", 0.2},
                        {"Re_inf", 12},
                        {"du_over_Uinf", 0.5},
                        {"L_over_a", 14},
                        {"precision", "double"},
                        {"numerics", {{"U_inf", 0.05}}},
                        {"protocol",
                         {{"stage1_min", 1},
                          {"stage1_max", 1},
                          {"stage2_settle", 0.5},
                          {"statistics", 1},
                          {"sample_every", 0.05},
                          {"stationarity_window", 0.5},
                          {"snapshot_every", 0}}}};
  const fs::path cpu_dir = testing::fresh_dir("gpu_averages_cpu"),
                 gpu_dir = testing::fresh_dir("gpu_averages_cuda");
  const run::RunReport cpu =
      run::run_sphere_case(cases::parse_case(doc).spheres, {cpu_dir, false, true, 0, 100});
  doc["device"] = "cuda";
  const run::RunReport gpu =
      run::run_sphere_case(cases::parse_case(doc).spheres, {gpu_dir, false, true, 0, 100});
  ASSERT_EQ(cpu.outcome, run::RunOutcome::completed);
  ASSERT_EQ(gpu.outcome, run::RunOutcome::completed);
  const auto read = [](const fs::path& dir, const char* name) {
    return output::Hdf5File(dir / "series.h5", output::Hdf5File::Mode::read)
        .read<double>(std::string("/") + name);
  };
  const double cells = static_cast<double>(cases::parse_case(doc).spheres.derived.box.cells());
  for (const char* name : {"liquid_velocity", "liquid_velocity_all_cells", "U_over_Uinf",
                           "sphere_velocity", "momentum_balance"}) {
    SCOPED_TRACE(name);
    const std::vector<double> a = read(gpu_dir, name), b = read(cpu_dir, name);
    ASSERT_EQ(a.size(), b.size());
    ASSERT_GT(b.size(), 20u);
    double scale = 0;
    for (double v : b) scale = std::max(scale, std::abs(v));
    // the momentum balance is a drift at round-off: its scale is the lattice
    // momentum's, the cell count times the settling velocity
    if (std::string(name) == "momentum_balance") scale = cells * 0.05;
    ASSERT_GT(scale, 0);
    for (std::size_t k = 0; k < b.size(); ++k)
      EXPECT_NEAR(a[k], b[k], 1e-6 * scale) << "sample " << k;
  }
  const auto& og = gpu.result["observables"];
  const auto& oc = cpu.result["observables"];
  for (const char* key : {"max_liquid_speed", "max_liquid_speed_outside_spheres"})
    EXPECT_NEAR(og[key].get<double>(), oc[key].get<double>(), 1e-6 * oc[key].get<double>()) << key;
  fs::remove_all(cpu_dir);
  fs::remove_all(gpu_dir);
}

}  // namespace
}  // namespace flocsim::gpu
