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

// Earliest time t >= 0 at which a closing pair (r.v < 0) reaches distance R
// from outside; kNever when it separates or passes by. A closing pair already
// at or inside R (touching, or overlapping by round-off) gives 0: it must be
// resolved now, never be allowed to pass through.
inline double time_to_close_to(const Vec3& r, const Vec3& v, double R) {
  const double b = r.dot(v);
  if (!(b < 0)) return kNever;
  const double c = r.squaredNorm() - R * R;
  if (c <= 0) return 0.0;
  const double disc = v.squaredNorm() * R * R - r.cross(v).squaredNorm();
  if (!(disc > 0)) return kNever;
  return c / (-b + std::sqrt(disc));
}

// Time t >= 0 at which a pair inside distance R reaches it moving outward
// (the far root); kNever when there is no relative motion. A pair found at or
// just beyond R by round-off: if it is separating the crossing is now (0); if
// it is closing it re-enters and leaves again after the chord, at -2b/vv.
inline double time_to_open_to(const Vec3& r, const Vec3& v, double R) {
  const double vv = v.squaredNorm();
  if (!(vv > 0)) return kNever;
  const double b = r.dot(v);
  const double c = r.squaredNorm() - R * R;
  if (c >= 0) return b < 0 ? -2.0 * b / vv : 0.0;
  const double disc = vv * R * R - r.cross(v).squaredNorm();
  const double root = std::sqrt(std::max(disc, b * b));  // disc >= b^2 exactly when c < 0
  return b > 0 ? -c / (b + root) : (-b + root) / vv;
}

}  // namespace flocsim::events
