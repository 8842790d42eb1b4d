#pragma once
// The lattice cells each sphere works on, and how threads share the spheres
// without two of them writing the same cell: what every coupling scheme needs
// around its own physics (the immersed boundary's marker stencils, the
// partially saturated cells' solid fractions).
//
// A sphere works on a cubic box of B^3 cells from its lowest corner `lo`
// (unwrapped lattice coordinates); of box row (j, k) it uses cells i0 .. i1
// (i0 > i1: none), stored as rows[2 (j + B k)], rows[2 (j + B k) + 1].
// Spheres are grouped in blocks at least one box wide and the blocks coloured
// by the parity of their block coordinates: blocks of one colour never share a
// cell, so threads take whole blocks of one colour at a time and write without
// atomics.
#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "engine/lattice/forced_liquid.hpp"

namespace flocsim::coupling {

inline int wrap(int i, int n) {
  i %= n;
  return i < 0 ? i + n : i;
}

// Calls run(j, k, i, x, count, r) for every piece i .. i + count - 1 of box
// row (j, k) that lies at lattice x .. x + count - 1 of lattice row
// r = y + ny z; pieces never cross the periodic edge in x.
template <class Run>
void for_each_box_run(const std::array<int, 3>& lo, const std::int16_t* rows, int B,
                      const lattice::Extent& e, Run&& run) {
  for (int k = 0; k < B; ++k) {
    const long plane = static_cast<long>(e.ny) * wrap(lo[2] + k, e.nz);
    for (int j = 0; j < B; ++j) {
      const int i0 = rows[2 * (j + B * k)], i1 = rows[2 * (j + B * k) + 1];
      if (i0 > i1) continue;
      const long r = wrap(lo[1] + j, e.ny) + plane;
      for (int i = i0; i <= i1;) {
        const int x = wrap(lo[0] + i, e.nx);
        const int count = std::min(i1 - i + 1, e.nx - x);
        run(j, k, i, x, count, r);
        i += count;
      }
    }
  }
}

// Spheres (by their boxes' lowest corners) grouped into blocks, blocks into
// colours: colours[c][b] lists the spheres of block b of colour c.
std::vector<std::vector<std::vector<int>>> make_colours(
    const std::vector<std::array<int, 3>>& origins, int box, const lattice::Extent& extent);

// One bit per chunk of kChunk cells of every lattice row: which chunks hold
// cells of interest (the cells some sphere reads, or holds a force on).
// Chunk c of row r covers x = kChunk c .. kChunk c + kChunk - 1: one vector of
// floats, so that a marked stretch is swept in whole vectors.
class ChunkMask {
 public:
  static constexpr int kChunk = 16;
  void resize(const lattice::Extent& e) {
    chunks_ = (e.nx + kChunk - 1) / kChunk;
    words_ = (chunks_ + 63) / 64;
    const std::size_t size = static_cast<std::size_t>(e.rows()) * words_;
    if (bits_.size() != size) bits_.assign(size, 0);
  }
  int chunks() const { return chunks_; }
  int words() const { return words_; }
  bool empty() const { return bits_.empty(); }
  std::uint64_t* row(std::size_t r) { return &bits_[r * words_]; }
  const std::uint64_t* row(std::size_t r) const { return &bits_[r * words_]; }
  static bool has(const std::uint64_t* row, int c) { return row[c / 64] >> (c % 64) & 1; }
  // Marks the chunks of cells x .. x + count - 1 of row r; safe when threads
  // mark the same row at once.
  void mark(long r, int x, int count);
  void clear() { std::fill(bits_.begin(), bits_.end(), std::uint64_t(0)); }
  void swap(ChunkMask& o) { bits_.swap(o.bits_); }

 private:
  int chunks_ = 0, words_ = 0;
  std::vector<std::uint64_t> bits_;
};

}  // namespace flocsim::coupling
