// The GPU's liquid averages in a build without CUDA: the constructor refuses
// with the reason (gpu_runtime.hpp's), so nothing else is ever called. With
// CUDA (FLOCSIM_HAVE_CUDA) gpu_liquid_averages.cu defines it.
#ifndef FLOCSIM_HAVE_CUDA
#include <stdexcept>

#include "engine/lattice_gpu/gpu_runtime.hpp"
#include "engine/observables_gpu/gpu_liquid_averages.hpp"

namespace flocsim::gpu {

template <class Real>
struct GpuLiquidAverages<Real>::Device {};

template <class Real>
GpuLiquidAverages<Real>::GpuLiquidAverages() {
  use_first_gpu();  // throws: this build has no CUDA back-end, and says so
  throw std::logic_error("unreachable: use_first_gpu() succeeded without CUDA");
}
template <class Real>
GpuLiquidAverages<Real>::~GpuLiquidAverages() = default;
template <class Real>
observables::LiquidSums GpuLiquidAverages<Real>::sums(const GpuFluidLattice<Real>&,
                                                      const std::vector<double>&, double) {
  return {};
}
template <class Real>
int GpuLiquidAverages<Real>::blocks() const {
  return 0;
}

template class GpuLiquidAverages<float>;
template class GpuLiquidAverages<double>;

}  // namespace flocsim::gpu
#endif
