// The GPU's liquid averages, run here on the CPU: a serial launcher that
// does, block after block and thread after thread, exactly the steps of the
// CUDA launcher (engine/observables_gpu/gpu_liquid_averages.cu): the solid
// mask marked per sphere over its cube, each thread's grid-stride sums
// (liquid_thread_sums), each block's fixed tree, the blocks added in block
// order. It must reproduce observables::liquid_averages, the CPU's path, on
// a lattice with spheres (across periodic faces, on a node), a body force and
// a per-cell force field in all three components, at both parities of the
// AA pattern, for several grids.
//
// Round-off: the two sum the same per-cell numbers in different orders
// (OpenMP rows against grid strides and trees), and the CPU's row reader
// sums the x-end cells' moments in another order at odd steps, so they
// agree to ~1e-15 relative per value; the bound is 1e-12. The same bound
// holds in float: both paths read each float population and force into
// double before the moments and sum in double, so float's 6e-8 rounding
// never enters the comparison (it is in the state both read, not in how
// they read it). Sums kept away from cancellation (a mean flow along x)
// make the relative bound meaningful.
#include "engine/observables/liquid_average_body.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "engine/lattice/fluid_lattice.hpp"
#include "engine/observables/liquid_averages.hpp"
#include "engine/observables_gpu/gpu_liquid_averages.hpp"
#include "tests/lattice/lattice_probes.hpp"

