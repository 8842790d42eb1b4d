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
// How it enters the step (the lattice knows no sphere: forced_liquid.hpp's
// SolidCoverage): apply() only bins the spheres by where they lie across the
// rows (y, z) and hands itself to the lattice for the next step. For each
// lattice row the step asks cover(): the row's runs of cells that each
// nearby sphere may cover (the cells whose centres lie within
// a_g + sqrt(3)/2 of its centre) are found from the bins, their coverage
// computed and the coverage and solid velocity written into the row's
// buffers, all in cache; after the row's collision exchange() sums each run's
// share of the exchange (force, torque, inside momenta) into its sphere's
// entry for that z plane. after_liquid_step() adds each sphere's planes up.
// A plane is stepped by one thread in a fixed order, and every sum is taken
// in an order fixed by the geometry alone, so a run is reproducible whatever
// the number of threads.
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
  void begin_step(int threads) override;
  bool cover(lattice::CoveredRow<Real>& row) override;
  void exchange(const lattice::CoveredRow<Real>& row) override;

  // The cells x .. x + count - 1 of the row being stepped that one sphere may
  // cover, where they lie from its centre (cell x + c at (rx0 + c, ry, rz),
  // rounded to single precision as they enter the coverage), where their
  // coverage is in the thread's scratch, and the sphere's entry for this
  // plane of its box (sums_).
  struct Run {
    std::int32_t sphere = 0;
    std::int32_t x = 0, count = 0;
    std::int32_t first = 0;  // coverage: Scratch::eps[first ..]
    std::size_t sums = 0;
    double rx0 = 0;
    float ry = 0, rz = 0;
  };
  // Per thread, for the row it steps: its runs and their cells' coverage,
  // and the cells that need the plane cut (not wholly inside), packed.
  struct Scratch {
    std::vector<Run> runs;
    std::vector<float> eps;
    std::vector<float> rx, ry, rz, cut;
    std::vector<std::int32_t> at;
  };
  // What the step measured for one sphere in one plane of its box: the
  // momentum the sphere's share of the solid operator gave the liquid (dP),
  // r x dP, eps_k rho u and r x eps_k rho u, summed over its cells there.
  struct Sums {
    double dP[3], r_dP[3], P[3], r_P[3];
  };

  // Finds the runs of row (y, z) into `t` and their cells' coverage.
  void find_runs(int y, int z, Scratch& t) const;
  template <bool kForceField>
  void exchange_runs(const lattice::CoveredRow<Real>& row);

  double input_radius_;
  int box_ = 0;  // B: a sphere's cells lie in a box of B^3 from its corner
  lattice::Extent extent_;
  // per sphere: u_p and omega
  std::vector<std::array<double, 6>> motion_;
  // The spheres binned by their centres' (y, z): bin (b, c) of bins_[0] x
  // bins_[1] holds binned_[bin_first_[b + bins_[0] c] .. next - 1], in index
  // order, with the centre (in the box) and the lowest corner of the box of
  // B^3 cells around it (unwrapped). Bins are at least a_g + sqrt(3)/2 + 1
  // wide, so the spheres that reach a row lie in its bin or the ones next to
  // it.
  struct Binned {
    std::int32_t sphere;
    std::int32_t corner[3];
    double centre[3];
  };
  int bins_[2] = {1, 1};
  std::vector<std::int32_t> bin_first_;
  std::vector<Binned> binned_;
  // sums_[B s + k]: sphere s's, plane k of its box
  std::vector<Sums> sums_;
  lattice::Vector3 body_force_;
  std::vector<Scratch> scratch_;  // per thread
};

extern template class PartiallySaturatedCells<float>;
extern template class PartiallySaturatedCells<double>;

}  // namespace flocsim::partially_saturated
