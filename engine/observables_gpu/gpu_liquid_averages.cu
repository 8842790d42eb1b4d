// The GPU's liquid averages (gpu_liquid_averages.hpp): the launchers of the
// kernel bodies of engine/observables/liquid_average_body.hpp, and the fixed
// order of their sums. tests/observables/liquid_average_body_test.cpp runs
// the same blocks serially on the CPU against observables::liquid_averages.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "engine/lattice_gpu/cuda_check.hpp"
#include "engine/lattice_gpu/cuda_launch.hpp"
#include "engine/observables_gpu/gpu_liquid_averages.hpp"

namespace flocsim::gpu {

using observables::LiquidSumInput;
using observables::LiquidSums;

namespace {

// Marks the cells of sphere blockIdx.x: its cube's cells, a thread stride
// apart. Cells two spheres share get 1 twice (same value, no race to lose).
__global__ void __launch_bounds__(kLiquidSumThreads)
    mark_solid_kernel(const double* __restrict__ centres, double radius, int reach, int nx, int ny,
                      int nz, std::uint8_t* __restrict__ solid) {
  const double c[3] = {centres[3 * blockIdx.x], centres[3 * blockIdx.x + 1],
                       centres[3 * blockIdx.x + 2]};
  const int side = observables::sphere_cube_side(reach);
  const long cube = static_cast<long>(side) * side * side;
  for (long q = threadIdx.x; q < cube; q += blockDim.x) {
    const long cell = observables::solid_cube_cell(c, radius, reach, nx, ny, nz, q);
    if (cell >= 0) solid[cell] = 1;
  }
}

// Thread t of block b sums cells b T + t, b T + t + G T, ... (T threads, G
// blocks: consecutive threads read consecutive cells); the block then adds
// its threads' sums in a fixed tree (t += t + half for half = T/2, T/4, ..,
// 1) and writes one LiquidSums to partial[b]. No atomics: the order of every
// addition is fixed by (G, T), not by which warp runs first.
template <class Real>
__global__ void __launch_bounds__(kLiquidSumThreads)
    liquid_sums_kernel(LiquidSumInput<Real> in, LiquidSums* __restrict__ partial) {
  // raw storage: a __shared__ array may not run LiquidSums' initialisers
  __shared__ __align__(16) unsigned char raw[sizeof(LiquidSums) * kLiquidSumThreads];
  LiquidSums* part = reinterpret_cast<LiquidSums*>(raw);
  const long stride = static_cast<long>(gridDim.x) * kLiquidSumThreads;
  part[threadIdx.x] = observables::liquid_thread_sums(
      in, static_cast<long>(blockIdx.x) * kLiquidSumThreads + threadIdx.x, stride);
  __syncthreads();
  for (int half = kLiquidSumThreads / 2; half > 0; half /= 2) {
    if (static_cast<int>(threadIdx.x) < half)
      observables::combine_liquid_sums(part[threadIdx.x], part[threadIdx.x + half]);
    __syncthreads();
  }
  if (threadIdx.x == 0) partial[blockIdx.x] = part[0];
}

}  // namespace

template <class Real>
struct GpuLiquidAverages<Real>::Device {
  std::uint8_t* solid = nullptr;  // 1 byte per cell
  long solid_cells = 0;
  double* centres = nullptr;
  std::size_t centres_held = 0;   // doubles
  LiquidSums* partial = nullptr;  // one per block
  int blocks = 0;
  std::vector<LiquidSums> host_partial;

