#include "engine/partially_saturated/partially_saturated_cells.hpp"

#include <omp.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <stdexcept>
#include <string>

#include "engine/coupling/sphere_cells.hpp"
#include "engine/partially_saturated/cell_coverage.hpp"

namespace flocsim::partially_saturated {

using coupling::for_each_box_run;
using spheres::Vec3;

namespace {
constexpr double kHalfDiagonal = 0.8660254037844386;  // sqrt(3) / 2
constexpr int kChunk = lattice::SolidCoverageView<float>::kChunk;
constexpr std::size_t kAhead = 48;  // list entries prefetched ahead
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
void PartiallySaturatedCells<Real>::locate(const spheres::SphereSet& spheres) {
  const std::size_t n = spheres.size();
  const int B = box_;
  const double reach = input_radius_ + kHalfDiagonal;
  origins_.resize(n);
  rows_.resize(2 * n * static_cast<std::size_t>(B) * B);
  first_.assign(n + 1, 0);
  for (std::size_t s = 0; s < n; ++s)
    for (int d = 0; d < 3; ++d)
      origins_[s][d] = static_cast<int>(std::floor(spheres.position[s][d] - reach)) - 1;
      // Per box row: the cells whose centres lie within a_g + sqrt(3)/2 of the
      // sphere's centre (beyond it cell_coverage() is zero).
#pragma omp parallel for schedule(static)
  for (std::size_t s = 0; s < n; ++s) {
    const Vec3 centre = spheres.position[s];
    const auto& lo = origins_[s];
    std::int16_t* rows = &rows_[2 * s * B * B];
    std::size_t cells = 0;
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
        if (i1 >= i0) cells += static_cast<std::size_t>(i1 - i0 + 1);
      }
    }
    first_[s + 1] = cells;
  }
  for (std::size_t s = 0; s < n; ++s) first_[s + 1] += first_[s];
  const std::size_t total = first_[n];
  if (cell_.size() < total) {
    cell_.resize(total);
    rx_.resize(total);
    ry_.resize(total);
    rz_.resize(total);
    eps_.resize(total);
  }
}

template <class Real>
void PartiallySaturatedCells<Real>::list_cells(std::size_t k, const spheres::SphereSet& spheres,
                                               const lattice::SolidCoverageView<Real>& view) {
  const lattice::Extent& e = view.extent;
  const int B = box_;
  const Vec3 centre = spheres.position[k];
  const auto& lo = origins_[k];
  // Cells wholly inside (centre within a_g - sqrt(3)/2: coverage 1) first,
  // the others (whose coverage needs computing) from the end of the slot.
  const double inner = input_radius_ - kHalfDiagonal;
  std::size_t front = first_[k], back = first_[k + 1];
  for_each_box_run(lo, &rows_[2 * k * B * B], B, e,
                   [&](int j, int kk, int i, int x, int count, long r) {
                     const double ryd = lo[1] + j - centre[1], rzd = lo[2] + kk - centre[2];
                     const float ry = static_cast<float>(ryd), rz = static_cast<float>(rzd);
                     const double rx0 = lo[0] + i - centre[0];
                     const std::int64_t at = view.offset(r) + x;
                     const double left = inner * inner - ryd * ryd - rzd * rzd;
                     const double half = left > 0 ? std::sqrt(left) : -1.0;
                     for (int c = 0; c < count; ++c) {
                       const double rx = rx0 + c;
                       const std::size_t q = std::abs(rx) <= half ? front++ : --back;
                       cell_[q] = at + c;
                       rx_[q] = static_cast<float>(rx);
                       ry_[q] = ry;
                       rz_[q] = rz;
                       eps_[q] = 1.0f;  // computed below for the others
                     }
                     std::uint64_t* bits = view.chunk_row(r);
                     for (int c = x / kChunk; c <= (x + count - 1) / kChunk; ++c)
                       std::atomic_ref<std::uint64_t>(bits[c / 64])
                           .fetch_or(std::uint64_t(1) << (c % 64), std::memory_order_relaxed);
                   });
  const std::size_t n = first_[k + 1] - front;
  list_coverage(static_cast<int>(n), &rx_[front], &ry_[front], &rz_[front], input_radius_,
                &eps_[front]);
}

