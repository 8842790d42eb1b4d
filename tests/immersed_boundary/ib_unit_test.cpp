// Behaviour of the immersed-boundary building blocks: the Roma kernel's
// moment conditions, the marker distribution, the Sangani-Acrivos series
// against its published values, the exact bookkeeping of spreading, and the
// optimised apply() against a plain reference transcription of the method.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <map>
#include <random>
#include <utility>
#include <vector>

#include "engine/calibration/hydrodynamic_radius.hpp"
#include "engine/immersed_boundary/immersed_boundary.hpp"
#include "engine/immersed_boundary/kernel.hpp"
#include "engine/immersed_boundary/sphere_markers.hpp"
#include "engine/spheres/sphere_dynamics.hpp"
#include "tests/lattice/lattice_probes.hpp"
#include "wake_sponge.hpp"

namespace flocsim {
namespace {

using spheres::Vec3;

TEST(RomaKernel, PartitionOfUnityAndZeroFirstMoment) {
  // Roma et al. (1999): sum_i phi(x - i) = 1 and sum_i (x - i) phi(x - i) = 0
  // for every x; both hold to round-off.
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-20.0, 20.0);
  for (int t = 0; t < 1000; ++t) {
    const double x = u(rng);
    const auto k = immersed_boundary::kernel_weights(x);
    double s0 = 0, s1 = 0;
    for (int a = 0; a < 3; ++a) {
      s0 += k.w[a];
      s1 += (x - (k.first + a)) * k.w[a];
      EXPECT_GE(k.w[a], 0.0);
    }
    EXPECT_NEAR(s0, 1.0, 1e-14);
    EXPECT_NEAR(s1, 0.0, 1e-14);
  }
  EXPECT_NEAR(immersed_boundary::roma_kernel(0.0), 2.0 / 3.0, 1e-15);
  EXPECT_EQ(immersed_boundary::roma_kernel(1.5), 0.0);
}

TEST(LinearKernel, PartitionOfUnityAndZeroFirstMoment) {
  // phi(r) = 1 - |r| on |r| < 1: at x, cells floor(x) and floor(x) + 1 carry
  // 1 - d and d (d = x - floor x), which sum to 1 with first moment
  // -d (1 - d) + (1 - d) d = 0.
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(-20.0, 20.0);
  for (int t = 0; t < 1000; ++t) {
    const double x = u(rng), first = std::floor(x);
    double w[2];
    immersed_boundary::linear_weights(x - first, w);
    double s0 = 0, s1 = 0;
    for (int a = 0; a < 2; ++a) {
      EXPECT_NEAR(w[a], immersed_boundary::linear_kernel(x - (first + a)), 1e-14);
      s0 += w[a];
      s1 += (x - (first + a)) * w[a];
    }
    EXPECT_NEAR(s0, 1.0, 1e-14);
    EXPECT_NEAR(s1, 0.0, 1e-14);
  }
  EXPECT_EQ(immersed_boundary::linear_kernel(0.0), 1.0);
  EXPECT_EQ(immersed_boundary::linear_kernel(1.0), 0.0);
  EXPECT_EQ(immersed_boundary::linear_kernel(-0.25), 0.75);
}

// The velocity direct forcing starts from: the lattice velocity minus half of
// the stored per-cell force over the density, at even and odd (AA) steps and
// at cells on the periodic edges.
TEST(FluidLattice, VelocityWithoutForceFieldRemovesHalfTheStoredForce) {
  lattice::FluidLattice<double> fluid({9, 7, 6}, {0.1, 0.25});
  fluid.set_body_force({1e-5, 0, 0});
  fluid.enable_force_field();
  fluid.initialise_equilibrium([](int x, int y, int z) {
    return lattice::Macroscopic{1.0 + 0.01 * std::sin(x + 2.0 * y),
                                {0.01 * std::cos(y + z), 0.02 * std::sin(x), 0.005 * z}};
  });
  for (long c = 0; c < fluid.extent().cells(); ++c)
    for (int d = 0; d < 3; ++d) fluid.force_field().component[d][c] = 1e-4 * std::sin(3.0 * c + d);
  for (int step = 0; step < 2; ++step) {
    fluid.step();
    for (int z = 0; z < 6; ++z)
      for (int y = 0; y < 7; ++y)
        for (int x = 0; x < 9; ++x) {
          const auto full = fluid.macroscopic(x, y, z);
          const auto bare = testing::macroscopic_without_force_field(fluid, x, y, z);
          const long c = fluid.cell_index(x, y, z);
          EXPECT_NEAR(bare.density, full.density, 1e-15);
          EXPECT_NEAR(bare.velocity.x,
                      full.velocity.x - 0.5 * fluid.force_field().component[0][c] / full.density,
                      1e-15);
          EXPECT_NEAR(bare.velocity.y,
                      full.velocity.y - 0.5 * fluid.force_field().component[1][c] / full.density,
                      1e-15);
          EXPECT_NEAR(bare.velocity.z,
                      full.velocity.z - 0.5 * fluid.force_field().component[2][c] / full.density,
                      1e-15);
        }
    // The row reader gives the same numbers, edge cells included.
    double rho[9], ux[9], uy[9], uz[9];
    fluid.macroscopic_row_without_force_field(0, 9, 6, 5, rho, ux, uy, uz);
    for (int x = 0; x < 9; ++x) {
      const auto bare = testing::macroscopic_without_force_field(fluid, x, 6, 5);
      EXPECT_NEAR(rho[x], bare.density, 1e-15);
      EXPECT_NEAR(ux[x], bare.velocity.x, 1e-15);
      EXPECT_NEAR(uy[x], bare.velocity.y, 1e-15);
      EXPECT_NEAR(uz[x], bare.velocity.z, 1e-15);
    }
    // The interleaved reader (the immersed boundary's), on pieces that start
    // or end at the periodic edges and inside.
    for (const auto& [x0, count] :
         {std::pair{0, 9}, std::pair{3, 6}, std::pair{0, 1}, std::pair{8, 1}, std::pair{2, 4}}) {
      double rho_u[36];
      fluid.macroscopic_row_without_force_field(x0, count, 6, 5, rho_u);
      for (int k = 0; k < count; ++k) {
        const auto bare = testing::macroscopic_without_force_field(fluid, x0 + k, 6, 5);
        EXPECT_NEAR(rho_u[4 * k], bare.density, 1e-15);
        EXPECT_NEAR(rho_u[4 * k + 1], bare.velocity.x, 1e-15);
        EXPECT_NEAR(rho_u[4 * k + 2], bare.velocity.y, 1e-15);
        EXPECT_NEAR(rho_u[4 * k + 3], bare.velocity.z, 1e-15);
      }
    }
  }
}

TEST(SphereMarkers, SpacingNearTheRequestedValue) {
  // Mean nearest-neighbour distance of the Fibonacci markers on a sphere of
  // radius 6 with spacing 0.7: a hexagonal-like covering of area 0.7^2 per
  // point has nearest neighbours at 0.7 * sqrt(2/sqrt(3)) = 0.75; accept
  // 0.6 - 0.8 and no point closer than 0.5 (no clustering at the poles).
  const double r = 6.0;
  const int n = immersed_boundary::marker_count(r, 0.7);
  EXPECT_LE(std::sqrt(4 * M_PI * r * r / n), 0.7);
  const auto p = immersed_boundary::fibonacci_sphere(n);
  double mean = 0, smallest = 1e9;
  for (int i = 0; i < n; ++i) {
    double best = 1e9;
    for (int j = 0; j < n; ++j)
      if (i != j)
        best = std::min(
            best, r * (p[static_cast<std::size_t>(i)] - p[static_cast<std::size_t>(j)]).norm());
    mean += best / n;
    smallest = std::min(smallest, best);
    EXPECT_NEAR(p[static_cast<std::size_t>(i)].norm(), 1.0, 1e-14);
  }
  EXPECT_GT(mean, 0.6);
  EXPECT_LT(mean, 0.8);
  EXPECT_GT(smallest, 0.5);
}

TEST(SanganiAcrivos, PublishedValues) {
  // docs/model.md section 5: K at phi = 0.001, 0.01, 0.05, 0.1, 0.2 (4 significant figures).
  const double phi[] = {0.001, 0.01, 0.05, 0.1, 0.2};
  const double K[] = {1.2121, 1.5857, 2.5071, 3.6425, 6.7765};
  for (int i = 0; i < 5; ++i) {
    const double chi = std::cbrt(phi[i] / (M_PI / 6.0));
    EXPECT_NEAR(calibration::sangani_acrivos_drag(chi), K[i], 1e-4) << "phi = " << phi[i];
  }
  // Hasimoto's dilute form agrees at phi = 0.001 (its error is O(phi^(8/3))).
  const double chi = std::cbrt(0.001 / (M_PI / 6.0));
  EXPECT_NEAR(calibration::hasimoto_drag(chi) / calibration::sangani_acrivos_drag(chi), 1.0, 1e-3);
}

TEST(SanganiAcrivos, RadiusFromDragInvertsTheSeries) {
  const double nu = 0.1, U = 1e-4, a = 5.3;
  const int L = 20;
  const double F = 6 * M_PI * nu * a * U * calibration::sangani_acrivos_drag(2 * a / L);
  EXPECT_NEAR(calibration::hydrodynamic_radius_from_drag(F, U, nu, L), a, 1e-9);
}

TEST(CalibrationTable, InputRadiusInterpolatesInLogViscosityAndNeverExtrapolates) {
  // Hand-made table: a = 6 at nu = 0.01 and 0.04 (a_g 5.57 and 5.59), a = 4 at
  // nu = 0.02, and an a = 6 entry with one sweep that must not be mixed in.
  const auto table = calibration::CalibrationTable::parse(R"({"entries": [
    {"hydrodynamic_radius": 6, "viscosity": 0.01, "input_radius": 5.57, "marker_spacing": 0.7, "iterations": 2},
    {"hydrodynamic_radius": 6, "viscosity": 0.04, "input_radius": 5.59, "marker_spacing": 0.7, "iterations": 2},
    {"hydrodynamic_radius": 6, "viscosity": 0.02, "input_radius": 5.00, "marker_spacing": 0.7, "iterations": 1},
    {"hydrodynamic_radius": 4, "viscosity": 0.02, "input_radius": 3.53, "marker_spacing": 0.7, "iterations": 2}]})",
                                                          "test table");
  // nu = 0.02 is halfway between 0.01 and 0.04 in log nu: the mean a_g.
  EXPECT_NEAR(table.input_radius(6, 0.02), 5.58, 1e-12);
  // a quarter of the way: log(0.01 sqrt(2)) = log 0.01 + (1/4) log 4
  EXPECT_NEAR(table.input_radius(6, 0.01 * std::sqrt(2.0)), 5.575, 1e-12);
  EXPECT_DOUBLE_EQ(table.input_radius(6, 0.01), 5.57);  // at an entry: that entry
  EXPECT_DOUBLE_EQ(table.input_radius(6, 0.04), 5.59);
  EXPECT_DOUBLE_EQ(table.input_radius(6, 0.005), 5.57);  // outside: the nearest entry
  EXPECT_DOUBLE_EQ(table.input_radius(6, 0.5), 5.59);
  EXPECT_DOUBLE_EQ(table.input_radius(6, 0.02, {0.7, 1, coupling::Kernel::roma3}),
                   5.00);  // sweeps are a separate scheme
  EXPECT_DOUBLE_EQ(table.input_radius(4, 0.001), 3.53);
  EXPECT_THROW(table.input_radius(5, 0.02), std::out_of_range);
}

