#pragma once
// The seam between a fluid back-end and what couples to it (the coupling
// schemes, the liquid averages): the velocity field that the next collision
// would see without the per-cell force, row by row; the per-cell force
// density that the next step applies (the immersed boundary writes it); and
// the cells' solid coverage, which the next step's collision blends with a
// solid operator, row by row through a SolidCoverage that the partially
// saturated cells implement. Nothing else of a back-end's storage
// (populations, their layout, the streaming pattern) is visible through it, so
// another back-end (a GPU one is planned) can sit behind the same immersed
// boundary and observables. FluidLattice (fluid_lattice.hpp) is the CPU one.
#include <cstddef>
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
// partially_saturated_collision.hpp) enter the step row by row. The lattice
// knows nothing of spheres: it lends each row a CoveredRow of row-local
// buffers, asks a SolidCoverage to fill in the coverage, runs the blended
// collision on the row if any of its cells is covered, and hands the density and momentum the
// collision saw back to the same SolidCoverage, which measures there what
// the spheres exchanged with the liquid. Nothing lattice-sized is read or
// written besides the populations.
//
// Per cell x of the row (x fastest within the lattice, row r = y + ny z):
// eps = sum_k eps_k, the summed coverage of the spheres k overlapping the
// cell, and V = sum_k eps_k u_k, the coverage-weighted solid velocity (u_k the
// velocity of sphere k's surface motion at the cell centre). A covered row
// takes the blended collision on all its cells, the uncovered ones with
// eps = 0 (the plain collision to round-off): it costs hardly more per cell
// than the plain one (the step waits on memory), while switching between the
// two along a row, stretch by stretch, cost a tenth of the step at phi 0.2.
// A row with no covered cell takes the plain collision.
template <class Real>
struct CoveredRow {
  // Every per-cell array holds nx + kPad values (x = nx .. nx + kPad - 1 are
  // slack for vector loops over whole blocks of cells; they stay zero).
  static constexpr int kPad = 16;
  long row = 0;
  int y = 0, z = 0, nx = 0;
  int thread = 0;  // the stepping thread: 0 .. threads - 1 (SolidCoverage::begin_step)
  // Written by the SolidCoverage (they are zero on entry):
  Real* coverage = nullptr;                               // eps
  Real* solid_velocity[3] = {nullptr, nullptr, nullptr};  // V
  // Written by the collision on every cell of a covered row: the density
  // and the momentum density rho u it saw (u with the half-force shift of
  // the body force and any per-cell force).
  Real* density = nullptr;
  Real* momentum[3] = {nullptr, nullptr, nullptr};
  // The row of the per-cell force field (forced_liquid's force_field()), null
  // where none is set; the uniform body force comes on top.
  const Real* force[3] = {nullptr, nullptr, nullptr};
};

// What the lattice's step asks of the partially saturated cells: begin_step()
// once, then for every row cover(), and exchange() where cover() found
// covered cells. Rows are stepped by several threads at once, but all rows of
// one z plane by one thread, in increasing y, each row's cover() and
// exchange() on the thread that steps it: an implementation may keep state
// per thread and sum per plane without locks.
template <class Real>
class SolidCoverage {
 public:
  virtual ~SolidCoverage() = default;
  // Before the step's first row: how many threads will step rows.
  virtual void begin_step(int threads) = 0;
  // Before the row's collision: write eps and V (add to the zeros there).
  // False when no cell of the row is covered (then nothing was written).
  virtual bool cover(CoveredRow<Real>& row) = 0;
  // After the row's collision: its density and momentum, to measure the
  // momentum exchanged there.
  virtual void exchange(const CoveredRow<Real>& row) = 0;
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
  // The solid coverage of the next step, for that one step: the step clears
  // it when done (a coupling sets it again before every step). `coverage`
  // must stay alive until then; null takes it back.
  virtual void set_solid_coverage(SolidCoverage<Real>* coverage) = 0;
  // The coverage set for the next step, null when none is pending.
  virtual const SolidCoverage<Real>* pending_solid_coverage() const = 0;

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
