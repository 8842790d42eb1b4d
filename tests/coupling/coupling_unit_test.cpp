// The pieces of the coupling schemes against hand-worked and independent
// results: the solid fraction of a cell cut by a plane against counting
// sub-cells, the coverage of a whole sphere against its volume, the blended
// collision of a covered cell against what it must do to density, momentum
// and velocity, and the control-forcing law against its definition.
#include <gtest/gtest.h>
#include <omp.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "engine/coupling/scheme.hpp"
#include "engine/immersed_boundary/control_forcing.hpp"
#include "engine/lattice/fluid_lattice.hpp"
#include "engine/partially_saturated/cell_coverage.hpp"
#include "engine/partially_saturated/partially_saturated_cells.hpp"
#include "tests/coupling/partially_saturated_reference.hpp"

namespace flocsim {
namespace {

using partially_saturated::cell_coverage;
using partially_saturated::cube_fraction_below_plane;
using spheres::Vec3;

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

// The branch-free form (the one the step evaluates, in vector loops) gives
// the scalar numbers, and the coverage of a cell moves smoothly as the sphere
// moves (no staircase: the sphere moved by 0.01 dx changes no cell's
// coverage by more than about 0.01 * sqrt(3)).
TEST(CellCoverage, BranchFreeFormAndSmallMovesAgree) {
  const double a = 5.7;
  std::vector<float> rx, ry, rz;
  for (int i = -8; i <= 8; ++i)
    for (int j = -8; j <= 8; ++j)
      for (int k = -8; k <= 8; ++k) {
        rx.push_back(static_cast<float>(i - 0.3));
        ry.push_back(static_cast<float>(j + 0.11));
        rz.push_back(static_cast<float>(k - 0.47));
      }
  const partially_saturated::SphereCoverage coverage(a);
  std::vector<float> eps(rx.size());
  const int n = static_cast<int>(rx.size());
#pragma omp simd
  for (int q = 0; q < n; ++q) eps[q] = coverage(rx[q], ry[q], rz[q]);
  double jump = 0;
  for (std::size_t q = 0; q < rx.size(); ++q) {
    const double e = cell_coverage(rx[q], ry[q], rz[q], a);
    EXPECT_NEAR(eps[q], e, 1e-6);
    jump = std::max(jump, std::abs(cell_coverage(rx[q] + 0.01, ry[q], rz[q], a) - e));
  }
  EXPECT_LT(jump, 0.02);
  EXPECT_GT(jump, 0.001);  // the moved sphere did change covered cells
}

// Covers every cell of a lattice alike (coverage eps, solid velocity u_s,
// every row covered) and keeps the density and momentum each cell's
// collision saw, in lattice order.
template <class Real>
class UniformCoverage final : public lattice::SolidCoverage<Real> {
 public:
  UniformCoverage(lattice::Extent e, double eps, std::array<double, 3> us)
      : velocity(us), density(static_cast<std::size_t>(e.cells())), eps_(eps) {
    for (auto& m : momentum) m.resize(density.size());
  }
  std::array<double, 3> velocity;
  std::vector<double> density;
  std::array<std::vector<double>, 3> momentum;

  void begin_step(int) override {}
  bool cover(lattice::CoveredRow<Real>& row) override {
    for (int x = 0; x < row.nx; ++x) {
      row.coverage[x] = static_cast<Real>(eps_);
      for (int d = 0; d < 3; ++d) row.solid_velocity[d][x] = static_cast<Real>(eps_ * velocity[d]);
    }
    return true;
  }
  void exchange(const lattice::CoveredRow<Real>& row) override {
    const std::size_t at = static_cast<std::size_t>(row.row) * row.nx;
    for (int x = 0; x < row.nx; ++x) {
      density[at + x] = row.density[x];
      for (int d = 0; d < 3; ++d) momentum[d][at + x] = row.momentum[d][x];
    }
  }

