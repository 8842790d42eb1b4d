#pragma once
// The liquid: a D3Q19 lattice-Boltzmann fluid in a fully periodic box.
//
// Storage and streaming. The 19 populations are kept as a structure of arrays
// (one array per direction) and updated in place with the AA pattern (Bailey
// et al. 2009): an "even" step reads and writes only the cell's own slots (the
// post-collision value of direction i goes to the slot of its opposite), an
// "odd" step reads from and writes to the neighbours. One step therefore moves
// exactly 19 loads + 19 stores per cell, with no second grid and no
// write-allocate traffic: 2 * 19 * sizeof(Real) bytes per cell update. The
// direction arrays are padded so that their distance in memory is never a
// multiple of 4 KiB (cache-set aliasing slows such a kernel several times).
//
// Populations are stored as deviations from the rest equilibrium, f_i - w_i,
// which keeps single precision accurate: the velocity is a small difference of
// O(1) numbers otherwise.
//
// Collision and forcing. Two-relaxation-time (TRT) collision (relaxation.hpp)
// with Guo et al. (2002) forcing split into its symmetric and antisymmetric
// parts, each scaled by (1 - omega/2) of its own relaxation rate. The force per
// cell is a uniform body force plus, optionally, a per-cell field written by the
// immersed boundary. The macroscopic velocity includes the half-force shift:
// rho u = sum_i c_i f_i + F/2. With this split the momentum of the whole box
// grows by exactly sum_cells F per step.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "engine/lattice/d3q19.hpp"
#include "engine/lattice/forced_liquid.hpp"
#include "engine/lattice/relaxation.hpp"

namespace flocsim::lattice {

// Density and velocity of one cell (velocity includes the half-force shift).
struct Macroscopic {
  double density = 1.0;
  Vector3 velocity;
};

template <class Real>
class FluidLattice final : public ForcedLiquid<Real> {
 public:
  FluidLattice(Extent extent, Relaxation relaxation);
  ~FluidLattice();
  FluidLattice(const FluidLattice&) = delete;
  FluidLattice& operator=(const FluidLattice&) = delete;

  const Extent& extent() const override { return extent_; }
  const Relaxation& relaxation() const { return relaxation_; }
  long time_step() const { return time_step_; }

  long cell_index(int x, int y, int z) const {
    return static_cast<long>(x) +
           static_cast<long>(extent_.nx) * (y + static_cast<long>(extent_.ny) * z);
  }

  // ---- forcing --------------------------------------------------------------
  void set_body_force(Vector3 force_density) { body_force_ = force_density; }
  Vector3 body_force() const override { return body_force_; }
  // Allocates (zeroed) the per-cell force field; the kernel then reads it.
  void enable_force_field();
  bool has_force_field() const { return force_x_ != nullptr; }
  // The per-cell force field (enabled on first use); index with cell_index.
  ForceFieldView<Real> force_field() override;
  ForceFieldView<const Real> force_field_if_set() const override;
  // Partially saturated cells (forced_liquid.hpp): the next step blends the
  // collision of the rows `coverage` covers (partially_saturated_collision.hpp).
  void set_solid_coverage(SolidCoverage<Real>* coverage) override { solid_coverage_ = coverage; }
  const SolidCoverage<Real>* pending_solid_coverage() const override { return solid_coverage_; }

  // ---- state ----------------------------------------------------------------
  // Sets every cell to the equilibrium of the given density and (physical,
  // half-force-shifted) velocity, which then reads back exactly.
  template <class Field>  // Field(x, y, z) -> Macroscopic
  void initialise_equilibrium(Field&& field);

  // The population f_i (full value, not the deviation) at the current time,
  // before collision: the AA pattern hides its storage slot.
  double population(int i, int x, int y, int z) const;
  Macroscopic macroscopic(int x, int y, int z) const;
  // Density and velocity with the half-force shift of the uniform body force
  // only, ignoring the per-cell force field (forced_liquid.hpp), for `count`
  // consecutive cells x0 .. x0 + count - 1 of row (y, z) (no wrap in x).
  void macroscopic_row_without_force_field(int x0, int count, int y, int z, double* density,
                                           double* ux, double* uy, double* uz) const override;
  void macroscopic_row_without_force_field(int x0, int count, int y, int z,
                                           Real* rho_u) const override;

