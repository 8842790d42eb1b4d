#pragma once
// A liquid and spheres on which two couplings are held to each other (the
// GPU coupling's serial launcher and the GPU itself against the CPU's
// ImmersedBoundary): a little of everything, so that no term of the method
// can hide behind a zero.
#include <cmath>

#include "engine/coupling/scheme.hpp"
#include "engine/lattice/fluid_lattice.hpp"
#include "engine/spheres/sphere_set.hpp"

namespace flocsim::testing {

// Shear in three directions, a density wave and a body force.
template <class Real>
void stir(lattice::FluidLattice<Real>& fluid) {
  const lattice::Extent e = fluid.extent();
  fluid.set_body_force({2e-5, -1e-5, 3e-6});
  const double k = 2 * M_PI;
  fluid.initialise_equilibrium([&](int x, int y, int z) {
    lattice::Macroscopic m;
    m.density = 1.0 + 0.01 * std::sin(k * (x + 2 * y) / e.nx);
    m.velocity = {0.02 * std::sin(k * y / e.ny), 0.01 * std::cos(k * z / e.nz),
                  0.015 * std::sin(k * x / e.nx)};
    return m;
  });
}

// Three spheres of radius 4 in a box of at least 32 x 30 x 28: two whose
// boxes (and kernels) overlap, one across the periodic wrap in x and z, each
// moving and turning differently.
inline spheres::SphereSet three_spheres() {
  using spheres::Vec3;
  spheres::SphereSet s;
  s.radius = 4.0;
  s.resize(3);
  s.position = {Vec3(12.3, 14.6, 13.1), Vec3(20.9, 15.2, 12.4), Vec3(0.4, 24.7, 27.8)};
  s.velocity = {Vec3(0.01, -0.005, 0.002), Vec3(-0.004, 0.003, 0.006), Vec3(0.0, 0.0, -0.008)};
  s.angular_velocity = {Vec3(0.001, 0.0, -0.002), Vec3(0.0, 0.0015, 0.0),
                        Vec3(-0.001, 0.001, 0.0005)};
  return s;
}

// Direct forcing with `sweeps` sweeps of `kernel`.
inline coupling::Scheme direct(int sweeps, coupling::Kernel kernel) {
  coupling::Scheme s;
  s.sweeps = sweeps;
  s.kernel = kernel;
  return s;
}

// Control forcing with a proportional part too, so that the carried slip matters.
inline coupling::Scheme control() {
  coupling::Scheme s;
  s.forcing = coupling::Forcing::control;
  s.sweeps = 1;
  s.gains = {1.5, 0.5};
  return s;
}

}  // namespace flocsim::testing
