#pragma once
// One cell of the AA-pattern step, as a kernel body (kernel_body.hpp): where
// the cell's 19 populations are read and written, and the collision between.
// The GPU runs it one thread per cell (engine/lattice_gpu); the CPU lattice
// (fluid_lattice.cpp) runs the same collision over whole rows through shifted
// row pointers instead, which is what lets it vectorise along x, and the test
// suite holds the two to each other (tests/lattice/aa_cell_test.cpp).
//
// The storage is the one fluid_lattice.hpp describes: deviations f_i - w_i,
// one array per direction (`stride` elements apart), x fastest. After an even
// number of steps population i of cell x sits in slot i at x; an even step
// writes its post-collision value into the opposite slot at x. After an odd
// number it sits in the opposite slot of the upstream cell x - c_i; an odd
// step writes its post-collision value into slot i of the downstream cell
// x + c_i. Either way each cell reads and writes 19 values and no two cells
// touch the same slot, so cells may be stepped in any order, in parallel.
#include "engine/lattice/d3q19.hpp"
#include "engine/lattice/kernel_body.hpp"
#include "engine/lattice/partially_saturated_collision.hpp"
#include "engine/lattice/trt_collision.hpp"

namespace flocsim::lattice {

// The populations of a lattice in any memory (host or device).
template <class Real>
struct AaSlots {
  Real* base = nullptr;  // slot array of direction i starts at base + i * stride
  long stride = 0;
  int nx = 0, ny = 0, nz = 0;
};

// Periodic neighbour coordinate n + d for d in {-1, 0, 1}.
FLOCSIM_KERNEL_BODY int periodic_step(int n, int d, int extent) {
  const int m = n + d;
  return m < 0 ? m + extent : (m >= extent ? m - extent : m);
}

template <class Real>
FLOCSIM_KERNEL_BODY long aa_cell_index(const AaSlots<Real>& s, int x, int y, int z) {
  return static_cast<long>(x) + static_cast<long>(s.nx) * (y + static_cast<long>(s.ny) * z);
}

// Where population i of cell (x, y, z) is stored now (before the step):
// element of the slot arrays, counted from `base`.
template <class Real>
FLOCSIM_KERNEL_BODY long aa_current_slot(const AaSlots<Real>& s, int i, int x, int y, int z,
                                         bool even) {
  using namespace d3q19;
  if (even) return i * s.stride + aa_cell_index(s, x, y, z);
  const int ux = periodic_step(x, -velocity_x(i), s.nx);
  const int uy = periodic_step(y, -velocity_y(i), s.ny);
  const int uz = periodic_step(z, -velocity_z(i), s.nz);
  return opposite(i) * s.stride + aa_cell_index(s, ux, uy, uz);
}

// Where the step leaves the post-collision population i of cell (x, y, z).
template <class Real>
FLOCSIM_KERNEL_BODY long aa_next_slot(const AaSlots<Real>& s, int i, int x, int y, int z,
                                      bool even) {
  using namespace d3q19;
  if (even) return opposite(i) * s.stride + aa_cell_index(s, x, y, z);
  const int dx = periodic_step(x, velocity_x(i), s.nx);
  const int dy = periodic_step(y, velocity_y(i), s.ny);
  const int dz = periodic_step(z, velocity_z(i), s.nz);
  return i * s.stride + aa_cell_index(s, dx, dy, dz);
}

// The current 19 deviations of cell (x, y, z).
template <class Real>
FLOCSIM_KERNEL_BODY void aa_load_cell(const AaSlots<Real>& s, int x, int y, int z, bool even,
                                      Real (&f)[d3q19::kQ]) {
  FLOCSIM_UNROLL
  for (int i = 0; i < d3q19::kQ; ++i) f[i] = s.base[aa_current_slot(s, i, x, y, z, even)];
}

// Collision with force density (Fx, Fy, Fz) and streaming of one cell.
template <class Real>
FLOCSIM_KERNEL_BODY void aa_update_cell(const AaSlots<Real>& s, int x, int y, int z, bool even,
                                        Real Fx, Real Fy, Real Fz,
                                        const CollisionConstants<Real>& k) {
  Real f[d3q19::kQ];
  aa_load_cell(s, x, y, z, even, f);
  collide(f, Fx, Fy, Fz, k);
  FLOCSIM_UNROLL
  for (int i = 0; i < d3q19::kQ; ++i) s.base[aa_next_slot(s, i, x, y, z, even)] = f[i];
}

// The same for a cell that spheres partly cover (partially saturated cells:
// coverage eps > 0, V = sum eps_k u_k), its collision blended with the solid
// operator of partially_saturated_collision.hpp; leaves the density and the
// momentum density rho u the collision saw in rho, jx, jy, jz.
template <class Real>
FLOCSIM_KERNEL_BODY void aa_update_covered_cell(const AaSlots<Real>& s, int x, int y, int z,
                                                bool even, Real Fx, Real Fy, Real Fz, Real eps,
                                                Real Vx, Real Vy, Real Vz,
                                                const CollisionConstants<Real>& k, Real& rho,
                                                Real& jx, Real& jy, Real& jz) {
  Real f[d3q19::kQ];
  aa_load_cell(s, x, y, z, even, f);
  collide_partially_saturated(f, Fx, Fy, Fz, eps, Vx, Vy, Vz, k, rho, jx, jy, jz);
  FLOCSIM_UNROLL
  for (int i = 0; i < d3q19::kQ; ++i) s.base[aa_next_slot(s, i, x, y, z, even)] = f[i];
}

// Density and velocity (with half of the force density F added to the
// momentum, Guo's shift) of a cell from its 19 deviations.
template <class Real>
FLOCSIM_KERNEL_BODY void cell_moments(const Real (&f)[d3q19::kQ], Real Fx, Real Fy, Real Fz,
                                      Real& rho, Real& ux, Real& uy, Real& uz) {
  Real drho = 0;
  FLOCSIM_UNROLL
  for (int i = 0; i < d3q19::kQ; ++i) drho += f[i];
  const Real jx = f[1] - f[2] + f[7] - f[8] + f[9] - f[10] + f[11] - f[12] + f[13] - f[14];
  const Real jy = f[3] - f[4] + f[7] - f[8] - f[9] + f[10] + f[15] - f[16] + f[17] - f[18];
  const Real jz = f[5] - f[6] + f[11] - f[12] - f[13] + f[14] + f[15] - f[16] - f[17] + f[18];
  rho = Real(1) + drho;
  const Real inv = Real(1) / rho;
  ux = (jx + Real(0.5) * Fx) * inv;
  uy = (jy + Real(0.5) * Fy) * inv;
  uz = (jz + Real(0.5) * Fz) * inv;
}

}  // namespace flocsim::lattice
