#include "engine/lattice/fluid_lattice.hpp"

#include <omp.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/lattice/aa_cell.hpp"
#include "engine/lattice/partially_saturated_collision.hpp"
#include "engine/lattice/trt_collision.hpp"

namespace flocsim::lattice {

using namespace d3q19;

namespace {

constexpr std::size_t kPageBytes = 4096;
// Distance between direction arrays is 4 KiB * k + 192 bytes, so the 19
// streams start at 19 different offsets within a page (192 * 18 < 4096).
constexpr std::size_t kStrideSkewBytes = 192;

int wrap(int i, int n) {
  i %= n;
  return i < 0 ? i + n : i;
}

// Pointers p[i] with p[i][x] = population i (deviation) of cell (x, y, z) at
// the current time: its own slot after an even number of steps, the
// opposite slot of the upstream cell x - c_i otherwise. Valid for every x
// when `even`, for the interior 0 < x < nx - 1 otherwise (the x shift of the
// end cells wraps). Neighbour rows wrap by comparison, not division.
template <class Real>
void current_population_rows(const Real* base, long stride, int nx, int ny, int nz, int y, int z,
                             bool even, const Real* (&p)[kQ]) {
  const int ys[3] = {y == 0 ? ny - 1 : y - 1, y, y == ny - 1 ? 0 : y + 1};
  const int zs[3] = {z == 0 ? nz - 1 : z - 1, z, z == nz - 1 ? 0 : z + 1};
  for (int i = 0; i < kQ; ++i) {
    if (even) {
      p[i] = base + i * stride + static_cast<long>(nx) * (y + static_cast<long>(ny) * z);
    } else {
      const long up =
          static_cast<long>(nx) * (ys[1 - cy[i]] + static_cast<long>(ny) * zs[1 - cz[i]]);
      p[i] = base + opposite(i) * stride + up - cx[i];
    }
  }
}

}  // namespace

template <class Real>
void FluidLattice<Real>::FreeAligned::operator()(Real* p) const {
  std::free(p);
}

template <class Real>
typename FluidLattice<Real>::Buffer FluidLattice<Real>::allocate(std::size_t elements) {
  std::size_t bytes = elements * sizeof(Real);
  bytes = (bytes + kPageBytes - 1) / kPageBytes * kPageBytes;
  void* p = std::aligned_alloc(kPageBytes, bytes);
  if (!p) throw std::bad_alloc();
  return Buffer(static_cast<Real*>(p));
}

template <class Real>
FluidLattice<Real>::FluidLattice(Extent extent, Relaxation relaxation)
    : extent_(extent), relaxation_(relaxation) {
  if (extent.nx < 1 || extent.ny < 1 || extent.nz < 1)
    throw std::invalid_argument("lattice extent must be at least 1 cell in each direction, got " +
                                std::to_string(extent.nx) + " x " + std::to_string(extent.ny) +
                                " x " + std::to_string(extent.nz));
  relaxation_.check();
  const std::size_t page_elements = kPageBytes / sizeof(Real);
  const std::size_t cells = static_cast<std::size_t>(extent.cells());
  stride_ = static_cast<long>((cells + page_elements - 1) / page_elements * page_elements +
                              kStrideSkewBytes / sizeof(Real));
  populations_ = allocate(static_cast<std::size_t>(stride_) * kQ);
  // First touch in the same static (z, y) schedule as the kernel, so each
  // thread's pages sit near it on NUMA machines.
  Real* base = populations_.get();
  const long stride = stride_;
  const int nx = extent.nx, ny = extent.ny, nz = extent.nz;
#pragma omp parallel for collapse(2) schedule(static)
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y)
      for (int i = 0; i < kQ; ++i)
        std::memset(base + i * stride + static_cast<long>(nx) * (y + static_cast<long>(ny) * z), 0,
                    sizeof(Real) * static_cast<std::size_t>(nx));
}

template <class Real>
FluidLattice<Real>::~FluidLattice() = default;

