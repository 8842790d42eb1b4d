#pragma once
// The D3Q19 velocity set: 1 rest velocity, 6 axis links, 12 face diagonals.
// Directions are stored in opposite pairs (2k-1, 2k) so that the opposite of
// a moving direction i is i+1 for odd i and i-1 for even i; the two-relaxation
// -time collision works on exactly these pairs.
#include <array>

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

constexpr int opposite(int i) {
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

}  // namespace flocsim::d3q19