// The shipped table against its own records: every entry keeps the runs
// that made it (box L, body force f, measured superficial velocity U; where
// the entry was made at several places on the grid, one run per place).
// From those the hydrodynamic radius is recomputed here by inverting the
// Sangani-Acrivos series, K(2a/L) = f L^3 / (6 pi nu a U), averaged over a
// box's places, and must be the wanted a to 0.02 dx in every box (0.5 % of
// a at a = 4), with the runs made at the entry's a_g. The offset a - a_g
// must lie where each scheme puts its boundary: direct forcing smears the
// surface outwards by at most about half a cell (0 < a - a_g <= 0.5, the
// model's "typically <= 0.5 dx"); control forcing holds the interpolated
// velocity at exactly the surface velocity, which with a kernel of positive
// weights needs the liquid at rest over its whole reach, so its wall lies at
// most the kernel's half-width, 1.5 dx, outside the markers (0 < a - a_g <=
// 1.5); partially saturated cells cover the sphere's exact volume, so their
// boundary moves by less than a cell either way (|a - a_g| <= 0.5). It also
// checks that a = 4, 6, 8 and 12 are all there, at nu = 1/6 at least.
TEST(CalibrationTable, ShippedEntriesReproduceTheirRadiusFromTheirOwnRuns) {
  const auto& table = calibration::CalibrationTable::shipped();
  ASSERT_FALSE(table.entries().empty());
  for (double a : {4.0, 6.0, 8.0, 12.0}) EXPECT_NO_THROW(table.lookup(a, 1.0 / 6.0)) << "a = " << a;
  for (const auto& e : table.entries()) {
    SCOPED_TRACE("a = " + std::to_string(e.hydrodynamic_radius) +
                 ", nu = " + std::to_string(e.viscosity) + ", " + e.scheme.describe());
    const double offset = e.hydrodynamic_radius - e.input_radius;
    if (!e.scheme.immersed_boundary()) {
      EXPECT_LE(std::abs(offset), 0.5);
    } else {
      EXPECT_GT(offset, 0.0);
      EXPECT_LE(offset, e.scheme.control() ? 1.5 : 0.5);
    }
    ASSERT_GE(e.checks.size(), 2u);
    std::map<int, std::pair<double, int>> per_box;  // sum of radii, runs
    for (const auto& c : e.checks) {
      EXPECT_DOUBLE_EQ(c.input_radius, e.input_radius);
      const double force = c.body_force * c.box * c.box * c.box;
      per_box[c.box].first += calibration::hydrodynamic_radius_from_drag(
          force, c.superficial_velocity, e.viscosity, c.box);
      ++per_box[c.box].second;
    }
    EXPECT_GE(per_box.size(), 2u);
    for (const auto& [box, sum] : per_box)
      EXPECT_NEAR(sum.first / sum.second, e.hydrodynamic_radius, 0.02) << "box " << box;
  }
}

