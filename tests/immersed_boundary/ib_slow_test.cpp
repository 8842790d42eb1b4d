// Long physics checks of the immersed-boundary spheres (label slow): the
// simple-cubic-array drag against Sangani & Acrivos over phi = 0.01 - 0.2 at
// a = 4, 6 and 8 dx with the calibrated input radii, a single sphere settling
// at Re_inf = 12 against Schiller-Naumann, and at Re_inf = 24 and 72 with a wake
// sponge in two box widths.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "engine/calibration/hydrodynamic_radius.hpp"
#include "engine/coupling_schemes/make_coupling.hpp"
#include "engine/immersed_boundary/immersed_boundary.hpp"
#include "engine/lattice/fluid_lattice.hpp"
#include "engine/observables/reference_correlations.hpp"
#include "engine/spheres/sphere_dynamics.hpp"
#include "ib_test_support.hpp"
#include "wake_sponge.hpp"

namespace flocsim {
namespace {

// K / K_SA - 1 at the given phi (box rounded to whole cells; chi from it).
// Direct forcing: the sphere at the cube's centre, as its calibration. The
// other schemes' boundary depends on where the sphere sits on the grid, and
// their calibration is the mean over a node-centred and a mid-cell sphere
// (what a moving sphere has on average): K is that mean here too.
// The viscosity: 1/6 where the scheme is calibrated there, else its calibrated
// viscosity nearest to it (control forcing: 0.02 only).
double array_error(double a, double phi, const coupling::Scheme& scheme = {}) {
  calibration::ArrayDragSettings s;
  s.scheme = scheme;
  s.viscosity = calibration::CalibrationTable::shipped().lookup(a, s.viscosity, scheme).viscosity;
  const double ag = test::calibrated_input_radius(a, s.viscosity, scheme);
  const double chi_wanted = std::cbrt(phi / (M_PI / 6));
  const int L = static_cast<int>(std::lround(2 * a / chi_wanted));
  const bool direct = scheme.immersed_boundary() && !scheme.control();
  double K = 0;
  if (direct) {
    K = calibration::simple_cubic_array_drag(ag, L, s).drag_coefficient(a, s.viscosity);
  } else {
    for (double offset : {0.0, 0.5})
      K += 0.5 *
           calibration::simple_cubic_array_drag(ag, L, s, offset).drag_coefficient(a, s.viscosity);
  }
  const double chi = 2 * a / L;
  const double K_ref = calibration::sangani_acrivos_drag(chi);
  std::printf(
      "%s, a = %g (a_g = %.4f) L = %3d phi = %.4f: K = %.4f  Sangani-Acrivos %.4f  error %+.2f "
      "%%\n",
      scheme.describe().c_str(), a, ag, L, M_PI / 6 * chi * chi * chi, K, K_ref,
      100 * (K / K_ref - 1));
  std::fflush(stdout);
  return K / K_ref - 1;
}

// The accuracy asked of the immersed boundary: within 2 % for phi = 0.01 - 0.2 at a = 6 dx.
TEST(SimpleCubicArraySweep, Resolution6WithinTwoPercent) {
  for (double phi : {0.01, 0.05, 0.1, 0.2})
    EXPECT_LT(std::abs(array_error(6.0, phi)), 0.02) << "phi " << phi;
}

// The densest arrays, phi = 0.27 (3 dx between the spheres' surfaces at
// a = 6, 4 dx at a = 8; at a = 4 the 10 dx cube cannot hold a sphere's kernel
// cells apart from its own image), with the paper's method. (With markers
// 1 dx apart and one sweep the overlap of neighbouring kernels is left
// uncorrected and K falls 3.2-3.8 % short here, docs/accuracy-cost.md, so
// cases refuse that option above phi = 0.2.)
TEST(SimpleCubicArraySweep, DensestArraysPhi027) {
  for (double a : {6.0, 8.0}) EXPECT_LT(std::abs(array_error(a, 0.27)), 0.02) << "a " << a;
}

// The error trend against resolution, reported; a = 4 and 8 dx are held to
// the same 2 % (the calibration is per resolution).
TEST(SimpleCubicArraySweep, Resolutions4And8) {
  for (double phi : {0.01, 0.05, 0.1, 0.2})
    EXPECT_LT(std::abs(array_error(4.0, phi)), 0.02) << "a 4, phi " << phi;
  // a = 8 at phi = 0.01 needs a 60^3 box for ~40 000 steps; 0.05 - 0.2 here.
  for (double phi : {0.05, 0.1, 0.2})
    EXPECT_LT(std::abs(array_error(8.0, phi)), 0.02) << "a 8, phi " << phi;
}

}  // namespace
}  // namespace flocsim

