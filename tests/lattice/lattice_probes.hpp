#pragma once
// Test-side readers of a lattice, built only from its public per-cell queries
// (population(), the force field view): independent references for the
// optimised row readers the engine uses.
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

}  // namespace flocsim::testing
