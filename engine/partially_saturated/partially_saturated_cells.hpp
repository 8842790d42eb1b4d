#pragma once
// Spheres coupled to the liquid as partially saturated cells (Noble &
// Torczynski 1998; as waLBerla's PSM coupling, Rettinger & Rüde 2017): no
// markers. Each step, before the liquid's step, apply() writes every cell's
// solid coverage eps (summed over the spheres reaching it,
// cell_coverage.hpp, on the sphere of input radius a_g) and the
// coverage-weighted surface velocity sum eps_k (u_k + omega_k x r) into the
// lattice's coverage view (engine/lattice/forced_liquid.hpp); the liquid's
// step blends each covered cell's collision with a solid operator
// (engine/lattice/partially_saturated_collision.hpp) and reports the density
// and momentum it saw. after_liquid_step() turns those into the loads: the
// momentum the solid operator added to the liquid in a cell,
// dP = B (rho (u_s - u) - F), goes to the cell's spheres in proportion to
// their coverage, reversed (force -dP, torque -r x dP), and the inside
// liquid's momentum is sum eps_k rho u over the sphere's cells. Liquid and
// spheres then exchange exactly the same momentum.
//
// The cells a sphere may cover are those whose centres lie within
// a_g + sqrt(3)/2 of its centre; apply() lists them per sphere (lattice
// index, position from the centre, coverage), so that both passes run as
// long vector loops over a sphere's list. Spheres are written colour by
// colour (engine/coupling/sphere_cells.hpp) so that no two threads add to
// one cell; the loads are summed per sphere, each by one thread in a fixed
// order, so a run is reproducible whatever the number of threads.
#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

#include "engine/coupling/sphere_coupling.hpp"

namespace flocsim::partially_saturated {

template <class Real>
class PartiallySaturatedCells final : public coupling::SphereCoupling<Real> {
 public:
  // `input_radius`: a_g, the radius whose cell overlaps give the coverage
  // (calibrated so that the hydrodynamic radius is the case's a).
  explicit PartiallySaturatedCells(double input_radius);

  std::string_view stage_name() const override { return "partially_saturated"; }
  double input_radius() const { return input_radius_; }

  void apply(lattice::ForcedLiquid<Real>& liquid, const spheres::SphereSet& spheres) override;
  void after_liquid_step(const lattice::ForcedLiquid<Real>& liquid,
                         const spheres::SphereSet& spheres) override;
  void remove(lattice::ForcedLiquid<Real>& liquid) override;

 private:
  // Cell boxes, their rows of possibly covered cells (sphere_cells.hpp
  // layout) and where each sphere's list starts.
  void locate(const spheres::SphereSet& spheres);
  // Lists sphere k's cells (lattice index, position, coverage) and marks their chunks.
  void list_cells(std::size_t k, const spheres::SphereSet& spheres,
                  const lattice::SolidCoverageView<Real>& view);
  // Zeroes the coverage of the chunks covered in the last step and clears them.
  void clear(const lattice::SolidCoverageView<Real>& view);

  double input_radius_;
  int box_ = 0;
  std::vector<std::array<int, 3>> origins_;
  std::vector<std::int16_t> rows_;
  // The cells of sphere k are entries first_[k] .. first_[k + 1] - 1 of:
  std::vector<std::size_t> first_;
  std::vector<std::int64_t> cell_;         // lattice index
  std::vector<float> rx_, ry_, rz_, eps_;  // position from the centre, coverage
};

extern template class PartiallySaturatedCells<float>;
extern template class PartiallySaturatedCells<double>;

}  // namespace flocsim::partially_saturated
