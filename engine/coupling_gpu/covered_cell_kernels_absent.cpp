// The GPU partially saturated cells' device side in a build without CUDA:
// the constructor refuses with the reason (gpu_runtime.hpp's), so nothing
// else is ever called. With CUDA (FLOCSIM_HAVE_CUDA) covered_cell_kernels.cu
// defines it.
#ifndef FLOCSIM_HAVE_CUDA
#include <stdexcept>

#include "engine/coupling_gpu/covered_cell_kernels.hpp"
#include "engine/lattice_gpu/gpu_runtime.hpp"

namespace flocsim::gpu {

template <class Real>
struct CoveredCellKernels<Real>::Device {};

template <class Real>
CoveredCellKernels<Real>::CoveredCellKernels(double input_radius) : input_radius_(input_radius) {
  use_first_gpu();  // throws: this build has no CUDA back-end, and says so
  throw std::logic_error("unreachable: use_first_gpu() succeeded without CUDA");
}
template <class Real>
CoveredCellKernels<Real>::~CoveredCellKernels() = default;
template <class Real>
void CoveredCellKernels<Real>::cover(GpuFluidLattice<Real>&, const std::vector<double>&) {}
template <class Real>
void CoveredCellKernels<Real>::exchange(GpuFluidLattice<Real>&, std::vector<double>&) {}
template <class Real>
void CoveredCellKernels<Real>::withdraw(GpuFluidLattice<Real>&) {}

template class CoveredCellKernels<float>;
template class CoveredCellKernels<double>;

}  // namespace flocsim::gpu
#endif
