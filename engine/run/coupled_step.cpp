#include "engine/run/coupled_step.hpp"

namespace flocsim::run {

std::string sphere_health(const spheres::SphereSet& s) {
  for (std::size_t i = 0; i < s.size(); ++i) {
    const double v = s.velocity[i].norm();
    if (!std::isfinite(v) || !std::isfinite(s.angular_velocity[i].norm()))
      return "sphere " + std::to_string(i) + " has a non-finite velocity";
    if (v > kMaxSphereSpeed)
      return "sphere " + std::to_string(i) + " moves at " + std::to_string(v) +
             " lattice units (limit " + std::to_string(kMaxSphereSpeed) + ")";
  }
  return {};
}

}  // namespace flocsim::run
