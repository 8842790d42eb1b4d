#include "engine/coupling/sphere_cells.hpp"

#include <atomic>
#include <cmath>

namespace flocsim::coupling {

std::vector<std::vector<std::vector<int>>> make_colours(
    const std::vector<std::array<int, 3>>& origins, int box, const lattice::Extent& extent) {
  const int length[3] = {extent.nx, extent.ny, extent.nz};
  int blocks[3];
  double width[3];
  for (int d = 0; d < 3; ++d) {
    int n = length[d] / box;
    n = n >= 2 ? n - n % 2 : 1;
    blocks[d] = n;
    width[d] = static_cast<double>(length[d]) / n;
  }
  const int total_blocks = blocks[0] * blocks[1] * blocks[2];
  std::vector<std::vector<int>> members(static_cast<std::size_t>(total_blocks));
  for (std::size_t s = 0; s < origins.size(); ++s) {
    int coord[3];
    for (int d = 0; d < 3; ++d) {
      const double centre = wrap(origins[s][d], length[d]) + 0.5 * box;
      double c = std::fmod(centre, static_cast<double>(length[d]));
      coord[d] = std::min(blocks[d] - 1, static_cast<int>(c / width[d]));
    }
    members[static_cast<std::size_t>(coord[0] + blocks[0] * (coord[1] + blocks[1] * coord[2]))]
        .push_back(static_cast<int>(s));
  }
  std::vector<std::vector<std::vector<int>>> colours(8);
  for (int bz = 0; bz < blocks[2]; ++bz)
    for (int by = 0; by < blocks[1]; ++by)
      for (int bx = 0; bx < blocks[0]; ++bx) {
        auto& m = members[static_cast<std::size_t>(bx + blocks[0] * (by + blocks[1] * bz))];
        if (m.empty()) continue;
        colours[static_cast<std::size_t>((bx % 2) | (by % 2) << 1 | (bz % 2) << 2)].push_back(
            std::move(m));
      }
  std::erase_if(colours, [](const auto& c) { return c.empty(); });
  return colours;
}

void ChunkMask::mark(long r, int x, int count) {
  std::uint64_t* word = row(static_cast<std::size_t>(r));
  for (int c = x / kChunk; c <= (x + count - 1) / kChunk; ++c)
    std::atomic_ref<std::uint64_t>(word[c / 64])
        .fetch_or(std::uint64_t(1) << (c % 64), std::memory_order_relaxed);
}

}  // namespace flocsim::coupling