namespace flocsim {
namespace {

using spheres::Vec3;

// One sphere (rho_p/rho = 4) about to settle from rest along x in a periodic
// box L x W x W, gravity set so that Schiller-Naumann gives U_inf (docs/model.md
// section 2), and the Schiller-Naumann velocity U_SN for the sphere's actual
// net weight (rho_p - rho_bar) V g.
struct SettlingSphere {
  SettlingSphere(double a, double nu, double re_inf, double u_inf, int L, int W)
      : box{Vec3(L, W, W)} {
    const double ratio = 4.0;
    s.radius = a;
    s.density_ratio = ratio;
    s.resize(1);
    s.position[0] = Vec3(0.75 * L + 0.3, 0.5 * W + 0.2, 0.5 * W - 0.1);
    const double cd = 24 / re_inf * (1 + 0.15 * std::pow(re_inf, 0.687));
    const double g = 0.375 * cd / (ratio - 1) * u_inf * u_inf / a;
    dyn.external = spheres::settling_forces(1, a, ratio, box.volume(), g);
    const double weight = -dyn.external.net_gravity.x();
    u_sn = u_inf;
    for (int it = 0; it < 100; ++it) {
      const double re = u_sn * 2 * a / nu;
      u_sn = weight / (6 * M_PI * nu * a * (1 + 0.15 * std::pow(re, 0.687)));
    }
    phi = s.volume() / box.volume();
  }
  // The sphere equations after the fluid step.
  template <class Real>
  void move(const coupling::SphereCoupling<Real>& coupling) {
    spheres::advance_velocities(s, coupling.loads(), dyn);
    spheres::advance_positions(s, box);
  }
  // Slip against the mean liquid velocity (zero total momentum).
  double slip() const {
    const double liquid = -phi * s.density_ratio * s.velocity[0].x() / (1 - phi);
    return liquid - s.velocity[0].x();
  }
  spheres::SphereSet s;
  spheres::PeriodicBox box;
  spheres::SphereDynamicsSettings dyn;
  double u_sn = 0, phi = 0;
};

// One sphere (a = 4 dx, rho_p/rho = 4) settling from rest at Re_inf = 12
// (nu = 0.02, U_inf = 0.03) in periodic boxes 2W x W x W. Reference: the
// Schiller-Naumann terminal velocity U_SN for the sphere's net weight
// (rho_p - rho_bar) V g. A periodic box can only slow the sphere, and by at
// most the creeping-flow hindrance of the same array (inertia screens the
// disturbance): U_SN / K_SA(chi_eq) - 2 % <= U_slip <= U_SN + 2 %, with
// chi_eq = 2a / V_box^(1/3) and 2 % the calibration accuracy. The
// deviation from U_SN is printed for both box sizes (the box-size effect).
double settling_velocity_ratio(int W, const coupling::Scheme& scheme = {}) {
  const double a = 4.0, nu = 0.02, re_inf = 12.0;
  const double ag = test::calibrated_input_radius(a, nu, scheme);
  const int L = 2 * W;
  lattice::FluidLattice<float> fluid({L, W, W}, {nu, 0.25});
  const auto coupling = coupling::make_coupling<float>(scheme, ag);
  auto& ib = *coupling;
  SettlingSphere sphere(a, nu, re_inf, re_inf * nu / (2 * a), L, W);
  fluid.set_body_force({sphere.dyn.external.liquid_body_force.x(), 0, 0});
  const double u_sn = sphere.u_sn;
  const spheres::PeriodicBox& box = sphere.box;
  const int steps = 9000;  // ~70 a / U_inf
  double mean = 0;
  int count = 0;
  for (int step = 0; step < steps; ++step) {
    ib.apply(fluid, sphere.s);
    fluid.step();
    ib.after_liquid_step(fluid, sphere.s);
    sphere.move(ib);
    if (step >= steps - 2000) {
      mean += sphere.slip();
      ++count;
    }
  }
  mean /= count;
  const double chi_eq = 2 * a / std::cbrt(box.volume());
  const double K = calibration::sangani_acrivos_drag(chi_eq);
  std::printf(
      "%s, settling a = 4, Re_inf = 12, box %d x %d x %d: slip %.5f, U_SN %.5f, ratio %.4f "
      "(creeping-flow bound 1/K = %.4f), Re = %.2f\n",
      scheme.describe().c_str(), L, W, W, mean, u_sn, mean / u_sn, 1 / K, mean * 2 * a / nu);
  std::fflush(stdout);
  EXPECT_GT(mean / u_sn, 1 / K - 0.02);
  EXPECT_LT(mean / u_sn, 1.02);
  return mean / u_sn;
}

TEST(SettlingSphere, SchillerNaumannAtRe12TwoBoxSizes) {
  const double small = settling_velocity_ratio(48);
  const double large = settling_velocity_ratio(64);
  EXPECT_GT(large, small - 0.005);  // a larger box hinders less
}

// One sphere (a = 6 dx, the paper's resolution, or a = 8; rho_p/rho = 4,
// U_inf = 0.05) settling from rest at Re_inf = 24 or 72 in a periodic box 16a
// long and W wide, with the wake sponge (wake_sponge.hpp) half a box behind it: without
// it the sphere drafts in its own periodic wake and never reaches a terminal
// velocity. Returns the slip U (against the mean liquid velocity) over the
// Schiller-Naumann velocity for the sphere's net weight, extrapolated in time
// (Aitken, from t = t_end - 10, - 5, t_end in a/U_inf, where the increments
// shrink geometrically; else the value at t_end).
double sponge_settling_ratio(double re_inf, double W_over_a, double t_end, double a = 6.0) {
  const double u_inf = 0.05;
  const double nu = 2 * a * u_inf / re_inf;
  const double ag = test::calibrated_input_radius(a, nu);
  const int L = static_cast<int>(16 * a), W = static_cast<int>(W_over_a * a);
  lattice::FluidLattice<float> fluid({L, W, W}, {nu, 0.25});
  immersed_boundary::ImmersedBoundary<float> ib({.input_radius = ag});
  test::WakeSponge<float> sponge(0.1, 8);
  SettlingSphere sphere(a, nu, re_inf, u_inf, L, W);
  fluid.set_body_force({sphere.dyn.external.liquid_body_force.x(), 0, 0});
  const double u_sn = sphere.u_sn;
  const int every = static_cast<int>(std::lround(5 * a / u_inf));  // 5 a / U_inf
  const int steps = static_cast<int>(std::lround(t_end / 5)) * every;
  std::vector<double> series;
  for (int step = 1; step <= steps; ++step) {
    ib.apply(fluid, sphere.s);
    sponge.apply(fluid, sphere.s.position[0].x(), ag + 1.5);
    fluid.step();
    sphere.move(ib);
    if (step % every == 0) series.push_back(sphere.slip() / u_sn);
  }
  const std::size_t n = series.size();
  const double x0 = series[n - 3], x1 = series[n - 2], x2 = series[n - 1];
  // Aitken only where the increments shrink geometrically (0 < ratio < 1);
  // otherwise (noise-level or growing increments) the last value.
  const double ratio_of_increments = (x1 - x0) != 0 ? (x2 - x1) / (x1 - x0) : 0.0;
  const double limit = ratio_of_increments > 0 && ratio_of_increments < 0.9
                           ? x2 + (x2 - x1) * ratio_of_increments / (1 - ratio_of_increments)
                           : x2;
  std::printf(
      "settling with wake sponge, a = %g, Re_inf = %g, box 16a x %ga x %ga: U/U_SN at t = %g, "
      "%g, %g: %.4f %.4f %.4f -> %.4f (Re %.2f)\n",
      a, re_inf, W_over_a, W_over_a, t_end - 10, t_end - 5, t_end, x0, x1, x2, limit,
      limit * u_sn * 2 * a / nu);
  std::fflush(stdout);
  return limit;
}

// The box-size effect with the wake removed: W = 12a and 16a (a 16a long box).
// Reference: Schiller-Naumann. It fits the standard drag curve to about 5 %
// (Clift, Grace & Weber 1978); here the standard curve's own correlation
// (their Table 5.2, as quoted from memory), C_D = 24/Re (1 + 0.1935 Re^0.6305)
// for 20 < Re < 260, lies 4.6 % (Re = 23) to 1.1 % (Re = 70) above it, i.e. an
// isolated sphere's velocity is 1-3 % below U_SN. Asserted: U/U_SN in [0.94, 1.03] in the wider box
// (U_SN's 5 % in drag, about 3.5 % in velocity, widened on the low side by the 3 % the standard
// curve sits below U_SN), and the box effect converged: the wider box within 1 % of the narrower
// one and not slower.
void sponge_settling_check(double re_inf, double t_end) {
  const double narrow = sponge_settling_ratio(re_inf, 12, t_end);
  const double wide = sponge_settling_ratio(re_inf, 16, t_end);
  EXPECT_GT(wide, 0.94);
  EXPECT_LT(wide, 1.03);
  EXPECT_GT(wide, narrow - 0.002);
  EXPECT_LT(wide - narrow, 0.01);
}

TEST(SettlingSphereWithWakeSponge, SchillerNaumannAtRe24) {
  sponge_settling_check(24, 50);
}
TEST(SettlingSphereWithWakeSponge, SchillerNaumannAtRe72) {
  sponge_settling_check(72, 60);
}

// Resolution: the same Re_inf = 72 run (W = 12a) at a = 8 dx. The offset from
// Schiller-Naumann must be a property of the flow, not of the grid: a = 8
// within the same bounds as a = 6 and within 1 % of it (at Re_inf = 24 the two
// differ by 0.2 %). About 30 minutes on one thread.
TEST(SettlingSphereWithWakeSponge, ResolutionAtRe72) {
  const double coarse = sponge_settling_ratio(72, 12, 60, 6.0);
  const double fine = sponge_settling_ratio(72, 12, 60, 8.0);
  EXPECT_GT(fine, 0.94);
  EXPECT_LT(fine, 1.03);
  EXPECT_LT(std::abs(fine - coarse), 0.01);
}

}  // namespace
}  // namespace flocsim