namespace flocsim::observables {
namespace {

using spheres::Vec3;

constexpr int T = gpu::kLiquidSumThreads;
constexpr double kRoundOff = 1e-12;

// What the serial launcher may be told to get wrong, to show that the
// comparison catches it.
struct Fault {
  double shift_x = 0;        // the mask marked from centres moved along x
  bool drop_field = false;   // the per-cell force left out
  bool flip_parity = false;  // the populations read as if at the other parity
};

// One GpuLiquidAverages::sums() with `blocks` blocks, serially.
template <class Real>
LiquidSums serial_sums(const lattice::FluidLattice<Real>& fluid, const spheres::SphereSet& s,
                       int blocks, std::vector<std::uint8_t>& solid, Fault fault = {}) {
  const lattice::Extent e = fluid.extent();
  // mark_solid_kernel: a block per sphere, its threads over the cube
  solid.assign(static_cast<std::size_t>(e.cells()), 0);
  const int reach = static_cast<int>(std::ceil(s.radius));
  const int side = sphere_cube_side(reach);
  const long cube = static_cast<long>(side) * side * side;
  for (std::size_t b = 0; b < s.size(); ++b) {
    const double c[3] = {s.position[b].x() + fault.shift_x, s.position[b].y(), s.position[b].z()};
    for (int t = 0; t < T; ++t)
      for (long q = t; q < cube; q += T) {
        const long cell = solid_cube_cell(c, s.radius, reach, e.nx, e.ny, e.nz, q);
        if (cell >= 0) solid[static_cast<std::size_t>(cell)] = 1;
      }
  }
  // liquid_sums_kernel: the lattice's slots as the device holds them
  std::vector<Real> slots = testing::slots_of(fluid);
  LiquidSumInput<Real> in;
  in.slots = {slots.data(), e.cells(), e.nx, e.ny, e.nz};
  in.even = (fluid.time_step() % 2 == 0) != fault.flip_parity;
  const lattice::Vector3 body = fluid.body_force();
  in.body[0] = body.x;
  in.body[1] = body.y;
  in.body[2] = body.z;
  const auto field = fluid.force_field_if_set();
  if (!fault.drop_field)
    for (int d = 0; d < 3; ++d) in.field[d] = field.component[d];
  in.solid = solid.data();
  const long stride = static_cast<long>(blocks) * T;
  std::vector<LiquidSums> partial(static_cast<std::size_t>(blocks));
  std::vector<LiquidSums> part(T);
  for (int b = 0; b < blocks; ++b) {
    for (int t = 0; t < T; ++t)
      part[t] = liquid_thread_sums(in, static_cast<long>(b) * T + t, stride);
    for (int half = T / 2; half > 0; half /= 2)
      for (int t = 0; t < half; ++t) combine_liquid_sums(part[t], part[t + half]);
    partial[b] = part[0];
  }
  LiquidSums total;  // the host: blocks in block order
  for (const LiquidSums& p : partial) combine_liquid_sums(total, p);
  return total;
}

// The largest relative difference over the averages (infinite when the
// liquid cells differ in number).
double worst_difference(const LiquidAverages& a, const LiquidAverages& ref) {
  if (a.liquid_cells != ref.liquid_cells) return std::numeric_limits<double>::infinity();
  double worst = 0;
  const double pairs[][2] = {{a.mean_velocity_x, ref.mean_velocity_x},
                             {a.mean_velocity_x_all_cells, ref.mean_velocity_x_all_cells},
                             {a.lattice_momentum_x, ref.lattice_momentum_x},
                             {a.mass, ref.mass},
                             {a.max_speed, ref.max_speed},
                             {a.max_speed_outside_spheres, ref.max_speed_outside_spheres}};
  for (const auto& p : pairs) {
    EXPECT_NE(p[1], 0.0) << "a zero reference would prove nothing";
    worst = std::max(worst, std::abs(p[0] - p[1]) / std::abs(p[1]));
  }
  return worst;
}

const lattice::Extent kExtent{24, 16, 20};

spheres::SphereSet some_spheres() {
  spheres::SphereSet s;
  s.radius = 3.5;
  s.resize(3);
  s.position = {{0.3, 9.6, 19.8},   // across three faces
                {12.0, 8.0, 10.0},  // on a lattice node: surface cells exactly at 3.5
                {18.7, 0.2, 6.45}};
  return s;
}

// A stirred liquid with a mean flow along x, a body force and a per-cell
// force everywhere (larger inside the spheres, as the immersed boundary's).
template <class Real>
void stir(lattice::FluidLattice<Real>& fluid, const spheres::SphereSet& s) {
  fluid.set_body_force({2e-5, -1e-5, 3e-6});
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> r(-1, 1);
  fluid.initialise_equilibrium([&](int, int, int) {
    return lattice::Macroscopic{1.0 + 0.01 * r(rng),
                                {0.013 + 0.005 * r(rng), 0.005 * r(rng), 0.005 * r(rng)}};
  });
  std::vector<std::uint8_t> solid;
  mark_solid_cells(kExtent, s.position, s.radius, solid);
  const auto field = fluid.force_field();
  for (long c = 0; c < kExtent.cells(); ++c)
    for (int d = 0; d < 3; ++d)
      field.component[d][c] =
          static_cast<Real>((solid[static_cast<std::size_t>(c)] ? 3e-3 : 1e-4) * r(rng));
}

template <class Real>
void launch_order_matches_the_cpu() {
  const spheres::SphereSet s = some_spheres();
  lattice::FluidLattice<Real> fluid(kExtent, {0.05, 0.25});
  stir(fluid, s);
  for (int parity = 0; parity < 2; ++parity) {
    SCOPED_TRACE(parity == 0 ? "even step" : "odd step");
    std::vector<std::uint8_t> cpu_solid, gpu_solid;
    const LiquidAverages cpu = liquid_averages(fluid, s, cpu_solid);
    ASSERT_GT(cpu.liquid_cells, 0);
    ASSERT_LT(cpu.liquid_cells, kExtent.cells());
    // 1 block: ~38 cells a thread; 40 blocks: more threads than cells
    for (int blocks : {1, 3, 7, 40}) {
      SCOPED_TRACE(std::to_string(blocks) + " blocks");
      const LiquidSums sums = serial_sums(fluid, s, blocks, gpu_solid);
      EXPECT_EQ(gpu_solid, cpu_solid) << "the solid masks differ";
      EXPECT_LE(worst_difference(averages_from_sums(sums, kExtent.cells()), cpu), kRoundOff);
    }
    fluid.step();  // the next parity (the field acts, the spheres stay)
  }
}

TEST(LiquidAverageBody, GpuLaunchOrderMatchesTheCpuDouble) {
  launch_order_matches_the_cpu<double>();
}
TEST(LiquidAverageBody, GpuLaunchOrderMatchesTheCpuFloat) {
  launch_order_matches_the_cpu<float>();
}

// The comparison has teeth: a mask one cell off, a forgotten force field or
// the wrong parity each move the averages far beyond round-off.
template <class Real>
void faults_are_caught() {
  const spheres::SphereSet s = some_spheres();
  lattice::FluidLattice<Real> fluid(kExtent, {0.05, 0.25});
  stir(fluid, s);
  fluid.step();
  std::vector<std::uint8_t> cpu_solid, gpu_solid;
  const LiquidAverages cpu = liquid_averages(fluid, s, cpu_solid);
  const Fault faults[] = {{.shift_x = 1.0}, {.drop_field = true}, {.flip_parity = true}};
  const char* names[] = {"mask shifted by a cell", "force field dropped", "parity flipped"};
  for (int f = 0; f < 3; ++f) {
    const LiquidSums sums = serial_sums(fluid, s, 3, gpu_solid, faults[f]);
    EXPECT_GT(worst_difference(averages_from_sums(sums, kExtent.cells()), cpu), 1e3 * kRoundOff)
        << names[f] << " went unnoticed";
  }
}

TEST(LiquidAverageBody, WrongMaskFieldOrParityIsCaughtDouble) {
  faults_are_caught<double>();
}
TEST(LiquidAverageBody, WrongMaskFieldOrParityIsCaughtFloat) {
  faults_are_caught<float>();
}

}  // namespace
}  // namespace flocsim::observables