// The validation runs' wake sponge (wake_sponge.hpp): its forces sum to zero,
// so a lattice with the sponge keeps the momentum of a twin without it; it
// relaxes the slab's velocity towards the slab mean; and it takes back its old
// force when the slab moves with the sphere.
TEST(WakeSponge, ConservesMomentumMixesTheSlabAndRemovesItsOldForce) {
  const lattice::Extent e{48, 8, 8};
  lattice::FluidLattice<double> with(e, {0.02, 0.25}), without(e, {0.02, 0.25});
  // A shear wave u_x = U0 sin(2 pi y / 8) on a uniform stream: a velocity
  // spread across every y-z slab that viscosity alone takes 1/(nu k^2) = 81
  // steps to damp.
  for (auto* f : {&with, &without}) {
    f->enable_force_field();
    f->initialise_equilibrium([&](int, int y, int) {
      return lattice::Macroscopic{1.0, {0.01 + 0.01 * std::sin(2 * M_PI * y / 8), 0.002, -0.001}};
    });
  }
  // Velocity spread (sum of squared deviations from the slab mean) over x = 22..25.
  auto spread = [&](const lattice::FluidLattice<double>& f) {
    double mass = 0, p[3] = {0, 0, 0};
    std::vector<lattice::Macroscopic> m;
    for (int x = 22; x < 26; ++x)
      for (int z = 0; z < e.nz; ++z)
        for (int y = 0; y < e.ny; ++y) {
          m.push_back(testing::macroscopic_without_force_field(f, x, y, z));
          mass += m.back().density;
          p[0] += m.back().density * m.back().velocity.x;
          p[1] += m.back().density * m.back().velocity.y;
          p[2] += m.back().density * m.back().velocity.z;
        }
    double s = 0;
    for (const auto& c : m)
      s += std::pow(c.velocity.x - p[0] / mass, 2) + std::pow(c.velocity.y - p[1] / mass, 2) +
           std::pow(c.velocity.z - p[2] / mass, 2);
    return s;
  };
  test::WakeSponge<double> sponge(0.5, 4);
  sponge.apply(with, 0.3, 2.0);  // slab x = 22..25, half a box from the sphere
  for (double F : sponge.total_force()) EXPECT_NEAR(F, 0.0, 1e-15);
  for (int x = 0; x < e.nx; ++x) {  // force on the slab only
    const bool in_slab = x >= 22 && x < 26;
    double sum = 0;
    for (int z = 0; z < e.nz; ++z)
      for (int y = 0; y < e.ny; ++y)
        sum += std::abs(with.force_field().component[0][with.cell_index(x, y, z)]);
    EXPECT_EQ(sum > 0, in_slab) << "x = " << x;
  }
  for (int step = 0; step < 20; ++step) {
    if (step > 0) sponge.apply(with, 0.3, 2.0);
    with.step();
    without.step();
  }
  // Momentum: the lattice's total (which adds half of the force field) after
  // removing the sponge's last force, so both lattices read the same way.
  sponge.apply(with, 0.3, 2.0);
  const auto last = sponge.total_force();
  lattice::Vector3 pw = with.total_momentum();
  pw.x -= 0.5 * last[0], pw.y -= 0.5 * last[1], pw.z -= 0.5 * last[2];
  // Tolerance: double round-off of momenta of size |p| = 31 summed over 3072
  // cells and 20 steps, eps |p| sqrt(3072 x 20) = 2e-12.
  const lattice::Vector3 po = without.total_momentum();
  EXPECT_NEAR(pw.x, po.x, 2e-12);
  EXPECT_NEAR(pw.y, po.y, 2e-12);
  EXPECT_NEAR(pw.z, po.z, 2e-12);
  // After 20 steps viscosity alone leaves (1 - 20/81)^2 ~ 0.6 of the spread;
  // the sponge (half the deviation per step on the slab) leaves far less.
  const double ratio = spread(with) / spread(without);
  std::printf("slab velocity spread after 20 steps, with / without sponge: %.3f\n", ratio);
  EXPECT_LT(ratio, 0.2);
  // The sphere moves 5 cells: the slab moves to x = 27..30 and x = 22..26 is clear again.
  sponge.apply(with, 5.3, 2.0);
  for (int x = 22; x < 27; ++x)
    for (int z = 0; z < e.nz; ++z)
      for (int y = 0; y < e.ny; ++y)
        for (int d = 0; d < 3; ++d)
          EXPECT_EQ(with.force_field().component[d][with.cell_index(x, y, z)], 0.0);
  EXPECT_THROW(sponge.apply(with, 0.3, 10.0), std::invalid_argument);  // slab would meet the sphere
}

