// The partially saturated cells' launchers on the GPU: one thread block per
// sphere, its threads over the sphere's cube of B^3 cells, each doing the
// work of a kernel body of engine/partially_saturated/covered_cell_body.hpp
// (the bodies the test suite holds to the CPU's PartiallySaturatedCells).
// Around the lattice's step (GpuFluidLattice::cover_next_step: a cell with
// eps > 0 takes the blended collision and leaves rho and rho u):
//   cover     before the step: each covered cell's eps_k and eps_k u_k added
//             into the lattice's per-cell eps and V;
//   exchange  after it: each covered cell's share of dP = B (rho (u_s - u) - F),
//             r x dP and the inside momenta eps_k rho u, r x eps_k rho u,
//             summed per block in a fixed tree, in double;
//   clear     then: eps and V back to zero on the spheres' cells (a second
//             launch, so that no block clears a cell another still reads).
// The cover's additions are atomic: spheres whose reaches overlap share
// cells. A cell one or two spheres cover gets the same sum in any order
// (0 + a + b is a + b either way), bit for bit as the CPU's; where three or
// more cover one cell the order, and so the last bit of eps and V there,
// varies from run to run. The exchange's sums add no variation of their own.
#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/coupling_gpu/covered_cell_kernels.hpp"
#include "engine/coupling_gpu/sphere_buffers.cuh"
#include "engine/lattice_gpu/cuda_check.hpp"
#include "engine/lattice_gpu/cuda_launch.hpp"
#include "engine/partially_saturated/covered_cell_body.hpp"

