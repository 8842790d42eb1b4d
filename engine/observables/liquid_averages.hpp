#pragma once
// Averages of the lattice liquid that the settling observables need (docs/model.md
// section 4): the mean liquid velocity <u> over the liquid volume, i.e. over
// the cells whose centre lies outside every sphere of hydrodynamic radius a
// (the liquid the immersed boundary keeps inside a sphere moves with the
// sphere and is not part of the suspending liquid), and the raw lattice
// momentum for the momentum balance of liquid + spheres.
#include <cstdint>
#include <vector>

#include "engine/lattice/forced_liquid.hpp"
#include "engine/observables/liquid_average_body.hpp"
#include "engine/spheres/sphere_set.hpp"

namespace flocsim::observables {

struct LiquidAverages {
  // Volume average over liquid cells of the physical velocity x component,
  // (sum_i c_ix f_i + F/2) / rho with F the whole force on the cell (body force
  // plus the per-cell force field).
  double mean_velocity_x = 0;
  long liquid_cells = 0;
  // The same over every cell, the liquid inside the spheres included: the
  // other reading of <u> (docs/validation/paper-baseline.md, "Which <u>"). If the inside
  // liquid moves with its sphere, (<u>_all - <u_p>) = (1 - phi)(<u> - <u_p>),
  // so a drag built on it reads F / (1 - phi).
  double mean_velocity_x_all_cells = 0;
  // sum over every cell of sum_i c_ix f_i: the lattice momentum without any
  // half-force shift (what the momentum balance conserves, sphere_dynamics.hpp).
  double lattice_momentum_x = 0;
  double mass = 0;  // sum of rho over every cell; not finite after a blow-up
  // The largest speed |u| (all three components, each cell's whole half force
  // included), over every cell and over the liquid cells only: what sets the
  // lattice Mach number |u| / c_s (docs/accuracy-cost.md, "The lattice Mach number").
  double max_speed = 0;
  double max_speed_outside_spheres = 0;
};

// `solid` is scratch space (one byte per cell), reused between calls. The
// per-cell work is add_liquid_cell (liquid_average_body.hpp), which the GPU's
// reduction shares (engine/observables_gpu).
template <class Real>
LiquidAverages liquid_averages(const lattice::ForcedLiquid<Real>& fluid,
                               const spheres::SphereSet& spheres, std::vector<std::uint8_t>& solid);

// The averages from sums over a lattice of `cells` cells (either back-end's).
LiquidAverages averages_from_sums(const LiquidSums& sums, long cells);

// Marks (1) the cells whose centre (integer coordinates) lies within `radius`
// of a sphere centre, periodic images included; the others 0.
void mark_solid_cells(const lattice::Extent& extent, const std::vector<spheres::Vec3>& centres,
                      double radius, std::vector<std::uint8_t>& solid);

}  // namespace flocsim::observables