template <class Real>
void PartiallySaturatedCells<Real>::clear(const lattice::SolidCoverageView<Real>& v) {
  const lattice::Extent& e = v.extent;
  const int chunks = (e.nx + kChunk - 1) / kChunk;
#pragma omp for schedule(static)
  for (long r = 0; r < e.rows(); ++r) {
    std::uint64_t* bits = v.chunk_row(r);
    for (int c = 0; c < chunks; ++c) {
      if (!(bits[c / 64] >> (c % 64) & 1)) continue;
      const long x0 = v.offset(r) + kChunk * c;
      const int count = std::min(kChunk, e.nx - kChunk * c);
      std::fill_n(v.coverage + x0, count, Real(0));
      for (int d = 0; d < 3; ++d) std::fill_n(v.solid_velocity[d] + x0, count, Real(0));
    }
    std::fill_n(bits, v.chunk_words, std::uint64_t(0));
  }
}

template <class Real>
void PartiallySaturatedCells<Real>::remove(lattice::ForcedLiquid<Real>& liquid) {
  const auto set = liquid.solid_coverage_if_set();
  if (set.empty()) return;
  const auto view = liquid.solid_coverage();
#pragma omp parallel
  clear(view);
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
  const lattice::SolidCoverageView<Real> view = liquid.solid_coverage();
  locate(spheres);
  const auto colours = coupling::make_colours(origins_, box_, e);
  // Every sphere's cells listed with their coverage, then the coverage and
  // the coverage-weighted surface velocity added to the lattice's cells,
  // blocks of one colour in parallel (they share no cell).
#pragma omp parallel
  {
    clear(view);  // (ends with a barrier)
#pragma omp for schedule(dynamic, 8)
    for (std::size_t k = 0; k < spheres.size(); ++k) {
      list_cells(k, spheres, view);
    }
    for (const auto& blocks : colours) {
#pragma omp for schedule(dynamic, 1)
      for (std::size_t b = 0; b < blocks.size(); ++b)
        for (int s : blocks[b]) {
          const std::size_t k = static_cast<std::size_t>(s);
          const Vec3 up = spheres.velocity[k], w = spheres.angular_velocity[k];
          const std::int64_t* cell = cell_.data();
          const float *rx = rx_.data(), *ry = ry_.data(), *rz = rz_.data(), *eps = eps_.data();
          // u = u_p + omega x r at each cell centre
          const std::size_t q_end = first_[k + 1];
          for (std::size_t q = first_[k]; q < q_end; ++q) {
            if (q % 8 == 0 && q + kAhead < q_end) {  // as in after_liquid_step()
              const std::int64_t p = cell[q + kAhead];
              __builtin_prefetch(view.coverage + p, 1);
              for (int d = 0; d < 3; ++d) __builtin_prefetch(view.solid_velocity[d] + p, 1);
            }
            const std::int64_t c = cell[q];
            const double ep = eps[q];
            view.coverage[c] += static_cast<Real>(ep);
            view.solid_velocity[0][c] +=
                static_cast<Real>(ep * (up[0] + w[1] * rz[q] - w[2] * ry[q]));
            view.solid_velocity[1][c] +=
                static_cast<Real>(ep * (up[1] + w[2] * rx[q] - w[0] * rz[q]));
            view.solid_velocity[2][c] +=
                static_cast<Real>(ep * (up[2] + w[0] * ry[q] - w[1] * rx[q]));
          }
        }
    }
  }
}

