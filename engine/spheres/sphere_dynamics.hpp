#pragma once
// Translation and rotation of the spheres under hydrodynamic force and torque
// (from the immersed boundary), net gravity, and the reaction to the body force
// that the lattice applies to the liquid inside each sphere.
//
// The liquid inside a sphere stays on the lattice, so the immersed-boundary
// force H on a sphere contains, besides the force of the outside liquid, the
// force that changes the momentum of the inside liquid and holds it against
// the body force f that the lattice applies to it (f V_p). Newton's law for
// the sphere, m_p du_p/dt = H_outside + F_g, becomes (Kempe & Froehlich 2012)
//
//   m_p du_p/dt = H + dP_in/dt + F_g - f V_p
//   I_p dw/dt   = T + dL_in/dt
//
// with P_in, L_in the momentum and angular momentum of the inside liquid as
// measured by the immersed boundary. Forward Euler in time (as in the paper),
// with the change of P_in over the last step. The quantity that then cannot
// drift is
//
//   lattice momentum + sum (m_p u_p - P_in(previous step))
//
// whose rate of change is f V_box + N (F_g - f V_p) = 0 when f and F_g balance
// (docs/model.md section 1). V_p uses the hydrodynamic radius a, as phi and F_g do.
#include <vector>

#include "engine/spheres/sphere_set.hpp"

namespace flocsim::spheres {

// External forces of a settling suspension (docs/model.md section 1), lattice units,
// gravity along -x.
struct SettlingForces {
  Vec3 liquid_body_force = Vec3::Zero();  // f = (rho_bar - rho) g e_x, on every lattice cell
  Vec3 net_gravity = Vec3::Zero();        // F_g = -(rho_p - rho_bar) V_p g e_x, per sphere
};

// The balancing pair for n spheres of radius a (hydrodynamic) in a box of
// volume `box_volume`, liquid density rho, density ratio rho_p / rho, gravity g.
SettlingForces settling_forces(std::size_t n, double radius, double density_ratio,
                               double box_volume, double gravity, double liquid_density = 1.0);

// The external force on one sphere of volume V_p: its net gravity and the
// buoyancy of the liquid's body force, F_g - f V_p (the weight a settling
// sphere's hydrodynamic force holds up).
inline Vec3 external_force_per_sphere(const SettlingForces& f, double sphere_volume) {
  return f.net_gravity - f.liquid_body_force * sphere_volume;
}

struct SphereDynamicsSettings {
  double liquid_density = 1.0;
  SettlingForces external;
  // Translation with the rigid-body approximation of the inside liquid,
  // (m_p - rho V_p) du_p/dt = H + F_g - f V_p, instead of the measured change
  // of its momentum (ten Cate et al. 2002; a comparison option). The two agree
  // when the inside liquid follows the sphere; they differ after a sudden
  // change of u_p (a collision, a square-well event), which the rigid-body form
  // partly undoes as the lattice brings the inside liquid along. Lubrication
  // and contact events still act on the mass m_p.
  bool rigid_inside_liquid = false;
};

// Immersed-boundary results for one step, one entry per sphere
// (ImmersedBoundary::force(), torque(), internal_momentum_change(),
// internal_angular_momentum_change()).
struct HydrodynamicLoads {
  const std::vector<Vec3>& force;
  const std::vector<Vec3>& torque;
  const std::vector<Vec3>& internal_momentum_change;
  const std::vector<Vec3>& internal_angular_momentum_change;
};

// The mass the immersed-boundary load H translates: m_p with the measured
// inside liquid, m_p - rho V_p with the rigid-body form (which must be > 0).
double translating_mass(const SphereSet& spheres, const SphereDynamicsSettings& settings);

// What is conserved with the liquid, per sphere: d/dt [lattice momentum +
// sum_s sphere_balance_momentum(s)] = f V_box + N (F_g - f V_p) = 0. With the
// measured inside liquid m_p u_p - P_in (P_in its inside momentum); with the
// rigid-body form (m_p - rho V_p) u_p, since the sphere then counts its
// inside liquid as moving with it. Contacts and lubrication, equal and opposite
// between equal spheres, keep either sum.
Vec3 sphere_balance_momentum(const SphereSet& spheres, const SphereDynamicsSettings& settings,
                             std::size_t s, const Vec3& inside_momentum);

// The liquid's load on a sphere over one step, as it moves the sphere, in units
// of m_p du_p (what the coupling monitor compares with the net weight): the
// immersed-boundary force H plus the inside-momentum change dP_in with the
// measured inside liquid; H m_p / (m_p - rho V_p) with the rigid-body form.
Vec3 liquid_load_per_step(const SphereSet& spheres, const SphereDynamicsSettings& settings,
                          const Vec3& force, const Vec3& inside_momentum_change);

// One forward-Euler step of the velocity and angular velocity of every sphere.
void advance_velocities(SphereSet& spheres, const HydrodynamicLoads& loads,
                        const SphereDynamicsSettings& settings, double dt = 1.0);

// Ballistic move of every centre by u_p dt, wrapped into the box. (The
// event-driven contact module replaces this when spheres can touch.)
void advance_positions(SphereSet& spheres, const PeriodicBox& box, double dt = 1.0);

// sum m_p u_p.
Vec3 sphere_momentum(const SphereSet& spheres, double liquid_density = 1.0);

}  // namespace flocsim::spheres