TEST(SettlingForces, BalanceOfSpecSectionOne) {
  // f V (1 - phi) = N (rho_p - rho_bar) V_p g, with the definitions of docs/model.md section 1.
  const std::size_t n = 37;
  const double a = 6, V = 100.0 * 80 * 80, g = 3e-5, ratio = 4;
  const auto f = spheres::settling_forces(n, a, ratio, V, g);
  const double vp = 4.0 / 3.0 * M_PI * a * a * a, phi = n * vp / V;
  const double rho_bar = phi * ratio + (1 - phi);
  EXPECT_NEAR(f.liquid_body_force.x() * V * (1 - phi), -f.net_gravity.x() * n, 1e-12);
  EXPECT_NEAR(f.net_gravity.x(), -(ratio - rho_bar) * vp * g, 1e-15);
  EXPECT_GT(f.liquid_body_force.x(), 0.0);  // liquid pushed up, spheres pulled down (-x)
}

// One step by hand, a = 2 (V_p = 32 pi / 3), density ratio 4, liquid density 1,
// no external force, H = (3, 0, 0), inside-liquid momentum change (0.5, 0, 0):
// measured: du = (H + dP_in) / m_p = 3.5 / (128 pi / 3) = 0.0261117;
// rigid body: du = H / (m_p - rho V_p) = 3 / (96 pi / 3) = 0.0298416, the
// measured change ignored. A density ratio of 1 leaves no mass: refused.
TEST(SphereDynamics, RigidBodyInsideLiquidByHand) {
  spheres::SphereSet s;
  s.radius = 2.0;
  s.density_ratio = 4.0;
  s.resize(1);
  const std::vector<Vec3> force{Vec3(3, 0, 0)}, torque{Vec3::Zero()}, dp{Vec3(0.5, 0, 0)},
      dl{Vec3::Zero()};
  spheres::SphereDynamicsSettings measured;  // no external force
  spheres::advance_velocities(s, {force, torque, dp, dl}, measured);
  EXPECT_NEAR(s.velocity[0].x(), 3.5 / (128 * M_PI / 3), 1e-15);
  s.velocity[0] = Vec3::Zero();
  spheres::SphereDynamicsSettings rigid;
  rigid.rigid_inside_liquid = true;
  spheres::advance_velocities(s, {force, torque, dp, dl}, rigid);
  EXPECT_NEAR(s.velocity[0].x(), 3.0 / (96 * M_PI / 3), 1e-15);
  s.density_ratio = 1.0;
  EXPECT_THROW(spheres::advance_velocities(s, {force, torque, dp, dl}, rigid),
               std::invalid_argument);
}

