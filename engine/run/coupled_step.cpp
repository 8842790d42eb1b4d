#include "engine/run/coupled_step.hpp"

#include <cstdio>

namespace flocsim::run {

int close_neighbours(const spheres::SphereSet& s, const spheres::PeriodicBox& box, std::size_t i,
                     double gap) {
  int k = 0;
  const double reach = 2 * s.radius + gap;
  for (std::size_t j = 0; j < s.size(); ++j)
    if (j != i && box.minimum_image(s.position[j] - s.position[i]).norm() < reach) ++k;
  return k;
}

std::string sphere_health(const spheres::SphereSet& s, const spheres::PeriodicBox& box,
                          double close_gap_over_a) {
  for (std::size_t i = 0; i < s.size(); ++i) {
    const double v = s.velocity[i].norm();
    const bool finite = std::isfinite(v) && std::isfinite(s.angular_velocity[i].norm());
    if (finite && v <= kMaxSphereSpeed) continue;
    // Where it ran away tells the cause apart: alone (the lattice, Mach) or
    // inside an aggregate (the coupling of close spheres, docs/numerics.md).
    const int k = close_neighbours(s, box, i, close_gap_over_a * s.radius);
    char gap_text[16];
    std::snprintf(gap_text, sizeof gap_text, "%g", close_gap_over_a);
    return "sphere " + std::to_string(i) +
           (finite ? " moves at " + std::to_string(v) + " lattice units (limit " +
                         std::to_string(kMaxSphereSpeed) + ")"
                   : std::string(" has a non-finite velocity")) +
           ", with " + std::to_string(k) + " other sphere" + (k == 1 ? "" : "s") + " within " +
           gap_text + " a of its surface";
  }
  return {};
}

}  // namespace flocsim::run
