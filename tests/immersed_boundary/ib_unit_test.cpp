// Behaviour of the immersed-boundary building blocks: the Roma kernel's
// moment conditions, the marker distribution, the Sangani-Acrivos series
// against its published values, and the exact bookkeeping of spreading.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "engine/calibration/hydrodynamic_radius.hpp"
#include "engine/immersed_boundary/immersed_boundary.hpp"
#include "engine/immersed_boundary/kernel.hpp"
#include "engine/immersed_boundary/sphere_markers.hpp"
#include "engine/spheres/sphere_dynamics.hpp"

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
    for (int d = 0; d < 3; ++d) fluid.force_field(d)[c] = 1e-4 * std::sin(3.0 * c + d);
  for (int step = 0; step < 2; ++step) {
    fluid.step();
    for (int z = 0; z < 6; ++z)
      for (int y = 0; y < 7; ++y)
        for (int x = 0; x < 9; ++x) {
          const auto full = fluid.macroscopic(x, y, z);
          const auto bare = fluid.macroscopic_without_force_field(x, y, z);
          const long c = fluid.cell_index(x, y, z);
          EXPECT_NEAR(bare.density, full.density, 1e-15);
          EXPECT_NEAR(bare.velocity.x,
                      full.velocity.x - 0.5 * fluid.force_field(0)[c] / full.density, 1e-15);
          EXPECT_NEAR(bare.velocity.y,
                      full.velocity.y - 0.5 * fluid.force_field(1)[c] / full.density, 1e-15);
          EXPECT_NEAR(bare.velocity.z,
                      full.velocity.z - 0.5 * fluid.force_field(2)[c] / full.density, 1e-15);
        }
    // The whole-field reader too.
    const std::size_t cells = static_cast<std::size_t>(fluid.extent().cells());
    std::vector<double> fr(cells), fx(cells), fy(cells), fz(cells);
    fluid.macroscopic_field_without_force_field(fr.data(), fx.data(), fy.data(), fz.data());
    for (int z = 0; z < 6; ++z)
      for (int y = 0; y < 7; ++y)
        for (int x = 0; x < 9; ++x) {
          const auto bare = fluid.macroscopic_without_force_field(x, y, z);
          const auto c = static_cast<std::size_t>(fluid.cell_index(x, y, z));
          EXPECT_NEAR(fr[c], bare.density, 1e-15);
          EXPECT_NEAR(fx[c], bare.velocity.x, 1e-15);
          EXPECT_NEAR(fy[c], bare.velocity.y, 1e-15);
          EXPECT_NEAR(fz[c], bare.velocity.z, 1e-15);
        }
    // The row reader gives the same numbers, edge cells included.
    double rho[9], ux[9], uy[9], uz[9];
    fluid.macroscopic_row_without_force_field(0, 9, 6, 5, rho, ux, uy, uz);
    for (int x = 0; x < 9; ++x) {
      const auto bare = fluid.macroscopic_without_force_field(x, 6, 5);
      EXPECT_NEAR(rho[x], bare.density, 1e-15);
      EXPECT_NEAR(ux[x], bare.velocity.x, 1e-15);
      EXPECT_NEAR(uy[x], bare.velocity.y, 1e-15);
      EXPECT_NEAR(uz[x], bare.velocity.z, 1e-15);
    }
  }
  fluid.clear_force_field();
  EXPECT_EQ(fluid.force_field(2)[17], 0.0);
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
  // VALIDATION.md: K at phi = 0.001, 0.01, 0.05, 0.1, 0.2 (4 significant figures).
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

TEST(SettlingForces, BalanceOfSpecSectionOne) {
  // f V (1 - phi) = N (rho_p - rho_bar) V_p g, with the SPEC's definitions.
  const std::size_t n = 37;
  const double a = 6, V = 100.0 * 80 * 80, g = 3e-5, ratio = 4;
  const auto f = spheres::settling_forces(n, a, ratio, V, g);
  const double vp = 4.0 / 3.0 * M_PI * a * a * a, phi = n * vp / V;
  const double rho_bar = phi * ratio + (1 - phi);
  EXPECT_NEAR(f.liquid_body_force.x() * V * (1 - phi), -f.net_gravity.x() * n, 1e-12);
  EXPECT_NEAR(f.net_gravity.x(), -(ratio - rho_bar) * vp * g, 1e-15);
  EXPECT_GT(f.liquid_body_force.x(), 0.0);  // liquid pushed up, spheres pulled down (-x)
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
  immersed_boundary::ImmersedBoundary<double> ib({3.5, 0.7, 2, false});
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
          for (int d = 0; d < 3; ++d) field[d] += fluid.force_field(d)[fluid.cell_index(x, y, z)];
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
    for (long c = 0; c < fluid.extent().cells(); ++c) left += std::abs(fluid.force_field(d)[c]);
  EXPECT_EQ(left, 0.0);
}

}  // namespace
}  // namespace flocsim