// The load the coupling monitor watches, by hand (a = 2, density ratio 4):
// measured, H + dP_in = 3 + 0.5 = 3.5; rigid body, H m_p / (m_p - rho V_p) =
// 3 x 4/3 = 4, the same acceleration as the velocity update above gives.
TEST(SphereDynamics, LiquidLoadPerStepByHand) {
  spheres::SphereSet s;
  s.radius = 2.0;
  s.density_ratio = 4.0;
  s.resize(1);
  spheres::SphereDynamicsSettings measured, rigid;
  rigid.rigid_inside_liquid = true;
  EXPECT_NEAR(spheres::liquid_load_per_step(s, measured, Vec3(3, 0, 0), Vec3(0.5, 0, 0)).x(), 3.5,
              1e-15);
  EXPECT_NEAR(spheres::liquid_load_per_step(s, rigid, Vec3(3, 0, 0), Vec3(0.5, 0, 0)).x(), 4.0,
              1e-14);
}

// Many spheres in one box, spread by both threads: the force the lattice
// receives equals minus the sum of the sphere forces (momentum), and the
// previous step's force is fully removed before the next is written.
TEST(ImmersedBoundary, SpreadForceEqualsSphereReactionWithManySpheres) {
  lattice::FluidLattice<double> fluid({64, 40, 40}, {0.1, 0.25});
  fluid.initialise_equilibrium([](int x, int y, int) {
    return lattice::Macroscopic{
        1.0, {0.01 * std::sin(2 * M_PI * y / 40.0), 0.005 * std::cos(2 * M_PI * x / 64.0), 0}};
  });
  immersed_boundary::ImmersedBoundary<double> ib({.input_radius = 3.5});
  spheres::SphereSet s;
  s.radius = 4.0;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> ux(0, 64), uy(0, 40), uv(-0.01, 0.01);
  for (int i = 0; i < 40; ++i) {
    s.position.push_back({ux(rng), uy(rng), uy(rng)});
    s.velocity.push_back({uv(rng), uv(rng), uv(rng)});
    s.angular_velocity.push_back({uv(rng), uv(rng), uv(rng)});
  }
  for (int rep = 0; rep < 2; ++rep) {
    if (rep == 1)
      for (auto& x : s.position)
        x = spheres::PeriodicBox{Vec3(64, 40, 40)}.wrap(x + Vec3(1.3, -0.7, 2.2));
    ib.apply(fluid, s);
    double field[3] = {0, 0, 0};
    for (int z = 0; z < 40; ++z)
      for (int y = 0; y < 40; ++y)
        for (int x = 0; x < 64; ++x)
          for (int d = 0; d < 3; ++d)
            field[d] += fluid.force_field().component[d][fluid.cell_index(x, y, z)];
    Vec3 total = Vec3::Zero();
    for (const Vec3& F : ib.force()) total += F;
    double scale = 0;
    for (const Vec3& F : ib.force()) scale += F.norm();
    ASSERT_GT(scale, 1e-3);
    for (int d = 0; d < 3; ++d)
      EXPECT_NEAR(field[d], -total[d], 1e-12 * scale) << "component " << d;
  }
  ib.remove(fluid);
  double left = 0;
  for (int d = 0; d < 3; ++d)
    for (long c = 0; c < fluid.extent().cells(); ++c)
      left += std::abs(fluid.force_field().component[d][c]);
  EXPECT_EQ(left, 0.0);
}

