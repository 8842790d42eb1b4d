#pragma once
// Two-relaxation-time (TRT) collision parameters.
//
// The symmetric (even) non-equilibrium moments relax with omega_plus, which
// fixes the kinematic viscosity nu = (1/omega_plus - 1/2) / 3. The
// antisymmetric (odd) ones relax with omega_minus, chosen through the "magic"
// parameter Lambda = (1/omega_plus - 1/2)(1/omega_minus - 1/2). Lambda = 1/4
// gives the widest linear stability range of TRT (Ginzburg et al. 2008), which
// is what lets the solver run at nu = 0.005 (tau = 0.515): see docs/numerics.md.
#include <cmath>
#include <stdexcept>
#include <string>

namespace flocsim::lattice {

struct Relaxation {
  double viscosity = 0.01;     // lattice units dx^2/dt
  double magic_lambda = 0.25;  // TRT magic parameter Lambda

  double tau_plus() const { return 3.0 * viscosity + 0.5; }
  double omega_plus() const { return 1.0 / tau_plus(); }
  double tau_minus() const { return 0.5 + magic_lambda / (tau_plus() - 0.5); }
  double omega_minus() const { return 1.0 / tau_minus(); }

  // Throws std::invalid_argument when the parameters leave the range in which
  // the scheme is defined (tau > 1/2, Lambda > 0).
  void check() const {
    if (!(viscosity > 0.0) || !std::isfinite(viscosity))
      throw std::invalid_argument("viscosity = " + std::to_string(viscosity) +
                                  ": must be > 0 (tau = 3 nu + 1/2 must exceed 1/2)");
    if (!(magic_lambda > 0.0) || !std::isfinite(magic_lambda))
      throw std::invalid_argument("magic_lambda = " + std::to_string(magic_lambda) +
                                  ": must be > 0");
  }
};

}  // namespace flocsim::lattice
