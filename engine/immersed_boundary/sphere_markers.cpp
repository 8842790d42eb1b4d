#include "engine/immersed_boundary/sphere_markers.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace flocsim::immersed_boundary {

std::vector<Eigen::Vector3d> fibonacci_sphere(int n) {
  if (n < 1)
    throw std::invalid_argument("marker count must be at least 1, got " + std::to_string(n));
  const double golden_angle = M_PI * (3.0 - std::sqrt(5.0));
  std::vector<Eigen::Vector3d> points(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / n;
    const double rho = std::sqrt(std::max(0.0, 1.0 - z * z));
    const double phi = golden_angle * i;
    points[static_cast<std::size_t>(i)] = {rho * std::cos(phi), rho * std::sin(phi), z};
  }
  return points;
}

int marker_count(double radius, double spacing) {
  if (!(radius > 0) || !(spacing > 0))
    throw std::invalid_argument("marker_count: radius and spacing must be > 0, got radius = " +
                                std::to_string(radius) + ", spacing = " + std::to_string(spacing));
  return static_cast<int>(std::ceil(4.0 * M_PI * radius * radius / (spacing * spacing)));
}

double marker_volume(double radius, int n) {
  return M_PI * (12.0 * radius * radius + 1.0) / (3.0 * n);
}

}  // namespace flocsim::immersed_boundary
