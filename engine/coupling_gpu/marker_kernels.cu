// The immersed boundary's launcher on the GPU: one thread block per sphere,
// its threads over the sphere's box cells or its markers, each doing the
// work of a kernel body of engine/immersed_boundary/marker_body.hpp (the
// bodies the test suite holds to the CPU's ImmersedBoundary). The steps are
// those of the CPU's SphereWork::process, in the same order:
//   load     (rho, u*) of the box's cells from the populations, force zero;
//   force    direct forcing's Jacobi sweeps, or control forcing's one
//            correction, with a block barrier between interpolation and
//            spreading;
//   loads    force and torque, the reaction of the markers, summed per
//            block in a fixed tree;
//   inside   momentum and angular momentum of the liquid inside, likewise;
//   write    the box's force added to the lattice's force field.
// Spreading inside a box and adding boxes to the field use atomic additions:
// markers of one sphere share cells, and so do neighbouring spheres' boxes.
// The box's force sits in the block's shared memory where it fits (a = 6:
// 79 KB in float, 157 KB in double; an H100 block may have 227 KB), so the
// spreading's many additions stay on the multiprocessor; the liquid's
// velocity in the box is read from global memory (through L1).
// Floating-point addition is not associative, so the force field, and every
// load from the second step on, vary at round-off from run to run (the
// fixed-tree sums of loads and inside momenta add no variation of their own).
#include <cmath>
#include <string>
#include <vector>

#include "engine/coupling_gpu/marker_kernels.hpp"
#include "engine/coupling_gpu/sphere_buffers.cuh"
#include "engine/immersed_boundary/marker_body.hpp"
#include "engine/lattice/aa_cell.hpp"
#include "engine/lattice_gpu/cuda_check.hpp"
#include "engine/lattice_gpu/cuda_launch.hpp"

