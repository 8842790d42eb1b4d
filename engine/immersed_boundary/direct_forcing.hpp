#pragma once
// The per-marker and per-cell physics of direct forcing (immersed_boundary.hpp),
// apart from the loops that schedule and vectorise them.
#include <algorithm>
#include <cmath>
#include <type_traits>

#include "engine/spheres/sphere_set.hpp"

namespace flocsim::immersed_boundary {

// Velocity of the sphere surface at r from the centre: U = u_p + omega x r.
inline spheres::Vec3 surface_velocity(const spheres::Vec3& u_p, const spheres::Vec3& omega,
                                      const spheres::Vec3& r) {
  return {u_p[0] + omega[1] * r[2] - omega[2] * r[1], u_p[1] + omega[2] * r[0] - omega[0] * r[2],
          u_p[2] + omega[0] * r[1] - omega[1] * r[0]};
}

// Force density increment at a marker, in a 4-vector (rho, u) -> (0, dF):
// dF = 2 rho (U - u), with u the interpolated velocity the collision would see
// and U the surface velocity in lanes 1-3. The factor 2: with Guo's forcing the
// lattice velocity carries half of a step's force, so a force density F moves
// the velocity the collision sees by F / (2 rho); 2 rho (U - u) brings it to U.
template <class V4>
inline V4 forcing_increment(const V4& rho_u, const V4& target) {
  using Real = std::remove_cvref_t<decltype(rho_u[0])>;
  const V4 vector_part = {0, 1, 1, 1};
  return (Real(2) * rho_u[0]) * (target - rho_u) * vector_part;
}

// Share of a cell (centre at squared distance r2 from the sphere centre) in the
// inside-liquid momentum: w = min(1, a_g + 1/2 - |r|), linear across the
// surface so that the inside momentum changes smoothly as the sphere moves.
// `reach` = a_g + 1/2; cells with r2 <= inner2 = (a_g - 1/2)^2 (1 - 1e-12)
// get 1 without a square root.
inline double inside_weight(double r2, double reach, double inner2) {
  return r2 <= inner2 ? 1.0 : std::min(1.0, reach - std::sqrt(r2));
}

}  // namespace flocsim::immersed_boundary
