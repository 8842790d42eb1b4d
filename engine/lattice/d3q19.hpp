#pragma once
// The D3Q19 velocity set: 1 rest velocity, 6 axis links, 12 face diagonals.
// Directions are stored in opposite pairs (2k-1, 2k) so that the opposite of
// a moving direction i is i+1 for odd i and i-1 for even i; the two-relaxation
// -time collision works on exactly these pairs.
#include <array>

#include "engine/lattice/kernel_body.hpp"

namespace flocsim::d3q19 {

inline constexpr int kQ = 19;
inline constexpr int kPairs = 9;  // moving directions come in 9 opposite pairs

inline constexpr std::array<int, kQ> cx = {0,  1, -1, 0, 0,  0, 0, 1, -1, 1,
                                           -1, 1, -1, 1, -1, 0, 0, 0, 0};
inline constexpr std::array<int, kQ> cy = {0, 0, 0, 1, -1, 0, 0,  1, -1, -1,
                                           1, 0, 0, 0, 0,  1, -1, 1, -1};
inline constexpr std::array<int, kQ> cz = {0, 0, 0,  0,  0, 1, -1, 0,  0, 0,
                                           0, 1, -1, -1, 1, 1, -1, -1, 1};

inline constexpr double kWeightRest = 1.0 / 3.0;
inline constexpr double kWeightAxis = 1.0 / 18.0;
inline constexpr double kWeightDiagonal = 1.0 / 36.0;
inline constexpr double kSoundSpeedSquared = 1.0 / 3.0;

FLOCSIM_HD constexpr int opposite(int i) {
  return i == 0 ? 0 : (i % 2 == 1 ? i + 1 : i - 1);
}

constexpr double weight(int i) {
  if (i == 0) return kWeightRest;
  return (cx[i] * cx[i] + cy[i] * cy[i] + cz[i] * cz[i]) == 1 ? kWeightAxis : kWeightDiagonal;
}

inline constexpr std::array<double, kQ> w = [] {
  std::array<double, kQ> out{};
  for (int i = 0; i < kQ; ++i) out[i] = weight(i);
  return out;
}();

// The same velocities and weights as functions, for kernel bodies
// (kernel_body.hpp): device code cannot read the host arrays above, while a
// constant argument (the unrolled loops' i) folds to a literal on both sides.
FLOCSIM_HD constexpr int velocity_x(int i) {
  constexpr int t[kQ] = {0, 1, -1, 0, 0, 0, 0, 1, -1, 1, -1, 1, -1, 1, -1, 0, 0, 0, 0};
  return t[i];
}
FLOCSIM_HD constexpr int velocity_y(int i) {
  constexpr int t[kQ] = {0, 0, 0, 1, -1, 0, 0, 1, -1, -1, 1, 0, 0, 0, 0, 1, -1, 1, -1};
  return t[i];
}
FLOCSIM_HD constexpr int velocity_z(int i) {
  constexpr int t[kQ] = {0, 0, 0, 0, 0, 1, -1, 0, 0, 0, 0, 1, -1, -1, 1, 1, -1, -1, 1};
  return t[i];
}
// Rest 1/3, the six axis links 1/18, the twelve face diagonals 1/36.
FLOCSIM_HD constexpr double weight_of(int i) {
  return i == 0 ? kWeightRest : (i <= 6 ? kWeightAxis : kWeightDiagonal);
}

namespace detail {
constexpr bool functions_match_arrays() {
  for (int i = 0; i < kQ; ++i)
    if (velocity_x(i) != cx[i] || velocity_y(i) != cy[i] || velocity_z(i) != cz[i] ||
        weight_of(i) != w[i])
      return false;
  return true;
}
static_assert(functions_match_arrays(), "D3Q19 velocity functions must match the arrays");
}  // namespace detail

}  // namespace flocsim::d3q19