namespace flocsim::gpu {

using immersed_boundary::MarkerStencil;
using immersed_boundary::SphereBox;

namespace {

// Threads per sphere: about 3 markers and 20 box cells each at a = 6.
constexpr int kThreads = 256;

template <class Real>
struct SphereLaunch {
  lattice::AaSlots<Real> slots;
  bool even = true;
  Real body[3] = {0, 0, 0};
  Real* field[3] = {nullptr, nullptr, nullptr};
  const double* poses = nullptr;
  double* loads = nullptr;
  const double* offsets = nullptr;
  Real* box_velocity = nullptr;
  Real* box_force = nullptr;
  Real* marker_force = nullptr;  // direct: this step's; control: carried
  Real* marker_slip = nullptr;   // control only
  Real* increment = nullptr;     // F_m dV per marker, 4 lanes
  int markers = 0, B = 0, sweeps = 1;
  bool control = false;
  double input_radius = 0, dV = 0;
  Real integral_gain = 0, proportional_gain = 0;
};

struct AtomicAdd {
  template <class Real>
  __device__ void operator()(Real* address, Real value) const {
    atomicAdd(address, value);
  }
};

// Sums v over the block's threads (blockDim.x == kThreads, as launched), six
// numbers each, in a fixed tree; every thread receives the result.
__device__ void block_sum6(double (&v)[6], double (*shared)[kThreads]) {
  for (int q = 0; q < 6; ++q) shared[q][threadIdx.x] = v[q];
  __syncthreads();
  for (int half = kThreads / 2; half > 0; half /= 2) {
    if (static_cast<int>(threadIdx.x) < half)
      for (int q = 0; q < 6; ++q) shared[q][threadIdx.x] += shared[q][threadIdx.x + half];
    __syncthreads();
  }
  for (int q = 0; q < 6; ++q) v[q] = shared[q][0];
  __syncthreads();
}

template <class Real, int W>
__device__ void interpolate_and_force(const SphereLaunch<Real>& p, const SphereBox<Real>& box,
                                      const double (&centre)[3], const double (&up)[3],
                                      const double (&omega)[3], int s, bool with_force) {
  const Real dV = static_cast<Real>(p.dV);
  for (int m = threadIdx.x; m < p.markers; m += blockDim.x) {
    const double* r = p.offsets + 3 * m;
    const auto st = immersed_boundary::marker_stencil<Real, W>(centre, r, box.lo);
    double Ud[3];
    immersed_boundary::surface_velocity_at(up, omega, r, Ud);
    const Real U[3] = {static_cast<Real>(Ud[0]), static_cast<Real>(Ud[1]),
                       static_cast<Real>(Ud[2])};
    Real rho_v[4];
    immersed_boundary::interpolate_at_marker(box, st, with_force, rho_v);
    Real* F = p.marker_force + 4 * (static_cast<long>(s) * p.markers + m);
    Real* inc = p.increment + 4 * (static_cast<long>(s) * p.markers + m);
    Real dF[3];
    if (p.control) {
      Real* e = p.marker_slip + 4 * (static_cast<long>(s) * p.markers + m);
      Real slip[3] = {e[1], e[2], e[3]};
      immersed_boundary::control_forcing_increment(rho_v, U, slip, p.integral_gain,
                                                   p.proportional_gain, dF);
      for (int d = 0; d < 3; ++d) {
        e[1 + d] = slip[d];
        F[1 + d] += dF[d];
        inc[1 + d] = F[1 + d] * dV;
      }
    } else {
      immersed_boundary::direct_forcing_increment(rho_v, U, dF);
      for (int d = 0; d < 3; ++d) {
        F[1 + d] += dF[d];
        inc[1 + d] = dF[d] * dV;
      }
    }
  }
}

template <class Real, int W>
__device__ void spread_increments(const SphereLaunch<Real>& p, const SphereBox<Real>& box,
                                  const double (&centre)[3], int s) {
  for (int m = threadIdx.x; m < p.markers; m += blockDim.x) {
    const auto st = immersed_boundary::marker_stencil<Real, W>(centre, p.offsets + 3 * m, box.lo);
    const Real* inc = p.increment + 4 * (static_cast<long>(s) * p.markers + m);
    const Real F_dV[3] = {inc[1], inc[2], inc[3]};
    immersed_boundary::spread_from_marker(box, st, F_dV, AtomicAdd{});
  }
}

template <class Real>
__device__ void zero_box_force(const SphereBox<Real>& box) {
  const int numbers = 4 * box.B * box.B * box.B;  // B^3 is a few thousand
  for (int c = threadIdx.x; c < numbers; c += blockDim.x) box.force[c] = 0;
}

// Float: two blocks per multiprocessor (2 x 91 KB of shared memory), so at
// most 128 registers a thread (no spills); double: one block fits (169 KB),
// and the registers are not capped below what it needs.
// InShared: the box's force in the block's shared memory (a pointer the
// compiler knows to be shared, so the spreading's additions are shared-memory
// atomics), else in the global scratch.
template <class Real, int W, bool InShared>
__global__ void __launch_bounds__(kThreads, sizeof(Real) == 4 ? 2 : 1)
    sphere_kernel(SphereLaunch<Real> p) {
  __shared__ double shared[6][kThreads];
  FLOCSIM_DYNAMIC_SHARED(unsigned char, box_shared);
  const int s = blockIdx.x;
  const double* pose = p.poses + kPoseNumbers * s;
  const double centre[3] = {pose[0], pose[1], pose[2]};
  const double up[3] = {pose[3], pose[4], pose[5]};
  const double omega[3] = {pose[6], pose[7], pose[8]};
  const int B = p.B;
  const int cells = B * B * B;  // a few thousand: int arithmetic in the loops
  SphereBox<Real> box;
  box.B = B;
  box.velocity = p.box_velocity + 4 * static_cast<long>(cells) * s;
  // The spreading's atomic additions go to shared memory where the box fits
  // (a = 6 in float: 79 KB; in double 157 KB), else to the global scratch.
  if constexpr (InShared)
    box.force = reinterpret_cast<Real*>(box_shared);
  else
    box.force = p.box_force + 4 * static_cast<long>(cells) * s;
  for (int d = 0; d < 3; ++d) box.lo[d] = static_cast<int>(::floor(centre[d] - p.input_radius)) - 2;

  // load: the velocity the next collision would see without per-cell force
  for (int c = threadIdx.x; c < cells; c += blockDim.x) {
    const int i = c % B, j = (c / B) % B, k = c / (B * B);
    const int x = immersed_boundary::wrap_coordinate(box.lo[0] + i, p.slots.nx);
    const int y = immersed_boundary::wrap_coordinate(box.lo[1] + j, p.slots.ny);
    const int z = immersed_boundary::wrap_coordinate(box.lo[2] + k, p.slots.nz);
    Real f[d3q19::kQ];
    lattice::aa_load_cell(p.slots, x, y, z, p.even, f);
    Real* u = box.velocity + 4 * c;
    lattice::cell_moments(f, p.body[0], p.body[1], p.body[2], u[0], u[1], u[2], u[3]);
    for (int q = 0; q < 4; ++q) box.force[4 * c + q] = 0;
  }
  __syncthreads();

  // force
  if (p.control) {
    spread_increments<Real, W>(p, box, centre, s);  // increments hold F_last dV
    __syncthreads();
    interpolate_and_force<Real, W>(p, box, centre, up, omega, s, true);
    __syncthreads();
    zero_box_force(box);
    __syncthreads();
    spread_increments<Real, W>(p, box, centre, s);
    __syncthreads();
  } else {
    for (int m = threadIdx.x; m < p.markers; m += blockDim.x)
      for (int q = 0; q < 4; ++q)
        p.marker_force[4 * (static_cast<long>(s) * p.markers + m) + q] = 0;
    for (int sweep = 0; sweep < p.sweeps; ++sweep) {
      interpolate_and_force<Real, W>(p, box, centre, up, omega, s, sweep > 0);
      __syncthreads();
      spread_increments<Real, W>(p, box, centre, s);
      __syncthreads();
    }
  }

  // loads: H = -sum F_m dV, T = -sum r_m x F_m dV
  double load[6] = {0, 0, 0, 0, 0, 0};
  for (int m = threadIdx.x; m < p.markers; m += blockDim.x) {
    const Real* F = p.marker_force + 4 * (static_cast<long>(s) * p.markers + m);
    const double Fm[3] = {static_cast<double>(F[1]) * p.dV, static_cast<double>(F[2]) * p.dV,
                          static_cast<double>(F[3]) * p.dV};
    const double* r = p.offsets + 3 * m;
    load[0] -= Fm[0];
    load[1] -= Fm[1];
    load[2] -= Fm[2];
    load[3] -= r[1] * Fm[2] - r[2] * Fm[1];
    load[4] -= r[2] * Fm[0] - r[0] * Fm[2];
    load[5] -= r[0] * Fm[1] - r[1] * Fm[0];
  }
  block_sum6(load, shared);

  // inside: the liquid's momentum and angular momentum
  double inside[6] = {0, 0, 0, 0, 0, 0};
  for (int c = threadIdx.x; c < cells; c += blockDim.x) {
    const int i = c % B, j = (c / B) % B, k = c / (B * B);
    double P[3], L[3];
    if (immersed_boundary::inside_share(box, i, j, k, centre, p.input_radius, P, L))
      for (int d = 0; d < 3; ++d) {
        inside[d] += P[d];
        inside[3 + d] += L[d];
      }
  }
  block_sum6(inside, shared);
  if (threadIdx.x == 0) {
    double* out = p.loads + kLoadNumbers * s;
    for (int q = 0; q < 6; ++q) out[q] = load[q];
    for (int q = 0; q < 6; ++q) out[6 + q] = inside[q];
  }

  // write: the box's force onto the lattice's field
  for (int c = threadIdx.x; c < cells; c += blockDim.x) {
    const Real* F = box.force + 4 * c;
    if (F[1] == 0 && F[2] == 0 && F[3] == 0) continue;
    const int i = c % B, j = (c / B) % B, k = c / (B * B);
    const int x = immersed_boundary::wrap_coordinate(box.lo[0] + i, p.slots.nx);
    const int y = immersed_boundary::wrap_coordinate(box.lo[1] + j, p.slots.ny);
    const int z = immersed_boundary::wrap_coordinate(box.lo[2] + k, p.slots.nz);
    const long cell = lattice::aa_cell_index(p.slots, x, y, z);
    for (int d = 0; d < 3; ++d) atomicAdd(p.field[d] + cell, F[1 + d]);
  }
}

// Control forcing, before the step's correction: each marker's increment
// holds its carried force times dV (spread again to give v = u* + F_last / (2 rho)).
template <class Real>
__global__ void carried_increment_kernel(Real* increment, const Real* carried, long lanes,
                                         Real dV) {
  const long q = blockIdx.x * static_cast<long>(blockDim.x) + threadIdx.x;
  if (q < lanes) increment[q] = carried[q] * dV;
}

}  // namespace

template <class Real>
struct MarkerKernels<Real>::Device {
  double* offsets = nullptr;
  Real *box_velocity = nullptr, *box_force = nullptr;
  Real *marker_force = nullptr, *marker_slip = nullptr, *increment = nullptr;
  std::size_t box_held = 0, box_force_held = 0, force_held = 0, slip_held = 0, inc_held = 0;
  double *poses = nullptr, *loads = nullptr;  // device
  std::size_t poses_held = 0, loads_held = 0;
  PinnedSphereBuffers pinned;        // the poses in, the loads out
  std::size_t spheres = 0;           // of the last apply(): the carried markers' count
  std::size_t shared_per_block = 0;  // dynamic shared memory the sphere kernel may take

