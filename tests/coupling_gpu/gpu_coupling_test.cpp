// The GPU immersed boundary (engine/coupling_gpu) against the CPU's
// ImmersedBoundary, the reference, on the same liquid and spheres: the loads
// of a step, the liquid after it, control forcing's carried state, a settling
// sphere's trajectory, and a checkpoint carried from the GPU to the CPU. The
// kernel bodies are the ones tests/immersed_boundary/marker_body_test.cpp
// holds to the CPU coupling here; this suite checks their launch on a GPU.
// Likewise the GPU's partially saturated cells against the CPU's
// PartiallySaturatedCells (their bodies held to it by
// tests/coupling/covered_cell_body_test.cpp): the steps' loads and liquid,
// and a suspension's coupled step.
//
// Round-off: as marker_body_test.cpp (1e-12 of the largest magnitude in
// double, 1e-4 in float); the GPU adds atomic additions in a varying order,
// which changes sums of ~10^3 terms by a few ulps.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "engine/case/case_file.hpp"
#include "engine/coupling_gpu/gpu_immersed_boundary.hpp"
#include "engine/coupling_gpu/gpu_partially_saturated.hpp"
#include "engine/immersed_boundary/immersed_boundary.hpp"
#include "engine/lattice/fluid_lattice.hpp"
#include "engine/lattice_gpu/gpu_fluid_lattice.hpp"
#include "engine/partially_saturated/partially_saturated_cells.hpp"
#include "engine/run/coupled_step.hpp"
#include "engine/run/sphere_run.hpp"
#include "engine/spheres/sphere_dynamics.hpp"
#include "tests/immersed_boundary/coupling_scenes.hpp"
#include "tests/lattice/lattice_probes.hpp"

