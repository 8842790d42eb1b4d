// The GPU immersed boundary's device side in a build without CUDA: the
// constructor refuses with the reason (gpu_runtime.hpp's), so nothing else is
// ever called. With CUDA (FLOCSIM_HAVE_CUDA) marker_kernels.cu defines it.
#ifndef FLOCSIM_HAVE_CUDA
#include <stdexcept>

#include "engine/coupling_gpu/marker_kernels.hpp"
#include "engine/lattice_gpu/gpu_runtime.hpp"

namespace flocsim::gpu {

template <class Real>
struct MarkerKernels<Real>::Device {};

template <class Real>
MarkerKernels<Real>::MarkerKernels(MarkerSetup setup) : setup_(std::move(setup)) {
  use_first_gpu();  // throws: this build has no CUDA back-end, and says so
  throw std::logic_error("unreachable: use_first_gpu() succeeded without CUDA");
}
template <class Real>
MarkerKernels<Real>::~MarkerKernels() = default;
template <class Real>
void MarkerKernels<Real>::apply(GpuFluidLattice<Real>&, const std::vector<double>&,
                                std::vector<double>&) {}
template <class Real>
void MarkerKernels<Real>::clear(GpuFluidLattice<Real>&) {}
template <class Real>
std::vector<Real> MarkerKernels<Real>::marker_force() const {
  return {};
}
template <class Real>
std::vector<Real> MarkerKernels<Real>::marker_slip() const {
  return {};
}
template <class Real>
void MarkerKernels<Real>::restore(const std::vector<Real>&, const std::vector<Real>&) {}

template class MarkerKernels<float>;
template class MarkerKernels<double>;

}  // namespace flocsim::gpu
#endif
