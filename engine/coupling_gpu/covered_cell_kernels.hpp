#pragma once
// The device side of the GPU's partially saturated cells
// (gpu_partially_saturated.hpp): per-sphere buffers and the launches of one
// thread block per sphere that run the kernel bodies of
// engine/partially_saturated/covered_cell_body.hpp around the lattice's
// step. Plain numbers in and out (no Eigen, no CUDA headers), so that this
// header compiles without CUDA.
#include <memory>
#include <vector>

#include "engine/lattice_gpu/gpu_fluid_lattice.hpp"

namespace flocsim::gpu {

// Per sphere, in: its centre in the box, the lowest corner of its cube of
// cells, velocity and angular velocity (partially_saturated::CoveringSphere,
// 12 numbers); out: what its share of the solid operator gave the liquid
// (dP), r x dP, and the inside liquid's eps_k rho u and r x eps_k rho u, each
// summed over its cells (12 numbers).
constexpr int kCoveringNumbers = 12;
constexpr int kExchangeNumbers = 12;

template <class Real>
class CoveredCellKernels {
 public:
  // Throws std::runtime_error where no GPU can be used.
  explicit CoveredCellKernels(double input_radius);
  ~CoveredCellKernels();
  CoveredCellKernels(const CoveredCellKernels&) = delete;
  CoveredCellKernels& operator=(const CoveredCellKernels&) = delete;

  // Before the liquid's step: every sphere's coverage eps_k and eps_k u_k
  // added into the lattice's coverage arrays, and the step asked to blend.
  // Queued, not waited for.
  void cover(GpuFluidLattice<Real>& liquid, const std::vector<double>& spheres);
  // After the step: `exchange` receives kExchangeNumbers per sphere; the
  // coverage is cleared again. Waits for the GPU.
  void exchange(GpuFluidLattice<Real>& liquid, std::vector<double>& exchange);
  // Takes back a cover() whose step has not run: clears the coverage.
  void withdraw(GpuFluidLattice<Real>& liquid);

 private:
  struct Device;  // defined in covered_cell_kernels.cu
  double input_radius_;
  std::unique_ptr<Device> device_;
};

extern template class CoveredCellKernels<float>;
extern template class CoveredCellKernels<double>;

}  // namespace flocsim::gpu
