#pragma once
// Random, non-overlapping initial positions (paper end of section 3): random
// sequential addition. Each new centre is drawn uniformly in the box and kept
// if it is at least 2a + gap from every centre placed before (periodic images
// included); a cell grid with cells >= 2a + gap makes each trial O(1). RSA
// jams near phi = 0.384, so phi = 0.32 (the paper's densest case) is reached
// in well under a second for thousands of spheres.
#include <cstdint>
#include <vector>

#include "engine/spheres/sphere_set.hpp"

namespace flocsim::placement {

struct PlacementRequest {
  int count = 0;
  double radius = 1.0;
  double minimum_gap = 0.0;  // extra surface-to-surface distance kept free
  std::uint64_t seed = 1;
  long max_trials_per_sphere = 100000;
};

// Throws std::runtime_error naming count, phi and the trials spent when the
// configuration cannot be completed (too dense for random addition).
std::vector<spheres::Vec3> place_randomly(const PlacementRequest& request,
                                          const spheres::PeriodicBox& box);

}  // namespace flocsim::placement
