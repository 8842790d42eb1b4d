#pragma once
// The partially saturated cells as they were first written, kept as the
// reference that the fused implementation (engine/partially_saturated/) must
// reproduce to round-off: per sphere, a list of its cells with their
// coverage; the coverage and the coverage-weighted solid velocity added into
// lattice-sized arrays before the step; the density and momentum each
// covered row's collision saw copied out into lattice-sized arrays; after
// the step each sphere's loads gathered from those arrays cell by cell. Only
// the arrays moved out of the lattice (which no longer has them) into this
// class, which hands them to the step row by row; nothing is fused, nothing
// threaded.
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "engine/coupling/sphere_cells.hpp"
#include "engine/lattice/forced_liquid.hpp"
#include "engine/partially_saturated/cell_coverage.hpp"
#include "engine/spheres/sphere_set.hpp"

namespace flocsim::testing_support {

template <class Real>
class ReferencePartiallySaturatedCells final : public lattice::SolidCoverage<Real> {
 public:
  explicit ReferencePartiallySaturatedCells(double input_radius) : a_(input_radius) {}

  std::vector<spheres::Vec3> force, torque, momentum, angular;

  void apply(lattice::ForcedLiquid<Real>& liquid, const spheres::SphereSet& s) {
    const lattice::Extent e = liquid.extent();
    const std::size_t cells = static_cast<std::size_t>(e.cells());
    nx_ = e.nx;
    coverage_.assign(cells, Real(0));
    for (auto& v : solid_velocity_) v.assign(cells, Real(0));
    density_.assign(cells, Real(0));
    for (auto& v : momentum_) v.assign(cells, Real(0));
    row_covered_.assign(static_cast<std::size_t>(e.rows()), 0);
    cells_.assign(s.size(), {});
    const double reach = a_ + kHalfDiagonal, inner = a_ - kHalfDiagonal;
    const partially_saturated::SphereCoverage shape(a_);
    for (std::size_t k = 0; k < s.size(); ++k) {
      const spheres::Vec3 c = s.position[k];
      const int B = static_cast<int>(std::ceil(2.0 * reach)) + 3;
      std::array<int, 3> lo;
      for (int d = 0; d < 3; ++d) lo[d] = static_cast<int>(std::floor(c[d] - reach)) - 1;
      for (int kk = 0; kk < B; ++kk)
        for (int j = 0; j < B; ++j) {
          const double ryd = lo[1] + j - c[1], rzd = lo[2] + kk - c[2];
          const double left = reach * reach - ryd * ryd - rzd * rzd;
          if (left <= 0) continue;
          const double half = std::sqrt(left);
          const int i0 = std::max(0, static_cast<int>(std::ceil(c[0] - half)) - lo[0]);
          const int i1 = std::min(B - 1, static_cast<int>(std::floor(c[0] + half)) - lo[0]);
          const double left_in = inner * inner - ryd * ryd - rzd * rzd;
          const double half_in = left_in > 0 ? std::sqrt(left_in) : -1.0;
          const long r = coupling::wrap(lo[1] + j, e.ny) +
                         static_cast<long>(e.ny) * coupling::wrap(lo[2] + kk, e.nz);
          for (int i = i0; i <= i1; ++i) {
            const double rxd = lo[0] + i - c[0];
            Cell q;
            q.index = static_cast<std::size_t>(r * e.nx + coupling::wrap(lo[0] + i, e.nx));
            q.r = {static_cast<float>(rxd), static_cast<float>(ryd), static_cast<float>(rzd)};
            // cells wholly inside skip the cut
            q.eps = std::abs(rxd) <= half_in ? 1.0f : shape(q.r[0], q.r[1], q.r[2]);
            cells_[k].push_back(q);
            row_covered_[static_cast<std::size_t>(r)] = 1;
          }
        }
      const spheres::Vec3 up = s.velocity[k], w = s.angular_velocity[k];
      for (const Cell& q : cells_[k]) {
        const double ep = q.eps;
        coverage_[q.index] += static_cast<Real>(ep);
        solid_velocity_[0][q.index] +=
            static_cast<Real>(ep * (up[0] + w[1] * q.r[2] - w[2] * q.r[1]));
        solid_velocity_[1][q.index] +=
            static_cast<Real>(ep * (up[1] + w[2] * q.r[0] - w[0] * q.r[2]));
        solid_velocity_[2][q.index] +=
            static_cast<Real>(ep * (up[2] + w[0] * q.r[1] - w[1] * q.r[0]));
      }
    }
    body_ = liquid.body_force();
    liquid.set_solid_coverage(this);
  }

  // dP = B (rho u_s - rho u - F) per cell, this sphere's share eps_k / eps.
  void after_liquid_step(const lattice::ForcedLiquid<Real>& liquid) {
    const auto field = liquid.force_field_if_set();
    const std::size_t n = cells_.size();
    force.assign(n, spheres::Vec3::Zero());
    torque = momentum = angular = force;
    for (std::size_t k = 0; k < n; ++k)
      for (const Cell& q : cells_[k]) {
        const std::size_t c = q.index;
        const double total = coverage_[c] > 0 ? static_cast<double>(coverage_[c]) : 1.0;
        const double share = q.eps / total * std::min(1.0, total);
        const double rho_over = density_[c] / total;
        spheres::Vec3 f(body_.x, body_.y, body_.z), d, j, r(q.r[0], q.r[1], q.r[2]);
        for (int a = 0; a < 3; ++a) {
          if (!field.empty()) f[a] += field.component[a][c];
          j[a] = momentum_[a][c];
          d[a] = share * (rho_over * solid_velocity_[a][c] - j[a] - f[a]);
        }
        force[k] -= d;
        torque[k] -= r.cross(d);
        momentum[k] += q.eps * j;
        angular[k] += q.eps * r.cross(j);
      }
  }

  // lattice::SolidCoverage: the rows' slices of the arrays
  void begin_step(int) override {}
  bool cover(lattice::CoveredRow<Real>& row) override {
    if (!row_covered_[static_cast<std::size_t>(row.row)]) return false;
    const std::size_t at = static_cast<std::size_t>(row.row) * nx_;
    for (int x = 0; x < nx_; ++x) {
      row.coverage[x] = coverage_[at + x];
      for (int d = 0; d < 3; ++d) row.solid_velocity[d][x] = solid_velocity_[d][at + x];
    }
    return true;
  }
  void exchange(const lattice::CoveredRow<Real>& row) override {
    const std::size_t at = static_cast<std::size_t>(row.row) * nx_;
    for (int x = 0; x < nx_; ++x) {
      density_[at + x] = row.density[x];
      for (int d = 0; d < 3; ++d) momentum_[d][at + x] = row.momentum[d][x];
    }
  }

 private:
  static constexpr double kHalfDiagonal = 0.8660254037844386;
  struct Cell {
    std::size_t index;
    std::array<float, 3> r;
    float eps;
  };
  double a_;
  int nx_ = 0;
  lattice::Vector3 body_;
  std::vector<std::vector<Cell>> cells_;
  std::vector<Real> coverage_, density_;
  std::array<std::vector<Real>, 3> solid_velocity_, momentum_;
  std::vector<char> row_covered_;  // per lattice row: some sphere's cells lie in it
};

}  // namespace flocsim::testing_support
