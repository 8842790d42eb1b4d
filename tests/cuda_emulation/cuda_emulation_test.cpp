// The CPU emulation of CUDA (cuda_emulation/) keeps the CUDA semantics the
// back-end's launchers rely on (every thread of a block past a barrier before
// any goes on; shared memory one per block; the launch's index space), and
// refuses what a GPU would punish, as a GPU does: by an error code (kept for
// cudaGetLastError), or for a barrier only part of a block reaches, by
// stopping.
#include <cuda_runtime.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <vector>

#include "engine/lattice_gpu/cuda_launch.hpp"

namespace {

constexpr int kThreads = 256;

// Each block sums its threads' indices by a tree in shared memory.
__global__ void tree_sum_kernel(long* out) {
  __shared__ long sums[kThreads];
  sums[threadIdx.x] = threadIdx.x + 1000L * blockIdx.x;
  __syncthreads();
  for (int half = kThreads / 2; half > 0; half /= 2) {
    if (static_cast<int>(threadIdx.x) < half) sums[threadIdx.x] += sums[threadIdx.x + half];
    __syncthreads();
  }
  if (threadIdx.x == 0) out[blockIdx.x] = sums[0];
}

TEST(CudaEmulation, BlockBarriersGiveTheTreeSumOfEveryBlock) {
  const int blocks = 3;
  long* d = nullptr;
  ASSERT_EQ(cudaMalloc(&d, sizeof(long) * blocks), cudaSuccess);
  FLOCSIM_LAUNCH(blocks, kThreads, 0, tree_sum_kernel)(d);
  ASSERT_EQ(cudaGetLastError(), cudaSuccess);
  std::vector<long> h(blocks);
  ASSERT_EQ(cudaMemcpy(h.data(), d, sizeof(long) * blocks, cudaMemcpyDeviceToHost), cudaSuccess);
  for (int b = 0; b < blocks; ++b)  // sum of 0..255, plus 1000 b for each thread
    EXPECT_EQ(h[b], kThreads * (kThreads - 1) / 2 + 1000L * b * kThreads) << "block " << b;
  cudaFree(d);
}

// Each thread reads its neighbour's value: right only if every thread wrote
// before any read, which the barrier between them guarantees.
__global__ void neighbour_kernel(int* out) {
  __shared__ int values[kThreads];
  values[threadIdx.x] = static_cast<int>(threadIdx.x) * 3;
  __syncthreads();
  out[threadIdx.x] = values[(threadIdx.x + 1) % kThreads];
}

TEST(CudaEmulation, NoThreadPassesABarrierBeforeAllHaveReachedIt) {
  int* d = nullptr;
  ASSERT_EQ(cudaMalloc(&d, sizeof(int) * kThreads), cudaSuccess);
  FLOCSIM_LAUNCH(1, kThreads, 0, neighbour_kernel)(d);
  std::vector<int> h(kThreads);
  ASSERT_EQ(cudaMemcpy(h.data(), d, sizeof(int) * kThreads, cudaMemcpyDeviceToHost), cudaSuccess);
  for (int t = 0; t < kThreads; ++t) EXPECT_EQ(h[t], ((t + 1) % kThreads) * 3) << "thread " << t;
  cudaFree(d);
}

// Writes the global index of each thread of a 3D grid of 2D blocks.
__global__ void index_kernel(int* out, int nx, int ny) {
  const int x = blockIdx.x * blockDim.x + threadIdx.x;
  const int y = blockIdx.y * blockDim.y + threadIdx.y;
  const int z = blockIdx.z;
  if (x < nx && y < ny) out[(z * ny + y) * nx + x] += 1 + x + 100 * y + 10000 * z;
}

TEST(CudaEmulation, EveryThreadOfTheGridRunsOnceWithItsIndices) {
  const int nx = 37, ny = 9, nz = 3;
  int* d = nullptr;
  ASSERT_EQ(cudaMalloc(&d, sizeof(int) * nx * ny * nz), cudaSuccess);
  ASSERT_EQ(cudaMemset(d, 0, sizeof(int) * nx * ny * nz), cudaSuccess);
  FLOCSIM_LAUNCH(dim3(3, 3, nz), dim3(16, 4), 0, index_kernel)(d, nx, ny);
  ASSERT_EQ(cudaGetLastError(), cudaSuccess);
  std::vector<int> h(nx * ny * nz);
  ASSERT_EQ(cudaMemcpy(h.data(), d, sizeof(int) * h.size(), cudaMemcpyDeviceToHost), cudaSuccess);
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x)
        ASSERT_EQ(h[(z * ny + y) * nx + x], 1 + x + 100 * y + 10000 * z)
            << x << " " << y << " " << z;
  cudaFree(d);
}

