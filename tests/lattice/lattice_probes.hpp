#pragma once
// Test-side readers of a lattice, built only from its public per-cell queries
// (population(), the force field view): independent references for the
// optimised row readers the engine uses.
#include <vector>

#include "engine/lattice/fluid_lattice.hpp"

namespace flocsim::testing {

// Density and velocity of one cell with the half shift of the uniform body
// force only, the per-cell force field left out: rho u* = sum_i c_i f_i + F_body / 2.
template <class Real>
lattice::Macroscopic macroscopic_without_force_field(const lattice::FluidLattice<Real>& fluid,
                                                     int x, int y, int z) {
  using namespace d3q19;
  double rho = 0, j[3] = {0, 0, 0};
  for (int i = 0; i < kQ; ++i) {
    const double dev = fluid.population(i, x, y, z) - w[i];
    rho += dev;
    j[0] += cx[i] * dev;
    j[1] += cy[i] * dev;
    j[2] += cz[i] * dev;
  }
  rho += 1.0;
  const lattice::Vector3 F = fluid.body_force();
  return {rho, {(j[0] + 0.5 * F.x) / rho, (j[1] + 0.5 * F.y) / rho, (j[2] + 0.5 * F.z) / rho}};
}

// Every population slot of the lattice as stored (direction after direction,
// cells() values each): what a bit-for-bit comparison of two lattices reads.
template <class Real>
std::vector<Real> slots_of(const lattice::FluidLattice<Real>& fluid) {
  std::vector<Real> all, one;
  for (int i = 0; i < d3q19::kQ; ++i) {
    fluid.save_slots(i, one);
    all.insert(all.end(), one.begin(), one.end());
  }
  return all;
}

}  // namespace flocsim::testing
