#pragma once
// The collision of a cell that spheres partly cover: partially saturated
// cells (Noble & Torczynski 1998; the formulation of Owen et al. 2011 that
// waLBerla's PSM sweep follows, Rettinger & Rüde 2017), with this lattice's
// TRT collision and Guo forcing (trt_collision.hpp) as the liquid's operator.
//
// A cell whose volume the spheres cover to a fraction eps (summed over the
// spheres reaching it, at most 1 counted) blends its liquid update with a
// solid one, in proportion B = eps:
//
//   f_i' = f_i + C_i + (1 - B) G_i + B (Feq_i(rho, u_s) - Feq_i(rho, u) + h_i)
//
// C the TRT collision (relaxation towards Feq(rho, u)), G the Guo forcing
// term, u the velocity the collision sees (with the half-force shift) and
// u_s the covering spheres' surface velocity at the cell centre (their
// coverage-weighted mean where two spheres share a cell). The solid part is
// the "superposition" operator (Owen et al. eq. 29: the collision relaxes
// towards the solid's equilibrium instead of the liquid's) with the force
// term replaced by h, an antisymmetric term of momentum -omega_minus F / 2:
// a fully covered cell then leaves its step with exactly the velocity u_s
// for the next collision, and the momentum the cell's update adds beyond
// the body force F is, to round-off,
//
//   dP_solid = B (rho (u_s - u) - F),
//
// which the spheres give up (partially_saturated/): at a steady state a
// covered cell's spheres hold its liquid against the body force, exactly as
// the immersed boundary's markers do. Mass is conserved exactly (Feq(rho, u_s)
// and Feq(rho, u) have the same density; h has none).
//
// Why B = eps (Owen et al.'s first weighting) and not Noble & Torczynski's
// B = eps (tau - 1/2) / ((1 - eps) + (tau - 1/2)): at the paper's viscosities
// (tau - 1/2 = 0.015-0.06) theirs makes a half-covered cell nearly liquid
// (B = 0.03 at eps = 0.5, tau = 0.53), so a moving sphere's boundary would
// jump from cell to cell; B = eps varies smoothly as a sphere moves, and the
// calibrated hydrodynamic radius absorbs its dependence on tau.
#include "engine/lattice/trt_collision.hpp"

namespace flocsim::lattice {

// In place on the deviations f_i - w_i. (Fx, Fy, Fz): the force density on
// the cell; eps the summed coverage; (Vx, Vy, Vz) = sum eps_k u_k. Returns
// the density and the momentum density rho u the collision saw.
template <class Real>
FLOCSIM_KERNEL_BODY void collide_partially_saturated(Real (&f)[d3q19::kQ], Real Fx, Real Fy,
                                                     Real Fz, Real eps, Real Vx, Real Vy, Real Vz,
                                                     const CollisionConstants<Real>& k,
                                                     Real& rho_out, Real& jx_out, Real& jy_out,
                                                     Real& jz_out) {
  using namespace d3q19;
  Real drho = 0;
  FLOCSIM_UNROLL
  for (int i = 0; i < kQ; ++i) drho += f[i];
  const Real rho = Real(1) + drho;
  const Real jx = f[1] - f[2] + f[7] - f[8] + f[9] - f[10] + f[11] - f[12] + f[13] - f[14];
  const Real jy = f[3] - f[4] + f[7] - f[8] - f[9] + f[10] + f[15] - f[16] + f[17] - f[18];
  const Real jz = f[5] - f[6] + f[11] - f[12] - f[13] + f[14] + f[15] - f[16] - f[17] + f[18];
  const Real inv_rho = Real(1) / rho;
  const Real ux = (jx + Real(0.5) * Fx) * inv_rho;
  const Real uy = (jy + Real(0.5) * Fy) * inv_rho;
  const Real uz = (jz + Real(0.5) * Fz) * inv_rho;
  // B = min(1, eps); u_s = V / eps (0 where nothing covers the cell)
  const Real B = eps < Real(1) ? eps : Real(1);
  const Real inv_eps = eps > Real(0) ? Real(1) / eps : Real(0);
  const Real sx = Vx * inv_eps, sy = Vy * inv_eps, sz = Vz * inv_eps;
  const Real usq15 = Real(1.5) * (ux * ux + uy * uy + uz * uz);
  const Real ssq15 = Real(1.5) * (sx * sx + sy * sy + sz * sz);
  const Real uF3 = Real(3) * (ux * Fx + uy * Fy + uz * Fz);
  const Real liquid = Real(1) - B;
  // The update of the pair (i, opposite) above, per population:
  //   d_plus  = -omega_plus (f_plus - eq_plus) + (1 - B) force_plus_factor force_plus
  //             + B (Feq_plus(u_s) - Feq_plus(u)),
  //   d_minus = -omega_minus (f_minus - eq_minus) + (1 - B) force_minus_factor force_minus
  //             + B (Feq_minus(u_s) - Feq_minus(u) + h),
  // with the equilibria and Guo terms of trt_collision.hpp and h of momentum
  // -omega_minus F / 2. Collected per power of c.u, c.s and c.F the cell's
  // coefficients are computed once and each pair costs a few multiply-adds:
  //   d_plus  = -omega_plus f_plus + w_i (K + (A_u c.u + A_F c.F) c.u + A_s (c.s)^2),
  //   d_minus = -omega_minus f_minus + w_i (M_u c.u + M_s c.s + M_F c.F).
  const Real op = k.omega_plus, om = k.omega_minus;
  const Real rho_B = rho * B;
  const Real K = op * drho - rho * ((op - B) * usq15) - rho_B * ssq15 - liquid * k.force_plus * uF3;
  const Real A_u = Real(4.5) * rho * (op - B), A_s = Real(4.5) * rho_B;
  const Real A_F = Real(9) * liquid * k.force_plus;
  const Real M_u = Real(3) * rho * (om - B), M_s = Real(3) * rho_B;
  // h: per pair -omega_minus / 2 * 3 w_i c_i . F
  const Real M_F = Real(3) * (liquid * k.force_minus - Real(0.5) * om * B);

  f[0] += -op * f[0] + Real(kWeightRest) * K;
  FLOCSIM_UNROLL
  for (int i = 1; i < kQ; i += 2) {
    const Real wi = Real(weight_of(i));
    const Real cu = Real(velocity_x(i)) * ux + Real(velocity_y(i)) * uy + Real(velocity_z(i)) * uz;
    const Real cs = Real(velocity_x(i)) * sx + Real(velocity_y(i)) * sy + Real(velocity_z(i)) * sz;
    const Real cF = Real(velocity_x(i)) * Fx + Real(velocity_y(i)) * Fy + Real(velocity_z(i)) * Fz;
    const Real f_plus = Real(0.5) * (f[i] + f[i + 1]);
    const Real f_minus = Real(0.5) * (f[i] - f[i + 1]);
    const Real d_plus = -op * f_plus + wi * (K + (A_u * cu + A_F * cF) * cu + A_s * cs * cs);
    const Real d_minus = -om * f_minus + wi * (M_u * cu + M_s * cs + M_F * cF);
    f[i] += d_plus + d_minus;
    f[i + 1] += d_plus - d_minus;
  }
  rho_out = rho;
  jx_out = rho * ux;
  jy_out = rho * uy;
  jz_out = rho * uz;
}

}  // namespace flocsim::lattice