__global__ void count_kernel(int* out) {
  atomicAdd(out, 1);
}

TEST(CudaEmulation, ALaunchBeyondTheHardwaresLimitsFailsAndRunsNothing) {
  int* d = nullptr;
  ASSERT_EQ(cudaMalloc(&d, sizeof(int)), cudaSuccess);
  ASSERT_EQ(cudaMemset(d, 0, sizeof(int)), cudaSuccess);
  FLOCSIM_LAUNCH(1, 1025, 0, count_kernel)(d);  // 1024 threads a block at most
  EXPECT_EQ(cudaGetLastError(), cudaErrorInvalidConfiguration);
  FLOCSIM_LAUNCH(dim3(1, 65536), 1, 0, count_kernel)(d);  // grid y at most 65535
  EXPECT_EQ(cudaGetLastError(), cudaErrorInvalidConfiguration);
  EXPECT_EQ(cudaGetLastError(), cudaSuccess) << "a launch error is not sticky";
  FLOCSIM_LAUNCH(2, 1024, 0, count_kernel)(d);
  EXPECT_EQ(cudaGetLastError(), cudaSuccess);
  int h = 0;
  ASSERT_EQ(cudaMemcpy(&h, d, sizeof(int), cudaMemcpyDeviceToHost), cudaSuccess);
  EXPECT_EQ(h, 2048) << "only the valid launch ran, each of its threads once";
  cudaFree(d);
}

__global__ void shared_fill_kernel(float* out, int n) {
  FLOCSIM_DYNAMIC_SHARED(float, box);
  for (int i = threadIdx.x; i < n; i += blockDim.x) box[i] = static_cast<float>(i);
  __syncthreads();
  for (int i = threadIdx.x; i < n; i += blockDim.x) out[i] = box[n - 1 - i];
}

TEST(CudaEmulation, DynamicSharedMemoryOver48KbNeedsTheKernelsAttribute) {
  const int n = 20000;  // 80 000 bytes of floats
  const std::size_t bytes = sizeof(float) * n;
  float* d = nullptr;
  ASSERT_EQ(cudaMalloc(&d, bytes), cudaSuccess);
  FLOCSIM_LAUNCH(1, 128, bytes, shared_fill_kernel)(d, n);
  EXPECT_EQ(cudaGetLastError(), cudaErrorInvalidValue);
  int optin = 0;
  ASSERT_EQ(cudaDeviceGetAttribute(&optin, cudaDevAttrMaxSharedMemoryPerBlockOptin, 0),
            cudaSuccess);
  EXPECT_EQ(cudaFuncSetAttribute(shared_fill_kernel, cudaFuncAttributeMaxDynamicSharedMemorySize,
                                 optin + 1),
            cudaErrorInvalidValue);
  EXPECT_EQ(cudaGetLastError(), cudaErrorInvalidValue) << "the refused attribute's error, kept";
  ASSERT_EQ(cudaFuncSetAttribute(shared_fill_kernel, cudaFuncAttributeMaxDynamicSharedMemorySize,
                                 static_cast<int>(bytes)),
            cudaSuccess);
  FLOCSIM_LAUNCH(1, 128, bytes, shared_fill_kernel)(d, n);
  ASSERT_EQ(cudaGetLastError(), cudaSuccess);
  std::vector<float> h(n);
  ASSERT_EQ(cudaMemcpy(h.data(), d, bytes, cudaMemcpyDeviceToHost), cudaSuccess);
  for (int i = 0; i < n; ++i) ASSERT_EQ(h[i], static_cast<float>(n - 1 - i)) << i;
  cudaFree(d);
}