// The optimised apply() against a plain transcription of the method (header
// of immersed_boundary.hpp) for spheres whose kernels do not overlap, two of
// them across the periodic edges, at an even and an odd (AA) time step:
// u* per cell from testing::macroscopic_without_force_field, Roma weights from
// roma_kernel, Jacobi sweeps interpolating u* + F/(2 rho) and spreading
// dF = 2 rho (U - u), H = -sum F dV, T = -sum r x F dV, and the inside
// momentum sum w (rho u* + F/2) with w = min(1, a_g + 1/2 - |r|).
struct ReferenceResult {
  std::vector<Vec3> force, torque, momentum, angular;
  std::vector<double> field[3];
};

ReferenceResult reference_apply(const lattice::FluidLattice<double>& fluid,
                                const spheres::SphereSet& s, double ag,
                                const coupling::Scheme& scheme) {
  const lattice::Extent e = fluid.extent();
  const int n = immersed_boundary::marker_count(ag, scheme.marker_spacing);
  const bool roma = scheme.kernel == coupling::Kernel::roma3;
  const int width = roma ? 3 : 2;
  // Roma: cells round(X) - 1 .. round(X) + 1; linear: floor(X), floor(X) + 1
  const auto first_cell = [roma](double X) {
    return roma ? static_cast<int>(std::nearbyint(X)) - 1 : static_cast<int>(std::floor(X));
  };
  const auto kernel = [roma](double r) {
    return roma ? immersed_boundary::roma_kernel(r) : immersed_boundary::linear_kernel(r);
  };
  const auto dirs = immersed_boundary::fibonacci_sphere(n);
  const double dV = immersed_boundary::marker_volume(ag, n);
  const auto wrap = [](int i, int L) { return ((i % L) + L) % L; };
  ReferenceResult out;
  for (auto& f : out.field) f.assign(static_cast<std::size_t>(e.cells()), 0.0);
  for (std::size_t p = 0; p < s.size(); ++p) {
    const Vec3 c = s.position[p];
    // Cells of the sphere's neighbourhood, keyed by unwrapped coordinates.
    const int lo[3] = {static_cast<int>(std::floor(c[0] - ag)) - 3,
                       static_cast<int>(std::floor(c[1] - ag)) - 3,
                       static_cast<int>(std::floor(c[2] - ag)) - 3};
    const int W = static_cast<int>(std::ceil(2 * ag)) + 7;
    const auto local = [&](int x, int y, int z) {
      return static_cast<std::size_t>((x - lo[0]) + W * ((y - lo[1]) + W * (z - lo[2])));
    };
    std::vector<double> rho(static_cast<std::size_t>(W * W * W)), ux(rho.size()), uy(rho.size()),
        uz(rho.size()), fx(rho.size(), 0.0), fy(rho.size(), 0.0), fz(rho.size(), 0.0);
    for (int z = lo[2]; z < lo[2] + W; ++z)
      for (int y = lo[1]; y < lo[1] + W; ++y)
        for (int x = lo[0]; x < lo[0] + W; ++x) {
          const auto m = testing::macroscopic_without_force_field(fluid, wrap(x, e.nx),
                                                                  wrap(y, e.ny), wrap(z, e.nz));
          const std::size_t l = local(x, y, z);
          rho[l] = m.density;
          ux[l] = m.velocity.x;
          uy[l] = m.velocity.y;
          uz[l] = m.velocity.z;
        }
    std::vector<Vec3> Fm(static_cast<std::size_t>(n), Vec3::Zero()), dF(Fm.size());
    const auto stencil = [&](const Vec3& X, auto&& visit) {
      const int base[3] = {first_cell(X[0]), first_cell(X[1]), first_cell(X[2])};
      for (int k = 0; k < width; ++k)
        for (int j = 0; j < width; ++j)
          for (int i = 0; i < width; ++i) {
            const double w = kernel(X[0] - (base[0] + i)) * kernel(X[1] - (base[1] + j)) *
                             kernel(X[2] - (base[2] + k));
            visit(local(base[0] + i, base[1] + j, base[2] + k), w);
          }
    };
    for (int it = 0; it < scheme.sweeps; ++it) {
      for (int m = 0; m < n; ++m) {
        const Vec3 r = ag * dirs[static_cast<std::size_t>(m)];
        double rm = 0;
        Vec3 um = Vec3::Zero();
        stencil(c + r, [&](std::size_t l, double w) {
          const double h = 0.5 / rho[l];
          rm += w * rho[l];
          um += w * Vec3(ux[l] + h * fx[l], uy[l] + h * fy[l], uz[l] + h * fz[l]);
        });
        const Vec3 U = s.velocity[p] + s.angular_velocity[p].cross(r);
        dF[static_cast<std::size_t>(m)] = 2 * rm * (U - um);
      }
      for (int m = 0; m < n; ++m) {
        Fm[static_cast<std::size_t>(m)] += dF[static_cast<std::size_t>(m)];
        stencil(c + ag * dirs[static_cast<std::size_t>(m)], [&](std::size_t l, double w) {
          fx[l] += w * dV * dF[static_cast<std::size_t>(m)][0];
          fy[l] += w * dV * dF[static_cast<std::size_t>(m)][1];
          fz[l] += w * dV * dF[static_cast<std::size_t>(m)][2];
        });
      }
    }
    Vec3 H = Vec3::Zero(), T = Vec3::Zero(), P = Vec3::Zero(), L = Vec3::Zero();
    for (int m = 0; m < n; ++m) {
      H -= Fm[static_cast<std::size_t>(m)] * dV;
      T -= (ag * dirs[static_cast<std::size_t>(m)]).cross(Fm[static_cast<std::size_t>(m)] * dV);
    }
    for (int z = lo[2]; z < lo[2] + W; ++z)
      for (int y = lo[1]; y < lo[1] + W; ++y)
        for (int x = lo[0]; x < lo[0] + W; ++x) {
          const Vec3 r = Vec3(x, y, z) - c;
          const double w = std::min(1.0, ag + 0.5 - r.norm());
          const std::size_t l = local(x, y, z);
          const long g = fluid.cell_index(wrap(x, e.nx), wrap(y, e.ny), wrap(z, e.nz));
          out.field[0][static_cast<std::size_t>(g)] += fx[l];
          out.field[1][static_cast<std::size_t>(g)] += fy[l];
          out.field[2][static_cast<std::size_t>(g)] += fz[l];
          if (w <= 0) continue;
          const Vec3 j(rho[l] * ux[l] + 0.5 * fx[l], rho[l] * uy[l] + 0.5 * fy[l],
                       rho[l] * uz[l] + 0.5 * fz[l]);
          P += w * j;
          L += w * r.cross(j);
        }
    out.force.push_back(H);
    out.torque.push_back(T);
    out.momentum.push_back(P);
    out.angular.push_back(L);
  }
  return out;
}

