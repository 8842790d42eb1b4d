#include "engine/spheres/sphere_dynamics.hpp"

#include <stdexcept>
#include <string>

namespace flocsim::spheres {

SettlingForces settling_forces(std::size_t n, double radius, double density_ratio,
                               double box_volume, double gravity, double liquid_density) {
  const double vp = 4.0 / 3.0 * M_PI * radius * radius * radius;
  const double phi = static_cast<double>(n) * vp / box_volume;
  const double rho = liquid_density, rho_p = density_ratio * liquid_density;
  const double rho_bar = phi * rho_p + (1.0 - phi) * rho;
  SettlingForces out;
  out.liquid_body_force = Vec3((rho_bar - rho) * gravity, 0.0, 0.0);
  out.net_gravity = Vec3(-(rho_p - rho_bar) * vp * gravity, 0.0, 0.0);
  return out;
}

namespace {
// m_p = rho_p V_p, with rho_p = density_ratio x the liquid's density (the
// SphereSet's own mass() takes the liquid density as 1).
double sphere_mass(const SphereSet& spheres, double liquid_density) {
  return spheres.density_ratio * liquid_density * spheres.volume();
}
}  // namespace

double translating_mass(const SphereSet& spheres, const SphereDynamicsSettings& settings) {
  const double mass = sphere_mass(spheres, settings.liquid_density);
  if (!settings.rigid_inside_liquid) return mass;
  const double rigid_mass = mass - settings.liquid_density * spheres.volume();
  if (!(rigid_mass > 0.0))
    throw std::invalid_argument(
        "sphere dynamics: density_ratio = " + std::to_string(spheres.density_ratio) +
        ": the rigid-body inside liquid needs > 1");
  return rigid_mass;
}

Vec3 sphere_balance_momentum(const SphereSet& spheres, const SphereDynamicsSettings& settings,
                             std::size_t s, const Vec3& inside_momentum) {
  const double m = translating_mass(spheres, settings);
  if (settings.rigid_inside_liquid) return m * spheres.velocity[s];
  return m * spheres.velocity[s] - inside_momentum;
}

Vec3 liquid_load_per_step(const SphereSet& spheres, const SphereDynamicsSettings& settings,
                          const Vec3& force, const Vec3& inside_momentum_change) {
  if (!settings.rigid_inside_liquid) return force + inside_momentum_change;
  return sphere_mass(spheres, settings.liquid_density) / translating_mass(spheres, settings) *
         force;
}

void advance_velocities(SphereSet& spheres, const HydrodynamicLoads& loads,
                        const SphereDynamicsSettings& settings, double dt) {
  const std::size_t n = spheres.size();
  if (loads.force.size() != n || loads.torque.size() != n ||
      loads.internal_momentum_change.size() != n ||
      loads.internal_angular_momentum_change.size() != n)
    throw std::invalid_argument(
        "sphere dynamics: need one force, torque and inside-momentum change per sphere");
  if (!(spheres.density_ratio > 0.0))
    throw std::invalid_argument("sphere dynamics: density_ratio = " +
                                std::to_string(spheres.density_ratio) + ": must be > 0");
  const double vp = spheres.volume();
  const double a = spheres.radius;
  const double mass = sphere_mass(spheres, settings.liquid_density);
  const double inertia = 0.4 * mass * a * a;
  const Vec3 external = external_force_per_sphere(settings.external, vp);
  const double translating = translating_mass(spheres, settings);
  for (std::size_t s = 0; s < n; ++s) {
    // The change of the inside momentum is already a change over one step.
    if (settings.rigid_inside_liquid)
      spheres.velocity[s] += dt * (loads.force[s] + external) / translating;
    else
      spheres.velocity[s] +=
          (dt * (loads.force[s] + external) + loads.internal_momentum_change[s]) / mass;
    spheres.angular_velocity[s] +=
        (dt * loads.torque[s] + loads.internal_angular_momentum_change[s]) / inertia;
  }
}

void advance_positions(SphereSet& spheres, const PeriodicBox& box, double dt) {
  for (std::size_t s = 0; s < spheres.size(); ++s)
    spheres.position[s] = box.wrap(spheres.position[s] + dt * spheres.velocity[s]);
}

Vec3 sphere_momentum(const SphereSet& spheres, double liquid_density) {
  const double mass = sphere_mass(spheres, liquid_density);
  Vec3 p = Vec3::Zero();
  for (const Vec3& u : spheres.velocity) p += mass * u;
  return p;
}

}  // namespace flocsim::spheres