  // Density and velocity of every cell (arrays of length cells(), x fastest).
  void macroscopic_fields(std::vector<double>& density, std::vector<double>& ux,
                          std::vector<double>& uy, std::vector<double>& uz) const;

  // Sum of the density over all cells (the liquid mass) and of the momentum
  // density (with half-force shift), accumulated in double.
  double total_mass() const;
  Vector3 total_momentum() const;

  // ---- time stepping --------------------------------------------------------
  // One lattice-Boltzmann step: collide with the current force, stream.
  void step();

  // The state as stored, for checkpoints: the slot array of direction i
  // (deviations from the rest equilibrium, cells() values in cell_index order,
  // in the AA pattern's layout for the current time-step parity). Restore it
  // into a lattice of the same extent and precision, with set_time_step(t) of
  // the same parity, and the run continues bit for bit.
  void save_slots(int i, std::vector<Real>& out) const;
  void restore_slots(int i, const std::vector<Real>& in);
  void set_time_step(long t) { time_step_ = t; }

  // Bytes moved per cell update by step(), for roofline figures.
  std::size_t bytes_per_cell_update() const;

 private:
  template <bool kForceField, bool kCoverage>
  void step_kernel();
  Real* storage(int i) { return populations_.get() + i * stride_; }
  const Real* storage(int i) const { return populations_.get() + i * stride_; }
  // One cell of macroscopic_row_without_force_field (x, y, z inside the box);
  // the row readers use it for the end cells whose upstream wraps in x.
  Macroscopic macroscopic_without_force_field(int x, int y, int z) const;
  long wrapped_index(int x, int y, int z) const;

  struct FreeAligned {
    void operator()(Real* p) const;
  };
  using Buffer = std::unique_ptr<Real[], FreeAligned>;
  static Buffer allocate(std::size_t elements);

  Extent extent_;
  Relaxation relaxation_;
  long stride_ = 0;  // elements between direction arrays (padded)
  Buffer populations_;
  Buffer force_x_, force_y_, force_z_;
  SolidCoverage<Real>* solid_coverage_ = nullptr;  // for the next step only
  Vector3 body_force_;
  long time_step_ = 0;
};

template <class Real>
template <class Field>
void FluidLattice<Real>::initialise_equilibrium(Field&& field) {
  using namespace d3q19;
  const Real* fields[3] = {force_x_.get(), force_y_.get(), force_z_.get()};
  for (int z = 0; z < extent_.nz; ++z)
    for (int y = 0; y < extent_.ny; ++y)
      for (int x = 0; x < extent_.nx; ++x) {
        const Macroscopic m = field(x, y, z);
        const long c = cell_index(x, y, z);
        double F[3] = {body_force_.x, body_force_.y, body_force_.z};
        if (has_force_field())
          for (int d = 0; d < 3; ++d) F[d] += fields[d][c];
        // Store j = rho u - F/2 so that (j + F/2)/rho reads back as u.
        const double rho = m.density;
        const double u[3] = {m.velocity.x - 0.5 * F[0] / rho, m.velocity.y - 0.5 * F[1] / rho,
                             m.velocity.z - 0.5 * F[2] / rho};
        const double usq = u[0] * u[0] + u[1] * u[1] + u[2] * u[2];
        for (int i = 0; i < kQ; ++i) {
          const double cu = cx[i] * u[0] + cy[i] * u[1] + cz[i] * u[2];
          const double feq_dev =
              w[i] * ((rho - 1.0) + rho * (3.0 * cu + 4.5 * cu * cu - 1.5 * usq));
          // At an even time step population i lives in its own slot at its cell;
          // at an odd one it lives in the opposite slot of the upstream cell.
          if (time_step_ % 2 == 0)
            storage(i)[c] = static_cast<Real>(feq_dev);
          else
            storage(opposite(i))[wrapped_index(x - cx[i], y - cy[i], z - cz[i])] =
                static_cast<Real>(feq_dev);
        }
      }
}

extern template class FluidLattice<float>;
extern template class FluidLattice<double>;

}  // namespace flocsim::lattice
