#pragma once
// Interpolation and spreading over one marker's kernel stencil in a sphere's
// scratch box (immersed_boundary.cpp), vectorised: every box cell holds four
// numbers, so a stencil row of four cells is one 16-number vector.
#include <cmath>
#include <cstddef>
#include <cstring>

namespace flocsim::immersed_boundary {

// Vectors of 4 and 16 numbers (GCC/Clang vector extensions: with AVX-512 a
// 16-float vector is one register, 16 doubles two).
template <class Real>
struct Simd {
  typedef Real V4 __attribute__((vector_size(4 * sizeof(Real))));
  typedef Real V16 __attribute__((vector_size(16 * sizeof(Real))));
  template <class V>
  static V load(const Real* p) {
    V v;
    std::memcpy(&v, p, sizeof v);
    return v;
  }
  template <class V>
  static void store(Real* p, V v) {
    std::memcpy(p, &v, sizeof v);
  }
};

// The W^3-cell stencil of one marker (W = 3: Roma, W = 2: linear) in a
// sphere's scratch box, shared by interpolation and spreading. A stencil row
// is W cells plus 4 - W with weight zero (the box rows have one spare cell for
// them), and each operation is W^2 whole-row vector steps.
//   state: (rho, v) per cell, v the velocity the collision sees;
//   force: (0, F) per cell, F this sphere's force density.
// w: the marker's 16 weight slots: x weights wx[a] in slots 0 .. W-1, the
// products wy[b] wz[c] in slot W + b + W c, the rest zero.
// base: the marker's stencil corner as an offset in numbers (4 per cell).
template <class Real, int W>
struct Stencil {
  static_assert(W == 2 || W == 3, "kernel width 2 or 3");
  static constexpr int kRows = W * W;
  using V4 = typename Simd<Real>::V4;
  using V16 = typename Simd<Real>::V16;
  std::size_t offset[kRows];  // numbers from the corner to stencil row (b, c), index b + W c

  Stencil(int row_cells, int box) {
    for (int c = 0; c < W; ++c)
      for (int b = 0; b < W; ++b)
        offset[b + W * c] = 4 * static_cast<std::size_t>(row_cells) * (b + box * c);
  }
  // x weight of each of the 16 numbers of a stencil row (slot 15 is zero).
  static V16 row_weights(const V16& w) {
    if constexpr (W == 3)
      return __builtin_shufflevector(w, w, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2, 15, 15, 15, 15);
    else
      return __builtin_shufflevector(w, w, 0, 0, 0, 0, 1, 1, 1, 1, 15, 15, 15, 15, 15, 15, 15, 15);
  }

  // Interpolated (rho, v) at the marker: the x weights multiply the sum of
  // the W^2 rows weighted by wy wz.
  V4 interpolate(const Real* state, std::size_t base, const V16& w) const {
    const Real* wyz = reinterpret_cast<const Real*>(&w) + W;
    std::size_t o[kRows];
    for (int l = 0; l < kRows; ++l) o[l] = offset[l];
    V16 acc[3] = {};  // three independent sums: a shorter dependency chain
#pragma GCC unroll 9
    for (int l = 0; l < kRows; ++l)
      acc[l % 3] += wyz[l] * Simd<Real>::template load<V16>(state + base + o[l]);
    V16 sum = (acc[0] + acc[1] + acc[2]) * row_weights(w);
    const V4 a = __builtin_shufflevector(sum, sum, 0, 1, 2, 3);
    const V4 b = __builtin_shufflevector(sum, sum, 4, 5, 6, 7);
    if constexpr (W == 3) {
      const V4 c = __builtin_shufflevector(sum, sum, 8, 9, 10, 11);
      return a + b + c;
    } else {
      return a + b;
    }
  }

  // Adds (0, F_m dV) spread with the kernel to force; s points to those 4
  // numbers (and 12 more, not used).
  void spread(Real* force, std::size_t base, const V16& w, const Real* s) const {
    const V16 s4 = Simd<Real>::template load<V16>(s);
    const V16 ws = row_weights(w) *
                   __builtin_shufflevector(s4, s4, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3);
    const Real* wyz = reinterpret_cast<const Real*>(&w) + W;
    std::size_t o[kRows];
    for (int l = 0; l < kRows; ++l) o[l] = offset[l];
    Real* f = force + base;
#pragma GCC unroll 9
    for (int l = 0; l < kRows; ++l)
      Simd<Real>::store(f + o[l], Simd<Real>::template load<V16>(f + o[l]) + ws * wyz[l]);
  }
};

}  // namespace flocsim::immersed_boundary
