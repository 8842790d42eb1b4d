#pragma once
// The state of N monodisperse spheres in a fully periodic box, in lattice
// units (dx = dt = 1, liquid density 1). Every module that moves or pushes
// spheres (immersed boundary, sphere dynamics, event-driven contacts,
// lubrication, observables) works on this one structure.
#include <Eigen/Core>
#include <cmath>
#include <cstddef>
#include <vector>

namespace flocsim::spheres {

using Vec3 = Eigen::Vector3d;

// Fully periodic box [0, Lx) x [0, Ly) x [0, Lz).
struct PeriodicBox {
  Vec3 length = Vec3::Ones();

  // The periodic image of a separation vector with each component in
  // [-L/2, L/2).
  Vec3 minimum_image(Vec3 d) const {
    for (int k = 0; k < 3; ++k) d[k] -= length[k] * std::floor(d[k] / length[k] + 0.5);
    return d;
  }
  // A position mapped back into the box.
  Vec3 wrap(Vec3 x) const {
    for (int k = 0; k < 3; ++k) {
      x[k] -= length[k] * std::floor(x[k] / length[k]);
      if (x[k] >= length[k]) x[k] = 0.0;  // -tiny wraps to L in round-off
    }
    return x;
  }
  double volume() const { return length.prod(); }
};

struct SphereSet {
  double radius = 6.0;                 // hydrodynamic radius a: all physics uses this one
  double density_ratio = 4.0;          // rho_p / rho
  std::vector<Vec3> position;          // centres, kept inside the box
  std::vector<Vec3> velocity;          // u_p
  std::vector<Vec3> angular_velocity;  // omega_p

  std::size_t size() const { return position.size(); }
  double volume() const { return 4.0 / 3.0 * M_PI * radius * radius * radius; }
  double mass() const { return density_ratio * volume(); }
  double moment_of_inertia() const { return 0.4 * mass() * radius * radius; }

  void resize(std::size_t n) {
    position.assign(n, Vec3::Zero());
    velocity.assign(n, Vec3::Zero());
    angular_velocity.assign(n, Vec3::Zero());
  }
};

}  // namespace flocsim::spheres