namespace flocsim::gpu {
namespace {

using immersed_boundary::ImmersedBoundary;
using immersed_boundary::ImmersedBoundarySettings;
using spheres::Vec3;
using testing::control;
using testing::direct;
using testing::stir;
using testing::three_spheres;

template <class Real>
constexpr double kRoundOff = sizeof(Real) == 8 ? 1e-12 : 1e-4;

double largest(const std::vector<Vec3>& v) {
  double m = 0;
  for (const Vec3& x : v) m = std::max(m, x.cwiseAbs().maxCoeff());
  return m;
}

void expect_near_lists(const std::vector<Vec3>& gpu, const std::vector<Vec3>& cpu, double relative,
                       const char* what) {
  ASSERT_EQ(gpu.size(), cpu.size()) << what;
  const double scale = largest(cpu);
  ASSERT_GT(scale, 0) << what << " is zero: the comparison would prove nothing";
  for (std::size_t s = 0; s < cpu.size(); ++s)
    for (int d = 0; d < 3; ++d)
      EXPECT_NEAR(gpu[s][d], cpu[s][d], relative * scale)
          << what << " of sphere " << s << ", component " << d;
}

template <class Real>
void expect_same_steps(const coupling::Scheme& scheme, int steps) {
  const lattice::Extent e{32, 30, 28};
  lattice::FluidLattice<Real> cpu_fluid(e, {0.02, 0.25}), mirror(e, {0.02, 0.25});
  stir(cpu_fluid);
  cpu_fluid.enable_force_field();
  GpuFluidLattice<Real> gpu_fluid(e, {0.02, 0.25});
  gpu_fluid.upload(cpu_fluid);
  const ImmersedBoundarySettings settings{.input_radius = 3.7, .scheme = scheme};
  ImmersedBoundary<Real> cpu(settings);
  GpuImmersedBoundary<Real> gpu(settings);
  const spheres::SphereSet s = three_spheres();
  for (int step = 0; step < steps; ++step) {
    SCOPED_TRACE("step " + std::to_string(step));
    cpu.apply(cpu_fluid, s);
    gpu.apply(gpu_fluid, s);
    expect_near_lists(gpu.force(), cpu.force(), kRoundOff<Real>, "force");
    expect_near_lists(gpu.torque(), cpu.torque(), kRoundOff<Real>, "torque");
    expect_near_lists(gpu.inside().momentum(), cpu.internal_momentum(), kRoundOff<Real>,
                      "inside momentum");
    expect_near_lists(gpu.inside().angular_momentum(), cpu.internal_angular_momentum(),
                      kRoundOff<Real>, "inside angular momentum");
    cpu_fluid.step();
    gpu_fluid.step();
  }
  // the liquid after the steps: the forces went into it alike
  gpu_fluid.download(mirror);
  const auto a = testing::slots_of(cpu_fluid), b = testing::slots_of(mirror);
  double worst = 0, scale = 0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    worst = std::max(worst, std::abs(static_cast<double>(a[k]) - b[k]));
    scale = std::max(scale, std::abs(static_cast<double>(a[k])));
  }
  EXPECT_LE(worst, kRoundOff<Real> * scale) << "populations after " << steps << " steps";
  if (scheme.control()) {
    const auto m_gpu = gpu.memory(), m_cpu = cpu.memory();
    ASSERT_EQ(m_gpu.size(), m_cpu.size());
    for (std::size_t q = 0; q < m_cpu.size(); ++q) {
      ASSERT_EQ(m_gpu[q].name, m_cpu[q].name);
      ASSERT_EQ(m_gpu[q].values.size(), m_cpu[q].values.size());
      double big = 0;
      for (double v : m_cpu[q].values) big = std::max(big, std::abs(v));
      for (std::size_t k = 0; k < m_cpu[q].values.size(); ++k)
        EXPECT_NEAR(m_gpu[q].values[k], m_cpu[q].values[k], kRoundOff<Real> * big)
            << m_cpu[q].name << " number " << k;
    }
  }
}

TEST(GpuCoupling, DirectForcingStepsMatchTheCpuCoupling) {
  expect_same_steps<double>(direct(1, coupling::Kernel::roma3), 3);
  expect_same_steps<double>(direct(2, coupling::Kernel::linear2), 3);
  expect_same_steps<float>(direct(2, coupling::Kernel::roma3), 3);
}

TEST(GpuCoupling, ControlForcingStepsAndCarriedStateMatchTheCpuCoupling) {
  expect_same_steps<double>(control(), 4);
  expect_same_steps<float>(control(), 4);
}

// Partially saturated cells: three spheres (two sharing cells, one across
// the periodic wrap) moving over the steps, each step's loads and the liquid
// after the steps on the GPU against the CPU coupling from the same liquid.
template <class Real>
void expect_same_partially_saturated_steps(int steps) {
  const lattice::Extent e{32, 30, 28};
  lattice::FluidLattice<Real> cpu_fluid(e, {0.02, 0.25}), mirror(e, {0.02, 0.25});
  stir(cpu_fluid);
  GpuFluidLattice<Real> gpu_fluid(e, {0.02, 0.25});
  gpu_fluid.upload(cpu_fluid);
  const double ag = 4.2;
  partially_saturated::PartiallySaturatedCells<Real> cpu(ag);
  GpuPartiallySaturatedCells<Real> gpu(ag, gpu_fluid);
  spheres::SphereSet s = three_spheres();
  for (int step = 0; step < steps; ++step) {
    SCOPED_TRACE("step " + std::to_string(step));
    cpu.apply(cpu_fluid, s);
    cpu_fluid.step();
    cpu.after_liquid_step(cpu_fluid, s);
    gpu.apply(mirror, s);
    gpu_fluid.step();
    gpu.after_liquid_step(mirror, s);
    expect_near_lists(gpu.force(), cpu.force(), kRoundOff<Real>, "force");
    expect_near_lists(gpu.torque(), cpu.torque(), kRoundOff<Real>, "torque");
    expect_near_lists(gpu.internal_momentum(), cpu.internal_momentum(), kRoundOff<Real>,
                      "inside momentum");
    expect_near_lists(gpu.internal_angular_momentum(), cpu.internal_angular_momentum(),
                      kRoundOff<Real>, "inside angular momentum");
    for (std::size_t k = 0; k < s.size(); ++k) s.position[k] += 3.0 * s.velocity[k];
  }
  gpu_fluid.download(mirror);
  const auto a = testing::slots_of(cpu_fluid), b = testing::slots_of(mirror);
  double worst = 0, scale = 0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    worst = std::max(worst, std::abs(static_cast<double>(a[k]) - b[k]));
    scale = std::max(scale, std::abs(static_cast<double>(a[k])));
  }
  EXPECT_LE(worst, kRoundOff<Real> * scale) << "populations after " << steps << " steps";
}

