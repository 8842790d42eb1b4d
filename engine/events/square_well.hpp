#pragma once
// The attractive square well of width delta around each sphere pair (docs/model.md
// section 3; Smith et al. 1997 as used by Derksen 2013). Its strength is the
// escape velocity du: the pair depth is m_p du^2 (E_swp = m_p du^2 / 2 per
// sphere). Both rules change only the radial relative velocity
// v_r = (u_j - u_i).n (n unit, i -> j; v_r < 0 closing), through equal and
// opposite impulses J n / 2 on i and -J n / 2 on j, which lower v_r by J.
// The kinetic energy of the radial relative motion is (m/4) v_r^2, so
// changing v_r^2 by 4 du^2 exchanges exactly the pair depth m du^2.
#include <cmath>

#include "engine/spheres/sphere_set.hpp"

namespace flocsim::events {

using spheres::Vec3;

// Entry at |x_j - x_i| = 2 (a + delta) while closing: the radial closing speed
// grows from |v_r| to sqrt(v_r^2 + 4 du^2). The paper's
// J = sqrt(v_r^2 + 4 du^2) + v_r is evaluated as 4 du^2 / (sqrt(..) - v_r),
// which is the same number without the cancellation when |v_r| >> du.
// Returns the impulse per unit mass J (zero when du = 0).
inline double enter_well(Vec3& u_i, Vec3& u_j, const Vec3& n, double du) {
  const double v_r = (u_j - u_i).dot(n);
  const double closing_after = std::sqrt(v_r * v_r + 4.0 * du * du);
  const double denominator = closing_after - v_r;
  const double J = denominator > 0 ? 4.0 * du * du / denominator : 0.0;
  u_i += 0.5 * J * n;
  u_j -= 0.5 * J * n;
  return J;
}

// Arrival at the well edge while separating (v_r > 0). The pair escapes when
// v_r >= 2 du: its separation speed drops to sqrt(v_r^2 - 4 du^2) (the
// kinetic energy pays the pair depth). Below that the radial relative
// velocity reverses and the pair stays attached. Returns true on escape.
inline bool reach_well_edge(Vec3& u_i, Vec3& u_j, const Vec3& n, double du) {
  const double v_r = (u_j - u_i).dot(n);
  const double barrier = 2.0 * du;
  double J;
  bool escaped;
  if (v_r >= barrier) {
    // J = v_r - sqrt(v_r^2 - 4 du^2), written without cancellation.
    const double separating_after = std::sqrt((v_r - barrier) * (v_r + barrier));
    const double denominator = v_r + separating_after;
    J = denominator > 0 ? 4.0 * du * du / denominator : 0.0;
    escaped = true;
  } else {
    J = v_r > 0 ? 2.0 * v_r : 0.0;  // reflect; a pair not separating is left alone
    escaped = false;
  }
  u_i += 0.5 * J * n;
  u_j -= 0.5 * J * n;
  return escaped;
}

}  // namespace flocsim::events
