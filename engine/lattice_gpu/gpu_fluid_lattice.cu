// The GPU lattice's launchers: one thread per cell, a block per run of cells
// along x (coalesced loads and stores in each direction's slot array), the
// cell's work the shared kernel body aa_update_cell (engine/lattice/aa_cell.hpp),
// or aa_update_covered_cell where spheres partly cover the cell.
#include <algorithm>
#include <string>
#include <vector>

#include "engine/lattice/aa_cell.hpp"
#include "engine/lattice_gpu/cuda_check.hpp"
#include "engine/lattice_gpu/cuda_launch.hpp"
#include "engine/lattice_gpu/gpu_fluid_lattice.hpp"
#include "engine/lattice_gpu/gpu_runtime.hpp"

namespace flocsim::gpu {

using lattice::AaSlots;
using lattice::CollisionConstants;

namespace {

constexpr int kReductionThreads = 256;

// Threads per block along x: whole warps covering a row where it fits.
int threads_along_x(int nx) {
  const int warps = (nx + 31) / 32;
  return 32 * (warps < 16 ? warps : 16);
}

// kCoverage: partially saturated cells; a cell with eps > 0 takes the
// blended collision (the CPU blends whole rows with any covered cell, the
// rest of such a row with eps = 0: the plain collision to round-off) and
// leaves the density and momentum it saw for the coupling's exchange.
// At most 512 threads a block (threads_along_x): the bound makes the compiler
// keep to the 128 registers a thread that this allows (the double covered
// step needs 126), rather than fail at launch on a row longer than 480 cells.
template <class Real, bool kForceField, bool kCoverage>
__global__ void __launch_bounds__(512)
    aa_step_kernel(AaSlots<Real> s, bool even, CollisionConstants<Real> k, Real bx, Real by,
                   Real bz, const Real* __restrict__ Fx, const Real* __restrict__ Fy,
                   const Real* __restrict__ Fz, DeviceCoverage<Real> cover) {
  const int x = blockIdx.x * blockDim.x + threadIdx.x;
  if (x >= s.nx) return;
  const int y = blockIdx.y, z = blockIdx.z;
  const long c = lattice::aa_cell_index(s, x, y, z);
  Real fx = bx, fy = by, fz = bz;
  if constexpr (kForceField) {
    fx += Fx[c];
    fy += Fy[c];
    fz += Fz[c];
  }
  if constexpr (kCoverage) {
    const Real eps = cover.eps[c];
    if (eps > Real(0)) {
      Real rho, jx, jy, jz;
      lattice::aa_update_covered_cell(s, x, y, z, even, fx, fy, fz, eps, cover.solid_velocity[0][c],
                                      cover.solid_velocity[1][c], cover.solid_velocity[2][c], k,
                                      rho, jx, jy, jz);
      cover.density[c] = rho;
      cover.momentum[0][c] = jx;
      cover.momentum[1][c] = jy;
      cover.momentum[2][c] = jz;
      return;
    }
  }
  lattice::aa_update_cell(s, x, y, z, even, fx, fy, fz, k);
}

// Per block: the sum over its cells of the mass excess (sum of deviations)
// and of the momentum density j + F/2, in double, by a fixed tree.
template <class Real>
__global__ void moments_sum_kernel(AaSlots<Real> s, bool even, double bx, double by, double bz,
                                   const Real* __restrict__ Fx, const Real* __restrict__ Fy,
                                   const Real* __restrict__ Fz, double* __restrict__ partial) {
  __shared__ double sums[4][kReductionThreads];
  const long cells = static_cast<long>(s.nx) * s.ny * s.nz;
  double m = 0, px = 0, py = 0, pz = 0;
  for (long c = blockIdx.x * static_cast<long>(blockDim.x) + threadIdx.x; c < cells;
       c += static_cast<long>(gridDim.x) * blockDim.x) {
    const int x = static_cast<int>(c % s.nx);
    const int y = static_cast<int>((c / s.nx) % s.ny);
    const int z = static_cast<int>(c / (static_cast<long>(s.nx) * s.ny));
    Real f[d3q19::kQ];
    lattice::aa_load_cell(s, x, y, z, even, f);
    double d[d3q19::kQ];
    for (int i = 0; i < d3q19::kQ; ++i) d[i] = f[i];
    double cell = 0;
    for (int i = 0; i < d3q19::kQ; ++i) cell += d[i];
    m += cell;
    const double hx = 0.5 * (bx + (Fx ? static_cast<double>(Fx[c]) : 0.0));
    const double hy = 0.5 * (by + (Fy ? static_cast<double>(Fy[c]) : 0.0));
    const double hz = 0.5 * (bz + (Fz ? static_cast<double>(Fz[c]) : 0.0));
    px += d[1] - d[2] + d[7] - d[8] + d[9] - d[10] + d[11] - d[12] + d[13] - d[14] + hx;
    py += d[3] - d[4] + d[7] - d[8] - d[9] + d[10] + d[15] - d[16] + d[17] - d[18] + hy;
    pz += d[5] - d[6] + d[11] - d[12] - d[13] + d[14] + d[15] - d[16] - d[17] + d[18] + hz;
  }
  sums[0][threadIdx.x] = m;
  sums[1][threadIdx.x] = px;
  sums[2][threadIdx.x] = py;
  sums[3][threadIdx.x] = pz;
  __syncthreads();
  for (int half = kReductionThreads / 2; half > 0; half /= 2) {
    if (static_cast<int>(threadIdx.x) < half)
      for (int q = 0; q < 4; ++q) sums[q][threadIdx.x] += sums[q][threadIdx.x + half];
    __syncthreads();
  }
  if (threadIdx.x == 0)
    for (int q = 0; q < 4; ++q) partial[4 * blockIdx.x + q] = sums[q][0];
}

}  // namespace

template <class Real>
struct GpuFluidLattice<Real>::Device {
  Real* populations = nullptr;
  long stride = 0;
  Real* force[3] = {nullptr, nullptr, nullptr};
  Real* coverage = nullptr;   // 8 arrays of cells (DeviceCoverage), on first use
  double* partial = nullptr;  // reduction blocks x 4
  int reduction_blocks = 0;
  GpuDevice gpu;  // where all of it lives

