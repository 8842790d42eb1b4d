// Radial lubrication (Nguyen & Ladd 2002) against docs/model.md section 3 and the
// closed-form motion of two spheres under it.
//
// Closed form: for a head-on pair with radial relative velocity w = ds/dt,
// (m/2) dw/dt = -c(s) w, i.e. dw/ds = -(2/m) c(s): the velocity is a function
// of the gap only,
//   w(s) = w(s_a) + (2/m) [C(s_a) - C(s)],   C(s) = integral of c from s to s0,
//   C(s) = K (ln(s0/s) - (s0 - s)/s0)                               s1 <= s <= s0
//   C(s) = C(s1) + K (1/s1 - 1/s0) (s1 - s)                         s < s1
// with K = (3/2) pi rho nu a^2. A pair released at s0 with speed w0 < 0 stops
// where (2/m) C(s) = -w0, or reaches contact with w0 + (2/m) C(0).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "engine/events/direct_interactions.hpp"
#include "engine/lubrication/radial_lubrication.hpp"
#include "engine/lubrication/two_sphere_resistance.hpp"

namespace flocsim::lubrication {
namespace {

constexpr double kA = 6.0, kNu = 0.01;
const PeriodicBox kBox{Vec3(100, 100, 100)};
const double kK = 1.5 * M_PI * kNu * kA * kA;
const double kS0 = 0.2 * kA, kS1 = 2e-4 * kA;

double integral_from_onset(double s) {
  if (s >= kS1) return kK * (std::log(kS0 / s) - (kS0 - s) / kS0);
  return integral_from_onset(kS1) + kK * (1 / kS1 - 1 / kS0) * (kS1 - s);
}

SphereSet pair_at_gap(double gap, const Vec3& n, const Vec3& u0, const Vec3& u1) {
  SphereSet s;
  s.radius = kA;
  s.density_ratio = 4.0;
  s.resize(2);
  s.position[0] = Vec3(50, 50, 50);
  s.position[1] = s.position[0] + (2 * kA + gap) * n;
  s.velocity = {u0, u1};
  return s;
}

// docs/model.md section 3: F = (3/2) pi rho nu a^2 (1/s - 1/s0)(n . du_ij) for s1 < s <= s0,
// saturated below s1, zero above s0; +F n on i, -F n on j. Sampled over the
// whole range, for an oblique pair; with a small dt the implicit update equals
// the explicit impulse F dt / m to relative order 2 c dt / m (< 1e-6 here).
TEST(RadialLubrication, ForceLawMatchesSpecAtSampledGaps) {
  const RadialLubrication lub({.viscosity = kNu});
  const Vec3 n = Vec3(1, 2, -0.5).normalized();
  for (double gap : {1e-6 * kA, 0.5 * kS1, kS1, 1e-3 * kA, 0.01 * kA, 0.05 * kA, 0.1 * kA,
                     0.999 * kS0, kS0, 1.001 * kS0, 0.3 * kA}) {
    const double s = std::max(gap, kS1);
    const double want_c = gap > kS0 ? 0.0 : kK * (1 / s - 1 / kS0);
    EXPECT_NEAR(lub.coefficient(gap, kA), want_c, 1e-13 * (want_c + 1)) << "gap " << gap;

    const Vec3 u0(0.01, -0.02, 0.005), u1(-0.015, 0.01, 0.02);
    auto pair = pair_at_gap(gap, n, u0, u1);
    const double dt = 1e-6, m = pair.mass();
    const int interacting = lub.apply(pair, kBox, dt);
    EXPECT_EQ(interacting, gap > kS0 ? 0 : 1);
    const double force = want_c * n.dot(u1 - u0);
    const Vec3 want_du0 = force * n * dt / m;
    const Vec3 got_du0 = pair.velocity[0] - u0;
    // Plus the round-off of forming a velocity change from velocities ~0.03.
    EXPECT_NEAR((got_du0 - want_du0).norm(), 0.0, 1e-6 * want_du0.norm() + 1e-16 * 0.03);
    EXPECT_NEAR((pair.velocity[0] + pair.velocity[1] - u0 - u1).norm(), 0.0,
                1e-17);  // equal, opposite
  }
}

// The implicit pairwise update never reverses the radial velocity, however
// large c dt / m, and leaves tangential motion alone.
TEST(RadialLubrication, NeverReversesTheApproach) {
  const RadialLubrication lub({.viscosity = 0.02});
  const Vec3 n = Vec3(0.3, -1, 0.2).normalized();
  for (double dt : {1.0, 100.0, 1e8}) {
    auto pair = pair_at_gap(0.1 * kS1, n, Vec3(0.03, 0.01, 0), Vec3(-0.02, 0, 0.01));
    const Vec3 du0 = pair.velocity[1] - pair.velocity[0];
    lub.apply(pair, kBox, dt);
    const Vec3 du1 = pair.velocity[1] - pair.velocity[0];
    EXPECT_LT(du1.dot(n), 0.0) << "dt " << dt;
    EXPECT_LT(std::abs(du1.dot(n)), std::abs(du0.dot(n)));
    EXPECT_NEAR((du1 - du1.dot(n) * n - (du0 - du0.dot(n) * n)).norm(), 0.0, 1e-17);
  }
}

struct Approach {
  double final_gap, min_gap, impact_speed;
  bool reversed_by_lubrication;
};

// Head-on approach from the onset gap, lubrication then the event engine
// moving the spheres each step (the order of the time loop).
Approach approach(double w0, double dt, int steps) {
  auto pair = pair_at_gap(kS0, Vec3::UnitX(), Vec3(-w0 / 2, 0, 0), Vec3(w0 / 2, 0, 0));
  const RadialLubrication lub({.viscosity = kNu});
  events::DirectInteractions contacts;
  Approach out{0, INFINITY, 0, false};
  for (int step = 0; step < steps; ++step) {
    const double before = pair.velocity[1].x() - pair.velocity[0].x();
    lub.apply(pair, kBox, dt);
    const double after = pair.velocity[1].x() - pair.velocity[0].x();
    out.reversed_by_lubrication |= (before < 0 && after > 0);
    const auto collisions = contacts.counters().collisions;
    contacts.advance(pair, kBox, dt);
    if (contacts.counters().collisions > collisions && out.impact_speed == 0)
      out.impact_speed = -after;
    const double gap = kBox.minimum_image(pair.position[1] - pair.position[0]).norm() - 2 * kA;
    out.min_gap = std::min(out.min_gap, gap);
    out.final_gap = gap;
    if (out.impact_speed != 0) break;
  }
  return out;
}

// A pair released at s0 that the lubrication stops before contact comes to
// rest at the closed-form gap. The time loop splits lubrication and motion,
// an error of first order in dt / tau, tau = m / (2 c(s_stop)) ~ 67 steps
// here: 3 % at dt = 1, and it must shrink ~4x at dt = 1/4.
TEST(RadialLubrication, HeadOnApproachStopsAtClosedFormGap) {
  const double s_stop = 0.01 * kA;
  SphereSet probe = pair_at_gap(0, Vec3::UnitX(), Vec3::Zero(), Vec3::Zero());
  const double w0 = -(2 / probe.mass()) * integral_from_onset(s_stop);
  const Approach coarse = approach(w0, 1.0, 4000);
  const Approach fine = approach(w0, 0.25, 16000);
  const double err_coarse = std::abs(coarse.final_gap / s_stop - 1);
  const double err_fine = std::abs(fine.final_gap / s_stop - 1);
  std::printf(
      "lubrication stop gap: closed form %.6f, dt = 1: %.6f (%.2f %%), dt = 1/4: %.6f (%.2f %%)\n",
      s_stop, coarse.final_gap, 100 * err_coarse, fine.final_gap, 100 * err_fine);
  EXPECT_LT(err_coarse, 0.03);
  EXPECT_LT(err_fine, 0.4 * err_coarse);
  EXPECT_FALSE(coarse.reversed_by_lubrication);
  EXPECT_EQ(coarse.impact_speed, 0.0);
}

// Fast enough to reach contact through the saturated film: the spheres slow
// down, never overlap (the event engine resolves the contact), lubrication
// never reverses the approach, and with a step that resolves the film the
// impact speed is the closed-form w0 + (2/m) C(0) (first order in dt; 2 % at
// dt = 0.01, where the pair still takes ~30 steps to cross s1).
TEST(RadialLubrication, SaturatedApproachSlowsWithoutOverlap) {
  SphereSet probe = pair_at_gap(0, Vec3::UnitX(), Vec3::Zero(), Vec3::Zero());
  const double m = probe.mass();
  for (double w0 : {-0.01, -0.05}) {
    const Approach lattice_step = approach(w0, 1.0, 100000);
    EXPECT_GT(lattice_step.impact_speed, 0.0);
    EXPECT_LT(lattice_step.impact_speed, std::abs(w0));
    EXPECT_GE(lattice_step.min_gap, -1e-12 * kA);
    EXPECT_FALSE(lattice_step.reversed_by_lubrication);
  }
  const double w0 = -0.01;
  const double want = -(w0 + (2 / m) * integral_from_onset(0.0));
  const Approach resolved = approach(w0, 0.01, 200000);
  std::printf("lubrication impact speed: closed form %.6e, dt = 0.01: %.6e\n", want,
              resolved.impact_speed);
  EXPECT_NEAR(resolved.impact_speed / want, 1.0, 0.02);
  EXPECT_GE(resolved.min_gap, -1e-12 * kA);
}

// What a bond of the square well holds (the mechanism behind "excess close-pair
// resistance works like a deeper well", docs/contacts.md). Pull the two spheres of
// an attached pair apart with a constant force f each. Their radial relative
// velocity obeys (m/2) dw/dt = f - c(s) w, so where the film relaxes fast against
// the crossing of the well (tau = m / (2 c) = 430 steps here, the crossing
// ~4000) the pair creeps at w = f / c(s) and meets the edge s = 2 delta at about
// f / c(2 delta). It escapes only when that reaches 2 du: a bond holds up to
// f* = 2 du c(2 delta), proportional to the close-pair resistance, not to the
// well's depth alone. Below f* it stays attached, bouncing at the edge; the
// threshold is sharp to 7 %.
TEST(RadialLubrication, AWellBondHoldsUpToTwiceDuTimesTheEdgeResistance) {
  const double du = 2e-5, delta = 0.025 * kA, edge_gap = 2 * delta;
  const RadialLubrication lub({.viscosity = kNu});
  const double f_star = 2 * du * lub.coefficient(edge_gap, kA);
  for (const double ratio : {0.8, 0.93, 1.07, 1.25}) {
    auto pair = pair_at_gap(delta, Vec3::UnitX(), Vec3::Zero(), Vec3::Zero());
    const double m = pair.mass(), dt = 1.0;
    events::DirectInteractions contacts({.escape_velocity = du, .well_width = delta});
    contacts.set_attached_pairs({{0, 1}});
    double max_gap = 0;
    for (int step = 0; step < 20000 && contacts.attached_count() == 1; ++step) {
      pair.velocity[0].x() -= ratio * f_star * dt / m;
      pair.velocity[1].x() += ratio * f_star * dt / m;
      lub.apply(pair, kBox, dt);
      contacts.advance(pair, kBox, dt);
      if (contacts.attached_count() == 1)
        max_gap = std::max(max_gap, (pair.position[1] - pair.position[0]).norm() - 2 * kA);
    }
    SCOPED_TRACE(testing::Message() << "f / f* = " << ratio);
    if (ratio < 1) {
      EXPECT_EQ(contacts.counters().escapes, 0u);
      EXPECT_EQ(contacts.attached_count(), 1u);
      EXPECT_GT(contacts.counters().edge_bounces, 10u);  // pressed against the edge
      EXPECT_LE(max_gap, edge_gap * (1 + 1e-12));
    } else {
      EXPECT_EQ(contacts.counters().escapes, 1u);
      EXPECT_EQ(contacts.counters().edge_bounces, 0u);  // out at the first arrival
    }
  }
}

TEST(RadialLubrication, RefusesBadParameters) {
  EXPECT_THROW(RadialLubrication({.viscosity = 0}), std::invalid_argument);
  EXPECT_THROW(RadialLubrication({.onset_gap = 0.1, .saturation_gap = 0.2}), std::invalid_argument);
}

}  // namespace
}  // namespace flocsim::lubrication

