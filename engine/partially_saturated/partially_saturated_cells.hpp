#pragma once
// Spheres coupled to the liquid as partially saturated cells (Noble &
// Torczynski 1998; as waLBerla's PSM coupling, Rettinger & Rüde 2017): no
// markers. The liquid's step blends each covered cell's collision with a
// solid operator (engine/lattice/partially_saturated_collision.hpp), in
// proportion to the cell's solid coverage eps (summed over the spheres
// reaching it, cell_coverage.hpp, on the sphere of input radius a_g), towards
// the coverage-weighted surface velocity sum eps_k (u_k + omega_k x r). The
// momentum the solid operator adds to the liquid in a cell,
// dP = B (rho (u_s - u) - F), goes to the cell's spheres in proportion to
// their coverage, reversed (force -dP, torque -r x dP), and the inside
// liquid's momentum is sum eps_k rho u over the sphere's cells. Liquid and
// spheres then exchange exactly the same momentum.
//
// How it enters the step (the lattice knows no sphere, forced_liquid.hpp):
// apply() lists, per lattice row, the runs of cells that each sphere may
// cover (the cells whose centres lie within a_g + sqrt(3)/2 of its centre, a
// row meets a few spheres) and hands itself to the lattice as the row-wise
// SolidCoverage of the next step. For each row with runs the step asks it to
// write the coverage and solid velocity into the row's buffers (the coverage
// computed there, in cache), collides, and hands back the density and
// momentum the collision saw; the sums of the exchange over each run (force,
// torque, inside momenta) are taken right there. after_liquid_step() adds
// each sphere's runs up. Every run has its own slot for its sums and each
// sphere adds its runs in a fixed order, so a run of the solver is
// reproducible whatever the number of threads and their schedule.
#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

#include "engine/coupling/sphere_coupling.hpp"

namespace flocsim::partially_saturated {

template <class Real>
class PartiallySaturatedCells final : public coupling::SphereCoupling<Real>,
                                      private lattice::SolidCoverage<Real> {
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
  // The lattice's side (lattice::SolidCoverage), called during its step.
  bool covers(long row) const override { return row_first_[row + 1] > row_first_[row]; }
  void cover(lattice::CoveredRow<Real>& row) const override;
  void exchange(const lattice::CoveredRow<Real>& row) override;

  // The cells x .. x + count - 1 of one lattice row that one sphere may
  // cover, and where they lie from its centre: cell x + c at
  // (rx0 + c, ry, rz) (positions rounded to single precision as they enter
  // the coverage).
  struct Run {
    std::int32_t sphere = 0;
    std::int32_t x = 0, count = 0;
    std::int32_t cell = 0;  // the coverage of its cells: coverage_[cell ..]
    float ry = 0, rz = 0;
    double rx0 = 0;
  };
  // What the liquid's step measured over one run: the momentum its sphere's
  // share of the solid operator gave the liquid (dP), r x dP, eps_k rho u
  // and r x eps_k rho u, summed over the run's cells.
  struct RunSums {
    double dP[3], r_dP[3], P[3], r_P[3];
  };

  // Each sphere's box of cells and its rows of possibly covered cells
  // (sphere_cells.hpp layout), and how many runs they make.
  void locate(const spheres::SphereSet& spheres, const lattice::Extent& e);
  // The runs, sphere by sphere (slot order), then by lattice row.
  void list_runs(const spheres::SphereSet& spheres, const lattice::Extent& e);
  template <bool kForceField>
  void exchange_runs(const lattice::CoveredRow<Real>& row);

  double input_radius_;
  int box_ = 0;
  std::vector<std::array<int, 3>> origins_;
  std::vector<std::int16_t> rows_;
  // The runs as apply() lists them, by slot: sphere s's are slots
  // sphere_first_[s] .. sphere_first_[s + 1] - 1, in the order of its box
  // rows; their lattice rows; their cells' coverage (sphere s's from
  // sphere_cells_[s]).
  std::vector<std::size_t> sphere_first_, sphere_cells_;
  std::vector<Run> slot_runs_;
  std::vector<std::int32_t> slot_row_;
  std::vector<float> slot_coverage_;
  // The same in the order the step reads them: lattice row r's runs are
  // runs_[row_first_[r] .. row_first_[r + 1] - 1], in slot order (so in the
  // order of their spheres), their cells' coverage in coverage_ (row r's
  // from row_cell_first_[r]); the slot of each and the place of each slot.
  std::vector<std::size_t> row_first_, row_cell_first_;
  std::vector<Run> runs_;
  std::vector<float> coverage_;
  std::vector<std::int32_t> row_slot_;
  std::vector<std::size_t> row_cell_, run_place_;
  std::vector<std::size_t> next_, next_cell_;  // (counting sort's cursors)
  // What each run measured, in row order (the step writes them one after
  // the other; slot q's are sums_[run_place_[q]]).
  std::vector<RunSums> sums_;
  std::vector<std::array<double, 6>> motion_;  // per sphere: u_p, omega
  lattice::Vector3 body_force_;
};

extern template class PartiallySaturatedCells<float>;
extern template class PartiallySaturatedCells<double>;

}  // namespace flocsim::partially_saturated
