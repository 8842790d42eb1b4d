#pragma once
// Partially saturated cells on the GPU: the method of
// engine/partially_saturated/partially_saturated_cells.hpp on a
// GpuFluidLattice, behind the interface every coupling offers the time loop
// (engine/coupling/sphere_coupling.hpp), so that a sphere scene's step, its
// coupling monitor and its checkpoints use it as they use the CPU's.
//
// apply() sends 12 numbers per sphere to the GPU (its centre in the box, the
// corner of its cube of cells, velocity, angular velocity) through a
// page-locked buffer and queues the kernel that adds each sphere's coverage
// eps_k and eps_k u_k into the lattice's per-cell coverage; the lattice's
// next step blends the collision of every covered cell
// (GpuFluidLattice::cover_next_step); after_liquid_step() runs the kernels
// that measure each sphere's share of the exchange and clear the coverage,
// and brings back 12 numbers per sphere: force, torque and the inside
// liquid's momenta, as the CPU coupling gives them. The per-cell and
// per-sphere work is the kernel bodies of covered_cell_body.hpp, which the
// test suite holds to the CPU coupling (tests/coupling/covered_cell_body_test.cpp).
//
// It couples the spheres to the GPU lattice it was given; the host lattice
// the time loop passes in is the run's mirror, which it neither reads nor
// writes.
#include <memory>
#include <string_view>
#include <vector>

#include "engine/coupling/sphere_coupling.hpp"
#include "engine/lattice_gpu/gpu_fluid_lattice.hpp"

namespace flocsim::gpu {

template <class Real>
class CoveredCellKernels;

// The spheres as the GPU's cells take them: kCoveringNumbers per sphere
// (covered_cell_kernels.hpp), placed as the CPU coupling places them.
std::vector<double> covering_spheres(const spheres::SphereSet& spheres, const lattice::Extent& e,
                                     double input_radius);

template <class Real>
class GpuPartiallySaturatedCells final : public coupling::SphereCoupling<Real> {
 public:
  // `input_radius`: a_g (as the CPU's PartiallySaturatedCells). Throws
  // std::invalid_argument for a radius the CPU coupling refuses,
  // std::runtime_error where no GPU can be used.
  GpuPartiallySaturatedCells(double input_radius, GpuFluidLattice<Real>& device);
  ~GpuPartiallySaturatedCells() override;

  std::string_view stage_name() const override { return "partially_saturated"; }
  double input_radius() const { return input_radius_; }

  void apply(lattice::ForcedLiquid<Real>& mirror, const spheres::SphereSet& spheres) override;
  void after_liquid_step(const lattice::ForcedLiquid<Real>& mirror,
                         const spheres::SphereSet& spheres) override;
  void remove(lattice::ForcedLiquid<Real>& mirror) override;

 private:
  double input_radius_;
  GpuFluidLattice<Real>& device_;
  std::unique_ptr<CoveredCellKernels<Real>> kernels_;
  std::vector<double> spheres_, exchange_;
};

extern template class GpuPartiallySaturatedCells<float>;
extern template class GpuPartiallySaturatedCells<double>;

}  // namespace flocsim::gpu