template <class Real>
void PartiallySaturatedCells<Real>::after_liquid_step(const lattice::ForcedLiquid<Real>& liquid,
                                                      const spheres::SphereSet& spheres) {
  const lattice::SolidCoverageView<const Real> view = liquid.solid_coverage_if_set();
  if (view.empty())
    throw std::logic_error("partially saturated cells: after_liquid_step() without apply()");
  const lattice::ForceFieldView<const Real> field = liquid.force_field_if_set();
  const lattice::Vector3 body = liquid.body_force();
  const std::size_t n = spheres.size();
  this->force_.assign(n, Vec3::Zero());
  this->torque_.assign(n, Vec3::Zero());
  std::vector<Vec3> momentum(n, Vec3::Zero()), angular(n, Vec3::Zero());
#pragma omp parallel for schedule(dynamic, 8)
  for (std::size_t k = 0; k < n; ++k) {
    const std::int64_t* cell = cell_.data();
    const float *rx = rx_.data(), *ry = ry_.data(), *rz = rz_.data(), *eps = eps_.data();
    const bool per_cell_force = !field.empty();
    // Sums over the sphere's cells of dP (the momentum its share of the solid
    // operator gave the liquid), r x dP, eps_k rho u and r x eps_k rho u.
    double F0 = 0, F1 = 0, F2 = 0, T0 = 0, T1 = 0, T2 = 0;
    double P0 = 0, P1 = 0, P2 = 0, L0 = 0, L1 = 0, L2 = 0;
    const std::size_t q_end = first_[k + 1];
    for (std::size_t q = first_[k]; q < q_end; ++q) {
      // the lattice's arrays are read at the sphere's cells, a few rows of
      // them at a time: fetch about three rows ahead (measured: the loop
      // waits on these loads, 20-30 % less time with the prefetch)
      if (q % 8 == 0 && q + kAhead < q_end) {
        const std::int64_t p = cell[q + kAhead];
        __builtin_prefetch(view.coverage + p);
        __builtin_prefetch(view.density + p);
        for (int d = 0; d < 3; ++d) {
          __builtin_prefetch(view.solid_velocity[d] + p);
          __builtin_prefetch(view.momentum[d] + p);
        }
      }
      const std::int64_t c = cell[q];
      // dP = B (rho u_s - rho u - F), u_s = V / eps, B = min(1, eps), this
      // sphere's share eps_k / eps; cells it does not reach have eps_k = 0
      const double total = view.coverage[c] > 0 ? static_cast<double>(view.coverage[c]) : 1.0;
      const double share = eps[q] / total * std::min(1.0, total);
      const double rho_over = view.density[c] / total;
      double f0 = body.x, f1 = body.y, f2 = body.z;
      if (per_cell_force) {
        f0 += field.component[0][c];
        f1 += field.component[1][c];
        f2 += field.component[2][c];
      }
      const double j0 = view.momentum[0][c], j1 = view.momentum[1][c], j2 = view.momentum[2][c];
      const double d0 = share * (rho_over * view.solid_velocity[0][c] - j0 - f0);
      const double d1 = share * (rho_over * view.solid_velocity[1][c] - j1 - f1);
      const double d2 = share * (rho_over * view.solid_velocity[2][c] - j2 - f2);
      const double x = rx[q], y = ry[q], z = rz[q], ep = eps[q];
      F0 += d0, F1 += d1, F2 += d2;
      T0 += y * d2 - z * d1, T1 += z * d0 - x * d2, T2 += x * d1 - y * d0;
      P0 += ep * j0, P1 += ep * j1, P2 += ep * j2;
      L0 += ep * (y * j2 - z * j1), L1 += ep * (z * j0 - x * j2), L2 += ep * (x * j1 - y * j0);
    }
    // the spheres give up what their solid operator gave the liquid
    this->force_[k] = -Vec3(F0, F1, F2);
    this->torque_[k] = -Vec3(T0, T1, T2);
    momentum[k] = Vec3(P0, P1, P2);
    angular[k] = Vec3(L0, L1, L2);
  }
  this->record_internal_momenta(std::move(momentum), std::move(angular));
}

template class PartiallySaturatedCells<float>;
template class PartiallySaturatedCells<double>;

}  // namespace flocsim::partially_saturated
