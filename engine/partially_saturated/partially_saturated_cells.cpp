#include "engine/partially_saturated/partially_saturated_cells.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

#include "engine/coupling/sphere_cells.hpp"
#include "engine/partially_saturated/cell_coverage.hpp"

namespace flocsim::partially_saturated {

using coupling::wrap;
using spheres::Vec3;

namespace {
constexpr double kHalfDiagonal = 0.8660254037844386;  // sqrt(3) / 2
constexpr int kChunk = lattice::CoveredRow<float>::kChunk;

// v in [0, n) for v in [-n, 2n).
int wrap_once(int v, int n) {
  return v < 0 ? v + n : (v >= n ? v - n : v);
}

// The momentum that one sphere's share of a cell's solid operator gave the
// liquid there (partially_saturated_collision.hpp): the cell's exchange
// B (rho u_s - rho u - F), u_s = V / eps, B = min(1, eps), times the share
// eps_k / eps of the cell's coverage that is the sphere's.
inline void exchange_share(double eps_k, double eps, double rho, double V0, double V1, double V2,
                           double j0, double j1, double j2, double f0, double f1, double f2,
                           double& d0, double& d1, double& d2) {
  const double total = eps > 0 ? eps : 1.0;  // (eps_k = 0 where eps = 0)
  const double inv = 1.0 / total;
  const double share = eps_k * inv * std::min(1.0, total);
  const double rho_over = rho * inv;
  d0 = share * (rho_over * V0 - j0 - f0);
  d1 = share * (rho_over * V1 - j1 - f1);
  d2 = share * (rho_over * V2 - j2 - f2);
}

// Sums of 16 rows of one chunk's lanes, q[i][0] + ... + q[i][kChunk - 1],
// accumulated over a run's chunks. One sum per row would end every run in
// 12 horizontal reductions (most of exchange()'s time); a tree of
// shuffles and adds sums eight rows at once instead.
class LaneSums {
 public:
  static_assert(kChunk == 16, "two groups of eight lanes per chunk");
  typedef double V8 __attribute__((vector_size(64)));
  typedef long long I8 __attribute__((vector_size(64)));

  void add(const double (&q)[16][kChunk]) {
    V8 v[16];
    for (int i = 0; i < 16; ++i) v[i] = load(q[i]) + load(q[i] + 8);
    // the tree's output lanes hold the totals of its inputs 0, 4, 2, 6, 1, 5, 3, 7
    for (int g = 0; g < 2; ++g) {
      const V8* p = v + 8 * g;
      total_[g] += tree(p[0], p[4], p[2], p[6], p[1], p[5], p[3], p[7]);
    }
  }
  // The first 12 sums, in order.
  template <class Sums>
  void store(Sums& out) const {
    static_assert(sizeof(Sums) == 12 * sizeof(double), "twelve sums");
    double all[16];
    std::memcpy(all, total_, sizeof all);
    std::memcpy(&out, all, sizeof out);
  }

