// The pieces of the coupling schemes against hand-worked and independent
// results: the solid fraction of a cell cut by a plane against counting
// sub-cells, the coverage of a whole sphere against its volume, the blended
// collision of a covered cell against what it must do to density, momentum
// and velocity, and the control-forcing law against its definition.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "engine/coupling/scheme.hpp"
#include "engine/immersed_boundary/control_forcing.hpp"
#include "engine/lattice/fluid_lattice.hpp"
#include "engine/partially_saturated/cell_coverage.hpp"

namespace flocsim {
namespace {

using partially_saturated::cell_coverage;
using partially_saturated::cube_fraction_below_plane;

// The fraction of the unit cube below the plane n . x = d, counted on a
// regular grid of k^3 sub-cell centres: error about 1/k for a cut plane.
double counted_fraction(double nx, double ny, double nz, double d, int k) {
  long below = 0;
  for (int i = 0; i < k; ++i)
    for (int j = 0; j < k; ++j)
      for (int l = 0; l < k; ++l) {
        const double x = (i + 0.5) / k - 0.5, y = (j + 0.5) / k - 0.5, z = (l + 0.5) / k - 0.5;
        below += nx * x + ny * y + nz * z <= d;
      }
  return static_cast<double>(below) / (static_cast<double>(k) * k * k);
}

TEST(CellCoverage, PlaneCutOfTheCubeMatchesCountedSubcells) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> gauss;
  std::uniform_real_distribution<double> offset(-0.9, 0.9);
  double worst = 0;
  for (int t = 0; t < 200; ++t) {
    double n[3] = {gauss(rng), gauss(rng), gauss(rng)};
    const double norm = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (double& c : n) c /= norm;
    const double d = offset(rng);
    worst = std::max(worst, std::abs(cube_fraction_below_plane(n[0], n[1], n[2], d) -
                                     counted_fraction(n[0], n[1], n[2], d, 200)));
  }
  // counting 200^3 sub-cells errs by about the cut area over 200: < 1e-2,
  // typically a few 1e-3
  EXPECT_LT(worst, 5e-3);
  // hand-worked: axis-aligned cuts are linear; the diagonal plane through
  // the centre halves the cube; the plane through one corner's three
  // neighbours cuts off a tetrahedron of 1/6
  EXPECT_NEAR(cube_fraction_below_plane(1, 0, 0, 0.2), 0.7, 2e-4);
  EXPECT_NEAR(cube_fraction_below_plane(0, 0, -1, 0.2), 0.7, 2e-4);
  const double s = 1 / std::sqrt(3.0);
  EXPECT_NEAR(cube_fraction_below_plane(s, s, s, 0), 0.5, 1e-12);
  EXPECT_NEAR(cube_fraction_below_plane(s, s, s, s * 1.0 - 1.5 * s), 1.0 / 6.0, 1e-12);
  EXPECT_EQ(cube_fraction_below_plane(s, s, s, -0.9), 0.0);
  EXPECT_EQ(cube_fraction_below_plane(s, s, s, 0.9), 1.0);
}

// Summed over the lattice, the coverage of a sphere is its volume: the
// tangent-plane cut with the mean-sagitta correction leaves a few 1e-5 at
// a = 4-8 (without the correction the sum is 1.6 %, 0.7 % and 0.4 % too big
// at a = 4, 6, 8). Centres off the lattice's symmetry points.
TEST(CellCoverage, SumsToTheSphereVolume) {
  for (double a : {4.0, 6.0, 8.0}) {
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u(0, 1);
    for (int t = 0; t < 3; ++t) {
      const double c[3] = {u(rng), u(rng), u(rng)};
      const int R = static_cast<int>(a) + 3;
      double sum = 0;
      for (int i = -R; i <= R; ++i)
        for (int j = -R; j <= R; ++j)
          for (int k = -R; k <= R; ++k) sum += cell_coverage(i - c[0], j - c[1], k - c[2], a);
      const double volume = 4.0 / 3.0 * M_PI * a * a * a;
      EXPECT_NEAR(sum / volume, 1.0, 2e-4) << "a = " << a;
    }
  }
}

// The vectorised list form gives the scalar numbers, and the coverage of a
// cell moves smoothly as the sphere moves (no staircase: the sphere moved by
// 0.01 dx changes no cell's coverage by more than about 0.01 * sqrt(3)).
TEST(CellCoverage, ListFormAndSmallMovesAgree) {
  const double a = 5.7;
  std::vector<float> rx, ry, rz;
  for (int i = -8; i <= 8; ++i)
    for (int j = -8; j <= 8; ++j)
      for (int k = -8; k <= 8; ++k) {
        rx.push_back(static_cast<float>(i - 0.3));
        ry.push_back(static_cast<float>(j + 0.11));
        rz.push_back(static_cast<float>(k - 0.47));
      }
  std::vector<float> eps(rx.size());
  partially_saturated::list_coverage(static_cast<int>(rx.size()), rx.data(), ry.data(), rz.data(),
                                     a, eps.data());
  double jump = 0;
  for (std::size_t q = 0; q < rx.size(); ++q) {
    const double e = cell_coverage(rx[q], ry[q], rz[q], a);
    EXPECT_NEAR(eps[q], e, 1e-6);
    jump = std::max(jump, std::abs(cell_coverage(rx[q] + 0.01, ry[q], rz[q], a) - e));
  }
  EXPECT_LT(jump, 0.02);
  EXPECT_GT(jump, 0.001);  // the moved sphere did change covered cells
}

// One step of a lattice whose every cell is covered: a fully covered cell
// leaves its step with the solid's velocity for the next collision, whatever
// the liquid did before; density is conserved; the solid's momentum
// exchange is B (rho (u_s - u) - F) (partially_saturated_collision.hpp).
TEST(PartiallySaturatedCollision, CoveredCellsConserveMassAndExchangeTheStatedMomentum) {
  for (const double covered : {1.0, 0.37}) {
    const lattice::Extent e{16, 4, 4};
    lattice::FluidLattice<double> fluid(e, {0.02, 0.25});
    const lattice::Vector3 F{2e-5, -1e-5, 3e-6};
    fluid.set_body_force(F);
    fluid.initialise_equilibrium([](int x, int y, int z) {
      return lattice::Macroscopic{1.0 + 0.01 * std::sin(x + 2 * y + 3 * z),
                                  {0.02 * std::cos(x), -0.01, 0.005 * y}};
    });
    const double us[3] = {0.012, -0.004, 0.007};
    auto view = fluid.solid_coverage();
    for (long c = 0; c < e.cells(); ++c) {
      view.coverage[c] = covered;
      for (int d = 0; d < 3; ++d) view.solid_velocity[d][c] = covered * us[d];
    }
    for (long r = 0; r < e.rows(); ++r) view.chunk_row(r)[0] = 1;  // the row's one chunk
    const double mass = fluid.total_mass();
    const lattice::Vector3 p0 = fluid.total_momentum();
    fluid.step();
    EXPECT_NEAR(fluid.total_mass(), mass, 1e-12 * mass);
    // the momentum the step added beyond the body force, from the density and
    // momentum the collision reported: sum B (rho u_s - rho u - F)
    const double f[3] = {F.x, F.y, F.z};
    double exchange[3] = {0, 0, 0};
    for (long c = 0; c < e.cells(); ++c)
      for (int d = 0; d < 3; ++d)
        exchange[d] += covered * (view.density[c] * us[d] - view.momentum[d][c] - f[d]);
    const lattice::Vector3 p1 = fluid.total_momentum();
    const double cells = static_cast<double>(e.cells());
    // total_momentum() adds half of the body force to each cell before and after alike
    EXPECT_NEAR(p1.x - p0.x, cells * F.x + exchange[0], 1e-12);
    EXPECT_NEAR(p1.y - p0.y, cells * F.y + exchange[1], 1e-12);
    EXPECT_NEAR(p1.z - p0.z, cells * F.z + exchange[2], 1e-12);
  }
}

// A fully covered cell leaves its step with the solid's velocity for the
// next collision, whatever the liquid's was (uniform state and coverage, so
// that streaming changes nothing), even with a body force acting.
TEST(PartiallySaturatedCollision, FullyCoveredCellsTakeTheSolidVelocity) {
  const lattice::Extent e{16, 2, 2};
  lattice::FluidLattice<double> fluid(e, {0.01, 0.25});
  fluid.set_body_force({4e-5, 1e-5, -2e-5});
  fluid.initialise_equilibrium([](int, int, int) {
    return lattice::Macroscopic{1.003, {0.02, -0.01, 0.015}};
  });
  const double us[3] = {-0.011, 0.006, 0.002};
  auto view = fluid.solid_coverage();
  for (long c = 0; c < e.cells(); ++c) {
    view.coverage[c] = 1.0;
    for (int d = 0; d < 3; ++d) view.solid_velocity[d][c] = us[d];
  }
  for (long r = 0; r < e.rows(); ++r) view.chunk_row(r)[0] = 1;
  for (int step = 0; step < 3; ++step) {
    fluid.step();
    for (int x = 0; x < e.nx; ++x) {
      const lattice::Macroscopic m = fluid.macroscopic(x, 1, 0);
      EXPECT_NEAR(m.velocity.x, us[0], 1e-15);
      EXPECT_NEAR(m.velocity.y, us[1], 1e-15);
      EXPECT_NEAR(m.velocity.z, us[2], 1e-15);
      EXPECT_NEAR(m.density, 1.003, 1e-14);
    }
  }
}

// A chunk marked covered whose cells hold no solid collides exactly as the
// plain liquid (to round-off: the blend is evaluated with B = 0).
TEST(PartiallySaturatedCollision, UncoveredCellsOfACoveredChunkAreLiquid) {
  const lattice::Extent e{20, 3, 3};
  auto init = [](int x, int y, int z) {
    return lattice::Macroscopic{1.0 + 0.01 * std::cos(x + y - z),
                                {0.03 * std::sin(0.3 * x), 0.01 * z, -0.02}};
  };
  lattice::FluidLattice<double> plain(e, {0.05, 0.25}), blended(e, {0.05, 0.25});
  for (auto* f : {&plain, &blended}) {
    f->set_body_force({1e-5, 0, 0});
    f->initialise_equilibrium(init);
  }
  auto view = blended.solid_coverage();
  for (long r = 0; r < e.rows(); ++r) view.chunk_row(r)[0] = 3;  // both chunks of every row
  for (int s = 0; s < 7; ++s) {                                  // odd and even steps
    plain.step();
    blended.step();
  }
  for (int x = 0; x < e.nx; ++x)
    for (int i = 0; i < 19; ++i)
      EXPECT_NEAR(blended.population(i, x, 1, 2), plain.population(i, x, 1, 2), 1e-15);
}

// The control law: e = U - v; F += rho (G e + P (e - e_previous)).
TEST(ControlForcing, IncrementIsTheDefinedPiLaw) {
  typedef double V4 __attribute__((vector_size(32)));
  const V4 rho_v = {1.02, 0.010, -0.004, 0.0};
  const V4 target = {0, 0.013, -0.002, 0.001};
  V4 slip = {0, 0.001, 0.002, -0.003};
  const V4 dF = immersed_boundary::control_increment(rho_v, target, slip, 1.5, 0.5);
  const double e[3] = {0.003, 0.002, 0.001}, previous[3] = {0.001, 0.002, -0.003};
  EXPECT_EQ(dF[0], 0.0);
  for (int d = 0; d < 3; ++d) {
    EXPECT_NEAR(dF[d + 1], 1.02 * (1.5 * e[d] + 0.5 * (e[d] - previous[d])), 1e-16);
    EXPECT_NEAR(slip[d + 1], e[d], 1e-16);
  }
}

// The gains accepted are those measured stable (scheme.hpp): the period-2
// edge integral + 2 proportional between 3 (stable) and 4 (unstable).
TEST(ControlForcing, OnlyMeasuredStableGainsAreAccepted) {
  EXPECT_TRUE(coupling::stable_gains({2, 0}));
  EXPECT_TRUE(coupling::stable_gains({3, 0}));
  EXPECT_TRUE(coupling::stable_gains({1, 1}));
  EXPECT_FALSE(coupling::stable_gains({4, 0}));
  EXPECT_FALSE(coupling::stable_gains({2, 1}));
  EXPECT_FALSE(coupling::stable_gains({0.5, 0}));
  EXPECT_FALSE(coupling::stable_gains({2, -0.1}));
}

}  // namespace
}  // namespace flocsim
