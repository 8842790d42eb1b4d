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
// SolidCoverage): apply() only lists each sphere's slices (its z planes) by
// plane and band of rows and hands itself to the lattice for the next step.
// For each lattice row the step asks cover(): the row's runs of cells that
// each sphere may cover (the cells whose centres lie within a_g + sqrt(3)/2
// of its centre) are found from the slices of its band, their coverage
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
  // (Four zeros fill it to one aligned vector store of 16 lanes.)
  struct alignas(64) Sums {
    double dP[3], r_dP[3], P[3], r_P[3], zero[4];
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
  // One sphere's slice of its box in one z plane: the rows it may reach
  // there are y = corner_y + j, j = j0 .. j1 (wrapped), with its centre's x
  // and y and the plane's distance rz from the centre.
  struct Slice {
    std::int32_t sphere, sums;  // sums: its slot in sums_
    std::int32_t corner_x, corner_y, j0, j1;
    double centre_x, centre_y, rz;
  };
  // The slices by z plane and band of rows (bands_ bands of at least
  // max(8, a_g + sqrt(3)/2) rows across y): band b of plane z holds
  // slices_[band_first_[b + bands_ z] .. next - 1], in sphere order, every
  // slice that reaches a row of the band. A row looks at its band only.
  int bands_ = 1;
  std::vector<std::int32_t> band_of_row_, band_first_;
  std::vector<Slice> slices_;
  // Every slice with its plane and the bands it meets, in sphere order, then
  // plane order (apply() places them by band; after_liquid_step() adds each
  // sphere's sums up in this order).
  struct Listed {
    Slice slice;
    int z = 0, count = 0, bands[3] = {0, 0, 0};
  };
  std::vector<Listed> listed_;
  std::vector<std::int32_t> next_;
  // The sums of every slice of every sphere, by plane (Slice::sums).
  std::vector<Sums> sums_;
  lattice::Vector3 body_force_;
  std::vector<Scratch> scratch_;  // per thread
};

extern template class PartiallySaturatedCells<float>;
extern template class PartiallySaturatedCells<double>;

}  // namespace flocsim::partially_saturated