 private:
  static V8 load(const double* p) {
    V8 v;
    std::memcpy(&v, p, sizeof v);
    return v;
  }
  static V8 tree(V8 p0, V8 p1, V8 p2, V8 p3, V8 p4, V8 p5, V8 p6, V8 p7) {
    // halves: lanes 0-3 of a and b, 4-7 of a and b, added
    const auto halves = [](V8 a, V8 b) {
      return __builtin_shuffle(a, b, I8{0, 1, 2, 3, 8, 9, 10, 11}) +
             __builtin_shuffle(a, b, I8{4, 5, 6, 7, 12, 13, 14, 15});
    };
    const auto quarters = [](V8 a, V8 b) {
      return __builtin_shuffle(a, b, I8{0, 1, 8, 9, 4, 5, 12, 13}) +
             __builtin_shuffle(a, b, I8{2, 3, 10, 11, 6, 7, 14, 15});
    };
    const auto eighths = [](V8 a, V8 b) {
      return __builtin_shuffle(a, b, I8{0, 8, 2, 10, 4, 12, 6, 14}) +
             __builtin_shuffle(a, b, I8{1, 9, 3, 11, 5, 13, 7, 15});
    };
    return eighths(quarters(halves(p0, p1), halves(p2, p3)),
                   quarters(halves(p4, p5), halves(p6, p7)));
  }
  V8 total_[2] = {};
};
}  // namespace

template <class Real>
PartiallySaturatedCells<Real>::PartiallySaturatedCells(double input_radius)
    : coupling::SphereCoupling<Real>(coupling::kPartiallySaturatedScheme),
      input_radius_(input_radius) {
  if (!(input_radius >= 1.0 && input_radius <= 2000.0))
    throw std::invalid_argument("partially saturated cells: input_radius = " +
                                std::to_string(input_radius) + ": must be in [1, 2000] dx");
  box_ = static_cast<int>(std::ceil(2.0 * (input_radius + kHalfDiagonal))) + 3;
}

template <class Real>
void PartiallySaturatedCells<Real>::locate(const spheres::SphereSet& spheres,
                                           const lattice::Extent& e) {
  const std::size_t n = spheres.size();
  const int B = box_;
  const double reach = input_radius_ + kHalfDiagonal;
  origins_.resize(n);
  rows_.resize(2 * n * static_cast<std::size_t>(B) * B);
  sphere_first_.assign(n + 1, 0);
  sphere_cells_.assign(n + 1, 0);
  for (std::size_t s = 0; s < n; ++s)
    for (int d = 0; d < 3; ++d)
      origins_[s][d] = static_cast<int>(std::floor(spheres.position[s][d] - reach)) - 1;
      // Per box row: the cells whose centres lie within a_g + sqrt(3)/2 of the
      // sphere's centre (beyond it cell_coverage() is zero), one run of them,
      // or two where the row crosses the periodic edge in x. (Dynamic
      // schedules here: on a busy machine a thread that runs takes over the
      // spheres of one that waits for a core.)
#pragma omp parallel for schedule(dynamic, 16)
  for (std::size_t s = 0; s < n; ++s) {
    const Vec3 centre = spheres.position[s];
    const auto& lo = origins_[s];
    const int x_lo = wrap(lo[0], e.nx);
    std::int16_t* rows = &rows_[2 * s * B * B];
    std::size_t runs = 0, cells = 0;
    for (int k = 0; k < B; ++k) {
      const double rz = lo[2] + k - centre[2];
      for (int j = 0; j < B; ++j) {
        const double ry = lo[1] + j - centre[1];
        const double left = reach * reach - ry * ry - rz * rz;
        int i0 = 1, i1 = 0;
        if (left > 0) {
          const double half = std::sqrt(left);
          i0 = std::max(0, static_cast<int>(std::ceil(centre[0] - half)) - lo[0]);
          i1 = std::min(B - 1, static_cast<int>(std::floor(centre[0] + half)) - lo[0]);
        }
        rows[2 * (j + B * k)] = static_cast<std::int16_t>(i0);
        rows[2 * (j + B * k) + 1] = static_cast<std::int16_t>(i1);
        if (i1 < i0) continue;
        runs += wrap_once(x_lo + i0, e.nx) + (i1 - i0) >= e.nx ? 2 : 1;
        cells += static_cast<std::size_t>(i1 - i0 + 1);
      }
    }
    sphere_first_[s + 1] = runs;
    sphere_cells_[s + 1] = cells;
  }
  for (std::size_t s = 0; s < n; ++s) {
    sphere_first_[s + 1] += sphere_first_[s];
    sphere_cells_[s + 1] += sphere_cells_[s];
  }
}

template <class Real>
void PartiallySaturatedCells<Real>::list_runs(const spheres::SphereSet& spheres,
                                              const lattice::Extent& e) {
  const std::size_t n = spheres.size();
  const int B = box_;
  const std::size_t total = sphere_first_[n];
  slot_runs_.resize(total);
  slot_row_.resize(total);
  slot_coverage_.resize(sphere_cells_[n]);
  const double inner = input_radius_ - kHalfDiagonal;
#pragma omp parallel
  {
    const SphereCoverage coverage(input_radius_);
    // the cells that need the plane cut (not wholly inside), packed: their
    // positions, their place in coverage_ and their coverage
    std::vector<float> rx, ry, rz, cut;
    std::vector<std::size_t> at;
    // Sphere by sphere, in the order of its box rows: the slots, and the
    // coverage of each run's cells.
#pragma omp for schedule(dynamic, 16)
    for (std::size_t s = 0; s < n; ++s) {
      const Vec3 centre = spheres.position[s];
      const auto& lo = origins_[s];
      const std::int16_t* rows = &rows_[2 * s * B * B];
      // the box's corner in the lattice (cells of the box that hold runs lie
      // less than a box length beyond it, so one wrap suffices)
      const int x_lo = wrap(lo[0], e.nx), y_lo = wrap(lo[1], e.ny), z_lo = wrap(lo[2], e.nz);
      std::size_t slot = sphere_first_[s], cell = sphere_cells_[s];
      const std::size_t most = sphere_cells_[s + 1] - cell;
      if (rx.size() < most) rx.resize(most), ry.resize(most), rz.resize(most), at.resize(most);
      int cuts = 0;
      for (int k = 0; k < B; ++k) {
        const long plane = static_cast<long>(e.ny) * wrap_once(z_lo + k, e.nz);
        const double rzd = lo[2] + k - centre[2];
        for (int j = 0; j < B; ++j) {
          const int i0 = rows[2 * (j + B * k)], i1 = rows[2 * (j + B * k) + 1];
          if (i0 > i1) continue;
          const auto row = static_cast<std::int32_t>(wrap_once(y_lo + j, e.ny) + plane);
          const double ryd = lo[1] + j - centre[1];
          Run run;
          run.sphere = static_cast<std::int32_t>(s);
          run.ry = static_cast<float>(ryd);
          run.rz = static_cast<float>(rzd);
          // cells within a_g - sqrt(3)/2 of the centre are wholly inside,
          // the others are cut below
          const double left = inner * inner - ryd * ryd - rzd * rzd;
          const double half = left > 0 ? std::sqrt(left) : -1.0;
          for (int i = i0; i <= i1; ++i, ++cell) {
            const double rxd = lo[0] + i - centre[0];
            slot_coverage_[cell] = 1.0f;
            rx[cuts] = static_cast<float>(rxd);
            ry[cuts] = run.ry;
            rz[cuts] = run.rz;
            at[cuts] = cell;
            cuts += std::abs(rxd) <= half ? 0 : 1;
          }
          for (int i = i0; i <= i1;) {  // pieces that do not cross the edge in x
            const int x = wrap_once(x_lo + i, e.nx);
            const int count = std::min(i1 - i + 1, e.nx - x);
            run.x = x;
            run.count = count;
            run.rx0 = lo[0] + i - centre[0];
            run.cell = static_cast<std::int32_t>(cell - static_cast<std::size_t>(i1 - i + 1));
            slot_runs_[slot] = run;
            slot_row_[slot++] = row;
            i += count;
          }
        }
      }
      if (cut.size() < rx.size()) cut.resize(rx.size());
      const float *x = rx.data(), *y = ry.data(), *z = rz.data();
      float* const eps = cut.data();
#pragma omp simd
      for (int q = 0; q < cuts; ++q) eps[q] = coverage(x[q], y[q], z[q]);
      for (int q = 0; q < cuts; ++q) slot_coverage_[at[q]] = eps[q];
    }
  }
  // Then the slots by lattice row (a counting sort: within a row, in slot
  // order), with where each run's cells will lie in coverage_.
  const std::size_t rows = static_cast<std::size_t>(e.rows());
  row_first_.assign(rows + 1, 0);
  row_cell_first_.assign(rows + 1, 0);
  for (std::size_t q = 0; q < total; ++q) {
    const auto r = static_cast<std::size_t>(slot_row_[q]);
    ++row_first_[r + 1];
    row_cell_first_[r + 1] += static_cast<std::size_t>(slot_runs_[q].count);
  }
  for (std::size_t r = 0; r < rows; ++r) {
    row_first_[r + 1] += row_first_[r];
    row_cell_first_[r + 1] += row_cell_first_[r];
  }
  next_.assign(row_first_.begin(), row_first_.end() - 1);
  next_cell_.assign(row_cell_first_.begin(), row_cell_first_.end() - 1);
  row_slot_.resize(total);
  row_cell_.resize(total);
  run_place_.resize(total);
  for (std::size_t q = 0; q < total; ++q) {
    const auto r = static_cast<std::size_t>(slot_row_[q]);
    const std::size_t k = next_[r]++;
    row_slot_[k] = static_cast<std::int32_t>(q);
    row_cell_[k] = next_cell_[r];
    next_cell_[r] += static_cast<std::size_t>(slot_runs_[q].count);
    run_place_[q] = k;
  }
  // Copied into row order, where the step reads them one after the other
  // (read from their slots during the step they cost it a wait each).
  runs_.resize(total);
  sums_.resize(total);
  coverage_.resize(row_cell_first_[rows] +
                   kChunk);  // a chunk of slack: the step reads whole chunks
  const long row_count = static_cast<long>(rows);
#pragma omp parallel for schedule(dynamic, 64)
  for (long r = 0; r < row_count; ++r)
    for (std::size_t k = row_first_[r]; k < row_first_[r + 1]; ++k) {
      Run run = slot_runs_[static_cast<std::size_t>(row_slot_[k])];
      std::copy_n(&slot_coverage_[static_cast<std::size_t>(run.cell)], run.count,
                  &coverage_[row_cell_[k]]);
      run.cell = static_cast<std::int32_t>(row_cell_[k]);
      runs_[k] = run;
    }
}

template <class Real>
void PartiallySaturatedCells<Real>::remove(lattice::ForcedLiquid<Real>& liquid) {
  if (liquid.pending_solid_coverage() == this) liquid.set_solid_coverage(nullptr);
}

template <class Real>
void PartiallySaturatedCells<Real>::apply(lattice::ForcedLiquid<Real>& liquid,
                                          const spheres::SphereSet& spheres) {
  const lattice::Extent e = liquid.extent();
  const int length[3] = {e.nx, e.ny, e.nz};
  const double reach = input_radius_ + kHalfDiagonal;
  for (int d = 0; d < 3; ++d)
    if (length[d] <= 2 * reach)  // else one cell could be within reach of a sphere and its image
      throw std::invalid_argument(
          "partially saturated cells: box length " + std::to_string(length[d]) +
          " must exceed 2 (a_g + sqrt(3)/2) = " + std::to_string(2 * reach) +
          " (a sphere must not cover its own periodic image)");
  locate(spheres, e);
  list_runs(spheres, e);
  motion_.resize(spheres.size());
  for (std::size_t s = 0; s < spheres.size(); ++s) {
    const Vec3 u = spheres.velocity[s], w = spheres.angular_velocity[s];
    motion_[s] = {u[0], u[1], u[2], w[0], w[1], w[2]};
  }
  body_force_ = liquid.body_force();
  liquid.set_solid_coverage(this);
}

template <class Real>
void PartiallySaturatedCells<Real>::cover(lattice::CoveredRow<Real>& row) const {
  Real* const eps = row.coverage;
  Real* const V0 = row.solid_velocity[0];
  Real* const V1 = row.solid_velocity[1];
  Real* const V2 = row.solid_velocity[2];
  for (std::size_t q = row_first_[row.row]; q < row_first_[row.row + 1]; ++q) {
    const Run& run = runs_[q];
    for (int c = run.x / kChunk; c <= (run.x + run.count - 1) / kChunk; ++c)
      row.chunks[c / 64] |= std::uint64_t(1) << (c % 64);
    const std::array<double, 6>& m = motion_[run.sphere];
    const float* const eps_k = &coverage_[static_cast<std::size_t>(run.cell)];
    // whole chunks of the run at a time (the row's buffers have the slack):
    // the cells beyond its end add zero
    for (int w = 0; w < run.count; w += kChunk) {
      const int x0 = run.x + w, left = run.count - w;
#pragma omp simd
      for (int c = 0; c < kChunk; ++c) {
        const double ep = c < left ? eps_k[w + c] : 0.0f;
        const double rx = static_cast<float>(run.rx0 + (w + c));
        // u = u_p + omega x r at the cell centre
        eps[x0 + c] += static_cast<Real>(ep);
        V0[x0 + c] += static_cast<Real>(ep * (m[0] + m[4] * run.rz - m[5] * run.ry));
        V1[x0 + c] += static_cast<Real>(ep * (m[1] + m[5] * rx - m[3] * run.rz));
        V2[x0 + c] += static_cast<Real>(ep * (m[2] + m[3] * run.ry - m[4] * rx));
      }
    }
  }
}

template <class Real>
void PartiallySaturatedCells<Real>::exchange(const lattice::CoveredRow<Real>& row) {
  if (row.force[0])
    exchange_runs<true>(row);
  else
    exchange_runs<false>(row);
}

template <class Real>
template <bool kForceField>
void PartiallySaturatedCells<Real>::exchange_runs(const lattice::CoveredRow<Real>& row) {
  const Real* const eps = row.coverage;
  const Real* const V0 = row.solid_velocity[0];
  const Real* const V1 = row.solid_velocity[1];
  const Real* const V2 = row.solid_velocity[2];
  const Real* const rho = row.density;
  const Real* const J0 = row.momentum[0];
  const Real* const J1 = row.momentum[1];
  const Real* const J2 = row.momentum[2];
  const Real* const F0 = row.force[0];
  const Real* const F1 = row.force[1];
  const Real* const F2 = row.force[2];
  const lattice::Vector3 body = body_force_;
  // per cell of a chunk of the run: what it adds to the run's sums (rows of
  // RunSums' order; four rows of zeros make two whole groups of eight)
  alignas(64) double q[16][kChunk] = {};
  for (std::size_t k = row_first_[row.row]; k < row_first_[row.row + 1]; ++k) {
    const Run& run = runs_[k];
    const double y = run.ry, z = run.rz;
    const float* const eps_k = &coverage_[static_cast<std::size_t>(run.cell)];
    LaneSums sums;
    for (int w = 0; w < run.count; w += kChunk) {
      const int x0 = run.x + w, left = run.count - w;
#pragma omp simd
      for (int c = 0; c < kChunk; ++c) {
        const int x = x0 + c;
        const bool inside = c < left;
        const double ep = inside ? eps_k[w + c] : 0.0f;
        double f0 = body.x, f1 = body.y, f2 = body.z;
        if constexpr (kForceField) {
          f0 += F0[x];
          f1 += F1[x];
          f2 += F2[x];
        }
        double d0, d1, d2;
        exchange_share(ep, eps[x], rho[x], V0[x], V1[x], V2[x], J0[x], J1[x], J2[x], f0, f1, f2, d0,
                       d1, d2);
        const double j0 = inside ? J0[x] : 0.0, j1 = inside ? J1[x] : 0.0,
                     j2 = inside ? J2[x] : 0.0;
        d0 = inside ? d0 : 0.0;
        d1 = inside ? d1 : 0.0;
        d2 = inside ? d2 : 0.0;
        const double rx = static_cast<float>(run.rx0 + (w + c));
        q[0][c] = d0, q[1][c] = d1, q[2][c] = d2;
        q[3][c] = y * d2 - z * d1, q[4][c] = z * d0 - rx * d2, q[5][c] = rx * d1 - y * d0;
        q[6][c] = ep * j0, q[7][c] = ep * j1, q[8][c] = ep * j2;
        q[9][c] = ep * (y * j2 - z * j1), q[10][c] = ep * (z * j0 - rx * j2);
        q[11][c] = ep * (rx * j1 - y * j0);
      }
      sums.add(q);
    }
    sums.store(sums_[k]);
  }
}

template <class Real>
void PartiallySaturatedCells<Real>::after_liquid_step(const lattice::ForcedLiquid<Real>& liquid,
                                                      const spheres::SphereSet& spheres) {
  const std::size_t n = spheres.size();
  if (sphere_first_.size() != n + 1)
    throw std::logic_error("partially saturated cells: after_liquid_step() without apply()");
  if (liquid.pending_solid_coverage() == this)
    throw std::logic_error(
        "partially saturated cells: after_liquid_step() before the liquid's step");
  this->force_.assign(n, Vec3::Zero());
  this->torque_.assign(n, Vec3::Zero());
  std::vector<Vec3> momentum(n, Vec3::Zero()), angular(n, Vec3::Zero());
  // each sphere's runs in a fixed order (its box rows')
#pragma omp parallel for schedule(dynamic, 16)
  for (std::size_t s = 0; s < n; ++s) {
    Vec3 dP = Vec3::Zero(), r_dP = Vec3::Zero(), P = Vec3::Zero(), r_P = Vec3::Zero();
    for (std::size_t q = sphere_first_[s]; q < sphere_first_[s + 1]; ++q) {
      const RunSums& m = sums_[run_place_[q]];
      dP += Vec3(m.dP[0], m.dP[1], m.dP[2]);
      r_dP += Vec3(m.r_dP[0], m.r_dP[1], m.r_dP[2]);
      P += Vec3(m.P[0], m.P[1], m.P[2]);
      r_P += Vec3(m.r_P[0], m.r_P[1], m.r_P[2]);
    }
    // the spheres give up what their solid operator gave the liquid
    this->force_[s] = -dP;
    this->torque_[s] = -r_dP;
    momentum[s] = P;
    angular[s] = r_P;
  }
  this->record_internal_momenta(std::move(momentum), std::move(angular));
}

template class PartiallySaturatedCells<float>;
template class PartiallySaturatedCells<double>;

}  // namespace flocsim::partially_saturated
