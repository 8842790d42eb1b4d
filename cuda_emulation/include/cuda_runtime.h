#pragma once
// The CUDA runtime, emulated on the CPU, for testing the CUDA back-end's
// launchers where no GPU is lent (docs/gpu.md, "Testing without a GPU").
//
// A build with FLOCSIM_CUDA_EMULATION compiles the back-end's .cu files as
// C++ against this header instead of the toolkit's: the same launchers, the
// same kernels, the same copies and reductions, run by cuda_emulation.cpp one
// block at a time, each of the block's threads a fiber of its own that gives
// way only at __syncthreads (a legal CUDA schedule). So the GPU tests run here
// in full: what they check of indexing, launch shapes, barriers, copy sizes
// and directions and the fixed-order sums is checked before any GPU time.
// What it cannot show: speed, and the interleavings of real warps (a race
// between threads with no barrier between them runs in one order here; the
// emulation can run the threads in reverse, FLOCSIM_CUDA_EMULATION_ORDER=
// reverse, to see a second).
//
// Only what the back-end uses is here. Misuse a GPU punishes, or may, is
// refused here, with a message on stderr: launch shapes beyond the hardware's
// limits, dynamic shared memory over 48 KB without the kernel's attribute,
// copies that fall outside a device allocation or go the wrong way, a barrier
// that only some of a block's threads reach. Fresh device, pinned and dynamic
// shared memory, and the fibers' stacks, are filled with NaN bytes (a GPU's
// are not zeroed either); static __shared__ arrays are not (docs/gpu.md).
#include <cstddef>
#include <cstring>
#include <functional>
#include <tuple>
#include <utility>

#define FLOCSIM_CUDA_EMULATION 1

// ---- the kernel language ---------------------------------------------------

#define __global__
#define __device__
#define __host__
#define __forceinline__ inline
#define __launch_bounds__(...)
#define __align__(n) __attribute__((aligned(n)))
// One block runs at a time, so a block's shared arrays are the function's
// statics: every thread of the block sees the same ones.
#define __shared__ static

struct dim3 {
  unsigned x = 1, y = 1, z = 1;
  constexpr dim3(unsigned x_ = 1, unsigned y_ = 1, unsigned z_ = 1) : x(x_), y(y_), z(z_) {}
};
struct alignas(16) double2 {
  double x, y;
};
struct alignas(8) float2 {
  float x, y;
};

// The running thread's indices, set by the emulation before it resumes a
// thread (one OS thread runs every emulated thread, launches one at a time).
extern dim3 threadIdx, blockIdx, blockDim, gridDim;

namespace flocsim_cuda_emulation {
void sync_threads();
void* dynamic_shared();

using Body = std::function<void()>;
// Runs `body` for every thread of every block; an error is left for
// cudaGetLastError, as a failed launch leaves it.
void launch(const void* kernel, dim3 grid, dim3 block, std::size_t shared_bytes, const Body& body);

// kernel<<<grid, block, shared>>>(args...): the arguments are converted to
// the kernel's parameters once, and each thread gets its own copy of them (its
// parameters by value), as on a GPU.
template <class... Params>
struct Launcher {
  void (*kernel)(Params...);
  dim3 grid, block;
  std::size_t shared_bytes;
  template <class... Args>
  void operator()(Args&&... args) const {
    std::tuple<Params...> copied(std::forward<Args>(args)...);
    auto* k = kernel;
    launch(reinterpret_cast<const void*>(k), grid, block, shared_bytes,
           [&copied, k] { std::apply(k, copied); });
  }
};
template <class... Params>
Launcher<Params...> launcher(dim3 grid, dim3 block, std::size_t shared_bytes,
                             void (*kernel)(Params...)) {
  return {kernel, grid, block, shared_bytes};
}
}  // namespace flocsim_cuda_emulation

inline void __syncthreads() {
  flocsim_cuda_emulation::sync_threads();
}

// The threads of one block never run at once here: an atomic addition is an
// addition (returning the old value, as CUDA's does).
template <class T>
inline T atomicAdd(T* address, T value) {
  const T old = *address;
  *address = old + value;
  return old;
}

// See engine/lattice_gpu/cuda_launch.hpp for the CUDA forms of these two.
#define FLOCSIM_LAUNCH(grid, block, shared_bytes, ...) \
  ::flocsim_cuda_emulation::launcher(grid, block, shared_bytes, &__VA_ARGS__)
#define FLOCSIM_DYNAMIC_SHARED(type, name) \
  type* const name = static_cast<type*>(::flocsim_cuda_emulation::dynamic_shared())

// ---- the runtime -------------------------------------------------------------

