#pragma once
// The total radial resistance of a close pair as the suspension run sees it:
// the lattice's own share (measured here, in a box other than the
// calibration's) plus the lubrication correction the case builds from the
// shipped close-pair calibration, against Brenner's exact value for an
// isolated pair. Shared by the default and the slow close-pair tests.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "engine/calibration/pair_resistance.hpp"
#include "engine/case/suspension_case.hpp"
#include "engine/lubrication/radial_lubrication.hpp"
#include "engine/lubrication/two_sphere_resistance.hpp"

namespace flocsim::lubrication {

// A suspension case at a_over_dx = a and lattice viscosity nu (Re_inf set so
// that U_inf = 0.01); its lubrication as the run builds it.
inline RadialLubrication lubrication_of_case(double a, double nu) {
  const auto c =
      cases::parse_suspension_case({{"scene", "suspension"},
                                    {"phi", 0.1},
                                    {"lubrication_model", "calibrated"},
                                    {"Re_inf", 2 * a * 0.01 / nu},
                                    {"numerics", {{"a_over_dx", a}, {"viscosity", nu}}}});
  return RadialLubrication({.viscosity = c.numerics.viscosity,
                            .onset_gap = c.physics.lubrication_onset_over_a,
                            .saturation_gap = c.physics.lubrication_saturation_over_a,
                            .lattice_share = c.numerics.lubrication_lattice_share});
}

// Every gap within 15 % of the exact resistance, approaching and separating,
// in a 20a x 10a x 10a box (the calibration used 16a x 8a x 8a); the box
// offset of this box is measured at s = 0.5a like the calibration's.
inline void expect_total_near_brenner(double a, double nu, const std::vector<double>& gaps) {
  const RadialLubrication lub = lubrication_of_case(a, nu);
  calibration::PairResistanceSettings set{.viscosity = nu, .box_over_a = 20};
  for (bool separating : {false, true}) {
    const double offset =
        calibration::measure_pair_resistance(a, 0.5, separating, set).lambda_measured -
        brenner_pair_resistance(0.5);
    for (double g : gaps) {
      const auto p = calibration::measure_pair_resistance(a, g, separating, set);
      const double correction = lub.coefficient(g * a, a) / (3 * M_PI * nu * a);
      const double total = p.lambda_measured - offset + correction;
      std::printf(
          "a = %g, nu = %g, s/a = %5.3f, %s: lattice %7.3f + correction %7.3f = %7.3f, "
          "exact %7.3f, ratio %.3f\n",
          a, nu, g, separating ? "separating " : "approaching", p.lambda_measured - offset,
          correction, total, p.lambda_exact, total / p.lambda_exact);
      EXPECT_NEAR(total / p.lambda_exact, 1.0, 0.15)
          << "a = " << a << ", nu = " << nu << ", s/a = " << g
          << (separating ? ", separating" : ", approaching") << ": lattice "
          << p.lambda_measured - offset << " + correction " << correction << " against exact "
          << p.lambda_exact;
    }
  }
}

}  // namespace flocsim::lubrication