namespace flocsim::lubrication {
namespace {

TEST(BrennerPairResistance, FarFieldNearFieldAndAMeasuredValue) {
  // Far apart, reflections: each sphere moves against the Stokeslet of the
  // other, lambda = 1 + (3/4)(a/h) + (9/16)(a/h)^2 + O((a/h)^3), h = a + s/2
  // the distance to the midplane. At h = 50a: 1.015225 (by hand).
  EXPECT_NEAR(brenner_pair_resistance(98.0), 1.0 + 0.75 / 50 + 0.5625 / 2500, 1e-5);
  // Close, lubrication theory (Cox & Brenner 1967): lambda = a/(2s) + (9/20)
  // ln(a/s) + C + O(s ln s): the remainder settles to a constant.
  auto remainder = [](double e) {
    return brenner_pair_resistance(e) - 0.5 / e - 0.45 * std::log(1 / e);
  };
  EXPECT_NEAR(remainder(1e-3), remainder(1e-4), 5e-3);
  // the squeeze film dominates: at s = 1e-4 a the log and constant terms add
  // 2e-4 (0.45 ln 1e4 + ~1.35) = 0.0011 to the leading term's 1
  EXPECT_NEAR(brenner_pair_resistance(1e-4) * 2e-4, 1.0011, 1e-4);
  // the exact value at s = 0.05a (the square well's edge): 12.7
  EXPECT_NEAR(brenner_pair_resistance(0.05), 12.7, 0.05);
  // monotone: closer is stiffer
  double last = 1.0;
  for (double e : {10.0, 1.0, 0.3, 0.1, 0.03, 0.01}) {
    const double l = brenner_pair_resistance(e);
    EXPECT_GT(l, last) << e;
    last = l;
  }
}

}  // namespace
}  // namespace flocsim::lubrication

