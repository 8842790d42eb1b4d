// The GPU's partially saturated cells, run here on the CPU: a serial launcher
// that does, sphere after sphere and cell after cell, exactly the steps of
// the CUDA launchers (engine/coupling_gpu/covered_cell_kernels.cu and the
// covered variant of the lattice step in engine/lattice_gpu/gpu_fluid_lattice.cu),
// their threads replaced by loops and their atomic additions by plain ones,
// calling the same kernel bodies (engine/partially_saturated/covered_cell_body.hpp,
// engine/lattice/aa_cell.hpp) on the spheres as gpu::covering_spheres places
// them. It must reproduce the CPU's PartiallySaturatedCells with the CPU's
// FluidLattice, the reference, which reaches the same method row by row
// through runs of cells and 16-wide vectors: the populations after every
// step, and force, torque and the inside liquid's momenta of every sphere,
// with spheres that share cells and one across the periodic wrap, moving
// from step to step. A launcher that gives a shared cell's exchange wholly
// to each of its spheres is caught.
//
// Round-off. The launcher blends the collision of the cells with eps > 0
// only, the CPU every cell of a row with any covered cell (the others with
// eps = 0: the plain collision to round-off), and the two sum each sphere's
// terms in different orders (a tree over 256 threads against 16 lanes per
// run). In double they agree to 1e-12 of the largest value compared
// (measured: 4e-16). In float the uncovered cells of covered rows differ by
// an ulp per step, and the liquids drift apart by such ulps: the populations
// agree to 2e-6 of the largest deviation f_i - w_i (about 30 float ulps;
// measured after 4 steps: 3e-7); the loads sum the same float cell values in
// double, so they differ only through those cells: 1e-6 of the largest load
// (measured: 2e-8).
#include "engine/partially_saturated/covered_cell_body.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "engine/coupling_gpu/covered_cell_kernels.hpp"
#include "engine/coupling_gpu/gpu_partially_saturated.hpp"
#include "engine/lattice/aa_cell.hpp"
#include "engine/lattice/fluid_lattice.hpp"
#include "engine/partially_saturated/partially_saturated_cells.hpp"
#include "tests/immersed_boundary/coupling_scenes.hpp"
#include "tests/lattice/lattice_probes.hpp"

