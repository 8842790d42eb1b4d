#pragma once
// Aggregates (paper section 4): connected groups of spheres whose centres are
// within the bond distance 2(a + delta) of one another, across periodic
// boundaries. From them: the contacts per sphere C_sph, the mass-weighted size
// distribution p(n_a) (the fraction of all spheres that sit in aggregates of
// n_a spheres) and its mean <n_a> = sum n_a p(n_a).
#include <vector>

#include "engine/spheres/sphere_set.hpp"

namespace flocsim::observables {

struct Aggregates {
  std::vector<int> aggregate_of;          // per sphere: aggregate id 0..count-1
  std::vector<int> aggregate_size;        // per aggregate: number of spheres
  std::vector<double> size_distribution;  // p(n), index n = 0..N (p(0) = 0)
  double mean_size = 0;                   // <n_a>
  double contacts_per_sphere = 0;  // C_sph: mean number of other centres within bond distance
};

Aggregates find_aggregates(const std::vector<spheres::Vec3>& position,
                           const spheres::PeriodicBox& box, double bond_distance);

}  // namespace flocsim::observables