class ReferenceScheme : public ::testing::TestWithParam<coupling::Scheme> {};

TEST_P(ReferenceScheme, MatchesAPlainReferenceImplementation) {
  const coupling::Scheme scheme = GetParam();
  const lattice::Extent e{44, 36, 34};
  lattice::FluidLattice<double> fluid(e, {0.1, 0.25});
  fluid.set_body_force({2e-6, -1e-6, 0});
  fluid.initialise_equilibrium([](int x, int y, int z) {
    return lattice::Macroscopic{1.0 + 0.002 * std::cos(0.3 * x + 0.2 * z),
                                {0.01 * std::sin(2 * M_PI * y / 36.0),
                                 0.006 * std::cos(2 * M_PI * x / 44.0) + 0.002 * std::sin(0.4 * z),
                                 0.004 * std::sin(2 * M_PI * (x + y) / 36.0)}};
  });
  const double ag = 3.6;
  immersed_boundary::ImmersedBoundary<double> ib({.input_radius = ag, .scheme = scheme});
  spheres::SphereSet s;
  s.radius = 4.0;
  // Kernels at least 3 dx apart; one sphere across x = 0, one across the
  // y and z edges, one inside.
  s.position = {{0.7, 17.3, 16.9}, {22.4, 35.2, 0.45}, {24.1, 12.6, 19.3}};
  s.velocity = {{0.003, -0.001, 0.002}, {-0.002, 0.0015, 0.0}, {0.0, 0.001, -0.0025}};
  s.angular_velocity = {{0.0002, 0.0, -0.0003}, {0.0, 0.0004, 0.0001}, {-0.0002, 0.0001, 0.0}};
  for (int step = 0; step < 2; ++step) {  // even, then odd time step
    if (step == 1) {
      fluid.step();
      for (auto& x : s.position) x += Vec3(0.37, -0.21, 0.13);
    }
    ib.apply(fluid, s);
    const ReferenceResult ref = reference_apply(fluid, s, ag, scheme);
    for (std::size_t p = 0; p < s.size(); ++p) {
      const double f = ref.force[p].norm(), t = ref.torque[p].norm();
      const double pm = ref.momentum[p].norm(), l = ref.angular[p].norm();
      ASSERT_GT(f, 1e-4);
      EXPECT_LT((ib.force()[p] - ref.force[p]).norm(), 1e-12 * f) << "sphere " << p;
      EXPECT_LT((ib.torque()[p] - ref.torque[p]).norm(), 1e-12 * t) << "sphere " << p;
      EXPECT_LT((ib.internal_momentum()[p] - ref.momentum[p]).norm(), 1e-12 * pm) << "sphere " << p;
      EXPECT_LT((ib.internal_angular_momentum()[p] - ref.angular[p]).norm(), 1e-12 * l)
          << "sphere " << p;
    }
    double biggest = 0, worst = 0;
    for (int d = 0; d < 3; ++d)
      for (long c = 0; c < e.cells(); ++c) {
        biggest = std::max(biggest, std::abs(ref.field[d][static_cast<std::size_t>(c)]));
        worst = std::max(worst, std::abs(fluid.force_field().component[d][c] -
                                         ref.field[d][static_cast<std::size_t>(c)]));
      }
    EXPECT_LT(worst, 1e-12 * biggest) << "step " << step;
  }
}