namespace flocsim {
namespace {

using spheres::Vec3;

// Beetstra, van der Hoef & Kuipers (2007), paper eq. 4, in the normalisation
// F = F_h / (6 pi mu a U), F_h = f V_p (1/phi - 1) (engine/observables).
using observables::beetstra_drag;

// A static random array (random sequential addition, no overlap) of spheres
// a = 4 dx (by default) in a (12a)^3 periodic box, nu = 0.02 (U = 0.025 at Re = 10), liquid driven
// by a body force chosen from the correlation for the wanted Re; run to a steady state; F and Re
// measured and F compared with Beetstra at the measured Re. Tolerance 15 %: the correlation's own
// scatter about its data (~10 %, Beetstra et al.) plus the spread between single random
// configurations of ~100 spheres (a few %). Returns F.
double static_random_array(double phi, double re_wanted, double nu = 0.02,
                           const coupling::Scheme& scheme = {}, double a = 4.0) {
  const int L = static_cast<int>(std::lround(12 * a));
  const double ag = test::calibrated_input_radius(a, nu, scheme);
  const spheres::PeriodicBox box{Vec3(L, L, L)};
  const double vp = 4.0 / 3.0 * M_PI * a * a * a;
  const auto n = static_cast<std::size_t>(std::lround(phi * box.volume() / vp));
  const double phi_real = n * vp / box.volume();
  spheres::SphereSet s;
  s.radius = a;
  std::mt19937_64 rng(12345);
  std::uniform_real_distribution<double> u(0.0, L);
  while (s.position.size() < n) {
    const Vec3 x(u(rng), u(rng), u(rng));
    bool ok = true;
    for (const Vec3& y : s.position) ok = ok && box.minimum_image(x - y).norm() >= 2 * a;
    if (ok) s.position.push_back(x);
  }
  s.velocity.assign(n, Vec3::Zero());
  s.angular_velocity.assign(n, Vec3::Zero());
  lattice::FluidLattice<float> fluid({L, L, L}, {nu, 0.25});
  const auto coupling = coupling::make_coupling<float>(scheme, ag);
  const double U_wanted = re_wanted * nu / (2 * a);
  // F_h = f V_p (1/phi - 1) = F 6 pi mu a U.
  const double f =
      beetstra_drag(phi_real, re_wanted) * 6 * M_PI * nu * a * U_wanted / (vp * (1 / phi_real - 1));
  fluid.set_body_force({f, 0, 0});
  double previous = 0, U = 0;
  int step = 0;
  for (; step < 20000; ++step) {
    coupling->apply(fluid, s);
    fluid.step();
    coupling->after_liquid_step(fluid, s);
    if (step % 200 == 199) {
      U = fluid.total_momentum().x / fluid.total_mass();
      if (std::abs(U - previous) < 1e-4 * std::abs(U)) break;
      previous = U;
    }
  }
  const double F = f * vp * (1 / phi_real - 1) / (6 * M_PI * nu * a * U);
  const double re = U * 2 * a / nu;
  const double F_ref = beetstra_drag(phi_real, re);
  std::printf(
      "%s, static random array phi = %.3f (N = %zu, a = %g, %d^3), %d steps: Re = %.2f, F = "
      "%.4f, Beetstra %.3f, deviation %+.1f %%\n",
      scheme.describe().c_str(), phi_real, n, a, L, step, re, F, F_ref, 100 * (F / F_ref - 1));
  std::fflush(stdout);
  EXPECT_NEAR(F / F_ref, 1.0, 0.15);
  return F;
}

TEST(StaticRandomArray, BeetstraPhi020Re10) {
  static_random_array(0.20, 10);
}
TEST(StaticRandomArray, BeetstraPhi012Re10) {
  static_random_array(0.12, 10);
}
TEST(StaticRandomArray, BeetstraPhi032Re10) {
  static_random_array(0.32, 10);
}
TEST(StaticRandomArray, BeetstraPhi020Re1) {
  static_random_array(0.20, 1);
}
TEST(StaticRandomArray, BeetstraPhi020Re40) {
  static_random_array(0.20, 40);
}

// ---- the offered coupling options ---------------------------------------------
// Every scheme the shipped calibration holds (at a = 4 or 6), the paper's
// included, is checked on the same references with the same tolerances at
// the resolutions it is calibrated at, and the drag of each other option on
// a frozen random array is compared with the paper scheme's on the identical
// configuration: that difference is what a user buys by choosing the option
// (docs/accuracy-cost.md).
std::vector<coupling::Scheme> offered_options() {
  std::vector<coupling::Scheme> out;
  for (const auto& e : calibration::CalibrationTable::shipped().entries()) {
    if (std::abs(e.hydrodynamic_radius - 6.0) > 1e-6 &&
        std::abs(e.hydrodynamic_radius - 4.0) > 1e-6)
      continue;
    bool seen = false;
    for (const auto& o : out) seen = seen || o.same_calibration(e.scheme);
    if (!seen) out.push_back(e.scheme);
  }
  return out;
}

class IbOption : public ::testing::TestWithParam<coupling::Scheme> {};

// Sangani & Acrivos over phi = 0.01 - 0.2 at a = 4 and 6, 0.05 - 0.2 at a = 8
// (0.01 would need a 60^3 box): box sizes the calibration did not use,
// within 2 %.
TEST_P(IbOption, SimpleCubicArraysMatchSanganiAcrivos) {
  for (double a : {4.0, 6.0, 8.0})
    for (double phi : {0.01, 0.05, 0.1, 0.2}) {
      if (a == 8.0 && phi == 0.01) continue;
      if (!calibration::CalibrationTable::shipped().has(a, GetParam())) {
        std::printf("%s: not calibrated at a = %g\n", GetParam().describe().c_str(), a);
        break;
      }
      EXPECT_LT(std::abs(array_error(a, phi, GetParam())), 0.02) << "a " << a << ", phi " << phi;
    }
}

// One sphere settling at Re_inf = 12 (a = 4): within the bounds of the paper
// scheme's check (SettlingSphere.SchillerNaumannAtRe12TwoBoxSizes).
TEST_P(IbOption, SettlingSphereMatchesSchillerNaumannAtRe12) {
  settling_velocity_ratio(48, GetParam());
}

// Frozen random arrays, phi = 0.2 at Re ~ 10 (the suspension's regime), a = 4
// and 6: within 15 % of Beetstra as above, and the drag's difference from
// the paper scheme on the same configuration printed for the table.
TEST_P(IbOption, StaticRandomArrayAgainstBeetstraAndThePaperScheme) {
  if (GetParam() == coupling::kPaperScheme)
    GTEST_SKIP() << "the paper scheme's own arrays: StaticRandomArray.*";
  static std::map<double, double> paper_drag;  // a -> F with the paper scheme, once per process
  for (double a : {4.0, 6.0}) {
    if (!calibration::CalibrationTable::shipped().has(a, GetParam())) {
      std::printf("%s: not calibrated at a = %g\n", GetParam().describe().c_str(), a);
      continue;
    }
    if (!paper_drag.count(a))
      paper_drag[a] = static_random_array(0.20, 10, 0.02, coupling::kPaperScheme, a);
    const double paper = paper_drag[a];
    const double option = static_random_array(0.20, 10, 0.02, GetParam(), a);
    std::printf("a = %g: F(%s) / F(paper scheme) - 1 = %+.2f %%\n", a,
                GetParam().describe().c_str(), 100 * (option / paper - 1));
  }
}

std::string option_name(const ::testing::TestParamInfo<coupling::Scheme>& info) {
  if (!info.param.immersed_boundary()) return "partially_saturated";
  std::string n = coupling::kernel_name(info.param.kernel) + "_spacing" +
                  std::to_string(static_cast<int>(std::lround(100 * info.param.marker_spacing)));
  return n + (info.param.control() ? "_control" : "_sweeps" + std::to_string(info.param.sweeps));
}

INSTANTIATE_TEST_SUITE_P(Offered, IbOption, ::testing::ValuesIn(offered_options()), option_name);
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(IbOption);

}  // namespace
}  // namespace flocsim
