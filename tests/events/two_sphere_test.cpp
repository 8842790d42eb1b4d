// Two- and three-sphere events against closed-form answers (docs/model.md section 5,
// "Event-driven direct interactions"): head-on and oblique collisions of the
// Yamamoto et al. (2001) model for several e and mu_f, capture into the
// square well, escape at exactly 2 du and bounce just below, plus the
// robustness rules of the event engine (touching and round-off overlapping starts,
// periodic images, the event cap, du = 0 composing no wells, checkpoints).
//
// Tolerances: these are single events in double precision, so answers must
// agree to a few ulps of the speeds involved (1e-12 relative is ~4500 ulps,
// far above round-off and far below any modelling error).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "engine/events/direct_interactions.hpp"
#include "engine/events/hard_sphere_collision.hpp"

namespace flocsim::events {
namespace {

constexpr double kA = 6.0;           // sphere radius (lattice units)
constexpr double kRoundOff = 1e-12;  // relative, see file comment
const PeriodicBox kBox{Vec3(100, 100, 100)};

SphereSet spheres_at(std::vector<Vec3> x, std::vector<Vec3> u) {
  SphereSet s;
  s.radius = kA;
  s.resize(x.size());
  s.position = std::move(x);
  s.velocity = std::move(u);
  return s;
}

void expect_vec_near(const Vec3& got, const Vec3& want, double scale) {
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(got[k], want[k], kRoundOff * scale) << "component " << k;
}

// Head-on: sphere i at speed v hits j at rest after a free flight of `gap`.
// Closed form (e.g. any mechanics text): u_i' = v (1 - e)/2, u_j' = v (1 + e)/2,
// friction does nothing (no slip), and the collision happens at t_c = gap / v,
// so the end positions follow exactly.
TEST(HardSphereCollision, HeadOnMatchesClosedFormForSeveralRestitutions) {
  for (double e : {1.0, 0.9, 0.5, 0.0}) {
    for (double mu : {0.0, 0.3}) {
      const double v = 0.03, gap = 0.012, dt = 1.0;
      auto s = spheres_at({{40, 50, 50}, {40 + 2 * kA + gap, 50, 50}}, {{v, 0, 0}, {0, 0, 0}});
      DirectInteractions contacts({.restitution = e, .friction = mu});
      contacts.advance(s, kBox, dt);
      const double tc = gap / v;
      expect_vec_near(s.velocity[0], {v * (1 - e) / 2, 0, 0}, v);
      expect_vec_near(s.velocity[1], {v * (1 + e) / 2, 0, 0}, v);
      expect_vec_near(s.position[0], {40 + v * tc + v * (1 - e) / 2 * (dt - tc), 50, 50}, 1.0);
      expect_vec_near(s.position[1], {40 + 2 * kA + gap + v * (1 + e) / 2 * (dt - tc), 50, 50},
                      1.0);
      EXPECT_EQ(s.angular_velocity[0].norm(), 0.0);
      EXPECT_EQ(contacts.counters().collisions, 1u);
    }
  }
}

// Oblique impact at the contact normal n = x of i moving at (v_n, v_t, 0) on j
// at rest, no spin. Closed forms of the two-parameter model (Crowe,
// Sommerfeld & Tsuji 2011, eqs. 5.xx for equal solid spheres):
//  sticking (|v_t| <= 7/2 mu (1+e) v_n): u_i = ((1-e)/2 v_n, 6/7 v_t),
//    u_j = ((1+e)/2 v_n, v_t/7), omega_i = omega_j = -5 v_t / (14 a) z;
//  sliding: u_i = ((1-e)/2 v_n, v_t - mu (1+e)/2 v_n), u_j = ((1+e)/2 v_n,
//    mu (1+e)/2 v_n), omega_i = omega_j = -5 mu (1+e) v_n / (4 a) z.
TEST(HardSphereCollision, ObliqueMatchesClosedFormStickingAndSliding) {
  const double vn = 0.02;
  int sticking = 0, sliding = 0;
  for (double e : {1.0, 0.7, 0.3}) {
    for (double mu : {0.0, 0.05, 0.2, 0.5}) {
      for (double angle_deg : {10.0, 30.0, 60.0, 80.0}) {
        const double vt = vn * std::tan(angle_deg * M_PI / 180);
        // Touching at start along x: the collision is at t = 0 with n = x exactly.
        auto s = spheres_at({{40, 50, 50}, {40 + 2 * kA, 50, 50}}, {{vn, vt, 0}, {0, 0, 0}});
        DirectInteractions contacts({.restitution = e, .friction = mu});
        contacts.advance(s, kBox, 1e-3);
        Vec3 ui, uj, wz;
        if (vt <= 3.5 * mu * (1 + e) * vn) {
          ++sticking;
          ui = {(1 - e) / 2 * vn, 6.0 / 7.0 * vt, 0};
          uj = {(1 + e) / 2 * vn, vt / 7.0, 0};
          wz = {0, 0, -5.0 * vt / (14.0 * kA)};
        } else {
          ++sliding;
          ui = {(1 - e) / 2 * vn, vt - mu * (1 + e) / 2 * vn, 0};
          uj = {(1 + e) / 2 * vn, mu * (1 + e) / 2 * vn, 0};
          wz = {0, 0, -5.0 * mu * (1 + e) * vn / (4.0 * kA)};
        }
        SCOPED_TRACE(testing::Message() << "e " << e << " mu " << mu << " angle " << angle_deg);
        expect_vec_near(s.velocity[0], ui, vn + vt);
        expect_vec_near(s.velocity[1], uj, vn + vt);
        expect_vec_near(s.angular_velocity[0], wz, (vn + vt) / kA);
        expect_vec_near(s.angular_velocity[1], wz, (vn + vt) / kA);
      }
    }
  }
  EXPECT_GT(sticking, 5);  // both regimes were exercised
  EXPECT_GT(sliding, 5);
}

// General 3D impacts with spin, checked against the laws that define the
// model rather than its formulas: total momentum conserved; each sphere's
// angular momentum about the contact point conserved (the impulse acts
// there); normal relative velocity -e times its old value; and either the
// contact slip stops (sticking, |P_t| <= mu |P_n|) or the tangential impulse
// is mu |P_n| against the slip direction, which it never reverses (sliding).
TEST(HardSphereCollision, RandomImpactsObeyTheDefiningLaws) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> g(0.0, 0.02);
  std::uniform_real_distribution<double> unif(0.0, 1.0);
  const double m = 1.0, inertia = 0.4 * m * kA * kA;
  for (int trial = 0; trial < 2000; ++trial) {
    const double e = unif(rng), mu = 0.6 * unif(rng);
    Vec3 n(g(rng), g(rng), g(rng));
    n.normalize();
    Vec3 ui(g(rng), g(rng), g(rng)), uj(g(rng), g(rng), g(rng));
    Vec3 wi = Vec3(g(rng), g(rng), g(rng)) / kA, wj = Vec3(g(rng), g(rng), g(rng)) / kA;
    if ((ui - uj).dot(n) <= 0) std::swap(ui, uj);  // make the pair close
    const Vec3 ui0 = ui, uj0 = uj, wi0 = wi, wj0 = wj;
    auto slip_of = [&](const Vec3& a_i, const Vec3& a_j, const Vec3& o_i, const Vec3& o_j) {
      const Vec3 gc = a_i - a_j + kA * (o_i + o_j).cross(n);
      return Vec3(gc - gc.dot(n) * n);
    };
    const Vec3 slip0 = slip_of(ui, uj, wi, wj);
    ASSERT_TRUE((HardSphereCollision{e, mu})(ui, wi, uj, wj, n, kA));
    const double scale = (ui0 - uj0).norm() + kA * (wi0.norm() + wj0.norm());
    const double tol = kRoundOff * scale;
    expect_vec_near(ui + uj, ui0 + uj0, scale);
    // Contact point at x_i + a n; angular momentum of i about it: I w + m (-a n) x u.
    expect_vec_near(inertia * wi - m * kA * n.cross(ui), inertia * wi0 - m * kA * n.cross(ui0),
                    scale * kA);
    expect_vec_near(inertia * wj + m * kA * n.cross(uj), inertia * wj0 + m * kA * n.cross(uj0),
                    scale * kA);
    EXPECT_NEAR((ui - uj).dot(n), -e * (ui0 - uj0).dot(n), tol);
    const Vec3 impulse = m * (ui - ui0);
    const double p_n = std::abs(impulse.dot(n));
    const Vec3 p_t = impulse - impulse.dot(n) * n;
    const Vec3 slip = slip_of(ui, uj, wi, wj);
    if (slip.norm() < 10 * tol) {
      EXPECT_LE(p_t.norm(), mu * p_n * (1 + 1e-12) + tol);
    } else {
      EXPECT_NEAR(p_t.norm(), mu * p_n, tol);
      if (mu > 0) {
        EXPECT_NEAR(p_t.normalized().dot(slip0.normalized()), -1.0, 1e-9);
      }
      EXPECT_GT(slip.dot(slip0), 0.0);
    }
  }
}

// Capture (paper eq. 1: J = sqrt(v_r^2 + 4 du^2) + v_r, J n/2 on i, -J n/2 on j):
// after entry the radial closing speed is sqrt(v_n^2 + 4 du^2), the
// tangential relative velocity and the total momentum are unchanged, and the
// pair is attached. Checked from v_n << du to v_n >> du (where the naive
// formula for J loses digits).
TEST(SquareWell, CaptureRaisesRadialSpeedToSqrtVn2Plus4du2) {
  const double du = 0.02, delta = 0.15, edge = 2 * (kA + delta);
  for (double vn : {1e-6, 0.005, 0.02, 0.1, 200.0}) {
    const double vt = 0.5 * vn, gap = 1e-4;
    const Vec3 x0(40, 50, 50), x1(40 + edge + gap, 50, 50);
    const Vec3 u0(vn / 2, 0, 0.004), u1(-vn / 2, vt, 0.004);
    auto s = spheres_at({x0, x1}, {u0, u1});
    // Entry time and normal from the straight-line flight before it.
    const Vec3 r0 = x1 - x0, v0 = u1 - u0;
    const double b = r0.dot(v0), vv = v0.squaredNorm();
    const double t_entry = (-b - std::sqrt(b * b - vv * (r0.squaredNorm() - edge * edge))) / vv;
    const Vec3 n = (r0 + v0 * t_entry) / edge;
    const double vr0 = v0.dot(n);
    DirectInteractions contacts({.escape_velocity = du, .well_width = delta});
    // The step ends shortly after entry, long before the pair reaches the core.
    contacts.advance(s, kBox, 1.01 * t_entry);
    ASSERT_EQ(contacts.counters().well_entries, 1u) << "vn " << vn;
    EXPECT_EQ(contacts.counters().collisions, 0u);
    EXPECT_EQ(contacts.attached_count(), 1u);
    const Vec3 v1 = s.velocity[1] - s.velocity[0];
    const double want = std::sqrt(vr0 * vr0 + 4 * du * du);
    EXPECT_NEAR(-v1.dot(n), want, 1e-9 * want) << "vn " << vn;  // n from a root: 1e-9
    const Vec3 tangential_change = (v1 - v0) - (v1 - v0).dot(n) * n;
    EXPECT_NEAR(tangential_change.norm(), 0.0, 1e-9 * want);
    expect_vec_near(s.velocity[0] + s.velocity[1], u0 + u1, want);
  }
}

// Escape rule: an attached pair reaching the edge with separation speed
// v_r >= 2 du escapes with sqrt(v_r^2 - 4 du^2); at exactly 2 du it escapes
// with zero radial speed; just below it bounces (v_r -> -v_r) and stays.
// With n = x and u = -/+ v_r/2 every number here is exact in binary.
TEST(SquareWell, EscapeAtExactly2duAndBounceJustBelow) {
  const double du = 0.02, delta = 0.15, edge = 2 * (kA + delta);
  struct Case {
    double vr;
    bool escapes;
    double vr_after;
  };
  const double below = 2 * du * (1 - 1e-12);
  for (const Case c : {Case{2 * du, true, 0.0}, Case{below, false, -below},
                       Case{3 * du, true, std::sqrt(5.0) * du}, Case{0.5 * du, false, -0.5 * du}}) {
    // Start inside the well, 0.01 from the edge: it is reached within the step.
    auto s = spheres_at({{40, 50, 50}, {40 + edge - 0.01, 50, 50}},
                        {{-c.vr / 2, 0, 0}, {c.vr / 2, 0, 0}});
    DirectInteractions contacts({.escape_velocity = du, .well_width = delta});
    contacts.set_attached_pairs({{0, 1}});
    contacts.advance(s, kBox, 0.01 / c.vr + 0.25);
    SCOPED_TRACE(testing::Message() << "v_r / 2du = " << c.vr / (2 * du));
    EXPECT_EQ(contacts.counters().escapes, c.escapes ? 1u : 0u);
    EXPECT_EQ(contacts.counters().edge_bounces, c.escapes ? 0u : 1u);
    EXPECT_EQ(contacts.attached_count(), c.escapes ? 0u : 1u);
    EXPECT_NEAR(s.velocity[1].x() - s.velocity[0].x(), c.vr_after, kRoundOff * c.vr);
    EXPECT_NEAR(s.velocity[1].x() + s.velocity[0].x(), 0.0, kRoundOff * c.vr);
    const double distance = kBox.minimum_image(s.position[1] - s.position[0]).norm();
    if (!c.escapes) {
      EXPECT_LE(distance, edge);
    }
  }
}

// With du = 0 nothing of the well exists (scene composition): pairs crossing
// 2(a + delta) in both directions produce no well events and no attachment.
TEST(SquareWell, NoWellEventsWhenEscapeVelocityIsZero) {
  auto s = spheres_at({{40, 50, 50}, {40 + 2 * kA + 1.0, 50.5, 50}}, {{0.05, 0, 0}, {-0.05, 0, 0}});
  DirectInteractions contacts({.escape_velocity = 0.0});
  for (int step = 0; step < 40; ++step) contacts.advance(s, kBox, 1.0);
  EXPECT_EQ(contacts.counters().collisions, 1u);
  EXPECT_EQ(contacts.counters().well_entries + contacts.counters().escapes +
                contacts.counters().edge_bounces,
            0u);
  EXPECT_EQ(contacts.attached_count(), 0u);
  EXPECT_THROW(contacts.set_attached_pairs({{0, 1}}), std::invalid_argument);
}

// A pair attached when the well is switched on is bound: it cannot leave
// slowly; switching the well off releases it.
TEST(SquareWell, SwitchOnAttachesPairsInsideAndSwitchOffReleases) {
  auto s = spheres_at({{40, 50, 50}, {40 + 2 * kA + 0.1, 50, 50}, {70, 50, 50}},
                      {{-0.001, 0, 0}, {0.001, 0, 0}, {0, 0, 0}});
  DirectInteractions contacts({.escape_velocity = 0.0, .well_width = 0.15});
  contacts.set_escape_velocity(0.02);
  contacts.attach_pairs_within_well(s, kBox);
  EXPECT_EQ(contacts.attached_pairs(), (std::vector<std::pair<int, int>>{{0, 1}}));
  for (int step = 0; step < 200; ++step) contacts.advance(s, kBox, 1.0);
  EXPECT_EQ(contacts.attached_count(), 1u);
  EXPECT_GT(contacts.counters().edge_bounces, 0u);
  contacts.set_escape_velocity(0.0);
  EXPECT_EQ(contacts.attached_count(), 0u);
}

// Starts touching or overlapping by round-off: resolved at t = 0 when closing,
// left alone when separating, no repeated events either way.
TEST(EventEngine, TouchingAndRoundOffOverlapStartsAreHandledOnce) {
  for (double overlap : {0.0, 1e-13}) {
    auto closing =
        spheres_at({{40, 50, 50}, {40 + 2 * kA - overlap, 50, 50}}, {{0.01, 0, 0}, {-0.01, 0, 0}});
    DirectInteractions contacts;
    contacts.advance(closing, kBox, 1.0);
    EXPECT_EQ(contacts.counters().collisions, 1u);
    EXPECT_NEAR(closing.velocity[0].x(), -0.01, 1e-17);
    EXPECT_NEAR(closing.velocity[1].x(), 0.01, 1e-17);

    auto separating =
        spheres_at({{40, 50, 50}, {40 + 2 * kA - overlap, 50, 50}}, {{-0.01, 0, 0}, {0.01, 0, 0}});
    DirectInteractions quiet;
    quiet.advance(separating, kBox, 1.0);
    EXPECT_EQ(quiet.counters().events(), 0u);

    auto resting =
        spheres_at({{40, 50, 50}, {40 + 2 * kA - overlap, 50, 50}}, {{0, 0, 0}, {0, 0, 0}});
    DirectInteractions still;
    for (int step = 0; step < 10; ++step) still.advance(resting, kBox, 1.0);
    EXPECT_EQ(still.counters().events(), 0u);
  }
  auto overlapping =
      spheres_at({{40, 50, 50}, {40 + 2 * kA - 1e-3, 50, 50}}, {{0, 0, 0}, {0, 0, 0}});
  DirectInteractions contacts;
  EXPECT_THROW(contacts.advance(overlapping, kBox, 1.0), std::runtime_error);
}

// Newton's cradle, three touching spheres in a row: an elastic impact on the
// first passes the whole momentum to the last (closed form for equal masses),
// through two collisions at the same instant.
TEST(EventEngine, NewtonsCradleTransfersMomentumThroughTouchingChain) {
  const double v = 0.02, gap = 0.01;
  auto s = spheres_at({{30, 50, 50}, {30 + 2 * kA + gap, 50, 50}, {30 + 4 * kA + gap, 50, 50}},
                      {{v, 0, 0}, {0, 0, 0}, {0, 0, 0}});
  DirectInteractions contacts;
  contacts.advance(s, kBox, 1.0);
  EXPECT_EQ(contacts.counters().collisions, 2u);
  expect_vec_near(s.velocity[0], {0, 0, 0}, v);
  expect_vec_near(s.velocity[1], {0, 0, 0}, v);
  expect_vec_near(s.velocity[2], {v, 0, 0}, v);
}

// A collision across the periodic boundary, same closed form as head-on.
TEST(EventEngine, CollidesThroughPeriodicImages) {
  const double v = 0.02, gap = 0.01;
  auto s =
      spheres_at({{1.0, 50, 50}, {100 - (2 * kA - 1.0) - gap, 50, 50}}, {{-v, 0, 0}, {0, 0, 0}});
  DirectInteractions contacts;
  contacts.advance(s, kBox, 1.0);
  EXPECT_EQ(contacts.counters().collisions, 1u);
  expect_vec_near(s.velocity[0], {0, 0, 0}, v);
  expect_vec_near(s.velocity[1], {-v, 0, 0}, v);
  EXPECT_NEAR(s.position[0].x(), 1.0 - gap, 1e-12);
}

SphereSet random_gas(int n, double box, double speed, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unif(0.0, box);
  std::normal_distribution<double> g(0.0, speed);
  SphereSet s;
  s.radius = kA;
  s.resize(0);
  while (static_cast<int>(s.size()) < n) {
    const Vec3 x(unif(rng), unif(rng), unif(rng));
    bool free = true;
    for (const auto& y : s.position)
      free = free && PeriodicBox{Vec3::Constant(box)}.minimum_image(y - x).norm() > 2 * kA + 0.3;
    if (!free) continue;
    s.position.push_back(x);
    s.velocity.push_back({g(rng), g(rng), g(rng)});
    s.angular_velocity.push_back(Vec3::Zero());
  }
  return s;
}

// The per-step cap stops a step with a diagnosis naming the last events.
TEST(EventEngine, EventCapThrowsWithDiagnosis) {
  auto s = random_gas(200, 100.0, 0.5, 3);
  DirectInteractions contacts({.max_events_per_sphere = 0.01});
  try {
    contacts.advance(s, kBox, 5.0);
    FAIL() << "no EventCapExceeded";
  } catch (const EventCapExceeded& e) {
    EXPECT_NE(std::string(e.what()).find("Last events"), std::string::npos) << e.what();
  }
}

// Checkpoint: stopping after k steps, exporting the attached pairs and
// counters into a fresh engine, and continuing gives bit-identical results
// to the uninterrupted run.
TEST(EventEngine, CheckpointRoundTripContinuesIdentically) {
  auto s = random_gas(150, 100.0, 0.05, 11);
  const DirectInteractionParams params{
      .restitution = 0.9, .friction = 0.2, .escape_velocity = 0.02, .well_width = 0.6};
  DirectInteractions straight(params);
  for (int step = 0; step < 50; ++step) straight.advance(s, kBox, 1.0);
  SphereSet saved = s;
  DirectInteractions resumed(params);
  resumed.set_attached_pairs(straight.attached_pairs());
  resumed.set_counters(straight.counters());
  for (int step = 0; step < 50; ++step) {
    straight.advance(s, kBox, 1.0);
    resumed.advance(saved, kBox, 1.0);
  }
  EXPECT_GT(straight.counters().well_entries, 0u);
  EXPECT_EQ(straight.attached_pairs(), resumed.attached_pairs());
  EXPECT_EQ(straight.counters().events(), resumed.counters().events());
  for (std::size_t i = 0; i < s.size(); ++i) {
    EXPECT_EQ(s.position[i], saved.position[i]);
    EXPECT_EQ(s.velocity[i], saved.velocity[i]);
  }
}

// Inelastic collapse: a dense cluster pulled together every step (as gravity
// or lubrication would) with e = 0.1 or 0 has touching spheres whose
// collisions at one instant never end without the TC model. With it every
// step finishes, under the cap, without overlaps.
TEST(EventEngine, PressedInelasticClusterDoesNotCollapse) {
  for (double e : {0.1, 0.0}) {
    SphereSet s;
    s.radius = kA;
    s.resize(0);
    const double spacing = 2 * kA + 0.05;  // simple cubic block of 5^3 nearly touching spheres
    for (int x = 0; x < 5; ++x)
      for (int y = 0; y < 5; ++y)
        for (int z = 0; z < 5; ++z) {
          s.position.push_back(Vec3(20 + x * spacing, 20 + y * spacing, 20 + z * spacing));
          s.velocity.push_back(0.01 *
                               Vec3(std::sin(x + 2 * y), std::cos(3 * z + y), std::sin(z * x)));
          s.angular_velocity.push_back(Vec3::Zero());
        }
    const Vec3 centre = Vec3::Constant(20 + 2 * spacing);
    DirectInteractions contacts({.restitution = e, .escape_velocity = 4e-4, .well_width = 0.15});
    for (int step = 0; step < 300; ++step) {
      for (std::size_t i = 0; i < s.size(); ++i)
        s.velocity[i] += 1e-4 * kBox.minimum_image(centre - s.position[i]).normalized();
      ASSERT_NO_THROW(contacts.advance(s, kBox, 1.0)) << "e " << e << " step " << step;
    }
    EXPECT_GT(contacts.counters().collisions, 1000u);
    EXPECT_LT(contacts.worst_overlap(), 1e-12 * kA);
  }
}

TEST(EventEngine, RefusesBadParameters) {
  EXPECT_THROW(DirectInteractions({.restitution = 1.5}), std::invalid_argument);
  EXPECT_THROW(DirectInteractions({.friction = -0.1}), std::invalid_argument);
  EXPECT_THROW(DirectInteractions({.escape_velocity = -1}), std::invalid_argument);
  EXPECT_THROW(DirectInteractions({.well_width = 0}), std::invalid_argument);
  EXPECT_THROW(DirectInteractions({.contact_duration = -1}), std::invalid_argument);
}

}  // namespace
}  // namespace flocsim::events