// The paper's scheme, one sweep, wider markers and the 2-point kernel.
INSTANTIATE_TEST_SUITE_P(Schemes, ReferenceScheme,
                         ::testing::Values(coupling::Scheme{0.7, 2, coupling::Kernel::roma3},
                                           coupling::Scheme{1.0, 1, coupling::Kernel::roma3},
                                           coupling::Scheme{0.7, 3, coupling::Kernel::roma3},
                                           coupling::Scheme{1.0, 1, coupling::Kernel::linear2},
                                           coupling::Scheme{0.7, 2, coupling::Kernel::linear2}),
                         [](const ::testing::TestParamInfo<coupling::Scheme>& param_info) {
                           const auto& p = param_info.param;
                           return coupling::kernel_name(p.kernel) + "_spacing" +
                                  std::to_string(static_cast<int>(10 * p.marker_spacing)) +
                                  "_sweeps" + std::to_string(p.sweeps);
                         });

// The float lattice runs the same method in single precision (populations,
// u*, marker sweeps): for the same flow its forces, torques and inside momenta
// agree with the double lattice's to single-precision round-off. Measured:
// at most 5e-7 relative (force 4e-7, torque 5e-7, momentum 3e-8) over three
// steps; tolerance 1e-5 (20 times that).
TEST(ImmersedBoundary, FloatAndDoubleLatticesAgree) {
  const lattice::Extent e{40, 32, 30};
  const auto flow = [](int x, int y, int z) {
    return lattice::Macroscopic{
        1.0 + 0.002 * std::cos(0.3 * x + 0.2 * z),
        {0.01 * std::sin(2 * M_PI * y / 32.0), 0.006 * std::cos(2 * M_PI * x / 40.0),
         0.004 * std::sin(2 * M_PI * (x + y) / 32.0)}};
  };
  lattice::FluidLattice<double> fd(e, {0.1, 0.25});
  lattice::FluidLattice<float> ff(e, {0.1, 0.25});
  fd.initialise_equilibrium(flow);
  ff.initialise_equilibrium(flow);
  immersed_boundary::ImmersedBoundary<double> ibd({.input_radius = 3.6});
  immersed_boundary::ImmersedBoundary<float> ibf({.input_radius = 3.6});
  spheres::SphereSet s;
  s.radius = 4.0;
  s.position = {{0.7, 15.3, 14.9}, {21.4, 31.2, 0.45}, {24.1, 12.6, 19.3}};
  s.velocity = {{0.003, -0.001, 0.002}, {-0.002, 0.0015, 0.0}, {0.0, 0.001, -0.0025}};
  s.angular_velocity.assign(3, Vec3(0.0002, -0.0001, 0.0003));
  for (int step = 0; step < 3; ++step) {
    ibd.apply(fd, s);
    ibf.apply(ff, s);
    for (std::size_t p = 0; p < s.size(); ++p) {
      const double f = ibd.force()[p].norm();
      EXPECT_LT((ibf.force()[p] - ibd.force()[p]).norm(), 1e-5 * f) << p << " " << step;
      EXPECT_LT((ibf.torque()[p] - ibd.torque()[p]).norm(), 1e-5 * ibd.torque()[p].norm())
          << p << " " << step;
      EXPECT_LT((ibf.internal_momentum()[p] - ibd.internal_momentum()[p]).norm(),
                1e-5 * ibd.internal_momentum()[p].norm())
          << p << " " << step;
    }
    fd.step();
    ff.step();
  }
}

}  // namespace
}  // namespace flocsim
