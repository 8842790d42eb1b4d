#pragma once
// A momentum-conserving wake sponge for single-sphere validation runs in a
// periodic box (test support, not part of the solver's model).
//
// Why: a sphere settling through a periodic box at Re >= 24 meets its own wake
// again after one box length (the wake's centre-line deficit is still
// ~1.5 (1 + 0.15 Re^0.687) a / x of the slip at x = L), drafts in it and never
// reaches the terminal velocity of an isolated sphere (docs/immersed-boundary.md:
// +27 % after 200 a/U_inf at Re_inf = 72, L = 16a). Comparing with an
// isolated-sphere drag law then measures the box, not the drag.
//
// What: on a slab of cells `width` thick across the whole y-z cross-section,
// centred half a box length from the sphere in x, the liquid is relaxed towards
// the slab's own mean velocity: F = -rate rho (u - <u>), <u> the mass-weighted
// mean over the slab. The forces sum to zero, so the sponge only redistributes
// momentum across the slab (it mixes the wake deficit into the cross-section)
// and the momentum balance of liquid plus sphere is untouched. It is a
// conserving variant of the fringe-region technique for spatially developing
// flows in periodic domains (Nordstrom, Nordin & Henningson 1999).
//
// Use: after ib.apply() and before fluid.step() every step. The sponge removes
// the force it added in the previous step before adding the new one (the
// immersed boundary clears only the cells it wrote). The slab must stay clear of
// the cells the immersed boundary writes: checked, with the immersed
// boundary's 16-cell row chunks included.
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/lattice/fluid_lattice.hpp"
#include "tests/lattice/lattice_probes.hpp"

namespace flocsim::test {

template <class Real>
class WakeSponge {
 public:
  WakeSponge(double rate, int width) : rate_(rate), width_(width) {}

  // Sphere centre x = sphere_x, immersed-boundary kernel reach `reach` (a_g + 1.5).
  void apply(lattice::FluidLattice<Real>& fluid, double sphere_x, double reach) {
    const lattice::Extent e = fluid.extent();
    if (0.5 * e.nx - 0.5 * width_ - 1 < reach + 16)
      throw std::invalid_argument("wake sponge: box length " + std::to_string(e.nx) +
                                  " too short for a slab of " + std::to_string(width_) +
                                  " cells clear of the sphere's cells (reach " +
                                  std::to_string(reach) + " + 16-cell chunks)");
    if (!fluid.has_force_field()) fluid.enable_force_field();
    for (std::size_t k = 0; k < cells_.size(); ++k)
      for (int d = 0; d < 3; ++d) fluid.force_field().component[d][cells_[k]] -= added_[3 * k + d];
    cells_.clear();
    added_.clear();
    // The slab's cells and their velocity without the per-cell force field
    // (what the collision would see without the sponge).
    const int centre = static_cast<int>(std::floor(sphere_x + 0.5 * e.nx));
    std::vector<lattice::Macroscopic> m;
    double mass = 0, momentum[3] = {0, 0, 0};
    for (int i = 0; i < width_; ++i) {
      const int x = ((centre - width_ / 2 + i) % e.nx + e.nx) % e.nx;
      for (int z = 0; z < e.nz; ++z)
        for (int y = 0; y < e.ny; ++y) {
          const lattice::Macroscopic c = testing::macroscopic_without_force_field(fluid, x, y, z);
          cells_.push_back(fluid.cell_index(x, y, z));
          m.push_back(c);
          mass += c.density;
          momentum[0] += c.density * c.velocity.x;
          momentum[1] += c.density * c.velocity.y;
          momentum[2] += c.density * c.velocity.z;
        }
    }
    const double mean[3] = {momentum[0] / mass, momentum[1] / mass, momentum[2] / mass};
    for (std::size_t k = 0; k < cells_.size(); ++k) {
      const double u[3] = {m[k].velocity.x, m[k].velocity.y, m[k].velocity.z};
      for (int d = 0; d < 3; ++d) {
        const auto f = static_cast<Real>(-rate_ * m[k].density * (u[d] - mean[d]));
        added_.push_back(f);
        fluid.force_field().component[d][cells_[k]] += f;
      }
    }
  }

  // The force added at the last apply(), summed over the slab (zero up to
  // round-off: the sponge conserves momentum).
  std::vector<double> total_force() const {
    std::vector<double> sum(3, 0.0);
    for (std::size_t k = 0; k < cells_.size(); ++k)
      for (int d = 0; d < 3; ++d) sum[d] += added_[3 * k + d];
    return sum;
  }

 private:
  double rate_;
  int width_;
  std::vector<long> cells_;
  std::vector<Real> added_;  // x y z per slab cell
};

}  // namespace flocsim::test