template <class Real>
void FluidLattice<Real>::enable_force_field() {
  if (has_force_field()) return;
  const std::size_t cells = static_cast<std::size_t>(extent_.cells());
  force_x_ = allocate(cells);
  force_y_ = allocate(cells);
  force_z_ = allocate(cells);
  // first touch in the kernel's static schedule, as for the populations
  Real* const f[3] = {force_x_.get(), force_y_.get(), force_z_.get()};
  const long n = static_cast<long>(cells);
#pragma omp parallel for schedule(static)
  for (long c = 0; c < n; ++c) f[0][c] = f[1][c] = f[2][c] = Real(0);
}

template <class Real>
ForceFieldView<Real> FluidLattice<Real>::force_field() {
  enable_force_field();
  return {extent_, {force_x_.get(), force_y_.get(), force_z_.get()}};
}

template <class Real>
ForceFieldView<const Real> FluidLattice<Real>::force_field_if_set() const {
  return {extent_, {force_x_.get(), force_y_.get(), force_z_.get()}};
}

template <class Real>
void FluidLattice<Real>::save_slots(int i, std::vector<Real>& out) const {
  const Real* from = storage(i);
  out.assign(from, from + extent_.cells());
}

template <class Real>
void FluidLattice<Real>::restore_slots(int i, const std::vector<Real>& in) {
  if (static_cast<long>(in.size()) != extent_.cells())
    throw std::invalid_argument("lattice: population slots of direction " + std::to_string(i) +
                                " hold " + std::to_string(in.size()) + " values, the lattice has " +
                                std::to_string(extent_.cells()) + " cells");
  std::copy(in.begin(), in.end(), storage(i));
}

template <class Real>
long FluidLattice<Real>::wrapped_index(int x, int y, int z) const {
  return cell_index(wrap(x, extent_.nx), wrap(y, extent_.ny), wrap(z, extent_.nz));
}

template <class Real>
double FluidLattice<Real>::population(int i, int x, int y, int z) const {
  // Even time: f_i(x) in slot i at x. Odd time (after an even step): the
  // post-collision value that streams into x along c_i was left in the
  // opposite slot of the upstream cell x - c_i.
  const double dev = time_step_ % 2 == 0
                         ? storage(i)[wrapped_index(x, y, z)]
                         : storage(opposite(i))[wrapped_index(x - cx[i], y - cy[i], z - cz[i])];
  return w[i] + dev;
}

template <class Real>
Macroscopic FluidLattice<Real>::macroscopic(int x, int y, int z) const {
  double drho = 0, j[3] = {0, 0, 0};
  for (int i = 0; i < kQ; ++i) {
    const double dev = population(i, x, y, z) - w[i];
    drho += dev;
    j[0] += cx[i] * dev;
    j[1] += cy[i] * dev;
    j[2] += cz[i] * dev;
  }
  double F[3] = {body_force_.x, body_force_.y, body_force_.z};
  if (has_force_field()) {
    const long c = wrapped_index(x, y, z);
    const Real* field[3] = {force_x_.get(), force_y_.get(), force_z_.get()};
    for (int d = 0; d < 3; ++d) F[d] += field[d][c];
  }
  Macroscopic m;
  m.density = 1.0 + drho;
  m.velocity = {(j[0] + 0.5 * F[0]) / m.density, (j[1] + 0.5 * F[1]) / m.density,
                (j[2] + 0.5 * F[2]) / m.density};
  return m;
}

