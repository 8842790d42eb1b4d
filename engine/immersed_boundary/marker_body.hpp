#pragma once
// The immersed boundary's per-cell and per-marker work for one sphere, as
// kernel bodies (engine/lattice/kernel_body.hpp) on a box of cells around the
// sphere: what the GPU's coupling (engine/coupling_gpu) runs with one thread
// block per sphere, one thread per marker or per box cell, and what the test
// suite runs here in plain loops against the CPU's ImmersedBoundary
// (tests/immersed_boundary/marker_body_test.cpp).
//
// The method is the one immersed_boundary.hpp describes, step for step: the
// box holds (rho, u*) and this sphere's force (0, F) per cell; a marker reads
// v = u* + F / (2 rho) interpolated with the kernel, its force density grows
// by 2 rho (U - v) (direct forcing, per sweep) or by the PI law of control
// forcing, and spreads F_m dV back onto the box; the sphere's load is the
// reaction of its markers, the liquid inside weighed by inside_weight(). Like
// the CPU's sweeps, a sphere's sweeps see its own force only; the boxes are
// added to the lattice's force field when the sphere is done.
//
// The CPU path (marker_stencil.hpp) runs the same arithmetic with 16-wide
// vectors over a padded box; it stays the reference. These bodies are
// scalar, one marker or one cell at a time, because a GPU thread is.
#include <cmath>

#include "engine/immersed_boundary/kernel.hpp"
#include "engine/lattice/kernel_body.hpp"

namespace flocsim::immersed_boundary {

// A cube of B^3 cells around one sphere, x fastest, four numbers per cell:
// velocity (rho, u*) as read from the lattice, force (0, F) this sphere's
// force density. lo: lattice coordinates of box cell (0, 0, 0), unwrapped.
template <class Real>
struct SphereBox {
  Real* velocity = nullptr;
  Real* force = nullptr;
  int B = 0;
  int lo[3] = {0, 0, 0};