namespace flocsim::gpu {

using partially_saturated::CoveredCell;
using partially_saturated::CoveringGeometry;
using partially_saturated::CoveringSphere;
using partially_saturated::unpack_covering_sphere;

namespace {

constexpr int kThreads = 256;  // per sphere: about 20 box cells each at a = 6

template <class Real>
struct CoverLaunch {
  CoveringGeometry g;
  const double* spheres = nullptr;  // kCoveringNumbers per sphere
  double* exchange = nullptr;       // kExchangeNumbers per sphere
  DeviceCoverage<Real> cover;
  const Real* field[3] = {nullptr, nullptr, nullptr};  // null where none is set
  double body[3] = {0, 0, 0};
};

__device__ long cell_index(const CoveringGeometry& g, const CoveredCell& c) {
  return static_cast<long>(c.x) +
         static_cast<long>(g.n[0]) * (c.y + static_cast<long>(g.n[1]) * c.z);
}

template <class Real>
__global__ void __launch_bounds__(kThreads) cover_kernel(CoverLaunch<Real> p) {
  const CoveringSphere sphere = unpack_covering_sphere(p.spheres + kCoveringNumbers * blockIdx.x);
  const int B = p.g.B;
  const int cells = B * B * B;  // a few thousand: int arithmetic
  for (int c = threadIdx.x; c < cells; c += blockDim.x) {
    const int i = c % B, j = (c / B) % B, k = c / (B * B);
    CoveredCell cell;
    if (!partially_saturated::covered_cell<true>(p.g, sphere, i, j, k, cell) || !(cell.eps > 0))
      continue;
    double v[3];
    partially_saturated::solid_velocity_share(sphere, cell, v);
    const long at = cell_index(p.g, cell);
    atomicAdd(p.cover.eps + at, static_cast<Real>(cell.eps));
    for (int d = 0; d < 3; ++d) atomicAdd(p.cover.solid_velocity[d] + at, static_cast<Real>(v[d]));
  }
}

template <class Real>
__global__ void __launch_bounds__(kThreads) exchange_kernel(CoverLaunch<Real> p) {
  __shared__ double shared[kExchangeNumbers][kThreads];
  const CoveringSphere sphere = unpack_covering_sphere(p.spheres + kCoveringNumbers * blockIdx.x);
  const int B = p.g.B;
  const int cells = B * B * B;
  double sums[kExchangeNumbers];
  for (int q = 0; q < kExchangeNumbers; ++q) sums[q] = 0;
  for (int c = threadIdx.x; c < cells; c += blockDim.x) {
    const int i = c % B, j = (c / B) % B, k = c / (B * B);
    CoveredCell cell;
    if (!partially_saturated::covered_cell<true>(p.g, sphere, i, j, k, cell) || !(cell.eps > 0))
      continue;
    const long at = cell_index(p.g, cell);
    const double V[3] = {p.cover.solid_velocity[0][at], p.cover.solid_velocity[1][at],
                         p.cover.solid_velocity[2][at]};
    const double J[3] = {p.cover.momentum[0][at], p.cover.momentum[1][at], p.cover.momentum[2][at]};
    double f[3] = {p.body[0], p.body[1], p.body[2]};
    if (p.field[0])
      for (int d = 0; d < 3; ++d) f[d] += static_cast<double>(p.field[d][at]);
    double q[kExchangeNumbers];
    partially_saturated::exchange_terms(cell, p.cover.eps[at], V, p.cover.density[at], J, f, q);
    for (int r = 0; r < kExchangeNumbers; ++r) sums[r] += q[r];
  }
  // a fixed tree over the block's threads
  for (int q = 0; q < kExchangeNumbers; ++q) shared[q][threadIdx.x] = sums[q];
  __syncthreads();
  for (int half = kThreads / 2; half > 0; half /= 2) {
    if (static_cast<int>(threadIdx.x) < half)
      for (int q = 0; q < kExchangeNumbers; ++q)
        shared[q][threadIdx.x] += shared[q][threadIdx.x + half];
    __syncthreads();
  }
  if (threadIdx.x < kExchangeNumbers)
    p.exchange[kExchangeNumbers * blockIdx.x + threadIdx.x] = shared[threadIdx.x][0];
}

template <class Real>
__global__ void __launch_bounds__(kThreads) clear_kernel(CoverLaunch<Real> p) {
  const CoveringSphere sphere = unpack_covering_sphere(p.spheres + kCoveringNumbers * blockIdx.x);
  const int B = p.g.B;
  const int cells = B * B * B;
  for (int c = threadIdx.x; c < cells; c += blockDim.x) {
    const int i = c % B, j = (c / B) % B, k = c / (B * B);
    CoveredCell cell;
    if (!partially_saturated::covered_cell<false>(p.g, sphere, i, j, k, cell)) continue;
    const long at = cell_index(p.g, cell);
    p.cover.eps[at] = 0;
    for (int d = 0; d < 3; ++d) p.cover.solid_velocity[d][at] = 0;
  }
}

}  // namespace

template <class Real>
struct CoveredCellKernels<Real>::Device {
  double *spheres = nullptr, *exchange = nullptr;  // device
  std::size_t spheres_held = 0, exchange_held = 0;
  PinnedSphereBuffers pinned;  // the covering spheres in, their exchange out
  std::size_t covered = 0;     // spheres of the pending or last cover()
  bool pending = false;        // cover() queued, exchange() not yet run

