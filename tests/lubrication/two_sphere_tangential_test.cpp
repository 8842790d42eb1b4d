// The exact tangential resistance of two equal spheres (Jeffrey & Onishi's
// series, engine/lubrication/two_sphere_tangential.hpp) against what it is
// not computed from: an independent method's published values, the method of
// reflections far apart, and an independent computation of the near-contact
// forms.
#include "engine/lubrication/two_sphere_tangential.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace flocsim::lubrication {
namespace {

// Wilson's solution by Lamb's method, lambda = 1, as tabulated by Townsend
// (2023, Phys. Fluids 35, 127126; the table of his stokesian-dynamics code)
// at s' = r / a = 2.1, 2.5, 3 and 4: a computation independent of the
// twin-multipole series.
struct Tabulated {
  double xi;
  TangentialFunctions y;
};
constexpr Tabulated kWilson[] = {
    {0.1, {1.39300628, -0.659875260, -0.394506440, 0.617143953, 1.23302792, 0.101739905}},
    {0.5, {1.16486469, -0.401078913, -0.124149048, 0.297030705, 1.05273781, 0.0417153952}},
    {1.0, {1.09210175, -0.297175858, -0.0567464848, 0.185388140, 1.01798571, 0.0216646652}},
    {2.0, {1.04330302, -0.204476858, -0.0203314200, 0.0981522764, 1.00422573, 0.00845802368}},
};

// Each of the six functions of the series within 1e-4 of the table's.
void expect_series_matches(const Tabulated& w) {
  const auto y = equal_sphere_tangential_functions(w.xi);
  SCOPED_TRACE(w.xi);
  EXPECT_NEAR(y.YA11, w.y.YA11, 1e-4);
  EXPECT_NEAR(y.YA12, w.y.YA12, 1e-4);
  EXPECT_NEAR(y.YB11, w.y.YB11, 1e-4);
  EXPECT_NEAR(y.YB12, w.y.YB12, 1e-4);
  EXPECT_NEAR(y.YC11, w.y.YC11, 1e-4);
  EXPECT_NEAR(y.YC12, w.y.YC12, 1e-4);
}

TEST(TwoSphereTangential, AgreesWithWilsonsLambSolution) {
  for (const auto& w : kWilson) expect_series_matches(w);
}

// Far apart (x = a / r), the first reflections: sphere 2's Stokeslet moves
// the liquid at sphere 1 by (3/4) x U_2 across the line of centres, so
// Y^A_12 = -(3/4) x and, reflected back, Y^A_11 = 1 + (9/16) x^2; its rotlet
// moves it by x^2 a d x W_2 (Y^B_12 = (3/2) x^2) and turns it at -(1/2) x^3
// W_2 (Y^C_12 = (1/2) x^3). What sphere 1 sends out comes back from sphere 2
// held still as a Stokeslet, whose vorticity turns the liquid at sphere 1:
// by (9/16) x^3 (U_1 x d) / a for sphere 1 translating (Y^B_11 = -(9/8) x^3),
// by -(3/4) x^4 W_1 for it rotating (Y^C_11 = 1 + (3/4) x^4).
TEST(TwoSphereTangential, FarApartIsTheFirstReflections) {
  const double xi = 18, x = 1 / (2 + xi);  // r = 20 a
  const auto y = equal_sphere_tangential_functions(xi);
  EXPECT_NEAR(y.YA12, -0.75 * x, 2 * std::pow(x, 3));
  EXPECT_NEAR(y.YA11, 1 + 9.0 / 16 * x * x, 4 * std::pow(x, 4));
  EXPECT_NEAR(y.YB12, 1.5 * x * x, 4 * std::pow(x, 4));
  EXPECT_NEAR(y.YB11, -9.0 / 8 * std::pow(x, 3), 4 * std::pow(x, 5));
  EXPECT_NEAR(y.YC12, 0.5 * x * x * x, 2 * std::pow(x, 5));
  EXPECT_NEAR(y.YC11, 1 + 0.75 * std::pow(x, 4), 8 * std::pow(x, 6));
}

// At contact, Townsend's near-field forms (lubrication theory's ln(1/xi) and
// xi ln(1/xi) terms with the O(1) constants his own series gives, as
// tabulated at s' = 2.00001 and 2.0001 in his stokesian-dynamics code): an
// independent computation of the constants this series sums to, whose
// neglected O(xi) terms are below 1e-5 here.
constexpr Tabulated kTownsendNearContact[] = {
    {1e-5, {2.91713802, -2.19247292, -2.63932618, 2.87662308, 3.00544095, 0.548189445}},
    {1e-4, {2.53337384, -1.80870874, -2.06378065, 2.30107754, 2.54507545, 0.433110156}},
};

TEST(TwoSphereTangential, AtContactAgreesWithTownsendsNearFieldForms) {
  for (const auto& w : kTownsendNearContact) expect_series_matches(w);
}

// The modes are the functions' combinations: far apart a sliding or rolling
// sphere feels Stokes's drag or torque alone.
TEST(TwoSphereTangential, ModesFarApartAreOneSphere) {
  EXPECT_NEAR(sliding_pair_force(200), 1, 0.01);
  EXPECT_NEAR(rolling_pair_torque(200), 1, 1e-5);
  EXPECT_NEAR(sliding_pair_torque(200), 0, 1e-4);
  EXPECT_NEAR(rolling_pair_force(200), 0, 1e-4);
}

TEST(TwoSphereTangential, RefusesAGapThatIsNotPositive) {
  EXPECT_THROW(equal_sphere_tangential_functions(0), std::invalid_argument);
  EXPECT_THROW(equal_sphere_tangential_functions(-0.1), std::invalid_argument);
  EXPECT_THROW(equal_sphere_tangential_functions(NAN), std::invalid_argument);
}

}  // namespace
}  // namespace flocsim::lubrication