TEST(GpuCoupling, PartiallySaturatedStepsMatchTheCpuCoupling) {
  expect_same_partially_saturated_steps<double>(4);
  expect_same_partially_saturated_steps<float>(4);
}

// A settling sphere, 400 steps of the coupled loop with the sphere equations
// on the CPU (as a run does), on both devices: the GPU's trajectory follows
// the CPU's to round-off grown over the steps (double), and the sphere does
// settle (its speed along gravity grows to a sizeable fraction of a terminal
// velocity), so that the comparison is not between two spheres at rest.
TEST(GpuCoupling, SettlingSphereFollowsTheCpuTrajectory) {
  const lattice::Extent e{48, 40, 40};
  const double a = 4.0, ag = 3.7;
  lattice::FluidLattice<double> cpu_fluid(e, {0.05, 0.25});
  cpu_fluid.enable_force_field();
  GpuFluidLattice<double> gpu_fluid(e, {0.05, 0.25});
  spheres::SphereDynamicsSettings dynamics;
  dynamics.external = spheres::settling_forces(1, a, 4.0, static_cast<double>(e.cells()), 2e-6);
  cpu_fluid.set_body_force({dynamics.external.liquid_body_force.x(), 0, 0});
  gpu_fluid.upload(cpu_fluid);
  const ImmersedBoundarySettings settings{.input_radius = ag,
                                          .scheme = direct(2, coupling::Kernel::roma3)};
  ImmersedBoundary<double> cpu(settings);
  GpuImmersedBoundary<double> gpu(settings);
  spheres::SphereSet s_cpu;
  s_cpu.radius = a;
  s_cpu.resize(1);
  s_cpu.position[0] = Vec3(20.3, 19.6, 20.1);
  spheres::SphereSet s_gpu = s_cpu;
  const spheres::PeriodicBox box{Vec3(e.nx, e.ny, e.nz)};
  for (int step = 0; step < 400; ++step) {
    cpu.apply(cpu_fluid, s_cpu);
    cpu_fluid.step();
    spheres::advance_velocities(s_cpu, cpu.loads(), dynamics);
    spheres::advance_positions(s_cpu, box);
    gpu.apply(gpu_fluid, s_gpu);
    gpu_fluid.step();
    spheres::advance_velocities(s_gpu, gpu.loads(), dynamics);
    spheres::advance_positions(s_gpu, box);
  }
  const double u = s_cpu.velocity[0].x();
  ASSERT_LT(u, -1e-4) << "the sphere did not settle: the comparison would prove little";
  EXPECT_NEAR(s_gpu.velocity[0].x(), u, 1e-9 * std::abs(u));
  EXPECT_LE((s_gpu.position[0] - s_cpu.position[0]).norm(), 1e-9 * a);
}

