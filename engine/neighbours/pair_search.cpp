#include "engine/neighbours/pair_search.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

namespace flocsim::neighbours {

namespace {

void add_if_near(const std::vector<Vec3>& x, const PeriodicBox& box, int i, int j, double cutoff_sq,
                 std::vector<NearPair>& out) {
  if (i > j) std::swap(i, j);
  const Vec3 d = x[j] - x[i];
  const Vec3 r = box.minimum_image(d);
  if (r.squaredNorm() < cutoff_sq) out.push_back({i, j, r - d});
}

}  // namespace

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
      for (int j = i + 1; j < n; ++j) add_if_near(x, box, i, j, cutoff_sq, out);
    return out;
  }

  auto cell_of = [&](const Vec3& p) {
    std::array<int, 3> c{};
    for (int k = 0; k < 3; ++k)
      c[k] = std::clamp(static_cast<int>(p[k] / box.length[k] * cells[k]), 0, cells[k] - 1);
    return c;
  };
  auto index = [&](int cx, int cy, int cz) { return (cz * cells[1] + cy) * cells[0] + cx; };
  const int ncells = cells[0] * cells[1] * cells[2];
  // Counting sort of spheres into cells (cell_start is a prefix sum).
  std::vector<int> cell_start(ncells + 1, 0), members(n), home(n);
  for (int i = 0; i < n; ++i) {
    const auto c = cell_of(x[i]);
    home[i] = index(c[0], c[1], c[2]);
    ++cell_start[home[i] + 1];
  }
  for (int c = 0; c < ncells; ++c) cell_start[c + 1] += cell_start[c];
  std::vector<int> fill(cell_start.begin(), cell_start.end() - 1);
  for (int i = 0; i < n; ++i) members[fill[home[i]]++] = i;

  for (int i = 0; i < n; ++i) {
    const auto c = cell_of(x[i]);
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int nx = (c[0] + dx + cells[0]) % cells[0];
          const int ny = (c[1] + dy + cells[1]) % cells[1];
          const int nz = (c[2] + dz + cells[2]) % cells[2];
          const int cell = index(nx, ny, nz);
          for (int m = cell_start[cell]; m < cell_start[cell + 1]; ++m) {
            const int j = members[m];
            if (j > i) add_if_near(x, box, i, j, cutoff_sq, out);
          }
        }
  }
  std::sort(out.begin(), out.end(), [](const NearPair& p, const NearPair& q) {
    return p.i != q.i ? p.i < q.i : p.j < q.j;
  });
  return out;
}

}  // namespace flocsim::neighbours
