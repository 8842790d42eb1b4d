#pragma once
// How the back-end's .cu files launch a kernel and name a block's dynamic
// shared memory (CUDA files only):
//   FLOCSIM_LAUNCH(grid, block, shared_bytes, kernel)(args...)
//     is kernel<<<grid, block, shared_bytes>>>(args...);
//   FLOCSIM_DYNAMIC_SHARED(type, name)
//     is extern __shared__ __align__(16) type name[].
// Written as macros so that the same files also compile as C++ against the
// CPU emulation of CUDA (cuda_emulation/, FLOCSIM_CUDA_EMULATION), whose
// cuda_runtime.h defines them as calls into the emulation; that build runs
// the GPU tests where no GPU is lent (docs/gpu.md).
#include <cuda_runtime.h>

#ifndef FLOCSIM_CUDA_EMULATION
#define FLOCSIM_LAUNCH(grid, block, shared_bytes, ...) __VA_ARGS__<<<grid, block, shared_bytes>>>
#define FLOCSIM_DYNAMIC_SHARED(type, name) extern __shared__ __align__(16) type name[]
#endif