  ~Device() {
    cudaFree(populations);
    for (Real* f : force) cudaFree(f);
    cudaFree(coverage);
    cudaFree(partial);
  }
};

template <class Real>
GpuFluidLattice<Real>::GpuFluidLattice(lattice::Extent extent, lattice::Relaxation relaxation)
    : extent_(extent), relaxation_(relaxation), device_(std::make_unique<Device>()) {
  relaxation_.check();
  // one row of cells per block along x: the grid's y and z are the rows
  if (extent.nx < 1 || extent.ny < 1 || extent.nz < 1 || extent.ny > 65535 || extent.nz > 65535)
    throw std::invalid_argument("GPU lattice: extent " + std::to_string(extent.nx) + " x " +
                                std::to_string(extent.ny) + " x " + std::to_string(extent.nz) +
                                ": each side must be at least 1, y and z at most 65535");
  device_->gpu = use_first_gpu();
  // Direction arrays start on 512-byte boundaries: every warp's loads of a
  // row segment fall in as few memory transactions as the shift allows.
  const long align = 512 / static_cast<long>(sizeof(Real));
  device_->stride = (extent.cells() + align - 1) / align * align;
  const std::size_t bytes = sizeof(Real) * static_cast<std::size_t>(device_->stride) * d3q19::kQ;
  cuda_check(cudaMalloc(&device_->populations, bytes),
             ("cudaMalloc of the populations (" + std::to_string(bytes >> 20) + " MiB)").c_str());
  cuda_check(cudaMemset(device_->populations, 0, bytes), "cudaMemset of the populations");
  int sms = 0;
  cuda_check(cudaDeviceGetAttribute(&sms, cudaDevAttrMultiProcessorCount, device_->gpu.index),
             "device attribute");
  device_->reduction_blocks = 4 * sms;
  cuda_check(cudaMalloc(&device_->partial, sizeof(double) * 4 * device_->reduction_blocks),
             "cudaMalloc of the reduction buffer");
}

template <class Real>
GpuFluidLattice<Real>::~GpuFluidLattice() = default;

template <class Real>
void GpuFluidLattice<Real>::upload(const lattice::FluidLattice<Real>& host) {
  const lattice::Extent& e = host.extent();
  if (e.nx != extent_.nx || e.ny != extent_.ny || e.nz != extent_.nz)
    throw std::invalid_argument("GPU lattice: upload from a lattice of another extent");
  cover_next_ = false;  // a new state: no coverage queued for the old one applies
  std::vector<Real> slots;
  for (int i = 0; i < d3q19::kQ; ++i) {
    host.save_slots(i, slots);
    cuda_check(cudaMemcpy(device_->populations + i * device_->stride, slots.data(),
                          sizeof(Real) * slots.size(), cudaMemcpyHostToDevice),
               "upload of the populations");
  }
  time_step_ = host.time_step();
  body_force_ = host.body_force();
  const auto field = host.force_field_if_set();
  if (!field.empty()) {
    upload_force_field(field);
  } else {
    // the host has none: neither has the device (a field left from before
    // would go on acting)
    for (Real*& f : device_->force) {
      cudaFree(f);
      f = nullptr;
    }
  }
}

template <class Real>
void GpuFluidLattice<Real>::download(lattice::FluidLattice<Real>& host) const {
  const lattice::Extent& e = host.extent();
  if (e.nx != extent_.nx || e.ny != extent_.ny || e.nz != extent_.nz)
    throw std::invalid_argument("GPU lattice: download into a lattice of another extent");
  std::vector<Real> slots(static_cast<std::size_t>(extent_.cells()));
  for (int i = 0; i < d3q19::kQ; ++i) {
    cuda_check(cudaMemcpy(slots.data(), device_->populations + i * device_->stride,
                          sizeof(Real) * slots.size(), cudaMemcpyDeviceToHost),
               "download of the populations");
    host.restore_slots(i, slots);
  }
  host.set_time_step(time_step_);
}

template <class Real>
void GpuFluidLattice<Real>::upload_force_field(const lattice::ForceFieldView<const Real>& field) {
  if (field.extent.nx != extent_.nx || field.extent.ny != extent_.ny ||
      field.extent.nz != extent_.nz || field.empty())
    throw std::invalid_argument("GPU lattice: a force field of another extent, or none");
  const std::size_t bytes = sizeof(Real) * static_cast<std::size_t>(extent_.cells());
  for (int d = 0; d < 3; ++d) {
    if (!device_->force[d])
      cuda_check(cudaMalloc(&device_->force[d], bytes), "cudaMalloc of the force field");
    cuda_check(cudaMemcpy(device_->force[d], field.component[d], bytes, cudaMemcpyHostToDevice),
               "upload of the force field");
  }
}

template <class Real>
void GpuFluidLattice<Real>::download_force_field(lattice::FluidLattice<Real>& host) const {
  const lattice::Extent& e = host.extent();
  if (e.nx != extent_.nx || e.ny != extent_.ny || e.nz != extent_.nz)
    throw std::invalid_argument("GPU lattice: force field into a lattice of another extent");
  // a device without a field (partially saturated cells) leaves a host
  // without one as it is: no zero field for the observables to read
  if (!device_->force[0] && !host.has_force_field()) return;
  const lattice::ForceFieldView<Real> field = host.force_field();
  const std::size_t count = static_cast<std::size_t>(extent_.cells());
  for (int d = 0; d < 3; ++d) {
    if (!device_->force[d]) {
      std::fill_n(field.component[d], count, Real(0));
      continue;
    }
    cuda_check(cudaMemcpy(field.component[d], device_->force[d], sizeof(Real) * count,
                          cudaMemcpyDeviceToHost),
               "download of the force field");
  }
}

template <class Real>
lattice::AaSlots<Real> GpuFluidLattice<Real>::device_slots() const {
  return {device_->populations, device_->stride, extent_.nx, extent_.ny, extent_.nz};
}

template <class Real>
DeviceForceField<Real> GpuFluidLattice<Real>::device_force_field() {
  const std::size_t bytes = sizeof(Real) * static_cast<std::size_t>(extent_.cells());
  DeviceForceField<Real> field;
  try {
    for (int d = 0; d < 3; ++d) {
      if (!device_->force[d]) {
        cuda_check(cudaMalloc(&device_->force[d], bytes), "cudaMalloc of the force field");
        cuda_check(cudaMemset(device_->force[d], 0, bytes), "cudaMemset of the force field");
      }
      field.component[d] = device_->force[d];
    }
  } catch (...) {
    // all three components or none: the step reads the field when the first is set
    for (Real*& component : device_->force) {
      cudaFree(component);
      component = nullptr;
    }
    throw;
  }
  return field;
}

template <class Real>
DeviceForceField<const Real> GpuFluidLattice<Real>::device_force_field_if_set() const {
  DeviceForceField<const Real> field;
  for (int d = 0; d < 3; ++d) field.component[d] = device_->force[d];
  return field;
}

template <class Real>
DeviceCoverage<Real> GpuFluidLattice<Real>::device_coverage() {
  const std::size_t cells = static_cast<std::size_t>(extent_.cells());
  if (!device_->coverage) {
    const std::size_t bytes = sizeof(Real) * 8 * cells;
    cuda_check(
        cudaMalloc(&device_->coverage, bytes),
        ("cudaMalloc of the cells' coverage (" + std::to_string(bytes >> 20) + " MiB)").c_str());
    cuda_check(cudaMemset(device_->coverage, 0, bytes), "cudaMemset of the cells' coverage");
  }
  Real* const p = device_->coverage;
  DeviceCoverage<Real> cover;
  cover.eps = p;
  cover.density = p + 4 * cells;
  for (int d = 0; d < 3; ++d) {
    cover.solid_velocity[d] = p + (1 + d) * cells;
    cover.momentum[d] = p + (5 + d) * cells;
  }
  return cover;
}

template <class Real>
void GpuFluidLattice<Real>::step() {
  const AaSlots<Real> s{device_->populations, device_->stride, extent_.nx, extent_.ny, extent_.nz};
  CollisionConstants<Real> k;
  k.omega_plus = static_cast<Real>(relaxation_.omega_plus());
  k.omega_minus = static_cast<Real>(relaxation_.omega_minus());
  k.force_plus = static_cast<Real>(1.0 - 0.5 * relaxation_.omega_plus());
  k.force_minus = static_cast<Real>(1.0 - 0.5 * relaxation_.omega_minus());
  const int threads = threads_along_x(extent_.nx);
  const dim3 grid((extent_.nx + threads - 1) / threads, extent_.ny, extent_.nz);
  const bool even = time_step_ % 2 == 0;
  const Real bx = static_cast<Real>(body_force_.x), by = static_cast<Real>(body_force_.y),
             bz = static_cast<Real>(body_force_.z);
  Real* const* F = device_->force;
  const bool field = F[0] != nullptr;
  if (cover_next_) {
    const DeviceCoverage<Real> cover = device_coverage();
    if (field) {
      FLOCSIM_LAUNCH(grid, threads, 0, aa_step_kernel<Real, true, true>)
      (s, even, k, bx, by, bz, F[0], F[1], F[2], cover);
    } else {
      FLOCSIM_LAUNCH(grid, threads, 0, aa_step_kernel<Real, false, true>)
      (s, even, k, bx, by, bz, nullptr, nullptr, nullptr, cover);
    }
  } else if (field) {
    FLOCSIM_LAUNCH(grid, threads, 0, aa_step_kernel<Real, true, false>)
    (s, even, k, bx, by, bz, F[0], F[1], F[2], DeviceCoverage<Real>{});
  } else {
    FLOCSIM_LAUNCH(grid, threads, 0, aa_step_kernel<Real, false, false>)
    (s, even, k, bx, by, bz, nullptr, nullptr, nullptr, DeviceCoverage<Real>{});
  }
  cuda_check(cudaGetLastError(), "launch of the lattice step");
  cover_next_ = false;  // one step: the coupling asks again
  ++time_step_;
}

template <class Real>
void GpuFluidLattice<Real>::synchronize() const {
  cuda_check(cudaDeviceSynchronize(), "lattice step");
}

namespace {
template <class Real>
std::vector<double> block_sums(const AaSlots<Real>& s, bool even, lattice::Vector3 body,
                               Real* const (&force)[3], double* partial, int blocks) {
  FLOCSIM_LAUNCH(blocks, kReductionThreads, 0, moments_sum_kernel<Real>)
  (s, even, body.x, body.y, body.z, force[0], force[1], force[2], partial);
  cuda_check(cudaGetLastError(), "launch of the mass and momentum sums");
  std::vector<double> host(4 * static_cast<std::size_t>(blocks));
  cuda_check(cudaMemcpy(host.data(), partial, sizeof(double) * host.size(), cudaMemcpyDeviceToHost),
             "mass and momentum sums");
  return host;
}
}  // namespace

template <class Real>
double GpuFluidLattice<Real>::total_mass() const {
  const AaSlots<Real> s{device_->populations, device_->stride, extent_.nx, extent_.ny, extent_.nz};
  const auto sums = block_sums(s, time_step_ % 2 == 0, body_force_, device_->force,
                               device_->partial, device_->reduction_blocks);
  double excess = 0;
  for (int b = 0; b < device_->reduction_blocks; ++b) excess += sums[4 * b];
  return static_cast<double>(extent_.cells()) + excess;
}

template <class Real>
lattice::Vector3 GpuFluidLattice<Real>::total_momentum() const {
  const AaSlots<Real> s{device_->populations, device_->stride, extent_.nx, extent_.ny, extent_.nz};
  const auto sums = block_sums(s, time_step_ % 2 == 0, body_force_, device_->force,
                               device_->partial, device_->reduction_blocks);
  lattice::Vector3 p;
  for (int b = 0; b < device_->reduction_blocks; ++b) {
    p.x += sums[4 * b + 1];
    p.y += sums[4 * b + 2];
    p.z += sums[4 * b + 3];
  }
  return p;
}

template <class Real>
std::size_t GpuFluidLattice<Real>::bytes_per_cell_update() const {
  return (2 * d3q19::kQ + (device_->force[0] ? 3 : 0)) * sizeof(Real);
}

template <class Real>
const GpuDevice& GpuFluidLattice<Real>::gpu() const {
  return device_->gpu;
}

template class GpuFluidLattice<float>;
template class GpuFluidLattice<double>;

}  // namespace flocsim::gpu
