// The CUDA back-end's entry points in a build without CUDA: the build says
// so, and anything that would need a GPU is refused with that reason. With
// CUDA (FLOCSIM_HAVE_CUDA) the .cu files of this folder define them instead.
#ifndef FLOCSIM_HAVE_CUDA
#include <stdexcept>

#include "engine/lattice_gpu/gpu_fluid_lattice.hpp"
#include "engine/lattice_gpu/gpu_runtime.hpp"

namespace flocsim::gpu {

namespace {
const char* kNoCuda =
    "this flocsim was built without its CUDA back-end (no CUDA compiler was found when it was "
    "configured: install the CUDA toolkit, put nvcc on PATH or set CUDACXX, and configure "
    "again; docs/gpu.md)";
}

bool built_with_cuda() {
  return false;
}

GpuQuery query_gpus() {
  return {{}, kNoCuda};
}

void release_gpus() {}

GpuDevice use_first_gpu() {
  throw std::runtime_error(kNoCuda);
}

double measure_copy_bandwidth_gbs(std::size_t, int) {
  throw std::runtime_error(kNoCuda);
}

template <class Real>
struct GpuFluidLattice<Real>::Device {};

template <class Real>
GpuFluidLattice<Real>::GpuFluidLattice(lattice::Extent extent, lattice::Relaxation relaxation)
    : extent_(extent), relaxation_(relaxation) {
  throw std::runtime_error(kNoCuda);
}
template <class Real>
GpuFluidLattice<Real>::~GpuFluidLattice() = default;
template <class Real>
void GpuFluidLattice<Real>::upload(const lattice::FluidLattice<Real>&) {}
template <class Real>
void GpuFluidLattice<Real>::download(lattice::FluidLattice<Real>&) const {}
template <class Real>
void GpuFluidLattice<Real>::upload_force_field(const lattice::ForceFieldView<const Real>&) {}
template <class Real>
void GpuFluidLattice<Real>::download_force_field(lattice::FluidLattice<Real>&) const {}
template <class Real>
lattice::AaSlots<Real> GpuFluidLattice<Real>::device_slots() const {
  return {};
}
template <class Real>
DeviceForceField<Real> GpuFluidLattice<Real>::device_force_field() {
  return {};
}
template <class Real>
DeviceForceField<const Real> GpuFluidLattice<Real>::device_force_field_if_set() const {
  return {};
}
template <class Real>
DeviceCoverage<Real> GpuFluidLattice<Real>::device_coverage() {
  return {};
}
template <class Real>
void GpuFluidLattice<Real>::step() {}
template <class Real>
void GpuFluidLattice<Real>::synchronize() const {}
template <class Real>
double GpuFluidLattice<Real>::total_mass() const {
  return 0;
}
template <class Real>
lattice::Vector3 GpuFluidLattice<Real>::total_momentum() const {
  return {};
}
template <class Real>
std::size_t GpuFluidLattice<Real>::bytes_per_cell_update() const {
  return 0;
}

template <class Real>
const GpuDevice& GpuFluidLattice<Real>::gpu() const {
  static const GpuDevice none;
  return none;
}

template class GpuFluidLattice<float>;
template class GpuFluidLattice<double>;

}  // namespace flocsim::gpu
#endif