  ~Device() {
    cudaFree(offsets);
    cudaFree(box_velocity);
    cudaFree(box_force);
    cudaFree(marker_force);
    cudaFree(marker_slip);
    cudaFree(increment);
    cudaFree(poses);
    cudaFree(loads);
  }
};

template <class Real>
MarkerKernels<Real>::MarkerKernels(MarkerSetup setup)
    : setup_(std::move(setup)), device_(std::make_unique<Device>()) {
  if (setup_.markers < 1 || setup_.offsets.size() != 3 * static_cast<std::size_t>(setup_.markers))
    throw std::invalid_argument("GPU immersed boundary: need 3 offsets per marker");
  if (setup_.kernel_width != 2 && setup_.kernel_width != 3)
    throw std::invalid_argument("GPU immersed boundary: kernel width " +
                                std::to_string(setup_.kernel_width) + ": must be 2 or 3");
  // Shared memory for a box's force: what a block may opt into, less the
  // kernel's static reduction arrays; granted to both kernel widths.
  int device = 0, optin = 0;
  cuda_check(cudaGetDevice(&device), "current device");
  cuda_check(cudaDeviceGetAttribute(&optin, cudaDevAttrMaxSharedMemoryPerBlockOptin, device),
             "device attribute");
  const std::size_t reduction = sizeof(double) * 6 * kThreads;
  const std::size_t box_bytes =
      sizeof(Real) * 4 * static_cast<std::size_t>(setup_.box) * setup_.box * setup_.box;
  if (static_cast<std::size_t>(optin) >= reduction + box_bytes) {
    cuda_check(cudaFuncSetAttribute(sphere_kernel<Real, 3, true>,
                                    cudaFuncAttributeMaxDynamicSharedMemorySize,
                                    static_cast<int>(box_bytes)),
               "shared memory of the immersed boundary");
    cuda_check(cudaFuncSetAttribute(sphere_kernel<Real, 2, true>,
                                    cudaFuncAttributeMaxDynamicSharedMemorySize,
                                    static_cast<int>(box_bytes)),
               "shared memory of the immersed boundary");
    device_->shared_per_block = box_bytes;
  }
  cuda_check(cudaMalloc(&device_->offsets, sizeof(double) * setup_.offsets.size()),
             "cudaMalloc of the marker offsets");
  cuda_check(cudaMemcpy(device_->offsets, setup_.offsets.data(),
                        sizeof(double) * setup_.offsets.size(), cudaMemcpyHostToDevice),
             "upload of the marker offsets");
}

template <class Real>
MarkerKernels<Real>::~MarkerKernels() = default;

template <class Real>
void MarkerKernels<Real>::clear(GpuFluidLattice<Real>& liquid) {
  const auto field = liquid.device_force_field();
  const std::size_t bytes = sizeof(Real) * static_cast<std::size_t>(liquid.extent().cells());
  for (Real* c : field.component) cuda_check(cudaMemset(c, 0, bytes), "clearing the force field");
}

template <class Real>
void MarkerKernels<Real>::apply(GpuFluidLattice<Real>& liquid, const std::vector<double>& poses,
                                std::vector<double>& loads) {
  Device& dev = *device_;
  const std::size_t n = poses.size() / kPoseNumbers;
  const std::size_t M = static_cast<std::size_t>(setup_.markers);
  const std::size_t B = static_cast<std::size_t>(setup_.box);
  loads.assign(kLoadNumbers * n, 0.0);
  clear(liquid);
  if (n == 0) return;
  device_resize(dev.box_velocity, dev.box_held, 4 * B * B * B * n, "the sphere boxes");
  const std::size_t box_bytes = sizeof(Real) * 4 * B * B * B;
  const bool in_shared = box_bytes <= dev.shared_per_block;
  if (!in_shared)
    device_resize(dev.box_force, dev.box_force_held, 4 * B * B * B * n, "the sphere boxes' force");
  device_resize(dev.increment, dev.inc_held, 4 * M * n, "the marker increments");
  if (setup_.control && dev.spheres != n) {  // a new sphere set: no carried force yet
    dev.force_held = dev.slip_held = 0;
    cudaFree(dev.marker_force);
    cudaFree(dev.marker_slip);
    dev.marker_force = dev.marker_slip = nullptr;
  }
  const bool fresh = dev.force_held < 4 * M * n;
  device_resize(dev.marker_force, dev.force_held, 4 * M * n, "the marker forces");
  if (setup_.control) {
    device_resize(dev.marker_slip, dev.slip_held, 4 * M * n, "the marker slips");
    if (fresh) {
      cuda_check(cudaMemset(dev.marker_force, 0, sizeof(Real) * 4 * M * n), "marker forces");
      cuda_check(cudaMemset(dev.marker_slip, 0, sizeof(Real) * 4 * M * n), "marker slips");
    }
  }
  dev.spheres = n;
  device_resize(dev.poses, dev.poses_held, kPoseNumbers * n, "the sphere poses");
  device_resize(dev.loads, dev.loads_held, kLoadNumbers * n, "the sphere loads");
  dev.pinned.reserve(n, kPoseNumbers, kLoadNumbers, "the sphere poses and loads");
  std::copy(poses.begin(), poses.end(), dev.pinned.to_device);
  cuda_check(cudaMemcpyAsync(dev.poses, dev.pinned.to_device, sizeof(double) * kPoseNumbers * n,
                             cudaMemcpyHostToDevice),
             "upload of the sphere poses");

  SphereLaunch<Real> p;
  p.slots = liquid.device_slots();
  p.even = liquid.next_step_is_even();
  const lattice::Vector3 body = liquid.body_force();
  p.body[0] = static_cast<Real>(body.x);
  p.body[1] = static_cast<Real>(body.y);
  p.body[2] = static_cast<Real>(body.z);
  const auto field = liquid.device_force_field();
  for (int d = 0; d < 3; ++d) p.field[d] = field.component[d];
  p.poses = dev.poses;
  p.loads = dev.loads;
  p.offsets = dev.offsets;
  p.box_velocity = dev.box_velocity;
  p.box_force = dev.box_force;
  p.marker_force = dev.marker_force;
  p.marker_slip = dev.marker_slip;
  p.increment = dev.increment;
  p.markers = setup_.markers;
  p.B = setup_.box;
  p.sweeps = setup_.sweeps;
  p.control = setup_.control;
  p.input_radius = setup_.input_radius;
  p.dV = setup_.marker_volume;
  p.integral_gain = static_cast<Real>(setup_.integral_gain);
  p.proportional_gain = static_cast<Real>(setup_.proportional_gain);
  if (setup_.control) {
    const long lanes = static_cast<long>(4 * M * n);
    FLOCSIM_LAUNCH(static_cast<unsigned>((lanes + 255) / 256), 256, 0,
                   carried_increment_kernel<Real>)
    (dev.increment, dev.marker_force, lanes, static_cast<Real>(setup_.marker_volume));
    cuda_check(cudaGetLastError(), "launch of the carried increments");
  }
  const unsigned blocks = static_cast<unsigned>(n);
  if (in_shared) {
    if (setup_.kernel_width == 3)
      FLOCSIM_LAUNCH(blocks, kThreads, box_bytes, sphere_kernel<Real, 3, true>)(p);
    else
      FLOCSIM_LAUNCH(blocks, kThreads, box_bytes, sphere_kernel<Real, 2, true>)(p);
  } else {
    if (setup_.kernel_width == 3)
      FLOCSIM_LAUNCH(blocks, kThreads, 0, sphere_kernel<Real, 3, false>)(p);
    else
      FLOCSIM_LAUNCH(blocks, kThreads, 0, sphere_kernel<Real, 2, false>)(p);
  }
  cuda_check(cudaGetLastError(), "launch of the immersed boundary");
  cuda_check(cudaMemcpyAsync(dev.pinned.from_device, dev.loads, sizeof(double) * kLoadNumbers * n,
                             cudaMemcpyDeviceToHost),
             "download of the sphere loads");
  cuda_check(cudaDeviceSynchronize(), "immersed boundary");
  std::copy(dev.pinned.from_device, dev.pinned.from_device + kLoadNumbers * n, loads.begin());
}

namespace {
template <class Real>
std::vector<Real> download(const Real* from, std::size_t count) {
  std::vector<Real> out(count);
  if (count)
    cuda_check(cudaMemcpy(out.data(), from, sizeof(Real) * count, cudaMemcpyDeviceToHost),
               "download of the marker state");
  return out;
}
}  // namespace

template <class Real>
std::vector<Real> MarkerKernels<Real>::marker_force() const {
  if (!setup_.control) return {};
  return download(device_->marker_force, 4 * setup_.markers * device_->spheres);
}

template <class Real>
std::vector<Real> MarkerKernels<Real>::marker_slip() const {
  if (!setup_.control) return {};
  return download(device_->marker_slip, 4 * setup_.markers * device_->spheres);
}

template <class Real>
void MarkerKernels<Real>::restore(const std::vector<Real>& force, const std::vector<Real>& slip) {
  if (!setup_.control) return;
  const std::size_t per_sphere = 4 * static_cast<std::size_t>(setup_.markers);
  if (force.size() != slip.size() || force.size() % per_sphere != 0)
    throw std::invalid_argument(
        "GPU immersed boundary: carried marker force and slip need 4 numbers per marker of "
        "whole spheres in both");
  Device& dev = *device_;
  const std::size_t n = force.size() / per_sphere;
  if (force.empty()) {  // no spheres: nothing carried
    dev.spheres = 0;
    return;
  }
  device_resize(dev.marker_force, dev.force_held, force.size(), "the marker forces");
  device_resize(dev.marker_slip, dev.slip_held, slip.size(), "the marker slips");
  cuda_check(cudaMemcpy(dev.marker_force, force.data(), sizeof(Real) * force.size(),
                        cudaMemcpyHostToDevice),
             "upload of the marker forces");
  cuda_check(
      cudaMemcpy(dev.marker_slip, slip.data(), sizeof(Real) * slip.size(), cudaMemcpyHostToDevice),
      "upload of the marker slips");
  dev.spheres = n;
}

template class MarkerKernels<float>;
template class MarkerKernels<double>;

}  // namespace flocsim::gpu