  FLOCSIM_HD long cell(int i, int j, int k) const {
    return static_cast<long>(i) + static_cast<long>(B) * (j + static_cast<long>(B) * k);
  }
};

// The kernel stencil of one marker: W cells per direction from `first` (box
// coordinates), x weights wx and products wyz[b + W c] = wy[b] wz[c] (in
// double, then rounded once, as the CPU's stencil does).
template <class Real, int W>
struct MarkerStencil {
  int first[3];
  Real wx[W];
  Real wyz[W * W];
};

// The stencil of the marker at X = centre + offset in a box with lowest
// corner lo. Roma's kernel (W = 3): cells round(X) - 1 .. round(X) + 1; the
// linear hat (W = 2): floor(X), floor(X) + 1 (kernel.hpp).
template <class Real, int W>
FLOCSIM_KERNEL_BODY MarkerStencil<Real, W> marker_stencil(const double (&centre)[3],
                                                          const double* offset,
                                                          const int (&lo)[3]) {
  static_assert(W == 2 || W == 3, "kernel width 2 or 3");
  MarkerStencil<Real, W> st;
  double w[3][W];
  for (int d = 0; d < 3; ++d) {
    const double X = centre[d] + offset[d];
    if constexpr (W == 3) {
      const double near = ::nearbyint(X);
      st.first[d] = static_cast<int>(near) - 1 - lo[d];
      const double f = X - near;
      roma_weights_from_root(f, ::sqrt(1.0 - 3.0 * f * f), w[d]);
    } else {
      const double below = ::floor(X);
      st.first[d] = static_cast<int>(below) - lo[d];
      linear_weights(X - below, w[d]);
    }
  }
  for (int a = 0; a < W; ++a) st.wx[a] = static_cast<Real>(w[0][a]);
  for (int c = 0; c < W; ++c)
    for (int b = 0; b < W; ++b) st.wyz[b + W * c] = static_cast<Real>(w[1][b] * w[2][c]);
  return st;
}

// The state a marker reads at box cell c: (rho, u* + F / (2 rho)), the
// velocity the collision would see with this sphere's force as it stands.
template <class Real>
FLOCSIM_KERNEL_BODY void box_state(const SphereBox<Real>& box, long c, Real (&v)[4]) {
  const Real* u = box.velocity + 4 * c;
  const Real* F = box.force + 4 * c;
  const Real half_inv = Real(0.5) / u[0];
  v[0] = u[0];
  for (int q = 1; q < 4; ++q) v[q] = u[q] + half_inv * F[q];
}

// (rho, v) interpolated at the marker. with_force = false reads u* alone (the
// first direct-forcing sweep, before any force of this step).
template <class Real, int W>
FLOCSIM_KERNEL_BODY void interpolate_at_marker(const SphereBox<Real>& box,
                                               const MarkerStencil<Real, W>& st, bool with_force,
                                               Real (&out)[4]) {
  for (int q = 0; q < 4; ++q) out[q] = 0;
  for (int c = 0; c < W; ++c)
    for (int b = 0; b < W; ++b) {
      const Real wyz = st.wyz[b + W * c];
      for (int a = 0; a < W; ++a) {
        const long cell = box.cell(st.first[0] + a, st.first[1] + b, st.first[2] + c);
        Real v[4];
        if (with_force) {
          box_state(box, cell, v);
        } else {
          for (int q = 0; q < 4; ++q) v[q] = box.velocity[4 * cell + q];
        }
        const Real w = st.wx[a] * wyz;
        for (int q = 0; q < 4; ++q) out[q] += w * v[q];
      }
    }
}

// Adds F_m dV spread with the kernel to the box's force. `add(address, value)`
// is the addition: plain on the CPU, atomic on the GPU, where the markers of
// a sphere spread at once.
template <class Real, int W, class Add>
FLOCSIM_KERNEL_BODY void spread_from_marker(const SphereBox<Real>& box,
                                            const MarkerStencil<Real, W>& st, const Real (&F_dV)[3],
                                            Add&& add) {
  for (int c = 0; c < W; ++c)
    for (int b = 0; b < W; ++b) {
      const Real wyz = st.wyz[b + W * c];
      for (int a = 0; a < W; ++a) {
        const long cell = box.cell(st.first[0] + a, st.first[1] + b, st.first[2] + c);
        for (int d = 0; d < 3; ++d) add(&box.force[4 * cell + 1 + d], (st.wx[a] * F_dV[d]) * wyz);
      }
    }
}

// Velocity of the surface at r from the centre, U = u_p + omega x r.
FLOCSIM_KERNEL_BODY void surface_velocity_at(const double (&u_p)[3], const double (&omega)[3],
                                             const double* r, double (&U)[3]) {
  U[0] = u_p[0] + omega[1] * r[2] - omega[2] * r[1];
  U[1] = u_p[1] + omega[2] * r[0] - omega[0] * r[2];
  U[2] = u_p[2] + omega[0] * r[1] - omega[1] * r[0];
}

// Direct forcing at one marker: dF = 2 rho (U - v) (direct_forcing.hpp).
template <class Real>
FLOCSIM_KERNEL_BODY void direct_forcing_increment(const Real (&rho_v)[4], const Real (&U)[3],
                                                  Real (&dF)[3]) {
  const Real two_rho = Real(2) * rho_v[0];
  for (int d = 0; d < 3; ++d) dF[d] = two_rho * (U[d] - rho_v[1 + d]);
}

// Control forcing at one marker (control_forcing.hpp): e = U - v, the force
// density grows by rho (G e + P (e - e_previous)); slip holds e_previous and
// receives e.
template <class Real>
FLOCSIM_KERNEL_BODY void control_forcing_increment(const Real (&rho_v)[4], const Real (&U)[3],
                                                   Real (&slip)[3], Real integral_gain,
                                                   Real proportional_gain, Real (&dF)[3]) {
  for (int d = 0; d < 3; ++d) {
    const Real e = U[d] - rho_v[1 + d];
    dF[d] = rho_v[0] * (integral_gain * e + proportional_gain * (e - slip[d]));
    slip[d] = e;
  }
}

// The share of box cell (i, j, k) in the momentum of the liquid inside a
// sphere of input radius a_g centred at `centre`: its weight w (0 outside,
// inside_weight() of direct_forcing.hpp) and w rho v, v the velocity the
// collision sees with this sphere's force, with its moment r x (w rho v)
// about the centre. False (nothing written) where w = 0.
template <class Real>
FLOCSIM_KERNEL_BODY bool inside_share(const SphereBox<Real>& box, int i, int j, int k,
                                      const double (&centre)[3], double input_radius,
                                      double (&momentum)[3], double (&moment)[3]) {
  const double r[3] = {box.lo[0] + i - centre[0], box.lo[1] + j - centre[1],
                       box.lo[2] + k - centre[2]};
  const double r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
  const double reach = input_radius + 0.5;
  if (r2 >= reach * reach) return false;
  const double inner2 = (input_radius - 0.5) * (input_radius - 0.5) * (1.0 - 1e-12);
  const double w = r2 <= inner2 ? 1.0 : (reach - ::sqrt(r2) < 1.0 ? reach - ::sqrt(r2) : 1.0);
  if (w <= 0) return false;
  Real v[4];
  box_state(box, box.cell(i, j, k), v);
  const double wrho = w * static_cast<double>(v[0]);
  for (int d = 0; d < 3; ++d) momentum[d] = wrho * static_cast<double>(v[1 + d]);
  moment[0] = r[1] * momentum[2] - r[2] * momentum[1];
  moment[1] = r[2] * momentum[0] - r[0] * momentum[2];
  moment[2] = r[0] * momentum[1] - r[1] * momentum[0];
  return true;
}

// Periodic lattice coordinate of box coordinate n (lo + n may leave the box
// by up to one sphere box on either side).
FLOCSIM_KERNEL_BODY int wrap_coordinate(int n, int extent) {
  const int m = n % extent;
  return m < 0 ? m + extent : m;
}

}  // namespace flocsim::immersed_boundary
