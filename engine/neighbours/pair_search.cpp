#include "engine/neighbours/pair_search.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

namespace flocsim::neighbours {

std::vector<NearPair> pairs_within(const std::vector<Vec3>& x, const PeriodicBox& box,
                                   double cutoff) {
  if (!(cutoff > 0) || !(2 * cutoff < box.length.minCoeff()))
    throw std::invalid_argument("pairs_within: cutoff " + std::to_string(cutoff) +
                                " must be positive and below half the smallest box length " +
                                std::to_string(box.length.minCoeff()));
  const int n = static_cast<int>(x.size());
  const double cutoff_sq = cutoff * cutoff;
  std::vector<NearPair> out;

  // Cells at least one cutoff wide: a pair within the cutoff lies in the same
  // or an adjacent cell. With fewer than 3 cells along an axis the 27
  // neighbouring cells would repeat, so small boxes use the all-pairs loop.
  std::array<int, 3> cells{};
  for (int k = 0; k < 3; ++k) cells[k] = static_cast<int>(std::floor(box.length[k] / cutoff));
  if (std::min({cells[0], cells[1], cells[2]}) < 3) {
    for (int i = 0; i < n; ++i)
      for (int j = i + 1; j < n; ++j) {
        const Vec3 d = x[j] - x[i];
        const Vec3 r = box.minimum_image(d);
        if (r.squaredNorm() < cutoff_sq) out.push_back({i, j, r - d});
      }
    return out;
  }

  auto index = [&](int cx, int cy, int cz) { return (cz * cells[1] + cy) * cells[0] + cx; };
  const int ncells = cells[0] * cells[1] * cells[2];
  // Counting sort of spheres into cells (cell_start is a prefix sum).
  std::vector<int> cell_start(ncells + 1, 0), members(n), home(n);
  for (int i = 0; i < n; ++i) {
    int c[3];
    for (int k = 0; k < 3; ++k)
      c[k] = std::clamp(static_cast<int>(x[i][k] / box.length[k] * cells[k]), 0, cells[k] - 1);
    home[i] = index(c[0], c[1], c[2]);
    ++cell_start[home[i] + 1];
  }
  for (int c = 0; c < ncells; ++c) cell_start[c + 1] += cell_start[c];
  std::vector<int> fill(cell_start.begin(), cell_start.end() - 1);
  for (int i = 0; i < n; ++i) members[fill[home[i]]++] = i;

  // Each cell meets itself and 13 of its 26 neighbours (the other 13 meet it),
  // so every pair of cells is visited once. Stepping off the box edge tells
  // which periodic image of the neighbour cell is adjacent: its shift is
  // known without a minimum-image computation per pair.
  static constexpr int kHalfShell[13][3] = {
      {1, 0, 0},  {-1, 1, 0}, {0, 1, 0}, {1, 1, 0},  {-1, -1, 1}, {0, -1, 1}, {1, -1, 1},
      {-1, 0, 1}, {0, 0, 1},  {1, 0, 1}, {-1, 1, 1}, {0, 1, 1},   {1, 1, 1}};
  auto emit = [&](int i, int j, const Vec3& shift) {
    // shift: x_j + shift is the image of j next to i.
    const Vec3 r = x[j] + shift - x[i];
    if (r.squaredNorm() >= cutoff_sq) return;
    if (i < j)
      out.push_back({i, j, shift});
    else
      out.push_back({j, i, -shift});
  };
  for (int cz = 0; cz < cells[2]; ++cz)
    for (int cy = 0; cy < cells[1]; ++cy)
      for (int cx = 0; cx < cells[0]; ++cx) {
        const int cell = index(cx, cy, cz);
        for (int m = cell_start[cell]; m < cell_start[cell + 1]; ++m)
          for (int l = m + 1; l < cell_start[cell + 1]; ++l)
            emit(members[m], members[l], Vec3::Zero());
        for (const auto& off : kHalfShell) {
          const int u[3] = {cx + off[0], cy + off[1], cz + off[2]};
          int w[3];
          Vec3 shift;
          for (int k = 0; k < 3; ++k) {
            w[k] = (u[k] + cells[k]) % cells[k];
            shift[k] = u[k] < 0 ? -box.length[k] : (u[k] >= cells[k] ? box.length[k] : 0.0);
          }
          const int other = index(w[0], w[1], w[2]);
          for (int m = cell_start[cell]; m < cell_start[cell + 1]; ++m)
            for (int l = cell_start[other]; l < cell_start[other + 1]; ++l)
              emit(members[m], members[l], shift);
        }
      }
  return out;
}

}  // namespace flocsim::neighbours