TEST(CudaEmulation, CopiesOutsideAnAllocationOrTheWrongWayAreRefused) {
  double* d = nullptr;
  ASSERT_EQ(cudaMalloc(&d, sizeof(double) * 10), cudaSuccess);
  std::vector<double> h(11, 1.0);
  EXPECT_EQ(cudaMemcpy(d, h.data(), sizeof(double) * 11, cudaMemcpyHostToDevice),
            cudaErrorInvalidValue)
      << "past the end of the allocation";
  EXPECT_EQ(cudaGetLastError(), cudaErrorInvalidValue) << "a failed call leaves its error";
  EXPECT_EQ(cudaGetLastError(), cudaSuccess) << "and cudaGetLastError clears it";
  EXPECT_EQ(cudaMemcpy(h.data(), d, sizeof(double) * 10, cudaMemcpyHostToDevice),
            cudaErrorInvalidValue)
      << "source and destination swapped";
  EXPECT_EQ(cudaMemcpy(d + 1, h.data(), sizeof(double) * 10, cudaMemcpyHostToDevice),
            cudaErrorInvalidValue)
      << "an offset that runs past the end";
  EXPECT_EQ(cudaMemset(d, 0, sizeof(double) * 11), cudaErrorInvalidValue);
  EXPECT_EQ(cudaFree(h.data()), cudaErrorInvalidValue);
  // what is in range goes through both ways
  for (int i = 0; i < 10; ++i) h[i] = i * 0.5;
  ASSERT_EQ(cudaMemcpy(d, h.data(), sizeof(double) * 10, cudaMemcpyHostToDevice), cudaSuccess);
  std::vector<double> back(10);
  ASSERT_EQ(cudaMemcpy(back.data(), d, sizeof(double) * 10, cudaMemcpyDeviceToHost), cudaSuccess);
  for (int i = 0; i < 10; ++i) EXPECT_EQ(back[i], i * 0.5);
  EXPECT_EQ(cudaFree(d), cudaSuccess);
}

TEST(CudaEmulation, FreshDeviceMemoryIsNotZeroButNaN) {
  // a GPU does not clear what cudaMalloc gives; code that reads it before
  // writing it must fail here rather than pass by luck on a zeroed page
  float* d = nullptr;
  ASSERT_EQ(cudaMalloc(&d, sizeof(float) * 4), cudaSuccess);
  float h[4];
  ASSERT_EQ(cudaMemcpy(h, d, sizeof h, cudaMemcpyDeviceToHost), cudaSuccess);
  for (float v : h) EXPECT_TRUE(std::isnan(v));
  cudaFree(d);
}

__global__ void divergent_barrier_kernel(int* out) {
  if (threadIdx.x % 2 == 0) return;
  __syncthreads();
  out[threadIdx.x] = 1;
}

TEST(CudaEmulationDeathTest, ABarrierOnlyPartOfABlockReachesStops) {
  int* d = nullptr;
  ASSERT_EQ(cudaMalloc(&d, sizeof(int) * 64), cudaSuccess);
  EXPECT_DEATH(FLOCSIM_LAUNCH(1, 64, 0, divergent_barrier_kernel)(d),
               "threads ended while the others wait at __syncthreads");
  cudaFree(d);
}

// Locals of 62 KB: more than the emulation's 64 KB fiber stacks leave once the
// frames above the kernel are in, so they reach the stack's lowest 4 KB, which
// no kernel may touch (the stacks have no guard page; the heap lies below).
__global__ void large_locals_kernel(int* out) {
  volatile unsigned char locals[62 * 1024];
  for (std::size_t i = 0; i < sizeof locals; ++i) locals[i] = 1;
  __syncthreads();
  out[threadIdx.x] = locals[threadIdx.x];
}

TEST(CudaEmulationDeathTest, AKernelWhoseLocalsOutgrowItsStackStops) {
  int* d = nullptr;
  ASSERT_EQ(cudaMalloc(&d, sizeof(int) * 2), cudaSuccess);
  EXPECT_DEATH(FLOCSIM_LAUNCH(1, 2, 0, large_locals_kernel)(d), "stack overflowed");
  cudaFree(d);
}

}  // namespace
