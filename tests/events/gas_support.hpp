#pragma once
// A dense gas of spheres (no fluid) for the many-event tests: face-centred
// cubic start at a chosen solids fraction, Maxwellian velocities with zero
// total momentum, and the energy/momentum sums the tests check.
#include <cmath>
#include <random>

#include "engine/spheres/sphere_set.hpp"

namespace flocsim::events::testing_gas {

using spheres::PeriodicBox;
using spheres::SphereSet;
using spheres::Vec3;

struct Gas {
  SphereSet spheres;
  PeriodicBox box;
};

// 4 cells^3 spheres of radius a on an fcc lattice filling solids fraction phi,
// velocities Maxwellian with k T / m = 1 per component, total momentum zero.
inline Gas fcc_gas(int cells, double a, double phi, std::uint64_t seed) {
  Gas g;
  const int n = 4 * cells * cells * cells;
  const double volume = n * (4.0 / 3.0) * M_PI * a * a * a / phi;
  const double side = std::cbrt(volume), cell = side / cells;
  g.box.length = Vec3::Constant(side);
  g.spheres.radius = a;
  g.spheres.density_ratio = 1.0;
  g.spheres.resize(0);
  const Vec3 basis[4] = {
      {0.25, 0.25, 0.25}, {0.75, 0.75, 0.25}, {0.75, 0.25, 0.75}, {0.25, 0.75, 0.75}};
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> maxwell(0.0, 1.0);
  Vec3 total = Vec3::Zero();
  for (int x = 0; x < cells; ++x)
    for (int y = 0; y < cells; ++y)
      for (int z = 0; z < cells; ++z)
        for (const auto& b : basis) {
          g.spheres.position.push_back((Vec3(x, y, z) + b) * cell);
          g.spheres.velocity.emplace_back(maxwell(rng), maxwell(rng), maxwell(rng));
          g.spheres.angular_velocity.push_back(Vec3::Zero());
          total += g.spheres.velocity.back();
        }
  for (auto& u : g.spheres.velocity) u -= total / n;
  return g;
}

inline double kinetic_energy(const SphereSet& s) {
  double e = 0;
  for (std::size_t i = 0; i < s.size(); ++i)
    e += 0.5 * s.mass() * s.velocity[i].squaredNorm() +
         0.5 * s.moment_of_inertia() * s.angular_velocity[i].squaredNorm();
  return e;
}

inline Vec3 momentum(const SphereSet& s) {
  Vec3 p = Vec3::Zero();
  for (const auto& u : s.velocity) p += s.mass() * u;
  return p;
}

// Smallest centre distance over all pairs (all-pairs loop: the definition).
inline double closest_pair(const SphereSet& s, const PeriodicBox& box) {
  double d = INFINITY;
  for (std::size_t i = 0; i < s.size(); ++i)
    for (std::size_t j = i + 1; j < s.size(); ++j)
      d = std::min(d, box.minimum_image(s.position[j] - s.position[i]).norm());
  return d;
}

}  // namespace flocsim::events::testing_gas
