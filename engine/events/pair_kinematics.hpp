#pragma once
// When does a pair of spheres moving in straight lines reach a given
// centre-to-centre distance R? With r = x_j - x_i and v = u_j - u_i the
// distance obeys |r + v t|^2 = R^2, a quadratic in t with
//   vv t^2 + 2 b t + c = 0,   vv = v.v,  b = r.v,  c = r.r - R^2.
// Both roots are formed without subtracting nearly equal numbers (the
// "stable quadratic" form c / (-b + sqrt(D)) for the near root), and the
// discriminant D = b^2 - vv c is evaluated as vv R^2 - |r x v|^2, which has no
// cancellation between b^2 and vv r.r when the pair is far apart.
#include <Eigen/Geometry>
#include <cmath>
#include <limits>

#include "engine/spheres/sphere_set.hpp"

namespace flocsim::events {

using spheres::Vec3;

inline constexpr double kNever = std::numeric_limits<double>::infinity();

// The radial relative velocity v.n, n = r/|r|, computed exactly as the event
// rules compute it when they act. Whether a pair is closing or separating is
// decided by this number alone, never by the sign of r.v (the two can differ
// in round-off for a grazing pair).
inline double radial_velocity(const Vec3& r, const Vec3& v) {
  return v.dot(r / r.norm());
}

// Radial speeds below this fraction of the spheres' own speeds cannot be
// changed in double precision: an impulse that small leaves both velocities
// bit for bit as they were. A pair predicted to collide "now" at such a speed
// would be predicted again after the collision, forever. Such pairs count as
// neither closing nor separating; the overlap this allows is below
// 1e-13 x speed x dt, i.e. round-off.
inline constexpr double kResolvableSpeedFraction = 1e-13;
inline double radial_speed_floor(const Vec3& u_i, const Vec3& u_j) {
  return kResolvableSpeedFraction * (u_i.norm() + u_j.norm());
}

// Earliest time t >= 0 at which a pair closing faster than `floor` reaches
// distance R from outside; kNever when it does not close or passes by. A
// closing pair already at or inside R (touching, or overlapping by round-off)
// gives 0: it must be resolved now, never be allowed to pass through.
inline double time_to_close_to(const Vec3& r, const Vec3& v, double R, double floor) {
  if (!(radial_velocity(r, v) < -floor)) return kNever;
  const double c = r.squaredNorm() - R * R;
  if (c <= 0) return 0.0;
  const double disc = v.squaredNorm() * R * R - r.cross(v).squaredNorm();
  if (!(disc > 0)) return kNever;
  return c / (std::abs(r.dot(v)) + std::sqrt(disc));
}

// Time t >= 0 at which a pair inside distance R reaches it moving outward
// (the far root); kNever without relative motion. A separating pair found at
// or just beyond R by round-off crosses now (0); a closing one re-enters and
// leaves after the chord, 2|r.v|/v.v. A pair moving exactly tangentially at
// the edge (radial speed below `floor`) has no chord: kNever.
inline double time_to_open_to(const Vec3& r, const Vec3& v, double R, double floor) {
  const double vv = v.squaredNorm();
  if (!(vv > 0)) return kNever;
  const double v_r = radial_velocity(r, v);
  const double b = std::abs(r.dot(v));
  const double c = r.squaredNorm() - R * R;
  if (c >= 0) {
    if (v_r > floor) return 0.0;
    return v_r < -floor ? 2.0 * b / vv : kNever;
  }
  const double disc = vv * R * R - r.cross(v).squaredNorm();
  const double root = std::sqrt(std::max(disc, b * b));  // disc >= b^2 exactly when c < 0
  return v_r > floor ? -c / (b + root) : (b + root) / vv;
}

}  // namespace flocsim::events