enum cudaError_t {
  cudaSuccess = 0,
  cudaErrorInvalidValue = 1,
  cudaErrorMemoryAllocation = 2,
  cudaErrorInvalidConfiguration = 9,
  cudaErrorInvalidDeviceFunction = 98,
  cudaErrorNoDevice = 100,
  cudaErrorInvalidDevice = 101,
  cudaErrorInsufficientDriver = 35,
  cudaErrorLaunchFailure = 719,
};
using cudaError = cudaError_t;

enum cudaMemcpyKind {
  cudaMemcpyHostToHost = 0,
  cudaMemcpyHostToDevice = 1,
  cudaMemcpyDeviceToHost = 2,
  cudaMemcpyDeviceToDevice = 3,
  cudaMemcpyDefault = 4,
};

enum cudaDeviceAttr {
  cudaDevAttrMultiProcessorCount = 16,
  cudaDevAttrMaxSharedMemoryPerBlockOptin = 97,
};

enum cudaFuncAttribute {
  cudaFuncAttributeMaxDynamicSharedMemorySize = 8,
};

struct cudaDeviceProp {
  char name[256];
  std::size_t totalGlobalMem;
  int major, minor;
  int multiProcessorCount;
  std::size_t sharedMemPerBlockOptin;
};

struct CUstream_st;
using cudaStream_t = CUstream_st*;
struct CUevent_st;
using cudaEvent_t = CUevent_st*;

const char* cudaGetErrorString(cudaError_t error);
cudaError_t cudaGetLastError();
cudaError_t cudaPeekAtLastError();

cudaError_t cudaGetDeviceCount(int* count);
cudaError_t cudaGetDeviceProperties(cudaDeviceProp* prop, int device);
cudaError_t cudaSetDevice(int device);
cudaError_t cudaGetDevice(int* device);
cudaError_t cudaDeviceGetAttribute(int* value, cudaDeviceAttr attr, int device);
cudaError_t cudaMemGetInfo(std::size_t* free, std::size_t* total);
cudaError_t cudaDeviceSynchronize();
cudaError_t cudaDeviceReset();

cudaError_t cudaMalloc(void** pointer, std::size_t bytes);
template <class T>
cudaError_t cudaMalloc(T** pointer, std::size_t bytes) {
  return cudaMalloc(reinterpret_cast<void**>(pointer), bytes);
}
cudaError_t cudaFree(void* pointer);
cudaError_t cudaMallocHost(void** pointer, std::size_t bytes);
template <class T>
cudaError_t cudaMallocHost(T** pointer, std::size_t bytes) {
  return cudaMallocHost(reinterpret_cast<void**>(pointer), bytes);
}
cudaError_t cudaFreeHost(void* pointer);
cudaError_t cudaMemcpy(void* to, const void* from, std::size_t bytes, cudaMemcpyKind kind);
cudaError_t cudaMemcpyAsync(void* to, const void* from, std::size_t bytes, cudaMemcpyKind kind,
                            cudaStream_t stream = nullptr);
cudaError_t cudaMemset(void* to, int value, std::size_t bytes);
cudaError_t cudaMemsetAsync(void* to, int value, std::size_t bytes, cudaStream_t stream = nullptr);

cudaError_t cudaEventCreate(cudaEvent_t* event);
cudaError_t cudaEventDestroy(cudaEvent_t event);
cudaError_t cudaEventRecord(cudaEvent_t event, cudaStream_t stream = nullptr);
cudaError_t cudaEventSynchronize(cudaEvent_t event);
cudaError_t cudaEventElapsedTime(float* ms, cudaEvent_t start, cudaEvent_t stop);

namespace flocsim_cuda_emulation {
cudaError_t set_max_dynamic_shared(const void* kernel, int bytes);
int occupancy_blocks_per_multiprocessor(int block_threads);
}  // namespace flocsim_cuda_emulation

template <class... Params>
cudaError_t cudaFuncSetAttribute(void (*kernel)(Params...), cudaFuncAttribute attr, int value) {
  if (attr != cudaFuncAttributeMaxDynamicSharedMemorySize) return cudaErrorInvalidValue;
  return flocsim_cuda_emulation::set_max_dynamic_shared(reinterpret_cast<const void*>(kernel),
                                                        value);
}
template <class... Params>
cudaError_t cudaOccupancyMaxActiveBlocksPerMultiprocessor(int* blocks, void (*)(Params...),
                                                          int block_threads, std::size_t) {
  *blocks = flocsim_cuda_emulation::occupancy_blocks_per_multiprocessor(block_threads);
  return cudaSuccess;
}
