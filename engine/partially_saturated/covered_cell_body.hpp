#pragma once
// The partially saturated cells' per-sphere, per-cell arithmetic as kernel
// bodies (engine/lattice/kernel_body.hpp), on a cube of B^3 cells around one
// sphere: what the GPU's coupling (engine/coupling_gpu/covered_cell_kernels.cu)
// runs with one thread block per sphere and one thread per box cell, and what
// the test suite runs here in plain loops against the CPU's
// PartiallySaturatedCells (tests/coupling/covered_cell_body_test.cpp).
//
// The CPU finds a sphere's cells row by row (partially_saturated_cells.cpp:
// its slices by z plane, then per row the run of cells i0 .. i1 within
// a_g + sqrt(3)/2 of the centre, the cells a .. b wholly inside, the run cut
// where it crosses the periodic edge in x). covered_cell() makes the same
// decisions for one box cell from the same numbers, in the same order of
// operations, so that a cell is covered, and by how much, exactly where the
// CPU says it is, and the offsets from the centre that enter the solid
// velocity and the torque are rounded as the CPU's runs round them.
#include <cmath>
#include <stdexcept>
#include <string>

#include "engine/lattice/forced_liquid.hpp"
#include "engine/lattice/kernel_body.hpp"
#include "engine/partially_saturated/cell_coverage.hpp"

