#pragma once
// A CUDA runtime call that fails becomes an exception naming the call and
// CUDA's reason (CUDA files of this folder only).
#include <cuda_runtime.h>

#include <stdexcept>
#include <string>

namespace flocsim::gpu {

inline void cuda_check(cudaError_t status, const char* what) {
  if (status != cudaSuccess)
    throw std::runtime_error(std::string("CUDA: ") + what + ": " + cudaGetErrorString(status));
}

}  // namespace flocsim::gpu