template <class Real>
Macroscopic FluidLattice<Real>::macroscopic_without_force_field(int x, int y, int z) const {
  const int nx = extent_.nx, ny = extent_.ny, nz = extent_.nz;
  const long c = cell_index(x, y, z);
  double f[kQ];
  if (time_step_ % 2 == 0) {
    for (int i = 0; i < kQ; ++i) f[i] = storage(i)[c];
  } else if (x > 0 && x < nx - 1 && y > 0 && y < ny - 1 && z > 0 && z < nz - 1) {
    const long plane = static_cast<long>(nx) * ny;
    for (int i = 0; i < kQ; ++i)
      f[i] = storage(opposite(i))[c - cx[i] - static_cast<long>(nx) * cy[i] - plane * cz[i]];
  } else {
    for (int i = 0; i < kQ; ++i)
      f[i] = storage(opposite(i))[wrapped_index(x - cx[i], y - cy[i], z - cz[i])];
  }
  double drho = 0, jx = 0, jy = 0, jz = 0;
  for (int i = 0; i < kQ; ++i) {
    drho += f[i];
    jx += cx[i] * f[i];
    jy += cy[i] * f[i];
    jz += cz[i] * f[i];
  }
  Macroscopic m;
  m.density = 1.0 + drho;
  m.velocity = {(jx + 0.5 * body_force_.x) / m.density, (jy + 0.5 * body_force_.y) / m.density,
                (jz + 0.5 * body_force_.z) / m.density};
  return m;
}

template <class Real>
void FluidLattice<Real>::macroscopic_row_without_force_field(int x0, int count, int y, int z,
                                                             double* density, double* ux,
                                                             double* uy, double* uz) const {
  const int nx = extent_.nx;
  const bool even = time_step_ % 2 == 0;
  const Real* p[kQ];
  current_population_rows(populations_.get(), stride_, nx, extent_.ny, extent_.nz, y, z, even, p);
  const double bx = body_force_.x, by = body_force_.y, bz = body_force_.z;
  int k_begin = 0, k_end = count;
  const auto edge = [&](int k) {  // an end cell at an odd step: its upstream wraps in x
    const Macroscopic m = macroscopic_without_force_field(x0 + k, y, z);
    density[k] = m.density;
    ux[k] = m.velocity.x;
    uy[k] = m.velocity.y;
    uz[k] = m.velocity.z;
  };
  if (!even && count > 0 && x0 == 0) edge(k_begin++);
  if (!even && k_end > k_begin && x0 + count == nx) edge(--k_end);
    // The rest of the row along x, vectorised as the lattice step is (a sample
    // reads the whole lattice through here: docs/performance.md, liquid averages).
#pragma omp simd
  for (int k = k_begin; k < k_end; ++k) {
    double f[kQ];
#pragma GCC unroll 19
    for (int i = 0; i < kQ; ++i) f[i] = p[i][x0 + k];
    cell_moments(f, bx, by, bz, density[k], ux[k], uy[k], uz[k]);
  }
}

template <class Real>
void FluidLattice<Real>::macroscopic_row_without_force_field(int x0, int count, int y, int z,
                                                             Real* rho_u) const {
  const int nx = extent_.nx;
  const bool even = time_step_ % 2 == 0;
  const Real* p[kQ];
  current_population_rows(populations_.get(), stride_, nx, extent_.ny, extent_.nz, y, z, even, p);
  const Real bx = static_cast<Real>(body_force_.x);
  const Real by = static_cast<Real>(body_force_.y);
  const Real bz = static_cast<Real>(body_force_.z);
  int k_begin = 0, k_end = count;
  // At an odd step the upstream of the end cells wraps in x: slot x - c_x is
  // read through p[i][x] as p[i][x - c_x + c_x], so wrap x - c_x first.
  const auto edge = [&](int k) {
    const int x = x0 + k;
    Real f[kQ];
    for (int i = 0; i < kQ; ++i) {
      int up = x - cx[i];
      up = up < 0 ? up + nx : (up >= nx ? up - nx : up);
      f[i] = p[i][up + cx[i]];
    }
    cell_moments(f, bx, by, bz, rho_u[4 * k], rho_u[4 * k + 1], rho_u[4 * k + 2], rho_u[4 * k + 3]);
  };
  if (!even && count > 0 && x0 == 0) edge(k_begin++);
  if (!even && k_end > k_begin && x0 + count == nx) edge(--k_end);
#pragma omp simd
  for (int k = k_begin; k < k_end; ++k) {
    Real f[kQ];
#pragma GCC unroll 19
    for (int i = 0; i < kQ; ++i) f[i] = p[i][x0 + k];
    cell_moments(f, bx, by, bz, rho_u[4 * k], rho_u[4 * k + 1], rho_u[4 * k + 2], rho_u[4 * k + 3]);
  }
}

