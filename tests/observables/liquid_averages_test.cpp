// The liquid averages behind U and the momentum balance, on prescribed
// fields: the solid-cell mask against a brute-force minimum-image count
// (spheres across periodic faces included), the liquid-volume mean velocity
// of a field that is U0 outside the spheres and V inside, and the raw lattice
// momentum with body force and per-cell force field (each cell's half force
// removed), and the correlations against hand-worked values.
#include "engine/observables/liquid_averages.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "engine/lattice/fluid_lattice.hpp"
#include "engine/observables/reference_correlations.hpp"

namespace flocsim::observables {
namespace {

using spheres::PeriodicBox;
using spheres::Vec3;

// Cells (integer coordinates) within r of any centre, by the minimum image.
std::vector<std::uint8_t> brute_force_solid(const lattice::Extent& e,
                                            const std::vector<Vec3>& centres, double r) {
  const PeriodicBox box{Vec3(e.nx, e.ny, e.nz)};
  std::vector<std::uint8_t> solid(static_cast<std::size_t>(e.cells()), 0);
  for (int z = 0; z < e.nz; ++z)
    for (int y = 0; y < e.ny; ++y)
      for (int x = 0; x < e.nx; ++x)
        for (const Vec3& c : centres)
          if (box.minimum_image(Vec3(x, y, z) - c).norm() <= r)
            solid[static_cast<std::size_t>(x + e.nx * (y + e.ny * z))] = 1;
  return solid;
}

const lattice::Extent kExtent{24, 16, 20};
const std::vector<Vec3> kCentres = {{0.3, 9.6, 19.8},   // across three faces
                                    {12.0, 8.0, 10.0},  // on a lattice node
                                    {18.7, 0.2, 6.45}};
constexpr double kRadius = 3.5;

TEST(LiquidAverages, SolidCellsMatchBruteForceAcrossPeriodicFaces) {
  std::vector<std::uint8_t> solid;
  mark_solid_cells(kExtent, kCentres, kRadius, solid);
  const auto expected = brute_force_solid(kExtent, kCentres, kRadius);
  EXPECT_EQ(solid, expected);
  // the node-centred ball of radius 3.5 holds 179 lattice points (count by hand:
  // sum over |z| <= 3 of the points of the disc of radius^2 12.25 - z^2)
  std::vector<std::uint8_t> one;
  mark_solid_cells(kExtent, {kCentres[1]}, kRadius, one);
  long n = 0;
  for (auto s : one) n += s;
  EXPECT_EQ(n, 179);
}

template <class Real>
void prescribed_field(double tolerance) {
  const double U0 = 0.013, V = -0.04, f = 2e-5, g = 3e-4;
  lattice::FluidLattice<Real> fluid(kExtent, {0.1, 0.25});
  fluid.set_body_force({f, 0, 0});
  fluid.enable_force_field();
  const auto solid = brute_force_solid(kExtent, kCentres, kRadius);
  // a per-cell force inside the spheres only, as the immersed boundary puts there
  double field_sum = 0;
  for (long c = 0; c < kExtent.cells(); ++c)
    if (solid[static_cast<std::size_t>(c)]) {
      fluid.force_field().component[0][c] = static_cast<Real>(g);
      field_sum += static_cast<Real>(g);
    }
  long solid_cells = 0;
  for (auto s : solid) solid_cells += s;
  fluid.initialise_equilibrium([&](int x, int y, int z) {
    const bool inside = solid[static_cast<std::size_t>(x + kExtent.nx * (y + kExtent.ny * z))];
    return lattice::Macroscopic{1.0, {inside ? V : U0, 0, 0}};
  });
  spheres::SphereSet s;
  s.radius = kRadius;
  s.resize(kCentres.size());
  s.position = kCentres;
  std::vector<std::uint8_t> scratch;
  const LiquidAverages l = liquid_averages(fluid, s, scratch);
  EXPECT_EQ(l.liquid_cells, kExtent.cells() - solid_cells);
  EXPECT_NEAR(l.mean_velocity_x, U0, tolerance * U0);
  // every cell: U0 outside, V inside, weighted by their counts
  const double all_cells = (U0 * static_cast<double>(kExtent.cells() - solid_cells) +
                            V * static_cast<double>(solid_cells)) /
                           static_cast<double>(kExtent.cells());
  EXPECT_NEAR(l.mean_velocity_x_all_cells, all_cells, tolerance * std::abs(all_cells));
  // raw momentum: sum rho u minus half of every force applied
  const double expected = U0 * static_cast<double>(kExtent.cells() - solid_cells) +
                          V * static_cast<double>(solid_cells) -
                          0.5 * (f * static_cast<double>(kExtent.cells()) + field_sum);
  EXPECT_NEAR(l.lattice_momentum_x, expected, tolerance * std::abs(expected));
  EXPECT_NEAR(l.mass, static_cast<double>(kExtent.cells()), tolerance * kExtent.cells());
}

TEST(LiquidAverages, PrescribedFieldDouble) {
  prescribed_field<double>(1e-12);
}
// float: populations stored as deviations, rounding ~1e-7 of u per cell
TEST(LiquidAverages, PrescribedFieldFloat) {
  prescribed_field<float>(1e-4);
}

// The largest speed (the lattice Mach number's |u|): all three components,
// each with its cell's whole half force (body force and the per-cell field in
// y and z too), over every cell and over the liquid cells only.
template <class Real>
void largest_speed(double tolerance) {
  const double f = 2e-5, g = 3e-4;
  lattice::FluidLattice<Real> fluid(kExtent, {0.1, 0.25});
  fluid.set_body_force({f, 0, 0});
  fluid.enable_force_field();
  const auto solid = brute_force_solid(kExtent, kCentres, kRadius);
  auto is_solid = [&](int x, int y, int z) {
    return solid[static_cast<std::size_t>(x + kExtent.nx * (y + kExtent.ny * z))] != 0;
  };
  for (long c = 0; c < kExtent.cells(); ++c)
    if (solid[static_cast<std::size_t>(c)]) {
      fluid.force_field().component[1][c] = static_cast<Real>(g);
      fluid.force_field().component[2][c] = static_cast<Real>(-g);
    }
  // one fast liquid cell, away from every sphere
  const int fx = 6, fy = 2, fz = 2;
  ASSERT_FALSE(is_solid(fx, fy, fz));
  fluid.initialise_equilibrium([&](int x, int y, int z) {
    if (x == fx && y == fy && z == fz) return lattice::Macroscopic{1.0, {0.0, -0.05, 0.03}};
    if (is_solid(x, y, z)) return lattice::Macroscopic{1.0, {-0.07, 0.01, 0.0}};
    return lattice::Macroscopic{1.0, {0.013, 0.02, -0.01}};
  });
  spheres::SphereSet s;
  s.radius = kRadius;
  s.resize(kCentres.size());
  s.position = kCentres;
  std::vector<std::uint8_t> scratch;
  const LiquidAverages l = liquid_averages(fluid, s, scratch);
  const double inside = std::sqrt(0.07 * 0.07 + 0.01 * 0.01);  // 0.0707
  const double fast = std::sqrt(0.05 * 0.05 + 0.03 * 0.03);    // 0.0583
  EXPECT_NEAR(l.max_speed, inside, tolerance * inside);
  EXPECT_NEAR(l.max_speed_outside_spheres, fast, tolerance * fast);
}

TEST(LiquidAverages, LargestSpeedDouble) {
  largest_speed<double>(1e-12);
}
TEST(LiquidAverages, LargestSpeedFloat) {
  largest_speed<float>(1e-4);
}

TEST(ReferenceCorrelations, HandWorkedValues) {
  // Beetstra at phi = 0.2, Re = 10: Stokes part 10 * 0.2 / 0.64 + 0.64 (1 + 1.5 sqrt 0.2)
  // = 3.125 + 1.069325 = 4.194325; inertial part 0.413 * 10 / (24 * 0.64) * (1.25 + 0.48 +
  // 8.4 * 10^-0.343) / (1 + 10^0.6 * 10^-0.9) = 0.268880 * 5.543095 / 1.501187 = 0.992836
  EXPECT_NEAR(beetstra_drag(0.2, 10), 5.187161, 2e-6);
  // Stokes limit of van der Hoef et al. (2005) at phi = 0.1: 1.234568 + 0.81 * 1.474342
  EXPECT_NEAR(beetstra_drag(0.1, 1e-12), 2.428785, 1e-6);
  // Richardson-Zaki: n(12) = 4.45 * 12^-0.1 = 3.470898; 0.8^n = exp(n ln 0.8)
  EXPECT_NEAR(richardson_zaki_exponent(12), 4.45 * std::pow(12.0, -0.1), 1e-15);
  EXPECT_NEAR(richardson_zaki_exponent(12), 3.47090, 1e-5);
  EXPECT_NEAR(richardson_zaki_velocity_ratio(0.2, 12), 0.460930, 1e-6);
  EXPECT_DOUBLE_EQ(richardson_zaki_exponent(0.1), 4.65);
  // Beetstra's settling velocity: x F(phi, Re_inf x) = (1 - phi)(1 + 0.15 Re_inf^0.687);
  // at phi = 0.2, Re_inf = 12 the right side is 0.8 * 1.826968 = 1.461575, x = 0.322677
  const double x = beetstra_velocity_ratio(0.2, 12);
  EXPECT_NEAR(x, 0.322677, 1e-6);
  EXPECT_NEAR(x * beetstra_drag(0.2, 12 * x), 0.8 * (1 + 0.15 * std::pow(12.0, 0.687)), 1e-12);
  EXPECT_DOUBLE_EQ(richardson_zaki_exponent(600), 2.39);
}

}  // namespace
}  // namespace flocsim::observables
