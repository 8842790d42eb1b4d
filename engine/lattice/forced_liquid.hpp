#pragma once
// The seam between a fluid back-end and what couples to it (the coupling
// schemes, the liquid averages): the velocity field that the next collision
// would see without the per-cell force, row by row; the per-cell force
// density that the next step applies (the immersed boundary writes it); and
// the cells' solid coverage, which the next step's collision blends with a
// solid operator, reporting the density and momentum it saw there (the
// partially saturated cells write and read it). Nothing else of a back-end's storage
// (populations, their layout, the streaming pattern) is visible through it, so
// another back-end (a GPU one is planned) can sit behind the same immersed
// boundary and observables. FluidLattice (fluid_lattice.hpp) is the CPU one.
#include <cstdint>

namespace flocsim::lattice {

struct Extent {
  int nx = 1, ny = 1, nz = 1;
  long cells() const { return static_cast<long>(nx) * ny * nz; }
  long rows() const { return static_cast<long>(ny) * nz; }
};

struct Vector3 {
  double x = 0, y = 0, z = 0;
};

// The per-cell force density, one array per component, x fastest: cell
// (x, y, z) is element x of row(d, y, z). Real may be const for reading.
template <class Real>
struct ForceFieldView {
  Extent extent;
  Real* component[3] = {nullptr, nullptr, nullptr};

  bool empty() const { return component[0] == nullptr; }
  // Lattice row r = y + ny z of component d.
  Real* row(int d, long r) const { return component[d] + static_cast<long>(extent.nx) * r; }
};

// Partially saturated cells (Noble & Torczynski 1998; the collision itself in
// partially_saturated_collision.hpp): per cell, the summed coverage
// eps = sum_k eps_k of the spheres k overlapping it and the coverage-weighted
// solid velocity V = sum_k eps_k u_k (u_k the velocity of sphere k's surface
// motion at the cell centre), both zero where no sphere reaches; the next
// step's collision writes the density and momentum density rho u it saw on
// every cell of a covered chunk (rho, j; u with the half-force shift of the
// body force and any per-cell force). Chunks are 16 cells of a row (x =
// 16 c .. 16 c + 15); `chunks` marks the rows' covered chunks, `chunk_words`
// words per row. Cells outside covered chunks are neither read nor written.
template <class Real>
struct SolidCoverageView {
  Extent extent;
  Real* coverage = nullptr;                               // eps
  Real* solid_velocity[3] = {nullptr, nullptr, nullptr};  // V
  Real* density = nullptr;                                // rho (written by the step)
  Real* momentum[3] = {nullptr, nullptr, nullptr};        // rho u (written by the step)
  std::uint64_t* chunks = nullptr;
  int chunk_words = 0;
  static constexpr int kChunk = 16;

  bool empty() const { return coverage == nullptr; }
  long offset(long row) const { return static_cast<long>(extent.nx) * row; }
  std::uint64_t* chunk_row(long row) const { return chunks + row * chunk_words; }
};

template <class Real>
class ForcedLiquid {
 public:
  virtual ~ForcedLiquid() = default;

  virtual const Extent& extent() const = 0;
  // The uniform body force density on the liquid.
  virtual Vector3 body_force() const = 0;
  // The per-cell force density of the next step (allocated and zero on first
  // use); the coupling adds its forces here and removes them again.
  virtual ForceFieldView<Real> force_field() = 0;
  // For reading; empty when no per-cell force was ever set.
  virtual ForceFieldView<const Real> force_field_if_set() const = 0;
  // The solid coverage of the next step (allocated, zero and without covered
  // chunks on first use: from then on every step's collision reads it).
  virtual SolidCoverageView<Real> solid_coverage() = 0;
  // For reading (the density and momentum of the last step); empty when never used.
  virtual SolidCoverageView<const Real> solid_coverage_if_set() const = 0;

  // Density and velocity of the cells x0 .. x0 + count - 1 of row (y, z) (no
  // wrap in x) with the half-force shift of the uniform body force only: the
  // velocity the next collision would see without the per-cell force, which
  // direct forcing needs. In the lattice's precision, interleaved: cell
  // x0 + k gets (density, ux, uy, uz) at rho_u[4 k .. 4 k + 3].
  virtual void macroscopic_row_without_force_field(int x0, int count, int y, int z,
                                                   Real* rho_u) const = 0;
  // The same in double, into four arrays (observables).
  virtual void macroscopic_row_without_force_field(int x0, int count, int y, int z, double* density,
                                                   double* ux, double* uy, double* uz) const = 0;
};

}  // namespace flocsim::lattice