template <class Real>
void FluidLattice<Real>::macroscopic_fields(std::vector<double>& density, std::vector<double>& ux,
                                            std::vector<double>& uy,
                                            std::vector<double>& uz) const {
  const long n = extent_.cells();
  density.resize(static_cast<std::size_t>(n));
  ux.resize(density.size());
  uy.resize(density.size());
  uz.resize(density.size());
#pragma omp parallel for collapse(2) schedule(static)
  for (int z = 0; z < extent_.nz; ++z)
    for (int y = 0; y < extent_.ny; ++y)
      for (int x = 0; x < extent_.nx; ++x) {
        const Macroscopic m = macroscopic(x, y, z);
        const auto c = static_cast<std::size_t>(cell_index(x, y, z));
        density[c] = m.density;
        ux[c] = m.velocity.x;
        uy[c] = m.velocity.y;
        uz[c] = m.velocity.z;
      }
}

template <class Real>
double FluidLattice<Real>::total_mass() const {
  // The sum of the deviations is the mass excess over the rest density;
  // summing it alone keeps the round-off of the sum at the level of the excess.
  double excess = 0;
  const long n = extent_.cells();
#pragma omp parallel for reduction(+ : excess) schedule(static)
  for (long c = 0; c < n; ++c) {
    double cell = 0;
    for (int i = 0; i < kQ; ++i) cell += storage(i)[c];
    excess += cell;
  }
  return static_cast<double>(n) + excess;
}

template <class Real>
Vector3 FluidLattice<Real>::total_momentum() const {
  double px = 0, py = 0, pz = 0;
#pragma omp parallel for collapse(2) reduction(+ : px, py, pz) schedule(static)
  for (int z = 0; z < extent_.nz; ++z)
    for (int y = 0; y < extent_.ny; ++y)
      for (int x = 0; x < extent_.nx; ++x) {
        const Macroscopic m = macroscopic(x, y, z);
        px += m.density * m.velocity.x;
        py += m.density * m.velocity.y;
        pz += m.density * m.velocity.z;
      }
  return {px, py, pz};
}

template <class Real>
std::size_t FluidLattice<Real>::bytes_per_cell_update() const {
  return (2 * kQ + (has_force_field() ? 3 : 0)) * sizeof(Real);
}

template <class Real>
void FluidLattice<Real>::step() {
  if (solid_coverage_) {
    if (has_force_field())
      step_kernel<true, true>();
    else
      step_kernel<false, true>();
  } else if (has_force_field()) {
    step_kernel<true, false>();
  } else {
    step_kernel<false, false>();
  }
  solid_coverage_ = nullptr;  // one step: the coupling sets it again
  ++time_step_;
}

namespace {

// The buffers one thread lends the partially saturated cells for each row it
// steps (forced_liquid.hpp: CoveredRow), zero where the row format wants zero.
template <class Real>
class CoveredRowBuffers {
 public:
  explicit CoveredRowBuffers(int nx)
      : cells_(static_cast<std::size_t>(nx) + CoveredRow<Real>::kPad) {
    const std::size_t cells = cells_;
    values_.assign(8 * cells, Real(0));
    row_.nx = nx;
    Real* p = values_.data();
    row_.coverage = p;
    row_.density = p + 4 * cells;
    for (int d = 0; d < 3; ++d) {
      row_.solid_velocity[d] = p + (1 + d) * cells;
      row_.momentum[d] = p + (5 + d) * cells;
    }
  }
  CoveredRow<Real>& row() { return row_; }
  // Back to zero coverage after a covered row (eps and V lie first, together).
  void reset() { std::fill_n(values_.data(), 4 * cells_, Real(0)); }

 private:
  std::size_t cells_ = 0;
  std::vector<Real> values_;
  CoveredRow<Real> row_;
};

}  // namespace