 private:
  double eps_;
};

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
    UniformCoverage<double> cover(e, covered, {0.012, -0.004, 0.007});
    const double mass = fluid.total_mass();
    const lattice::Vector3 p0 = fluid.total_momentum();
    fluid.set_solid_coverage(&cover);
    fluid.step();
    EXPECT_NEAR(fluid.total_mass(), mass, 1e-12 * mass);
    // the momentum the step added beyond the body force, from the density and
    // momentum the collision reported: sum B (rho u_s - rho u - F)
    const double f[3] = {F.x, F.y, F.z};
    double exchange[3] = {0, 0, 0};
    for (long c = 0; c < e.cells(); ++c)
      for (int d = 0; d < 3; ++d)
        exchange[d] +=
            covered * (cover.density[c] * cover.velocity[d] - cover.momentum[d][c] - f[d]);
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
  UniformCoverage<double> cover(e, 1.0, {us[0], us[1], us[2]});
  for (int step = 0; step < 3; ++step) {
    fluid.set_solid_coverage(&cover);  // for one step
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

// Cells of a covered row that hold no solid collide exactly as the plain
// liquid (to round-off: the blend is evaluated with B = 0).
TEST(PartiallySaturatedCollision, UncoveredCellsOfACoveredRowAreLiquid) {
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
  UniformCoverage<double> cover(e, 0.0, {0, 0, 0});  // covers every row, with eps = 0
  for (int s = 0; s < 7; ++s) {                      // odd and even steps
    plain.step();
    blended.set_solid_coverage(&cover);
    blended.step();
  }
  for (int x = 0; x < e.nx; ++x)
    for (int i = 0; i < 19; ++i)
      EXPECT_NEAR(blended.population(i, x, 1, 2), plain.population(i, x, 1, 2), 1e-15);
}

// Five spheres in a small periodic box, moving and spinning, on a lattice
// with a flow and a per-cell force field: two touching (they share the cells
// at their contact), two overlapping (summed coverage above 1, where
// B = min(1, eps) saturates), one across the box's corner (its rows wrap in
// x, y and z).
template <class Real>
struct FiveSpheres {
  static constexpr double kInputRadius = 3.6;
  lattice::Extent e{40, 30, 26};
  spheres::SphereSet s;
  lattice::FluidLattice<Real> fused{e, {0.05, 0.25}}, reference{e, {0.05, 0.25}};

  FiveSpheres() {
    const double a = kInputRadius;
    s.radius = a;
    s.density_ratio = 4;
    s.resize(6);
    s.position = {{20.3, 15.2, 13.1}, {20.3 + 2 * a, 15.2, 13.1},
                  {10.5, 22.0, 7.0},  {10.5 + 2 * a - 0.5, 22.3, 7.2},
                  {0.7, 0.4, 25.6},   {33.2, 6.1, 19.4}};
    for (std::size_t k = 0; k < s.size(); ++k) {
      const double q = static_cast<double>(k);
      s.velocity[k] = Vec3(0.01 * std::cos(q), -0.004 * q, 0.003 - 0.002 * q);
      s.angular_velocity[k] = Vec3(0.001 * q, -0.0015, 0.0007 * std::sin(q));
    }
    for (auto* f : {&fused, &reference}) {
      f->set_body_force({2e-5, -1e-5, 5e-6});
      auto field = f->force_field();
      for (long c = 0; c < e.cells(); ++c)
        for (int d = 0; d < 3; ++d)
          field.component[d][c] = static_cast<Real>(1e-6 * std::sin(0.7 * c + d));
      f->initialise_equilibrium([](int x, int y, int z) {
        return lattice::Macroscopic{1.0 + 0.01 * std::sin(0.3 * x + 0.2 * y - 0.1 * z),
                                    {0.02 * std::cos(0.2 * y), -0.01 * std::sin(0.15 * x), 0.005}};
      });
    }
  }
  void move() {
    for (std::size_t k = 0; k < s.size(); ++k) {
      s.position[k] += s.velocity[k];
      const double length[3] = {double(e.nx), double(e.ny), double(e.nz)};
      for (int d = 0; d < 3; ++d)
        s.position[k][d] -= length[d] * std::floor(s.position[k][d] / length[d]);
    }
  }
};

// The largest difference over the spheres relative to the largest value.
double relative_difference(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  double diff = 0, scale = 0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    diff = std::max(diff, (a[k] - b[k]).norm());
    scale = std::max(scale, b[k].norm());
  }
  return scale > 0 ? diff / scale : 1.0;
}

// The fused step (coverage, blended collision and the loads' sums in one
// pass over each row) gives each sphere the force, torque and inside
// momenta of the reference (the lattice-sized arrays, gathered sphere by
// sphere afterwards) to round-off, step after step, odd and even.
template <class Real>
void expect_fused_matches_reference(double tolerance) {
  FiveSpheres<Real> scene;
  const double a = scene.kInputRadius;
  // the touching pair does share cells
  int shared = 0;
  for (int i = 20; i < 30; ++i)
    for (int j = 10; j < 20; ++j)
      for (int k = 8; k < 18; ++k)
        shared += partially_saturated::cell_coverage(i - 20.3, j - 15.2, k - 13.1, a) > 0 &&
                  partially_saturated::cell_coverage(i - 20.3 - 2 * a, j - 15.2, k - 13.1, a) > 0;
  EXPECT_GT(shared, 4);
  partially_saturated::PartiallySaturatedCells<Real> fused(a);
  testing_support::ReferencePartiallySaturatedCells<Real> reference(a);
  for (int step = 0; step < 4; ++step) {
    fused.apply(scene.fused, scene.s);
    scene.fused.step();
    fused.after_liquid_step(scene.fused, scene.s);
    reference.apply(scene.reference, scene.s);
    scene.reference.step();
    reference.after_liquid_step(scene.reference);
    EXPECT_LT(relative_difference(fused.force(), reference.force), tolerance) << "step " << step;
    EXPECT_LT(relative_difference(fused.torque(), reference.torque), tolerance) << "step " << step;
    EXPECT_LT(relative_difference(fused.internal_momentum(), reference.momentum), tolerance);
    EXPECT_LT(relative_difference(fused.internal_angular_momentum(), reference.angular), tolerance);
    // not trivially: the liquid pushes every sphere, and holds liquid inside it
    for (std::size_t k = 0; k < scene.s.size(); ++k) {
      EXPECT_GT(reference.force[k].norm(), 1e-4);
      EXPECT_GT(reference.momentum[k].norm(), 0.1);
    }
    scene.move();
  }
}

TEST(PartiallySaturatedCells, FusedStepMatchesTheReference) {
  expect_fused_matches_reference<double>(1e-12);
  expect_fused_matches_reference<float>(1e-5);
}

// Each run of cells keeps its own sums and each sphere adds them in a fixed
// order: the loads and the liquid come out bit for bit the same on one
// thread and on three.
TEST(PartiallySaturatedCells, ResultsDoNotDependOnTheThreadCount) {
  const int threads = omp_get_max_threads();
  std::vector<Vec3> loads[2];
  double population[2] = {0, 0};
  for (int run = 0; run < 2; ++run) {
    omp_set_num_threads(run == 0 ? 1 : 3);
    FiveSpheres<float> scene;
    partially_saturated::PartiallySaturatedCells<float> psm(scene.kInputRadius);
    for (int step = 0; step < 3; ++step) {
      psm.apply(scene.fused, scene.s);
      scene.fused.step();
      psm.after_liquid_step(scene.fused, scene.s);
      scene.move();
    }
    for (const auto* v :
         {&psm.force(), &psm.torque(), &psm.internal_momentum(), &psm.internal_angular_momentum()})
      loads[run].insert(loads[run].end(), v->begin(), v->end());
    population[run] = scene.fused.population(7, 21, 15, 13) + scene.fused.population(3, 0, 0, 25);
  }
  omp_set_num_threads(threads);
  ASSERT_EQ(loads[0].size(), loads[1].size());
  for (std::size_t q = 0; q < loads[0].size(); ++q) EXPECT_EQ(loads[0][q], loads[1][q]) << q;
  EXPECT_EQ(population[0], population[1]);
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

// The refusal's reason is whole: it was cut at 199 characters, losing where
// to read why (the doc it names) and its closing parenthesis.
TEST(ControlForcing, TheRefusalNamesTheWholeStableRegion) {
  const std::string why = coupling::stable_gains_region();
  EXPECT_NE(why.find("integral >= "), std::string::npos);
  EXPECT_NE(why.find("period-2 mode at 4; docs/coupling.md)"), std::string::npos) << why;
  EXPECT_EQ(why.back(), ')');
}

}  // namespace
}  // namespace flocsim
