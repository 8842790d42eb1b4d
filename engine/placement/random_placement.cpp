#include "engine/placement/random_placement.hpp"

#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

namespace flocsim::placement {

std::vector<spheres::Vec3> place_randomly(const PlacementRequest& r,
                                          const spheres::PeriodicBox& box) {
  using spheres::Vec3;
  const double contact = 2.0 * r.radius + r.minimum_gap;
  if (r.count < 0 || r.radius <= 0)
    throw std::invalid_argument("place_randomly: count >= 0 and radius > 0 required");
  for (int k = 0; k < 3; ++k)
    if (box.length[k] < 2.0 * contact)
      throw std::invalid_argument("place_randomly: box length " + std::to_string(box.length[k]) +
                                  " must be at least twice the contact distance " +
                                  std::to_string(contact));
  // cell grid: cells at least one contact distance wide, so overlaps are
  // found among the 27 cells around a trial position
  int cells[3];
  for (int k = 0; k < 3; ++k) cells[k] = std::max(3, static_cast<int>(box.length[k] / contact));
  std::vector<std::vector<int>> grid(static_cast<std::size_t>(cells[0]) * cells[1] * cells[2]);
  auto cell_of = [&](const Vec3& x, int k) {
    return std::min(cells[k] - 1, static_cast<int>(x[k] / box.length[k] * cells[k]));
  };

  std::mt19937_64 rng(r.seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Vec3> placed;
  placed.reserve(static_cast<std::size_t>(r.count));
  const double contact2 = contact * contact;
  long trials = 0;
  while (static_cast<int>(placed.size()) < r.count) {
    long tries_here = 0;
    for (;;) {
      if (++tries_here > r.max_trials_per_sphere) {
        const double phi = r.count * 4.0 / 3.0 * M_PI * std::pow(r.radius, 3) / box.volume();
        throw std::runtime_error("random placement stalled after " + std::to_string(placed.size()) +
                                 " of " + std::to_string(r.count) + " spheres (phi = " +
                                 std::to_string(phi) + ", " + std::to_string(trials) +
                                 " trials): random sequential addition jams near phi = 0.38; lower "
                                 "phi or the minimum gap");
      }
      ++trials;
      const Vec3 x(u(rng) * box.length.x(), u(rng) * box.length.y(), u(rng) * box.length.z());
      const int c[3] = {cell_of(x, 0), cell_of(x, 1), cell_of(x, 2)};
      bool free = true;
      for (int dz = -1; dz <= 1 && free; ++dz)
        for (int dy = -1; dy <= 1 && free; ++dy)
          for (int dx = -1; dx <= 1 && free; ++dx) {
            const int gx = (c[0] + dx + cells[0]) % cells[0],
                      gy = (c[1] + dy + cells[1]) % cells[1],
                      gz = (c[2] + dz + cells[2]) % cells[2];
            for (int j : grid[gx + cells[0] * (gy + static_cast<std::size_t>(cells[1]) * gz)])
              if (box.minimum_image(placed[j] - x).squaredNorm() < contact2) {
                free = false;
                break;
              }
          }
      if (!free) continue;
      grid[c[0] + cells[0] * (c[1] + static_cast<std::size_t>(cells[1]) * c[2])].push_back(
          static_cast<int>(placed.size()));
      placed.push_back(x);
      break;
    }
  }
  return placed;
}

}  // namespace flocsim::placement
