#pragma once
// The collision of one liquid cell: two-relaxation-time (TRT) with Guo et al.
// (2002) forcing split into its symmetric and antisymmetric parts, each scaled
// by (1 - omega/2) of its own relaxation rate (relaxation.hpp, fluid_lattice.hpp).
// A kernel body (kernel_body.hpp): one source for the CPU loops that vectorise
// it over the rows (fluid_lattice.cpp) and the GPU's one thread per cell.
#include "engine/lattice/d3q19.hpp"
#include "engine/lattice/kernel_body.hpp"

namespace flocsim::lattice {

// Collision parameters in the kernel's precision.
template <class Real>
struct CollisionConstants {
  Real omega_plus, omega_minus;
  Real force_plus, force_minus;  // 1 - omega/2 of the symmetric / antisymmetric parts
};

// TRT collision with Guo forcing, on the deviations f_i - w_i of one cell, in
// place. F is the force density acting on the cell.
template <class Real>
FLOCSIM_KERNEL_BODY void collide(Real (&f)[d3q19::kQ], Real Fx, Real Fy, Real Fz,
                                 const CollisionConstants<Real>& k) {
  using namespace d3q19;
  Real drho = 0;
  FLOCSIM_UNROLL
  for (int i = 0; i < d3q19::kQ; ++i) drho += f[i];
  const Real rho = Real(1) + drho;
  const Real jx = f[1] - f[2] + f[7] - f[8] + f[9] - f[10] + f[11] - f[12] + f[13] - f[14];
  const Real jy = f[3] - f[4] + f[7] - f[8] - f[9] + f[10] + f[15] - f[16] + f[17] - f[18];
  const Real jz = f[5] - f[6] + f[11] - f[12] - f[13] + f[14] + f[15] - f[16] - f[17] + f[18];
  const Real inv_rho = Real(1) / rho;
  const Real ux = (jx + Real(0.5) * Fx) * inv_rho;
  const Real uy = (jy + Real(0.5) * Fy) * inv_rho;
  const Real uz = (jz + Real(0.5) * Fz) * inv_rho;
  const Real usq15 = Real(1.5) * (ux * ux + uy * uy + uz * uz);
  const Real uF3 = Real(3) * (ux * Fx + uy * Fy + uz * Fz);

  // Rest population: symmetric only.
  {
    const Real w0 = Real(kWeightRest);
    const Real eq = w0 * (drho - rho * usq15);
    f[0] += -k.omega_plus * (f[0] - eq) - k.force_plus * w0 * uF3;
  }
  // Moving populations, one opposite pair (i, i+1) at a time; c = c_i.
  FLOCSIM_UNROLL
  for (int i = 1; i < kQ; i += 2) {
    const Real wi = Real(weight_of(i));
    const Real cu = Real(velocity_x(i)) * ux + Real(velocity_y(i)) * uy + Real(velocity_z(i)) * uz;
    const Real cF = Real(velocity_x(i)) * Fx + Real(velocity_y(i)) * Fy + Real(velocity_z(i)) * Fz;
    const Real eq_plus = wi * (drho + rho * (Real(4.5) * cu * cu - usq15));
    const Real eq_minus = wi * rho * Real(3) * cu;
    const Real force_plus = wi * (Real(9) * cu * cF - uF3);
    const Real force_minus = wi * Real(3) * cF;
    const Real f_plus = Real(0.5) * (f[i] + f[i + 1]);
    const Real f_minus = Real(0.5) * (f[i] - f[i + 1]);
    const Real d_plus = -k.omega_plus * (f_plus - eq_plus) + k.force_plus * force_plus;
    const Real d_minus = -k.omega_minus * (f_minus - eq_minus) + k.force_minus * force_minus;
    f[i] += d_plus + d_minus;
    f[i + 1] += d_plus - d_minus;
  }
}

}  // namespace flocsim::lattice
