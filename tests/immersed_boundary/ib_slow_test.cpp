// Long physics checks of the immersed-boundary spheres (label slow): the
// simple-cubic-array drag against Sangani & Acrivos over phi = 0.01 - 0.2 at
// a = 4, 6 and 8 dx with the calibrated input radii.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "engine/calibration/hydrodynamic_radius.hpp"
#include "ib_test_support.hpp"

namespace flocsim {
namespace {

// K / K_SA - 1 at the given phi (box rounded to whole cells; chi from it).
double array_error(double a, double phi) {
  calibration::ArrayDragSettings s;
  const double ag = test::calibrated_input_radius(a, s.viscosity);
  const double chi_wanted = std::cbrt(phi / (M_PI / 6));
  const int L = static_cast<int>(std::lround(2 * a / chi_wanted));
  const auto r = calibration::simple_cubic_array_drag(ag, L, s);
  const double chi = 2 * a / L;
  const double K = r.drag_coefficient(a, s.viscosity),
               K_ref = calibration::sangani_acrivos_drag(chi);
  std::printf(
      "a = %g (a_g = %.4f) L = %3d phi = %.4f: K = %.4f  Sangani-Acrivos %.4f  error %+.2f %%\n", a,
      ag, L, M_PI / 6 * chi * chi * chi, K, K_ref, 100 * (K / K_ref - 1));
  std::fflush(stdout);
  return K / K_ref - 1;
}

// The requirement: within 2 % for phi = 0.01 - 0.2 at a = 6 dx.
TEST(SimpleCubicArraySweep, Resolution6WithinTwoPercent) {
  for (double phi : {0.01, 0.05, 0.1, 0.2})
    EXPECT_LT(std::abs(array_error(6.0, phi)), 0.02) << "phi " << phi;
}

// The error trend against resolution, reported; a = 4 and 8 dx are held to
// the same 2 % (the calibration is per resolution).
TEST(SimpleCubicArraySweep, Resolutions4And8) {
  for (double a : {4.0, 8.0})
    for (double phi : {0.01, 0.05, 0.1, 0.2})
      EXPECT_LT(std::abs(array_error(a, phi)), 0.02) << "a " << a << " phi " << phi;
}

}  // namespace
}  // namespace flocsim
