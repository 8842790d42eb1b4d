#pragma once
// How much of a lattice cell a sphere covers: the solid fraction eps of the
// partially saturated cells (partially_saturated_cells.hpp).
//
// Near the surface the sphere is replaced by its tangent plane at the point
// nearest the cell centre, moved inwards by the mean sagitta 1 / (12 a) of
// the curved surface over the cell (the surface lies rho^2 / (2a) inside the
// plane at a tangential distance rho; rho^2 averages 1/6 over a unit cell),
// and the cell's volume below that plane is exact (the fraction of a unit cube
// cut by a plane, Scardovelli & Zaleski 2000). Cells whose centres are farther
// than sqrt(3)/2 from the surface are wholly inside or outside. The fraction
// varies continuously as the sphere moves, and summed over the cells it gives
// the sphere's volume to a few 1e-5 at a = 4-8, where the plane alone would
// be 1.6-0.4 % too big (tests/coupling, CellCoverage).
#include <algorithm>
#include <cmath>

#include "engine/lattice/kernel_body.hpp"

namespace flocsim::partially_saturated {

// Fraction of the unit cube [-1/2, 1/2]^3 on the side n . x <= d of the plane
// n . x = d (|n| = 1). With m_i = |n_i| the fraction is the probability that
// sum m_i U_i <= d + sum m_i / 2 for independent U_i uniform on [0, 1]: a
// piecewise cubic in d. Components below 1e-4 count as 1e-4, which changes
// the fraction by at most about 1e-4 and keeps the divisions well conditioned.
inline double cube_fraction_below_plane(double nx, double ny, double nz, double d) {
  constexpr double kSmallest = 1e-4;
  const double m0 = std::max(std::abs(nx), kSmallest), m1 = std::max(std::abs(ny), kSmallest),
               m2 = std::max(std::abs(nz), kSmallest);
  const double s = m0 + m1 + m2;
  double alpha = d + 0.5 * s;  // the plane's distance from the cube's lowest corner, along m
  if (alpha <= 0) return 0.0;
  if (alpha >= s) return 1.0;
  const bool upper = alpha > 0.5 * s;  // evaluate the smaller side: less cancellation
  if (upper) alpha = s - alpha;
  auto cube = [](double x) { return x > 0 ? x * x * x : 0.0; };
  // alpha <= s/2, so the term in alpha - s vanishes
  double v = (cube(alpha) - cube(alpha - m0) - cube(alpha - m1) - cube(alpha - m2) +
              cube(alpha - m0 - m1) + cube(alpha - m0 - m2) + cube(alpha - m1 - m2)) /
             (6.0 * m0 * m1 * m2);
  v = std::clamp(v, 0.0, 1.0);
  return upper ? 1.0 - v : v;
}

// Fraction of the unit cell centred at r (from the sphere's centre) that lies
// inside the sphere of radius a (a >= 1).
inline double cell_coverage(double rx, double ry, double rz, double a) {
  constexpr double kHalfDiagonal = 0.8660254037844386;  // sqrt(3) / 2
  const double r2 = rx * rx + ry * ry + rz * rz;
  const double inner = a - kHalfDiagonal, outer = a + kHalfDiagonal;
  if (r2 <= inner * inner) return 1.0;
  if (r2 >= outer * outer) return 0.0;
  const double r = std::sqrt(r2);
  const double d = a - 1.0 / (12.0 * a) - r;  // the cell centre's depth below the plane
  return cube_fraction_below_plane(rx / r, ry / r, rz / r, d);
}

// cell_coverage() without branches, so that loops over cells vectorise (the
// partially saturated cells evaluate it for every covered cell of every
// sphere each step): one sphere's constants, then the fraction of the cell
// centred at (x, y, z) from its centre. Positions come in single precision
// (as the cells are listed); the cubic is evaluated in double, whose
// cancellation error stays below 1e-9 where the normal is near an axis.
// A kernel body (kernel_body.hpp): the GPU's partially saturated cells
// (engine/coupling_gpu) evaluate the same function, one cell per thread.
struct SphereCoverage {
  double inner2, outer2, plane;  // (a - sqrt(3)/2)^2, (a + sqrt(3)/2)^2, a - 1/(12 a)
  SphereCoverage() = default;
  FLOCSIM_HD explicit SphereCoverage(double a)
      : inner2((a - 0.8660254037844386) * (a - 0.8660254037844386)),
        outer2((a + 0.8660254037844386) * (a + 0.8660254037844386)),
        plane(a - 1.0 / (12.0 * a)) {}

  FLOCSIM_KERNEL_BODY float operator()(float rx, float ry, float rz) const {
    constexpr double kSmallest = 1e-4;
    const double x = rx, y = ry, z = rz;
    const double r2 = x * x + y * y + z * z;
    const double r = std::sqrt(r2 > 0 ? r2 : 1.0);  // the centre cell is inside anyway
    const double inv = 1.0 / r;
    const double m0 = std::max(std::abs(x) * inv, kSmallest);
    const double m1 = std::max(std::abs(y) * inv, kSmallest);
    const double m2 = std::max(std::abs(z) * inv, kSmallest);
    const double s = m0 + m1 + m2;
    const double alpha = plane - r + 0.5 * s;
    const bool upper = alpha > 0.5 * s;
    const double al = upper ? s - alpha : alpha;
    const double t0 = std::max(al, 0.0), t1 = std::max(al - m0, 0.0), t2 = std::max(al - m1, 0.0),
                 t3 = std::max(al - m2, 0.0), t4 = std::max(al - m0 - m1, 0.0),
                 t5 = std::max(al - m0 - m2, 0.0), t6 = std::max(al - m1 - m2, 0.0);
    double v = (t0 * t0 * t0 - t1 * t1 * t1 - t2 * t2 * t2 - t3 * t3 * t3 + t4 * t4 * t4 +
                t5 * t5 * t5 + t6 * t6 * t6) /
               (6.0 * m0 * m1 * m2);
    v = std::min(std::max(v, 0.0), 1.0);
    const double cut = upper ? 1.0 - v : v;
    return static_cast<float>(r2 <= inner2 ? 1.0 : (r2 >= outer2 ? 0.0 : cut));
  }
};

}  // namespace flocsim::partially_saturated
