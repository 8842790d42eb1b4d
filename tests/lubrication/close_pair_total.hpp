#pragma once
// The total radial resistance of a close pair as the suspension run sees it:
// the lattice's own share (measured here, in a box other than the
// calibration's) plus the lubrication correction the case builds from the
// shipped close-pair calibration, against Brenner's exact value for an
// isolated pair. Shared by the default and the slow close-pair tests.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "engine/calibration/pair_resistance.hpp"
#include "engine/case/suspension_case.hpp"
#include "engine/lubrication/radial_lubrication.hpp"
#include "engine/lubrication/two_sphere_resistance.hpp"

namespace flocsim::lubrication {

// A suspension case at a_over_dx = a, lattice viscosity nu (Re_inf set so
// that U_inf = 0.01) and IB scheme; its lubrication as the run builds it.
inline RadialLubrication lubrication_of_case(double a, double nu, const coupling::Scheme& scheme,
                                             const std::string& fidelity) {
  const auto c = cases::parse_suspension_case(
      {{"scene", "suspension"},
       {"fidelity", fidelity},
       {"phi", 0.1},
       {"lubrication_model", "calibrated"},
       {"Re_inf", 2 * a * 0.01 / nu},
       {"numerics",
        {{"a_over_dx", a},
         {"viscosity", nu},
         {"immersed_boundary", cases::immersed_boundary_json(scheme)}}}});
  EXPECT_EQ(c.numerics.coupling, scheme);
  return RadialLubrication({.viscosity = c.numerics.viscosity,
                            .onset_gap = c.physics.lubrication_onset_over_a,
                            .saturation_gap = c.physics.lubrication_saturation_over_a,
                            .lattice_share = c.numerics.lubrication_lattice_share});
}

// Every gap within 15 % of the exact resistance, approaching and separating,
// in a box other than the calibration's (box_over_a; the calibration used 16a
// at a = 4 and 12a at a = 6 and 8, 16a for control forcing at a = 6), scheme `scheme`. The gaps are
// measured in one pass, each from the flow of the one before, and the box offset of this box is
// read at s = 0.5a like the calibration's.
inline void expect_total_near_brenner(double a, double nu, const std::vector<double>& gaps,
                                      double box_over_a = 20, const coupling::Scheme& scheme = {},
                                      const std::string& fidelity = "paper") {
  const RadialLubrication lub = lubrication_of_case(a, nu, scheme, fidelity);
  calibration::PairResistanceSettings set{
      .viscosity = nu, .scheme = scheme, .box_over_a = box_over_a};
  std::vector<double> pass = gaps;
  pass.push_back(0.5);
  for (bool separating : {false, true}) {
    const auto entry = calibration::calibrate_pair_resistance(a, pass, separating, set);
    for (std::size_t k = 0; k < gaps.size(); ++k) {
      const auto& p = entry.points[k];
      const double g = p.gap_over_a;
      const double lattice = p.lambda_measured - entry.box_offset;
      const double correction = lub.coefficient(g * a, a) / (3 * M_PI * nu * a);
      const double total = lattice + correction;
      std::printf(
          "a = %g, nu = %g, %s, box %ga, s/a = %5.3f, %s: lattice %7.3f + correction %7.3f = "
          "%7.3f, exact %7.3f, ratio %.3f\n",
          a, nu, scheme.describe().c_str(), box_over_a, g,
          separating ? "separating " : "approaching", lattice, correction, total, p.lambda_exact,
          total / p.lambda_exact);
      EXPECT_NEAR(total / p.lambda_exact, 1.0, 0.15)
          << "a = " << a << ", nu = " << nu << ", s/a = " << g
          << (separating ? ", separating" : ", approaching") << ": lattice " << lattice
          << " + correction " << correction << " against exact " << p.lambda_exact;
    }
  }
}

}  // namespace flocsim::lubrication
