#pragma once
// The interpolation/spreading kernels of the immersed boundary, per marker
// and per direction: the weights of the cells a marker reads and forces.
//
// roma3: the 3-point kernel of Roma, Peskin & Berger (1999), support |r| < 1.5 dx.
//
// phi(r) = (1 + sqrt(1 - 3 r^2)) / 3                      |r| <= 1/2
//        = (5 - 3|r| - sqrt(1 - 3 (1 - |r|)^2)) / 6        1/2 <= |r| <= 3/2
//        = 0                                              otherwise
//
// It satisfies sum_i phi(x - i) = 1 and sum_i (x - i) phi(x - i) = 0 for every
// x, so spreading conserves the total force exactly and its first moment
// (torque about a marker) to round-off, and interpolation reproduces linear
// fields exactly. Three points per direction (27 cells per marker) is the
// narrowest smooth kernel with these properties; the 4-point Peskin kernel
// costs 64 cells per marker for the same moments.
#include <algorithm>
#include <cmath>

#include "engine/lattice/kernel_body.hpp"

namespace flocsim::immersed_boundary {

inline double roma_kernel(double r) {
  r = std::abs(r);
  if (r <= 0.5) return (1.0 + std::sqrt(1.0 - 3.0 * r * r)) / 3.0;
  if (r <= 1.5) {
    const double s = 1.0 - r;
    return (5.0 - 3.0 * r - std::sqrt(std::max(0.0, 1.0 - 3.0 * s * s))) / 6.0;
  }
  return 0.0;
}

// The three weights of one direction for a marker at coordinate x: cells
// first, first + 1, first + 2, with first = round(x) - 1.
struct KernelWeights {
  int first;
  double w[3];
};

// With d = x - round(x) in [-1/2, 1/2] the three arguments are d + 1, d and
// d - 1, and all three weights share one square root q = sqrt(1 - 3 d^2):
// phi(d) = (1 + q) / 3, phi(d + 1) = (2 - 3 d - q) / 6, phi(d - 1) = (2 + 3 d - q) / 6
// (the values of roma_kernel to round-off, one sqrt instead of three). The
// weights sum to 1 and have zero first moment for any q, so an error in q
// changes only the kernel's shape, never the conservation of force or torque.
// A kernel body (the GPU's coupling calls it too: marker_body.hpp).
FLOCSIM_KERNEL_BODY void roma_weights_from_root(double d, double q, double (&w)[3]) {
  constexpr double sixth = 1.0 / 6.0;
  const double low = 2.0 - 3.0 * d - q, high = 2.0 + 3.0 * d - q;
  w[0] = (low > 0.0 ? low : 0.0) * sixth;  // no -1e-17 at |d| = 1/2
  w[1] = (2.0 + 2.0 * q) * sixth;
  w[2] = (high > 0.0 ? high : 0.0) * sixth;
}

inline void roma_weights(double d, double (&w)[3]) {
  roma_weights_from_root(d, std::sqrt(1.0 - 3.0 * d * d), w);
}

inline KernelWeights kernel_weights(double x) {
  KernelWeights k;
  const double nearest = std::nearbyint(x);
  k.first = static_cast<int>(nearest) - 1;
  roma_weights(x - nearest, k.w);
  return k;
}

// linear2: the 2-point linear hat, support |r| < 1 dx,
//
// phi(r) = 1 - |r|   |r| <= 1,   0 otherwise.
//
// It has the same two moment conditions (sum 1, first moment 0), so force and
// torque are conserved exactly in spreading and linear fields interpolated
// exactly, with 8 cells per marker instead of 27. It is only continuous, not
// smooth: as a marker crosses a lattice node the weights change slope, which
// makes the force on a moving sphere ripple at the lattice period (measured in
// docs/immersed-boundary.md, "Options").
inline double linear_kernel(double r) {
  r = std::abs(r);
  return r < 1.0 ? 1.0 - r : 0.0;
}

// The two weights of one direction for a marker at coordinate x: cells
// first = floor(x) and first + 1, with d = x - floor(x) in [0, 1).
FLOCSIM_KERNEL_BODY void linear_weights(double d, double (&w)[2]) {
  w[0] = 1.0 - d;
  w[1] = d;
}

}  // namespace flocsim::immersed_boundary
