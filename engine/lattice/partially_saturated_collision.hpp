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
FLOCSIM_ALWAYS_INLINE void collide_partially_saturated(Real (&f)[d3q19::kQ], Real Fx, Real Fy,
                                                       Real Fz, Real eps, Real Vx, Real Vy, Real Vz,
                                                       const CollisionConstants<Real>& k,
                                                       Real& rho_out, Real& jx_out, Real& jy_out,
                                                       Real& jz_out) {
  using namespace d3q19;
  Real drho = 0;
#pragma GCC unroll 19
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
  // h: an antisymmetric term of momentum -omega_minus F / 2 (per pair i:
  // -omega_minus / 2 * 3 w_i c_i . F), in units of force_minus * force_minus_term
  const Real h_factor = Real(-0.5) * k.omega_minus;

  {
    const Real w0 = Real(kWeightRest);
    const Real eq = w0 * (drho - rho * usq15);
    const Real shift = w0 * rho * (usq15 - ssq15);  // Feq_0(u_s) - Feq_0(u)
    f[0] += -k.omega_plus * (f[0] - eq) - liquid * k.force_plus * w0 * uF3 + B * shift;
  }
#pragma GCC unroll 9
  for (int i = 1; i < kQ; i += 2) {
    const Real wi = Real(w[i]);
    const Real cu = Real(cx[i]) * ux + Real(cy[i]) * uy + Real(cz[i]) * uz;
    const Real cs = Real(cx[i]) * sx + Real(cy[i]) * sy + Real(cz[i]) * sz;
    const Real cF = Real(cx[i]) * Fx + Real(cy[i]) * Fy + Real(cz[i]) * Fz;
    const Real eq_plus = wi * (drho + rho * (Real(4.5) * cu * cu - usq15));
    const Real eq_minus = wi * rho * Real(3) * cu;
    const Real force_plus = wi * (Real(9) * cu * cF - uF3);
    const Real force_minus = wi * Real(3) * cF;
    const Real shift_plus = wi * rho * (Real(4.5) * (cs * cs - cu * cu) - ssq15 + usq15);
    const Real shift_minus = wi * rho * Real(3) * (cs - cu);
    const Real f_plus = Real(0.5) * (f[i] + f[i + 1]);
    const Real f_minus = Real(0.5) * (f[i] - f[i + 1]);
    const Real d_plus =
        -k.omega_plus * (f_plus - eq_plus) + liquid * k.force_plus * force_plus + B * shift_plus;
    const Real d_minus = -k.omega_minus * (f_minus - eq_minus) +
                         liquid * k.force_minus * force_minus +
                         B * (shift_minus + h_factor * force_minus);
    f[i] += d_plus + d_minus;
    f[i + 1] += d_plus - d_minus;
  }
  rho_out = rho;
  jx_out = rho * ux;
  jy_out = rho * uy;
  jz_out = rho * uz;
}

}  // namespace flocsim::lattice