namespace flocsim::lubrication {
namespace {

// The lattice's own share measured at a = 4, nu = 1/6, box 16a x 8a x 8a
// (docs/contacts.md table), the box offset 0.17 of that table subtracted.
LubricationParams calibrated_a4() {
  return {.viscosity = 1.0 / 6.0,
          .lattice_share = {{0.01, 7.19}, {0.02, 7.02}, {0.05, 6.51}, {0.1, 5.71}, {0.2, 4.45}}};
}

// The calibrated coefficient is the exact resistance minus the lattice's
// share: at s = 0.05a, 3 pi rho nu a (12.71 - 6.51) per unit relative radial
// velocity, with 12.71 Brenner's value there (docs/contacts.md table).
TEST(RadialLubrication, CalibratedCoefficientIsExactMinusLatticeShare) {
  const RadialLubrication lub(calibrated_a4());
  const double a = 4.0, unit = 3 * M_PI * (1.0 / 6.0) * a;
  EXPECT_NEAR(lub.coefficient(0.05 * a, a) / unit, 12.71 - 6.51, 0.01);
  // between points the share is linear: at 0.03a, 7.02 - (1/3)(0.51) = 6.85
  // (the exact part is tabulated: good to 1e-9 of it, test below)
  EXPECT_NEAR(lub.coefficient(0.03 * a, a) / unit + 6.85, brenner_pair_resistance(0.03),
              1e-9 * brenner_pair_resistance(0.03));
  // below s1 saturated, above s0 zero
  EXPECT_EQ(lub.coefficient(1e-5 * a, a), lub.coefficient(2e-4 * a, a));
  EXPECT_EQ(lub.coefficient(0.21 * a, a), 0.0);
  // closer is stiffer
  EXPECT_GT(lub.coefficient(0.01 * a, a), lub.coefficient(0.02 * a, a));
}

// The exact resistance is tabulated once per model (the series costs up to
// ~1400 terms a pair near s1): across the whole range s1 <= s <= s0, at gaps
// between the grid points and on them, it matches the series to 1e-9.
TEST(RadialLubrication, TabulatedExactResistanceMatchesTheSeries) {
  const RadialLubrication lub(calibrated_a4());
  const double a = 4.0, unit = 3 * M_PI * (1.0 / 6.0) * a;
  double worst = 0;
  for (int k = 0; k <= 3000; ++k) {
    const double e = 2e-4 * std::pow(0.2 / 2e-4, k / 3000.0);
    const auto& t = calibrated_a4().lattice_share;
    double share = t.front().second;  // as the model interpolates it
    if (e >= t.back().first) {
      share = t.back().second;
    } else if (e > t.front().first) {
      std::size_t j = 1;
      while (t[j].first < e) ++j;
      share = t[j - 1].second + (e - t[j - 1].first) / (t[j].first - t[j - 1].first) *
                                    (t[j].second - t[j - 1].second);
    }
    const double exact = brenner_pair_resistance(e);
    worst = std::max(worst, std::abs(lub.coefficient(e * a, a) / unit + share - exact) / exact);
  }
  EXPECT_LT(worst, 1e-9);
  std::printf("largest relative error of the tabulated exact resistance: %.2e\n", worst);
}

// Brenner's definition, worked by hand: two spheres each moving at U towards
// the other feel F = 6 pi mu a U lambda each; the correction must add
// 6 pi mu a U (lambda_exact - lambda_IB), i.e. an impulse F dt on each sphere
// in a short step (implicit update, relative order 2 c dt / m < 1e-6 here).
TEST(RadialLubrication, CalibratedForceOnEachSphereIsBrennersPerSphereSpeed) {
  const RadialLubrication lub(calibrated_a4());
  const double nu = 1.0 / 6.0, U = 1e-3, dt = 1e-4;
  const Vec3 n = Vec3(1, 2, -2).normalized();
  auto pair = pair_at_gap(0.05 * kA, n, U * n, -U * n);
  const double mass = pair.mass();
  lub.apply(pair, kBox, dt);
  const double force_on_0 = -(pair.velocity[0] - U * n).dot(n) * mass / dt;
  const double expected = 6 * M_PI * nu * kA * U * (brenner_pair_resistance(0.05) - 6.51);
  EXPECT_NEAR(force_on_0 / expected, 1.0, 1e-5);
}

TEST(RadialLubrication, CalibratedNeverReversesTheApproach) {
  const RadialLubrication lub(calibrated_a4());
  const Vec3 n = Vec3(0.3, -1, 0.2).normalized();
  for (double dt : {1.0, 100.0, 1e8}) {
    auto pair = pair_at_gap(0.1 * kS1, n, Vec3(0.03, 0.01, 0), Vec3(-0.02, 0, 0.01));
    const Vec3 du0 = pair.velocity[1] - pair.velocity[0];
    lub.apply(pair, kBox, dt);
    const Vec3 du1 = pair.velocity[1] - pair.velocity[0];
    EXPECT_LT(du1.dot(n), 0.0) << "dt " << dt;
    EXPECT_LT(std::abs(du1.dot(n)), std::abs(du0.dot(n)));
  }
}

// The paper's forward Euler, worked by hand: w' = w (1 - 2 c dt / m). With
// 2 c dt / m = 1.5 at s1 an approach turns into a separation at half the speed,
// which the default implicit update, w' = w / 2.5, never does.
TEST(RadialLubrication, ExplicitPaperSchemeReversesWhereImplicitDoesNot) {
  LubricationParams p{.viscosity = kNu};
  const RadialLubrication implicit_lub(p);
  p.explicit_euler = true;
  const RadialLubrication explicit_lub(p);
  const Vec3 n = Vec3(0, 0, 1);
  auto pair = pair_at_gap(kS1, n, Vec3(0, 0, 0.01), Vec3(0, 0, -0.01));
  const double dt = 1.5 * pair.mass() / (2 * implicit_lub.coefficient(kS1, kA));
  auto explicit_pair = pair;
  implicit_lub.apply(pair, kBox, dt);
  explicit_lub.apply(explicit_pair, kBox, dt);
  EXPECT_NEAR((pair.velocity[1] - pair.velocity[0]).dot(n), -0.02 / 2.5, 1e-15);
  EXPECT_NEAR((explicit_pair.velocity[1] - explicit_pair.velocity[0]).dot(n), +0.01, 1e-15);
}

// Where the lattice alone resists more than the exact value the correction is
// negative, c = 3 pi rho nu a (lambda_exact - lambda_IB) < 0, and takes the
// excess off; the approach is still never reversed, at any dt.
TEST(RadialLubrication, CalibratedTakesOffWhatTheLatticeOvercounts) {
  // lambda_IB 6.41 at 0.15a, above Brenner's 5.58 (a = 4, nu = 0.02, measured)
  const RadialLubrication lub({.viscosity = 0.02, .lattice_share = {{0.1, 8.13}, {0.15, 6.41}}});
  const double a = 4.0;
  EXPECT_NEAR(lub.coefficient(0.15 * a, a) / (3 * M_PI * 0.02 * a),
              brenner_pair_resistance(0.15) - 6.41, 1e-9 * brenner_pair_resistance(0.15));
  EXPECT_LT(lub.coefficient(0.15 * a, a), 0.0);
  const Vec3 n = Vec3(0.3, -1, 0.2).normalized();
  for (double dt : {1.0, 1e4, 1e8}) {
    auto pair = pair_at_gap(0.15 * kA, n, Vec3(0.03, 0.01, 0), Vec3(-0.02, 0, 0.01));
    const double w0 = (pair.velocity[1] - pair.velocity[0]).dot(n);
    lub.apply(pair, kBox, dt);
    const double w1 = (pair.velocity[1] - pair.velocity[0]).dot(n);
    EXPECT_LT(w1, 0.0) << "dt " << dt;
    EXPECT_GT(std::abs(w1), std::abs(w0)) << "dt " << dt;
  }
}

TEST(RadialLubrication, RefusesAnUnorderedLatticeShare) {
  EXPECT_THROW(RadialLubrication({.lattice_share = {{0.1, 5.0}, {0.05, 6.0}}}),
               std::invalid_argument);
  EXPECT_THROW(RadialLubrication({.lattice_share = {{0.1, -1.0}}}), std::invalid_argument);
}

}  // namespace
}  // namespace flocsim::lubrication
