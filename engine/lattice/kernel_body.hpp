#pragma once
// Kernel bodies: the per-cell functions that every back-end's loop calls.
// The CPU loops (fluid_lattice.cpp) run them vectorised along x; the CUDA
// launchers (engine/lattice_gpu) run them one thread per cell. Each body has
// one source, so the CPU test suite checks the arithmetic the GPU executes,
// and a GPU file holds only its thread-to-cell mapping.
//
// FLOCSIM_KERNEL_BODY marks such a function: host and device code under nvcc,
// and always inlined (the CPU row loop vectorises only when the collision is
// inlined into it; GCC and Clang need telling, other compilers get inline).
#if defined(__GNUC__)
#define FLOCSIM_ALWAYS_INLINE inline __attribute__((always_inline))
#define FLOCSIM_LAMBDA_ALWAYS_INLINE __attribute__((always_inline))
#else
#define FLOCSIM_ALWAYS_INLINE inline
#define FLOCSIM_LAMBDA_ALWAYS_INLINE
#endif

#if defined(__CUDACC__)
#define FLOCSIM_HD __host__ __device__
#define FLOCSIM_KERNEL_BODY __host__ __device__ __forceinline__
#else
#define FLOCSIM_HD
#define FLOCSIM_KERNEL_BODY FLOCSIM_ALWAYS_INLINE
#endif

// Unroll the loop over the 19 directions (or the 9 pairs): indices then
// become constants and the velocity functions of d3q19.hpp fold to literals.
#if defined(__CUDACC__)  // nvcc: its host pass takes GCC's -Wno-unknown-pragmas
#define FLOCSIM_UNROLL _Pragma("unroll")
#elif defined(__GNUC__) && !defined(__clang__)
#define FLOCSIM_UNROLL _Pragma("GCC unroll 19")
#elif defined(__clang__)
#define FLOCSIM_UNROLL _Pragma("clang loop unroll(full)")
#else
#define FLOCSIM_UNROLL
#endif