// A checkpoint of a GPU run with control forcing (its carried marker state
// and inside momenta) resumes on the CPU: the CPU coupling restored from it
// gives the step the GPU coupling gives.
TEST(GpuCoupling, ControlForcingStateMovesFromTheGpuToTheCpu) {
  const lattice::Extent e{32, 30, 28};
  lattice::FluidLattice<double> host(e, {0.02, 0.25});
  stir(host);
  host.enable_force_field();
  GpuFluidLattice<double> gpu_fluid(e, {0.02, 0.25});
  gpu_fluid.upload(host);
  const ImmersedBoundarySettings settings{.input_radius = 3.7, .scheme = control()};
  GpuImmersedBoundary<double> gpu(settings);
  const spheres::SphereSet s = three_spheres();
  for (int step = 0; step < 3; ++step) {
    gpu.apply(gpu_fluid, s);
    gpu_fluid.step();
  }
  gpu_fluid.download(host);  // the checkpoint: populations, marker state, inside momenta
  ImmersedBoundary<double> cpu(settings);
  cpu.restore_memory(gpu.memory());
  cpu.set_internal_momenta(gpu.inside().momentum(), gpu.inside().angular_momentum());
  gpu.apply(gpu_fluid, s);
  cpu.apply(host, s);
  expect_near_lists(gpu.force(), cpu.force(), 1e-12, "force after the move");
  expect_near_lists(gpu.inside().momentum_change(), cpu.internal_momentum_change(), 1e-10,
                    "inside momentum change after the move");
}

// The demo's suspension (draft: a = 4, 64 x 32 x 32, 49 spheres, with the
// square well), in double, through a sphere scene's whole coupled step
// (engine/run/coupled_step.hpp: coupling, fluid, sphere equations,
// lubrication, events) on each device from the same placement: for 300
// steps the GPU's spheres follow the CPU's to round-off grown over the steps.
// (Collisions and well events are decided by comparisons, so a round-off
// difference could flip one; over 300 steps of a dilute start none does, and
// the bound would show it.)
TEST(GpuCoupling, ASuspensionsCoupledStepFollowsTheCpuTrajectories) {
  const nlohmann::json doc = {{"scene", "suspension"},
                              {"fidelity", "draft"},
                              {"phi", 0.2},
                              {"Re_inf", 24},
                              {"du_over_Uinf", 0.03},
                              {"precision", "double"},
                              {"numerics", {{"U_inf", 0.03}}}};
  cases::SuspensionCase c = cases::parse_case(doc).spheres;
  run::TimedStages cpu_stages, gpu_stages;
  run::CoupledStep<double> cpu(c, 0.03 * c.derived.settling_velocity, cpu_stages);
  auto lattice = std::make_unique<GpuFluidLattice<double>>(
      c.derived.box, lattice::Relaxation{c.numerics.viscosity, c.numerics.trt_magic});
  run::CoupledStep<double> gpu(c, 0.03 * c.derived.settling_velocity, gpu_stages,
                               std::move(lattice));
  spheres::SphereSet s_cpu;
  s_cpu.radius = c.numerics.radius_cells;
  s_cpu.density_ratio = c.physics.density_ratio;
  run::place_spheres(c, cases::modules_of(c.scene), cpu.box(), s_cpu);
  spheres::SphereSet s_gpu = s_cpu;
  gpu.liquid()->to_device();
  // the largest velocity difference every 50 steps: a smooth growth is
  // round-off carried by the flow, a jump an event decided differently
  auto largest_difference = [&] {
    double worst = 0;
    for (std::size_t i = 0; i < s_cpu.size(); ++i)
      worst = std::max(worst, (s_gpu.velocity[i] - s_cpu.velocity[i]).norm());
    return worst;
  };
  std::string growth;
  for (int step = 1; step <= 300; ++step) {
    ASSERT_EQ(cpu.advance(s_cpu), "") << "step " << step;
    ASSERT_EQ(gpu.advance(s_gpu), "") << "step " << step;
    if (step % 50 == 0) {
      char entry[48];
      std::snprintf(entry, sizeof entry, " %d: %.2e", step, largest_difference());
      growth += entry;
    }
  }
  double fastest = 0;
  for (const Vec3& v : s_cpu.velocity) fastest = std::max(fastest, v.norm());
  ASSERT_GT(fastest, 1e-4) << "the spheres did not move: the comparison would prove little";
  EXPECT_LE(largest_difference(), 1e-8 * fastest)
      << "largest velocity difference after 300 steps; by step:" << growth;
  // and the liquid the observables read: the mirror brought up to date
  gpu.liquid()->to_host();
  EXPECT_NEAR(gpu.liquid()->fluid.total_mass(), cpu.liquid()->fluid.total_mass(),
              1e-10 * cpu.liquid()->fluid.total_mass());
}