template <class Real>
template <bool kForceField, bool kCoverage>
void FluidLattice<Real>::step_kernel() {
  const int nx = extent_.nx, ny = extent_.ny, nz = extent_.nz;
  const bool even = time_step_ % 2 == 0;
  CollisionConstants<Real> k;
  k.omega_plus = static_cast<Real>(relaxation_.omega_plus());
  k.omega_minus = static_cast<Real>(relaxation_.omega_minus());
  k.force_plus = static_cast<Real>(1.0 - 0.5 * relaxation_.omega_plus());
  k.force_minus = static_cast<Real>(1.0 - 0.5 * relaxation_.omega_minus());
  const Real bx = static_cast<Real>(body_force_.x);
  const Real by = static_cast<Real>(body_force_.y);
  const Real bz = static_cast<Real>(body_force_.z);
  Real* const base = populations_.get();
  const long stride = stride_;
  const Real* const Fxs = force_x_.get();
  const Real* const Fys = force_y_.get();
  const Real* const Fzs = force_z_.get();
  SolidCoverage<Real>* const solid = kCoverage ? solid_coverage_ : nullptr;
  if constexpr (kCoverage) solid->begin_step(omp_get_max_threads());

#pragma omp parallel
  {
    // per thread: the row-local coverage buffers (a few KiB, in cache)
    CoveredRowBuffers<Real> buffers(kCoverage ? nx : 0);
    CoveredRow<Real>& cover = buffers.row();
    const Real* const eps = cover.coverage;
    const Real* const Vx = cover.solid_velocity[0];
    const Real* const Vy = cover.solid_velocity[1];
    const Real* const Vz = cover.solid_velocity[2];
    Real* const rho_seen = cover.density;
    Real* const jx_seen = cover.momentum[0];
    Real* const jy_seen = cover.momentum[1];
    Real* const jz_seen = cover.momentum[2];
    if constexpr (kCoverage) cover.thread = omp_get_thread_num();

    // One lattice row: collision and streaming of cells (0 .. nx - 1, y, z).
    const auto step_row = [&](int z, int y) FLOCSIM_LAMBDA_ALWAYS_INLINE {
      const long row = static_cast<long>(nx) * (y + static_cast<long>(ny) * z);
      // Start of the neighbouring rows (y + dy, z + dz), dy, dz in {-1, 0, 1},
      // periodic: neighbour_row[dz + 1][dy + 1]. Only unit offsets occur, so
      // the wrap is a comparison, not an integer division per direction.
      long neighbour_row[3][3];
      {
        const int ys[3] = {y == 0 ? ny - 1 : y - 1, y, y == ny - 1 ? 0 : y + 1};
        const int zs[3] = {z == 0 ? nz - 1 : z - 1, z, z == nz - 1 ? 0 : z + 1};
        for (int dz = 0; dz < 3; ++dz)
          for (int dy = 0; dy < 3; ++dy)
            neighbour_row[dz][dy] =
                static_cast<long>(nx) * (ys[dy] + static_cast<long>(ny) * zs[dz]);
      }
      // Per direction: where this row's incoming populations are read and its
      // outgoing ones written, as pointers indexed by x.
      const Real* load[kQ];
      Real* store[kQ];
      for (int i = 0; i < kQ; ++i) {
        if (even) {
          load[i] = base + i * stride + row;
          store[i] = base + opposite(i) * stride + row;
        } else {
          const long up = neighbour_row[1 - cz[i]][1 - cy[i]];
          const long down = neighbour_row[1 + cz[i]][1 + cy[i]];
          load[i] = base + opposite(i) * stride + up - cx[i];
          store[i] = base + i * stride + down + cx[i];
        }
      }
      const Real* Fx = kForceField ? Fxs + row : nullptr;
      const Real* Fy = kForceField ? Fys + row : nullptr;
      const Real* Fz = kForceField ? Fzs + row : nullptr;

      auto update = [&](int x, const Real* const* ld, Real* const* st, int lx, int sx)
                        FLOCSIM_LAMBDA_ALWAYS_INLINE {
                          Real f[kQ];
#pragma GCC unroll 19
                          for (int i = 0; i < kQ; ++i) f[i] = ld[i][lx];
                          Real Fcx = bx, Fcy = by, Fcz = bz;
                          if constexpr (kForceField) {
                            Fcx += Fx[x];
                            Fcy += Fy[x];
                            Fcz += Fz[x];
                          }
                          collide(f, Fcx, Fcy, Fcz, k);
#pragma GCC unroll 19
                          for (int i = 0; i < kQ; ++i) st[i][sx] = f[i];
                        };

      // A cell that spheres partly cover (partially_saturated_collision.hpp):
      // it reads its coverage from the row's buffers and leaves there the
      // density and momentum it saw.
      auto update_covered = [&](int x, const Real* const* ld, Real* const* st, int lx,
                                int sx) FLOCSIM_LAMBDA_ALWAYS_INLINE {
        Real f[kQ];
#pragma GCC unroll 19
        for (int i = 0; i < kQ; ++i) f[i] = ld[i][lx];
        Real Fcx = bx, Fcy = by, Fcz = bz;
        if constexpr (kForceField) {
          Fcx += Fx[x];
          Fcy += Fy[x];
          Fcz += Fz[x];
        }
        collide_partially_saturated(f, Fcx, Fcy, Fcz, eps[x], Vx[x], Vy[x], Vz[x], k, rho_seen[x],
                                    jx_seen[x], jy_seen[x], jz_seen[x]);
#pragma GCC unroll 19
        for (int i = 0; i < kQ; ++i) st[i][sx] = f[i];
      };

      const long row_index = static_cast<long>(y) + static_cast<long>(ny) * z;
      bool covered_row = false;
      if constexpr (kCoverage) {
        cover.row = row_index;
        cover.y = y;
        cover.z = z;
        for (int d = 0; d < 3; ++d) cover.force[d] = nullptr;
        if constexpr (kForceField) {
          cover.force[0] = Fx;
          cover.force[1] = Fy;
          cover.force[2] = Fz;
        }
        covered_row = solid->cover(cover);
      }
      // Interior of the row: every shifted pointer stays inside the row, so
      // the loop is a plain unit-stride sweep the compiler vectorises.
      const int x_begin = even ? 0 : 1;
      const int x_end = even ? nx : nx - 1;
      if (covered_row) {
        // the whole row blended, its uncovered cells with eps = 0
        // (forced_liquid.hpp: CoveredRow says why)
#pragma omp simd
        for (int x = x_begin; x < x_end; ++x) update_covered(x, load, store, x, x);
      } else {
#pragma omp simd
        for (int x = x_begin; x < x_end; ++x) update(x, load, store, x, x);
      }

      // Odd steps: the two end cells of the row stream across the periodic
      // boundary in x; give them explicitly wrapped pointers.
      if (!even) {
        // the first and the last cell of the row: one cell when nx == 1
        for (int end = 0; end < (nx == 1 ? 1 : 2); ++end) {
          const int x = end == 0 ? 0 : nx - 1;
          const Real* ld[kQ];
          Real* st[kQ];
          for (int i = 0; i < kQ; ++i) {
            const int from = x - cx[i], to = x + cx[i];  // within one cell of the row
            ld[i] = load[i] + cx[i] + (from < 0 ? from + nx : from >= nx ? from - nx : from);
            st[i] = store[i] - cx[i] + (to < 0 ? to + nx : to >= nx ? to - nx : to);
          }
          if (covered_row)
            update_covered(x, ld, st, 0, 0);
          else
            update(x, ld, st, 0, 0);
        }
      }

      if constexpr (kCoverage)
        if (covered_row) {
          solid->exchange(cover);
          buffers.reset();
        }
    };

    if constexpr (kCoverage) {
      // each z plane on one thread, its rows in order (forced_liquid.hpp)
#pragma omp for schedule(static)
      for (int z = 0; z < nz; ++z)
        for (int y = 0; y < ny; ++y) step_row(z, y);
    } else {
#pragma omp for collapse(2) schedule(static)
      for (int z = 0; z < nz; ++z)
        for (int y = 0; y < ny; ++y) step_row(z, y);
    }
  }
}

template class FluidLattice<float>;
template class FluidLattice<double>;

}  // namespace flocsim::lattice
