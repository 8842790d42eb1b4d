#pragma once
// Radial lubrication between close spheres (Nguyen & Ladd 2002, docs/model.md
// section 3): the part of the squeeze-film force the lattice cannot resolve,
//   F_lub = (3/2) pi rho nu a^2 (1/s - 1/s0) (n . du_ij)   for s1 < s <= s0,
// saturated at s = s1 below s1 and zero above s0, with s = |x_j - x_i| - 2a,
// n unit from i to j, du_ij = u_j - u_i; +F_lub n acts on i and -F_lub n on j.
//
// The force is a drag on the radial relative velocity w = n . du_ij:
// dw/dt = -(2/m) c(s) w with c(s) the coefficient above. Integrated explicitly
// it overshoots once 2 c dt / m > 1 (at s1, a = 6, nu = 0.01 it is ~0.8);
// integrated implicitly per pair, w' = w / (1 + 2 c dt / m), it only ever
// shrinks w towards zero and can never reverse an approach.
#include <utility>
#include <vector>

#include "engine/spheres/sphere_set.hpp"

namespace flocsim::lubrication {

using spheres::PeriodicBox;
using spheres::SphereSet;
using spheres::Vec3;

struct LubricationParams {
  double viscosity = 0.01;       // nu, lattice units
  double liquid_density = 1.0;   // rho, lattice units
  double onset_gap = 0.2;        // s0 / a
  double saturation_gap = 2e-4;  // s1 / a
  // Optional calibration (docs/contacts.md, "Calibrated close-pair
  // coefficient"): the lattice's own measured radial resistance lambda_IB(s/a)
  // of a held IB pair, periodic-box offset removed, as (s/a, lambda_IB) points
  // in increasing s/a. When given, the coefficient below s0 is the exact
  // (Brenner) resistance minus the lattice's share,
  //   c(s) = 3 pi rho nu a (lambda_exact(s/a) - lambda_IB(s/a))
  // (lambda is per sphere speed U, F = 6 pi mu a U lambda; c multiplies the
  // relative radial velocity 2U), negative where the lattice alone resists
  // more than the exact value,
  // lambda_IB linear between points and held at the end values outside them,
  // instead of the Nguyen-Ladd (3/2) pi rho nu a^2 (1/s - 1/s0). Empty: Nguyen-Ladd.
  std::vector<std::pair<double, double>> lattice_share;
  // Forward Euler in w, as the paper integrates it: w' = w (1 - 2 c dt / m),
  // which reverses an approach once 2 c dt / m > 1. Offered only to measure
  // what the paper's scheme does to aggregation; the default is implicit.
  bool explicit_euler = false;

  void check() const;  // std::invalid_argument naming the field, value and allowed range
};

class RadialLubrication {
 public:
  explicit RadialLubrication(LubricationParams params = {});

  // The coefficient c(s) in F_lub = c(s) (n . du_ij) for surface gap s between
  // spheres of radius a (zero above the onset gap, constant below saturation).
  double coefficient(double gap, double radius) const;

  // Applies the lubrication impulse of one time step dt to the velocities of
  // all pairs closer than the onset gap, pair by pair, implicitly in each
  // pair's radial relative velocity (or explicitly, see explicit_euler). Momentum is conserved
  // exactly (equal and opposite impulses). Sphere masses m_p = (rho_p / rho) rho (4/3) pi a^3.
  // Returns the number of pairs that interacted.
  int apply(SphereSet& spheres, const PeriodicBox& box, double dt) const;

  const LubricationParams& params() const { return params_; }

 private:
  // Brenner's exact lambda, tabulated once as e lambda(e) on a grid uniform in
  // ln e over [s1/a, s0/a] (kExactPoints points) and interpolated by the cubic
  // through the four nearest points: the series needs up to ~1400 terms of
  // cosh/sinh near s1, which made the calibrated model cost 30x Nguyen-Ladd's
  // per pair (12 % of a suspension step). e lambda(e) is smooth (1/4 at
  // contact), so the cubic is good to about 1e-10 relative where linear
  // interpolation on the same grid left 2e-6 (tests/lubrication).
  static constexpr int kExactPoints = 1024;
  double exact_resistance(double gap_over_a) const;
  LubricationParams params_;
  double log_first_ = 0, log_step_ = 1;
  std::vector<double> gap_times_exact_;  // e lambda_exact(e) on the grid; empty: Nguyen-Ladd
};

}  // namespace flocsim::lubrication
