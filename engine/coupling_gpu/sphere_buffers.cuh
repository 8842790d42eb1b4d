#pragma once
// The buffers both GPU couplings (immersed boundary, partially saturated
// cells) move their per-sphere numbers through each step: device arrays grown
// on demand, and page-locked host buffers for the copies (a copy from
// pageable memory is staged through a driver buffer and cannot overlap).
// CUDA files of this folder only.
#include <cuda_runtime.h>

#include <cstddef>
#include <string>

#include "engine/lattice_gpu/cuda_check.hpp"

namespace flocsim::gpu {

// `pointer` with room for at least `wanted` elements; the contents are not
// kept when it grows. `held`: its room now.
template <class T>
void device_resize(T*& pointer, std::size_t& held, std::size_t wanted, const char* what) {
  if (held >= wanted) return;
  cudaFree(pointer);
  pointer = nullptr;
  held = 0;
  cuda_check(cudaMalloc(&pointer, sizeof(T) * wanted),
             (std::string("cudaMalloc of ") + what + " (" +
              std::to_string((sizeof(T) * wanted) >> 20) + " MiB)")
                 .c_str());
  held = wanted;
}

// Page-locked host buffers for `held` spheres: what goes to the device (`in`
// numbers a sphere) and what comes back (`out` numbers a sphere).
struct PinnedSphereBuffers {
  double* to_device = nullptr;
  double* from_device = nullptr;
  std::size_t held = 0;

  PinnedSphereBuffers() = default;
  PinnedSphereBuffers(const PinnedSphereBuffers&) = delete;
  PinnedSphereBuffers& operator=(const PinnedSphereBuffers&) = delete;
  ~PinnedSphereBuffers() { release(); }

  void reserve(std::size_t spheres, std::size_t in, std::size_t out, const char* what) {
    if (held >= spheres) return;
    release();
    cuda_check(cudaMallocHost(&to_device, sizeof(double) * in * spheres),
               (std::string("pinned buffer of ") + what + ", to the GPU").c_str());
    cuda_check(cudaMallocHost(&from_device, sizeof(double) * out * spheres),
               (std::string("pinned buffer of ") + what + ", from the GPU").c_str());
    held = spheres;
  }

 private:
  void release() {
    cudaFreeHost(to_device);
    cudaFreeHost(from_device);
    to_device = from_device = nullptr;
    held = 0;
  }
};

}  // namespace flocsim::gpu