  ~Device() {
    cudaFree(solid);
    cudaFree(centres);
    cudaFree(partial);
  }
};

template <class Real>
GpuLiquidAverages<Real>::GpuLiquidAverages() : device_(std::make_unique<Device>()) {
  int device = 0, sms = 0, per_sm = 0;
  cuda_check(cudaGetDevice(&device), "current device");
  cuda_check(cudaDeviceGetAttribute(&sms, cudaDevAttrMultiProcessorCount, device),
             "device attribute");
  // One full wave: as many blocks as fit on the multiprocessors at once (3
  // a multiprocessor on sm_90 at 72-79 registers a thread), so no block
  // waits for a second round; each thread then sums ~30 cells at the paper's
  // box, enough loads in flight to hide the memory's latency.
  cuda_check(cudaOccupancyMaxActiveBlocksPerMultiprocessor(&per_sm, liquid_sums_kernel<Real>,
                                                           kLiquidSumThreads, 0),
             "occupancy of the liquid averages");
  device_->blocks = std::max(1, per_sm) * sms;
  cuda_check(cudaMalloc(&device_->partial, sizeof(LiquidSums) * device_->blocks),
             "cudaMalloc of the liquid averages' partial sums");
  device_->host_partial.resize(static_cast<std::size_t>(device_->blocks));
}

template <class Real>
GpuLiquidAverages<Real>::~GpuLiquidAverages() = default;

template <class Real>
LiquidSums GpuLiquidAverages<Real>::sums(const GpuFluidLattice<Real>& liquid,
                                         const std::vector<double>& centres, double radius) {
  Device& dev = *device_;
  const lattice::Extent& e = liquid.extent();
  const long cells = e.cells();
  if (dev.solid_cells != cells) {
    cudaFree(dev.solid);
    dev.solid = nullptr;
    dev.solid_cells = 0;
    cuda_check(cudaMalloc(&dev.solid, static_cast<std::size_t>(cells)),
               ("cudaMalloc of the solid mask (" + std::to_string(cells >> 20) + " MiB)").c_str());
    dev.solid_cells = cells;
  }
  const std::size_t spheres = centres.size() / 3;
  if (dev.centres_held < centres.size()) {
    cudaFree(dev.centres);
    dev.centres = nullptr;
    dev.centres_held = 0;
    cuda_check(cudaMalloc(&dev.centres, sizeof(double) * centres.size()),
               "cudaMalloc of the sphere centres");
    dev.centres_held = centres.size();
  }
  cuda_check(cudaMemsetAsync(dev.solid, 0, static_cast<std::size_t>(cells)), "clearing the mask");
  if (spheres > 0) {
    cuda_check(cudaMemcpy(dev.centres, centres.data(), sizeof(double) * 3 * spheres,
                          cudaMemcpyHostToDevice),
               "upload of the sphere centres");
    const int reach = static_cast<int>(std::ceil(radius));
    FLOCSIM_LAUNCH(static_cast<unsigned>(spheres), kLiquidSumThreads, 0, mark_solid_kernel)
    (dev.centres, radius, reach, e.nx, e.ny, e.nz, dev.solid);
    cuda_check(cudaGetLastError(), "launch of the solid mask");
  }
  LiquidSumInput<Real> in;
  in.slots = liquid.device_slots();
  in.even = liquid.next_step_is_even();
  const lattice::Vector3 body = liquid.body_force();
  in.body[0] = body.x;
  in.body[1] = body.y;
  in.body[2] = body.z;
  const DeviceForceField<const Real> field = liquid.device_force_field_if_set();
  for (int d = 0; d < 3; ++d) in.field[d] = field.component[d];
  in.solid = dev.solid;
  FLOCSIM_LAUNCH(static_cast<unsigned>(dev.blocks), kLiquidSumThreads, 0, liquid_sums_kernel<Real>)
  (in, dev.partial);
  cuda_check(cudaGetLastError(), "launch of the liquid averages");
  cuda_check(cudaMemcpy(dev.host_partial.data(), dev.partial, sizeof(LiquidSums) * dev.blocks,
                        cudaMemcpyDeviceToHost),
             "download of the liquid averages' partial sums");
  // the blocks in block order: the last fixed step of the sum
  LiquidSums total;
  for (const LiquidSums& b : dev.host_partial) observables::combine_liquid_sums(total, b);
  return total;
}

template <class Real>
int GpuLiquidAverages<Real>::blocks() const {
  return device_->blocks;
}

template class GpuLiquidAverages<float>;
template class GpuLiquidAverages<double>;

}  // namespace flocsim::gpu