namespace flocsim::partially_saturated {

inline constexpr double kHalfCellDiagonal = 0.8660254037844386;  // sqrt(3) / 2

// The edge B of the cube of cells around a sphere of input radius a_g.
inline int covering_box_edge(double input_radius) {
  return static_cast<int>(std::ceil(2.0 * (input_radius + kHalfCellDiagonal))) + 3;
}

// A sphere must not cover its own periodic image: every box length must
// exceed 2 (a_g + sqrt(3)/2). Throws std::invalid_argument otherwise.
inline void check_box_length(const lattice::Extent& e, double input_radius) {
  const int length[3] = {e.nx, e.ny, e.nz};
  const double reach = input_radius + kHalfCellDiagonal;
  for (int d = 0; d < 3; ++d)
    if (length[d] <= 2 * reach)  // else one cell could be within reach of a sphere and its image
      throw std::invalid_argument(
          "partially saturated cells: box length " + std::to_string(length[d]) +
          " must exceed 2 (a_g + sqrt(3)/2) = " + std::to_string(2 * reach) +
          " (a sphere must not cover its own periodic image)");
}

// One sphere as the cells see it: its centre moved into the box, the lowest
// corner of its cube of cells (unwrapped), its velocity and angular velocity.
struct CoveringSphere {
  double centre[3] = {0, 0, 0};
  int lo[3] = {0, 0, 0};
  double motion[6] = {0, 0, 0, 0, 0, 0};  // u_p, omega
};

// A CoveringSphere from the 12 numbers per sphere the GPU receives (centre,
// corner, u_p, omega; gpu_partially_saturated.cpp packs them in this order).
FLOCSIM_KERNEL_BODY CoveringSphere unpack_covering_sphere(const double* p) {
  CoveringSphere s;
  for (int d = 0; d < 3; ++d) {
    s.centre[d] = p[d];
    s.lo[d] = static_cast<int>(p[3 + d]);
  }
  for (int q = 0; q < 6; ++q) s.motion[q] = p[6 + q];
  return s;
}

// Host side, as the CPU's apply() places a sphere.
inline CoveringSphere covering_sphere(const double (&position)[3], const double (&velocity)[3],
                                      const double (&omega)[3], const lattice::Extent& e,
                                      double input_radius) {
  const int length[3] = {e.nx, e.ny, e.nz};
  const double reach = input_radius + kHalfCellDiagonal;
  CoveringSphere s;
  for (int d = 0; d < 3; ++d) {
    const double L = length[d];
    s.centre[d] = position[d] - L * std::floor(position[d] / L);
    s.lo[d] = static_cast<int>(std::floor(s.centre[d] - reach)) - 1;
    s.motion[d] = velocity[d];
    s.motion[3 + d] = omega[d];
  }
  return s;
}

// What every sphere shares: the box edge, the reach, the coverage's constants.
struct CoveringGeometry {
  int B = 0;
  int n[3] = {1, 1, 1};         // the lattice's extent
  double reach = 0, inner = 0;  // a_g + sqrt(3)/2, a_g - sqrt(3)/2
  SphereCoverage coverage;
  CoveringGeometry() = default;
  CoveringGeometry(double input_radius, const lattice::Extent& e)
      : B(covering_box_edge(input_radius)),
        n{e.nx, e.ny, e.nz},
        reach(input_radius + kHalfCellDiagonal),
        inner(input_radius - kHalfCellDiagonal),
        coverage(input_radius) {}
};

// One cell of a sphere's runs: the lattice cell, the sphere's coverage eps_k
// of it, and its offset from the centre as the CPU's run has it (rx rounded
// to single precision from the run's start, ry and rz in single precision).
struct CoveredCell {
  int x = 0, y = 0, z = 0;
  float eps = 0;
  double rx = 0, ry = 0, rz = 0;
};

FLOCSIM_KERNEL_BODY int wrap_once(int v, int n) {
  return v < 0 ? v + n : (v >= n ? v - n : v);
}
FLOCSIM_KERNEL_BODY int larger(int a, int b) {
  return a < b ? b : a;
}
FLOCSIM_KERNEL_BODY int smaller(int a, int b) {
  return b < a ? b : a;
}

// Whether box cell (i, j, k) of sphere s lies in one of the CPU's runs (its
// centre within a_g + sqrt(3)/2 of the sphere's, decided row by row as the
// CPU does); then `out` holds the cell, and with kCoverage its coverage.
template <bool kCoverage>
FLOCSIM_KERNEL_BODY bool covered_cell(const CoveringGeometry& g, const CoveringSphere& s, int i,
                                      int j, int k, CoveredCell& out) {
  const double reach = g.reach;
  // the slice: plane k of the box and the rows j0 .. j1 it reaches
  const double rz = s.lo[2] + k - s.centre[2];
  const double left_z = reach * reach - rz * rz;
  if (left_z <= 0) return false;
  const double half_z = ::sqrt(left_z);
  const int j0 = larger(0, static_cast<int>(::ceil(s.centre[1] - half_z)) - s.lo[1]);
  const int j1 = smaller(g.B - 1, static_cast<int>(::floor(s.centre[1] + half_z)) - s.lo[1]);
  if (j < j0 || j > j1) return false;
  // the row: cells i0 .. i1
  const double ry = s.lo[1] + j - s.centre[1];
  const double left = reach * reach - ry * ry - rz * rz;
  if (left <= 0) return false;
  const double cx = s.centre[0];
  const int lo_x = s.lo[0];
  const double half = ::sqrt(left);
  const int i0 = larger(0, static_cast<int>(::ceil(cx - half)) - lo_x);
  const int i1 = smaller(g.B - 1, static_cast<int>(::floor(cx + half)) - lo_x);
  if (i < i0 || i > i1) return false;
  out.x = wrap_once(lo_x + i, g.n[0]);
  out.y = wrap_once(s.lo[1] + j, g.n[1]);
  out.z = wrap_once(s.lo[2] + k, g.n[2]);
  if constexpr (kCoverage) {
    // wholly inside: cells a .. b of the row
    bool inside = false;
    const double left_in = g.inner * g.inner - ry * ry - rz * rz;
    if (left_in > 0) {
      const double half_in = ::sqrt(left_in);
      const int a = larger(i0, static_cast<int>(::ceil(cx - half_in)) - lo_x);
      const int b = smaller(i1, static_cast<int>(::floor(cx + half_in)) - lo_x);
      inside = a <= b && i >= a && i <= b;
    }
    const float ry_f = static_cast<float>(ry), rz_f = static_cast<float>(rz);
    out.eps = inside ? 1.0f : g.coverage(static_cast<float>(lo_x + i - cx), ry_f, rz_f);
    // the CPU's run starts at i0 or where the row crosses the edge in x
    // (lo_x + i = 0 or nx), and measures x from its start
    int start = i0;
    const int edges[2] = {-lo_x, g.n[0] - lo_x};
    for (int q = 0; q < 2; ++q)
      if (edges[q] > i0 && edges[q] <= i) start = edges[q];
    const double rx0 = lo_x + start - cx;
    out.rx = static_cast<float>(rx0 + (i - start));
    out.ry = ry_f;
    out.rz = rz_f;
  }
  return true;
}

// What sphere s adds to the cell's V = sum eps_k u_k: eps_k (u_p + omega x r).
FLOCSIM_KERNEL_BODY void solid_velocity_share(const CoveringSphere& s, const CoveredCell& c,
                                              double (&v)[3]) {
  const double* m = s.motion;
  const double ep = c.eps;
  v[0] = ep * (m[0] + m[4] * c.rz - m[5] * c.ry);
  v[1] = ep * (m[1] + m[5] * c.rx - m[3] * c.rz);
  v[2] = ep * (m[2] + m[3] * c.ry - m[4] * c.rx);
}

// The momentum that one sphere's share of a cell's solid operator gave the
// liquid there (partially_saturated_collision.hpp): the cell's exchange
// B (rho u_s - rho u - F), u_s = V / eps, B = min(1, eps), times the share
// eps_k / eps of the cell's coverage that is the sphere's.
FLOCSIM_KERNEL_BODY void exchange_share(double eps_k, double eps, double rho, double V0, double V1,
                                        double V2, double j0, double j1, double j2, double f0,
                                        double f1, double f2, double& d0, double& d1, double& d2) {
  const double total = eps > 0 ? eps : 1.0;  // (eps_k = 0 where eps = 0)
  const double inv = 1.0 / total;
  const double share = eps_k * inv * (total < 1.0 ? total : 1.0);
  const double rho_over = rho * inv;
  d0 = share * (rho_over * V0 - j0 - f0);
  d1 = share * (rho_over * V1 - j1 - f1);
  d2 = share * (rho_over * V2 - j2 - f2);
}

// What one covered cell adds to its sphere's sums, in the order of the CPU's
// sums: dP, r x dP, eps_k rho u, r x eps_k rho u. eps, V, rho, j: the cell's
// (summed over its spheres; what its collision saw); f the force density
// there (body force and any per-cell force).
FLOCSIM_KERNEL_BODY void exchange_terms(const CoveredCell& c, double eps, const double (&V)[3],
                                        double rho, const double (&j)[3], const double (&f)[3],
                                        double (&q)[12]) {
  const double ep = c.eps, rx = c.rx, y = c.ry, z = c.rz;
  double d0, d1, d2;
  exchange_share(ep, eps, rho, V[0], V[1], V[2], j[0], j[1], j[2], f[0], f[1], f[2], d0, d1, d2);
  q[0] = d0, q[1] = d1, q[2] = d2;
  q[3] = y * d2 - z * d1, q[4] = z * d0 - rx * d2, q[5] = rx * d1 - y * d0;
  q[6] = ep * j[0], q[7] = ep * j[1], q[8] = ep * j[2];
  q[9] = ep * (y * j[2] - z * j[1]), q[10] = ep * (z * j[0] - rx * j[2]);
  q[11] = ep * (rx * j[1] - y * j[0]);
}

}  // namespace flocsim::partially_saturated