// The same suspension coupled by partially saturated cells, its GPU run
// chosen by the scene's Liquid (engine/run/coupled_step.hpp) as a case on
// "cuda" gets it: 150 steps on each device from the same placement.
TEST(GpuCoupling, APartiallySaturatedSuspensionFollowsTheCpuTrajectories) {
  const nlohmann::json doc = {{"scene", "suspension"},
                              {"fidelity", "draft"},
                              {"phi", 0.2},
                              {"Re_inf", 24},
                              {"du_over_Uinf", 0.03},
                              {"precision", "double"},
                              {"numerics", {{"U_inf", 0.03}, {"coupling", "partially-saturated"}}}};
  cases::SuspensionCase c = cases::parse_case(doc).spheres;
  ASSERT_FALSE(c.numerics.coupling.immersed_boundary());
  run::TimedStages cpu_stages, gpu_stages;
  run::CoupledStep<double> cpu(c, 0.03 * c.derived.settling_velocity, cpu_stages);
  auto lattice = std::make_unique<GpuFluidLattice<double>>(
      c.derived.box, lattice::Relaxation{c.numerics.viscosity, c.numerics.trt_magic});
  run::CoupledStep<double> gpu(c, 0.03 * c.derived.settling_velocity, gpu_stages,
                               std::move(lattice));
  ASSERT_NE(dynamic_cast<GpuPartiallySaturatedCells<double>*>(gpu.liquid()->coupling.get()),
            nullptr);
  spheres::SphereSet s_cpu;
  s_cpu.radius = c.numerics.radius_cells;
  s_cpu.density_ratio = c.physics.density_ratio;
  run::place_spheres(c, cases::modules_of(c.scene), cpu.box(), s_cpu);
  spheres::SphereSet s_gpu = s_cpu;
  gpu.liquid()->to_device();
  double worst = 0;
  for (int step = 1; step <= 150; ++step) {
    ASSERT_EQ(cpu.advance(s_cpu), "") << "step " << step;
    ASSERT_EQ(gpu.advance(s_gpu), "") << "step " << step;
  }
  for (std::size_t i = 0; i < s_cpu.size(); ++i)
    worst = std::max(worst, (s_gpu.velocity[i] - s_cpu.velocity[i]).norm());
  double fastest = 0;
  for (const Vec3& v : s_cpu.velocity) fastest = std::max(fastest, v.norm());
  ASSERT_GT(fastest, 1e-4) << "the spheres did not move: the comparison would prove little";
  EXPECT_LE(worst, 1e-8 * fastest) << "largest velocity difference after 150 steps";
  // a sample of a partially saturated run on the GPU reduces the liquid there
  // too (the Liquid once made the GPU's averages for the immersed boundary only)
  const observables::LiquidAverages on_gpu = gpu.liquid()->averages(s_gpu);
  const observables::LiquidAverages on_cpu = cpu.liquid()->averages(s_cpu);
  EXPECT_NEAR(on_gpu.mean_velocity_x, on_cpu.mean_velocity_x, 1e-8 * fastest);
  EXPECT_NEAR(static_cast<double>(on_gpu.liquid_cells), static_cast<double>(on_cpu.liquid_cells),
              2.0);  // a cell centre within ~1e-8 of a surface may fall either way
  EXPECT_NEAR(on_gpu.mass, on_cpu.mass, 1e-10 * on_cpu.mass);
  gpu.liquid()->to_host();
  EXPECT_NEAR(gpu.liquid()->fluid.total_mass(), cpu.liquid()->fluid.total_mass(),
              1e-10 * cpu.liquid()->fluid.total_mass());
}

}  // namespace
}  // namespace flocsim::gpu
