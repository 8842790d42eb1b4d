#pragma once
// The per-marker law of control forcing (the paper's: Derksen 2013 after ten
// Cate et al. 2002 and Derksen & Van den Akker 1999; Goldstein et al. 1993's
// feedback forcing in discrete form), apart from the loops that schedule it
// (immersed_boundary.cpp).
//
// Each marker carries its force density F_m from step to step. Every step it
// reads the slip its force left, e = U - v(X_m), with U the surface velocity
// and v the velocity the next collision would see if the liquid kept the
// forces of the last step (interpolated from u* + F_last / (2 rho)), and
// corrects the force as a PI controller:
//
//   F_m <- F_m + rho (G e + P (e - e_previous))
//
// G, the integral gain, is the fraction of 2 rho e (the force that would
// remove e at an isolated marker in one step) applied per step: G = 2 with
// P = 0 forces an isolated marker exactly as one direct-forcing sweep. A
// smaller G lets the force build up over several steps, which a sphere of
// overlapping kernels needs (its markers share cells: a force moves the
// interpolated velocity by about half of what it would at an isolated marker).
// At a steady state e = 0 at every marker for any stable gains: the integral
// action removes the slip that one direct-forcing sweep leaves.
#include <type_traits>

namespace flocsim::immersed_boundary {

// Force-density increment of one marker in a 4-vector (rho, v) -> (0, dF);
// `slip` holds e_previous in lanes 1-3 and receives e.
template <class V4>
inline V4 control_increment(const V4& rho_v, const V4& target, V4& slip, double integral_gain,
                            double proportional_gain) {
  using Real = std::remove_cvref_t<decltype(rho_v[0])>;
  const V4 vector_part = {0, 1, 1, 1};
  const V4 e = (target - rho_v) * vector_part;
  const V4 change =
      static_cast<Real>(integral_gain) * e + static_cast<Real>(proportional_gain) * (e - slip);
  slip = e;
  return rho_v[0] * change;
}

}  // namespace flocsim::immersed_boundary
