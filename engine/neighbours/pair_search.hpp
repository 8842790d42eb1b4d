#pragma once
// Finding all pairs of sphere centres closer than a cutoff in a fully periodic
// box, with a cell list so the cost grows with N (not N^2). Used by the event
// engine (pairs that may interact within one time step) and by lubrication
// (pairs within the lubrication onset gap).
#include <vector>

#include "engine/spheres/sphere_set.hpp"

namespace flocsim::neighbours {

using spheres::PeriodicBox;
using spheres::Vec3;

// A pair i < j whose minimum-image separation is x_j - x_i + shift. The shift
// (a whole number of box lengths per component) is fixed when the pair is
// found, so the separation of the pair stays continuous while the spheres
// move during a time step, even when one of them leaves the box.
struct NearPair {
  int i;
  int j;
  Vec3 shift;
};

// All pairs with |minimum image of x_j - x_i| < cutoff, each once (i < j),
// in a deterministic order. Positions must lie inside the box. The cutoff
// must be below half the smallest box length so that a pair has one image
// only; otherwise std::invalid_argument.
std::vector<NearPair> pairs_within(const std::vector<Vec3>& position, const PeriodicBox& box,
                                   double cutoff);

}  // namespace flocsim::neighbours