  ~Device() {
    cudaFree(spheres);
    cudaFree(exchange);
  }
};

template <class Real>
CoveredCellKernels<Real>::CoveredCellKernels(double input_radius)
    : input_radius_(input_radius), device_(std::make_unique<Device>()) {
  int device = 0;
  cuda_check(cudaGetDevice(&device), "current device");
}

template <class Real>
CoveredCellKernels<Real>::~CoveredCellKernels() = default;

namespace {
template <class Real>
CoverLaunch<Real> launch_of(GpuFluidLattice<Real>& liquid, double input_radius,
                            const double* spheres, double* exchange) {
  CoverLaunch<Real> p;
  p.g = CoveringGeometry(input_radius, liquid.extent());
  p.spheres = spheres;
  p.exchange = exchange;
  p.cover = liquid.device_coverage();
  const DeviceForceField<const Real> field = liquid.device_force_field_if_set();
  for (int d = 0; d < 3; ++d) p.field[d] = field.component[d];
  const lattice::Vector3 body = liquid.body_force();
  p.body[0] = body.x;
  p.body[1] = body.y;
  p.body[2] = body.z;
  return p;
}
}  // namespace

template <class Real>
void CoveredCellKernels<Real>::cover(GpuFluidLattice<Real>& liquid,
                                     const std::vector<double>& spheres) {
  Device& dev = *device_;
  if (dev.pending) withdraw(liquid);
  const std::size_t n = spheres.size() / kCoveringNumbers;
  dev.covered = n;
  dev.pending = true;
  liquid.cover_next_step();
  if (n == 0) return;
  device_resize(dev.spheres, dev.spheres_held, kCoveringNumbers * n, "the covering spheres");
  device_resize(dev.exchange, dev.exchange_held, kExchangeNumbers * n, "the spheres' exchange");
  dev.pinned.reserve(n, kCoveringNumbers, kExchangeNumbers, "the covering spheres");
  std::copy(spheres.begin(), spheres.begin() + kCoveringNumbers * n, dev.pinned.to_device);
  cuda_check(cudaMemcpyAsync(dev.spheres, dev.pinned.to_device,
                             sizeof(double) * kCoveringNumbers * n, cudaMemcpyHostToDevice),
             "upload of the covering spheres");
  const CoverLaunch<Real> p = launch_of(liquid, input_radius_, dev.spheres, dev.exchange);
  FLOCSIM_LAUNCH(static_cast<unsigned>(n), kThreads, 0, cover_kernel<Real>)(p);
  cuda_check(cudaGetLastError(), "launch of the cells' coverage");
}

template <class Real>
void CoveredCellKernels<Real>::exchange(GpuFluidLattice<Real>& liquid,
                                        std::vector<double>& exchange) {
  Device& dev = *device_;
  // on cleared coverage the kernel would read an older step's density and
  // momentum and give loads that look valid: refuse instead
  if (!dev.pending)
    throw std::logic_error(
        "partially saturated cells on the GPU: exchange() without a cover() since the last one");
  const std::size_t n = dev.covered;
  exchange.assign(kExchangeNumbers * n, 0.0);
  dev.pending = false;
  if (n == 0) return;
  const CoverLaunch<Real> p = launch_of(liquid, input_radius_, dev.spheres, dev.exchange);
  FLOCSIM_LAUNCH(static_cast<unsigned>(n), kThreads, 0, exchange_kernel<Real>)(p);
  cuda_check(cudaGetLastError(), "launch of the cells' exchange");
  FLOCSIM_LAUNCH(static_cast<unsigned>(n), kThreads, 0, clear_kernel<Real>)(p);
  cuda_check(cudaGetLastError(), "launch of the coverage's clearing");
  cuda_check(cudaMemcpyAsync(dev.pinned.from_device, dev.exchange,
                             sizeof(double) * kExchangeNumbers * n, cudaMemcpyDeviceToHost),
             "download of the spheres' exchange");
  cuda_check(cudaDeviceSynchronize(), "partially saturated cells");
  std::copy(dev.pinned.from_device, dev.pinned.from_device + kExchangeNumbers * n,
            exchange.begin());
}

template <class Real>
void CoveredCellKernels<Real>::withdraw(GpuFluidLattice<Real>& liquid) {
  Device& dev = *device_;
  if (!dev.pending) return;
  dev.pending = false;
  liquid.cancel_cover();
  if (dev.covered == 0) return;
  const CoverLaunch<Real> p = launch_of(liquid, input_radius_, dev.spheres, dev.exchange);
  FLOCSIM_LAUNCH(static_cast<unsigned>(dev.covered), kThreads, 0, clear_kernel<Real>)(p);
  cuda_check(cudaGetLastError(), "launch of the coverage's clearing");
  cuda_check(cudaDeviceSynchronize(), "partially saturated cells");
}

template class CoveredCellKernels<float>;
template class CoveredCellKernels<double>;

}  // namespace flocsim::gpu
