#pragma once
// Hard-sphere collision of two equal spheres with restitution and Coulomb
// friction: the two-parameter model (e, mu_f) of Yamamoto et al. (2001), in
// the form of Crowe, Sommerfeld & Tsuji (Multiphase flows with droplets and
// particles, ch. 5).
//
// Impulse P acts on sphere i, -P on sphere j, at the contact point a n from
// the centre of i (n unit, from i to j). With G = u_i - u_j (G.n > 0 when
// closing) and the slip of the contact point
//   G_ct = G + a (omega_i + omega_j) x n - (G.n) n,
// the normal impulse is P_n = -(1 + e) (m/2) (G.n) n. A tangential impulse
// P_t changes G_ct by (2/m + 2 a^2/I) P_t = (7/m) P_t for solid spheres
// (I = 2/5 m a^2), so the impulse that stops the slip (sticking) is
// P_t = -(m/7) G_ct. Coulomb's law bounds it by mu_f |P_n|: if
// |G_ct| > (7/2) mu_f (1 + e) (G.n) the contact slides all through the
// collision and P_t = -mu_f |P_n| G_ct / |G_ct|.
#include <Eigen/Geometry>
#include <cmath>

#include "engine/spheres/sphere_set.hpp"

namespace flocsim::events {

using spheres::Vec3;

struct HardSphereCollision {
  double restitution = 1.0;  // e
  double friction = 0.0;     // mu_f

  // Updates the velocities and angular velocities of two equal solid spheres
  // of radius a in contact along n (unit, i -> j). Returns false (and changes
  // nothing) when the pair is not closing.
  bool operator()(Vec3& u_i, Vec3& omega_i, Vec3& u_j, Vec3& omega_j, const Vec3& n,
                  double a) const {
    const Vec3 g = u_i - u_j;
    const double g_n = g.dot(n);
    if (!(g_n > 0)) return false;
    // Impulses per unit mass from here on (p = P / m).
    const double p_n = -(1.0 + restitution) * 0.5 * g_n;
    Vec3 p = p_n * n;
    if (friction > 0) {
      const Vec3 slip = g + a * (omega_i + omega_j).cross(n) - g_n * n;
      const double slip_speed = slip.norm();
      if (slip_speed > 0) {
        if (slip_speed <= 3.5 * friction * (1.0 + restitution) * g_n)
          p -= slip / 7.0;  // sticking: contact slip brought to zero
        else
          p -= friction * std::abs(p_n) * (slip / slip_speed);  // sliding
      }
    }
    u_i += p;
    u_j -= p;
    // Torque a n x P on both spheres (j: (-a n) x (-P)); I = 2/5 m a^2.
    const Vec3 spin = (2.5 / a) * n.cross(p);
    omega_i += spin;
    omega_j += spin;
    return true;
  }
};

}  // namespace flocsim::events