namespace flocsim::partially_saturated {
namespace {

using spheres::Vec3;

constexpr int kThreads = 256;  // covered_cell_kernels.cu's threads per sphere
// Spheres 0 and 1 (radius 4, centres 8.65 apart) at a_g = 4.4 overlap a
// little: their shared cells include some covered more than once (eps > 1).
constexpr double kInputRadius = 4.4;

enum class Launcher { as_built, whole_share };

// The device's per-cell arrays (GpuFluidLattice's DeviceCoverage) and the
// populations, in host memory.
template <class Real>
struct SerialLiquid {
  std::vector<Real> slots;  // direction after direction, cells() each
  std::vector<Real> eps, V[3], rho, J[3];
  explicit SerialLiquid(const lattice::FluidLattice<Real>& fluid)
      : slots(testing::slots_of(fluid)) {
    const std::size_t cells = static_cast<std::size_t>(fluid.extent().cells());
    for (auto* a : {&eps, &V[0], &V[1], &V[2], &rho, &J[0], &J[1], &J[2]})
      a->assign(cells, Real(0));
  }
};

long cell_index(const CoveringGeometry& g, const CoveredCell& c) {
  return static_cast<long>(c.x) +
         static_cast<long>(g.n[0]) * (c.y + static_cast<long>(g.n[1]) * c.z);
}

// Calls work(sphere, box cell's CoveredCell, thread) for every covered box
// cell of every sphere, in the launchers' order.
template <bool kCoverage, class Work>
void for_each_cell(const CoveringGeometry& g, const std::vector<double>& spheres, Work&& work) {
  const int B = g.B, cells = B * B * B;
  for (std::size_t s = 0; s < spheres.size() / gpu::kCoveringNumbers; ++s) {
    const CoveringSphere sphere = unpack_covering_sphere(&spheres[gpu::kCoveringNumbers * s]);
    for (int c = 0; c < cells; ++c) {
      const int i = c % B, j = (c / B) % B, k = c / (B * B);
      CoveredCell cell;
      if (!covered_cell<kCoverage>(g, sphere, i, j, k, cell)) continue;
      work(s, sphere, cell, c % kThreads);
    }
  }
}

// One coupled step of the GPU path: cover, the lattice's step, exchange,
// clear. `exchange` receives kExchangeNumbers per sphere.
template <class Real>
void serial_step(const lattice::FluidLattice<Real>& fluid, const std::vector<double>& spheres,
                 SerialLiquid<Real>& l, std::vector<double>& exchange, Launcher launcher) {
  const lattice::Extent e = fluid.extent();
  const CoveringGeometry g(kInputRadius, e);
  // cover
  for_each_cell<true>(g, spheres,
                      [&](std::size_t, const CoveringSphere& sphere, const CoveredCell& cell, int) {
                        if (!(cell.eps > 0)) return;
                        double v[3];
                        solid_velocity_share(sphere, cell, v);
                        const long at = cell_index(g, cell);
                        l.eps[at] += static_cast<Real>(cell.eps);
                        for (int d = 0; d < 3; ++d) l.V[d][at] += static_cast<Real>(v[d]);
                      });
  // the lattice's step (aa_step_kernel with kCoverage)
  const lattice::Relaxation& relax = fluid.relaxation();
  lattice::CollisionConstants<Real> k;
  k.omega_plus = static_cast<Real>(relax.omega_plus());
  k.omega_minus = static_cast<Real>(relax.omega_minus());
  k.force_plus = static_cast<Real>(1.0 - 0.5 * relax.omega_plus());
  k.force_minus = static_cast<Real>(1.0 - 0.5 * relax.omega_minus());
  const lattice::Vector3 body = fluid.body_force();
  const Real bx = static_cast<Real>(body.x), by = static_cast<Real>(body.y),
             bz = static_cast<Real>(body.z);
  const lattice::AaSlots<Real> s{l.slots.data(), e.cells(), e.nx, e.ny, e.nz};
  const bool even = fluid.time_step() % 2 == 0;
  for (int z = 0; z < e.nz; ++z)
    for (int y = 0; y < e.ny; ++y)
      for (int x = 0; x < e.nx; ++x) {
        const long c = lattice::aa_cell_index(s, x, y, z);
        if (l.eps[c] > Real(0))
          lattice::aa_update_covered_cell(s, x, y, z, even, bx, by, bz, l.eps[c], l.V[0][c],
                                          l.V[1][c], l.V[2][c], k, l.rho[c], l.J[0][c], l.J[1][c],
                                          l.J[2][c]);
        else
          lattice::aa_update_cell(s, x, y, z, even, bx, by, bz, k);
      }
  // exchange: per sphere, per thread, then a tree over the threads
  const std::size_t n = spheres.size() / gpu::kCoveringNumbers;
  std::vector<double> partial(n * kThreads * gpu::kExchangeNumbers, 0.0);
  for_each_cell<true>(
      g, spheres,
      [&](std::size_t sphere, const CoveringSphere&, const CoveredCell& cell, int thread) {
        if (!(cell.eps > 0)) return;
        const long at = cell_index(g, cell);
        const double V[3] = {l.V[0][at], l.V[1][at], l.V[2][at]};
        const double J[3] = {l.J[0][at], l.J[1][at], l.J[2][at]};
        const double f[3] = {body.x, body.y, body.z};
        // the perturbation: each sphere takes the cell's whole exchange (as if
        // its coverage were the cell's)
        CoveredCell share = cell;
        if (launcher == Launcher::whole_share) share.eps = static_cast<float>(l.eps[at]);
        double q[gpu::kExchangeNumbers];
        exchange_terms(share, l.eps[at], V, l.rho[at], J, f, q);
        double* sums = &partial[(sphere * kThreads + thread) * gpu::kExchangeNumbers];
        for (int r = 0; r < gpu::kExchangeNumbers; ++r) sums[r] += q[r];
      });
  exchange.assign(n * gpu::kExchangeNumbers, 0.0);
  for (std::size_t sphere = 0; sphere < n; ++sphere) {
    double* p = &partial[sphere * kThreads * gpu::kExchangeNumbers];
    for (int half = kThreads / 2; half > 0; half /= 2)
      for (int t = 0; t < half; ++t)
        for (int r = 0; r < gpu::kExchangeNumbers; ++r)
          p[t * gpu::kExchangeNumbers + r] += p[(t + half) * gpu::kExchangeNumbers + r];
    std::copy(p, p + gpu::kExchangeNumbers, &exchange[sphere * gpu::kExchangeNumbers]);
  }
  // clear
  for_each_cell<false>(g, spheres,
                       [&](std::size_t, const CoveringSphere&, const CoveredCell& cell, int) {
                         const long at = cell_index(g, cell);
                         l.eps[at] = 0;
                         for (int d = 0; d < 3; ++d) l.V[d][at] = 0;
                       });
}

double largest(const std::vector<double>& v) {
  double m = 0;
  for (double x : v) m = std::max(m, std::abs(x));
  return m;
}

template <class Real>
constexpr double kLoadRoundOff = sizeof(Real) == 8 ? 1e-12 : 1e-6;
template <class Real>
constexpr double kPopulationRoundOff = sizeof(Real) == 8 ? 1e-12 : 2e-6;

// The largest difference of each of force, torque, inside momentum and
// inside angular momentum between the launcher and the CPU, over its scale
// (the largest magnitude of the CPU's values of that quantity).
std::vector<double> load_errors(const std::vector<double>& gpu, const std::vector<Vec3>* cpu[4]) {
  std::vector<double> out;
  for (int q = 0; q < 4; ++q) {
    std::vector<double> ref;
    for (const Vec3& v : *cpu[q])
      for (int d = 0; d < 3; ++d) ref.push_back(v[d]);
    const double scale = largest(ref);
    EXPECT_GT(scale, 0) << "quantity " << q << " is zero: the test would prove nothing";
    double worst = 0;
    for (std::size_t s = 0; s < cpu[q]->size(); ++s)
      for (int d = 0; d < 3; ++d) {
        // force and torque are the exchange reversed
        const double sign = q < 2 ? -1.0 : 1.0;
        worst = std::max(worst, std::abs(sign * gpu[gpu::kExchangeNumbers * s + 3 * q + d] -
                                         ref[3 * s + static_cast<std::size_t>(d)]));
      }
    out.push_back(worst / scale);
  }
  return out;
}

// Runs `steps` coupled steps both ways from the same liquid, spheres moving
// between steps; returns the largest relative load difference seen, and
// checks the populations and the clearing on the way.
template <class Real>
double run_both(int steps, Launcher launcher) {
  const lattice::Extent e{32, 30, 28};
  lattice::FluidLattice<Real> fluid(e, {0.02, 0.25});
  testing::stir(fluid);
  fluid.step();  // one step old: the odd parity first
  spheres::SphereSet spheres = testing::three_spheres();
  PartiallySaturatedCells<Real> cpu(kInputRadius);
  SerialLiquid<Real> serial(fluid);
  double worst_load = 0, worst_population = 0;
  for (int step = 0; step < steps; ++step) {
    SCOPED_TRACE("step " + std::to_string(step));
    const std::vector<double> placed = gpu::covering_spheres(spheres, e, kInputRadius);
    std::vector<double> exchange;
    serial_step(fluid, placed, serial, exchange, launcher);
    cpu.apply(fluid, spheres);
    fluid.step();
    cpu.after_liquid_step(fluid, spheres);
    // the coverage left zero for the next step
    for (auto* a : {&serial.eps, &serial.V[0], &serial.V[1], &serial.V[2]})
      EXPECT_TRUE(std::all_of(a->begin(), a->end(), [](Real v) { return v == Real(0); }))
          << "coverage left behind";
    const std::vector<Vec3>* ref[4] = {&cpu.force(), &cpu.torque(), &cpu.internal_momentum(),
                                       &cpu.internal_angular_momentum()};
    for (double err : load_errors(exchange, ref)) worst_load = std::max(worst_load, err);
    if (launcher == Launcher::as_built) {
      const std::vector<Real> reference = testing::slots_of(fluid);
      double scale = 0, worst = 0;
      for (std::size_t q = 0; q < reference.size(); ++q) {
        scale = std::max(scale, std::abs(static_cast<double>(reference[q])));
        worst = std::max(worst, std::abs(static_cast<double>(reference[q]) - serial.slots[q]));
      }
      EXPECT_LE(worst, kPopulationRoundOff<Real> * scale) << "populations";
      worst_population = std::max(worst_population, worst / scale);
    }
    for (std::size_t s = 0; s < spheres.size(); ++s)  // move on
      spheres.position[s] += 3.0 * spheres.velocity[s];
  }
  std::printf(
      "%s, %d steps: largest relative difference of the loads %.2e, of the populations %.2e\n",
      sizeof(Real) == 8 ? "double" : "float", steps, worst_load, worst_population);
  return worst_load;
}

// The scene shares cells between spheres and reaches across the wrap: what
// the comparisons below rely on to mean something.
TEST(CoveredCellBody, TheSceneHasSharedCellsAndCellsAcrossTheWrap) {
  const lattice::Extent e{32, 30, 28};
  const spheres::SphereSet spheres = testing::three_spheres();
  const CoveringGeometry g(kInputRadius, e);
  std::vector<int> covering(static_cast<std::size_t>(e.cells()), 0);
  std::vector<double> total(covering.size(), 0.0);
  int wrapped = 0;  // cells of a sphere reaching below x = 0, at the far end
  double volume[3] = {0, 0, 0};
  for_each_cell<true>(
      g, gpu::covering_spheres(spheres, e, kInputRadius),
      [&](std::size_t s, const CoveringSphere& sphere, const CoveredCell& cell, int) {
        if (!(cell.eps > 0)) return;
        ++covering[static_cast<std::size_t>(cell_index(g, cell))];
        total[static_cast<std::size_t>(cell_index(g, cell))] += cell.eps;
        volume[s] += cell.eps;
        wrapped += sphere.lo[0] < 0 && cell.x >= e.nx + sphere.lo[0];
      });
  const auto shared = std::count(covering.begin(), covering.end(), 2);
  std::printf("cells covered by two spheres: %d, cells of the wrapped sphere across x = 0: %d\n",
              static_cast<int>(shared), wrapped);
  EXPECT_GT(shared, 10);
  EXPECT_GT(std::count_if(total.begin(), total.end(), [](double t) { return t > 1.0; }), 0)
      << "no cell covered more than once: B = min(1, eps) untested";
  EXPECT_GT(wrapped, 0);
  // each sphere's coverage sums to its volume (cell_coverage.hpp; 1.5e-4 of
  // it here, the CPU coupling's coverage being the same)
  const double ball = 4.0 / 3.0 * M_PI * std::pow(kInputRadius, 3);
  for (double v : volume) EXPECT_NEAR(v, ball, 3e-4 * ball);
}

TEST(CoveredCellBody, SerialLauncherMatchesTheCpuCouplingInDouble) {
  EXPECT_LE(run_both<double>(4, Launcher::as_built), kLoadRoundOff<double>);
}

TEST(CoveredCellBody, SerialLauncherMatchesTheCpuCouplingInFloat) {
  EXPECT_LE(run_both<float>(4, Launcher::as_built), kLoadRoundOff<float>);
}

// A launcher that gives each sphere a shared cell's whole exchange, instead
// of its share eps_k / eps, is told apart from the CPU coupling.
TEST(CoveredCellBody, AWrongCoverageShareIsCaught) {
  EXPECT_GT(run_both<double>(2, Launcher::whole_share), 1e3 * kLoadRoundOff<double>);
}

}  // namespace
}  // namespace flocsim::partially_saturated
